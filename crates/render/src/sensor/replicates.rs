//! Randomised quasi-Monte Carlo with independent replicates for sensor points (Owen 1997,
//! "Scrambled net variance for integrals of smooth functions"; L'Ecuyer & Lemieux 2002,
//! "Recent advances in randomized quasi-Monte Carlo methods", §2.2).
//!
//! A point's samples are split over `R` replicates; replicate r draws the first n_r points
//! of its own Owen-scrambled Sobol sequence (`SamplerKind::Sobol` seeded per replicate, so
//! the scrambles are independent). Each replicate mean is unbiased; their average is the
//! reading, and the spread of the R replicate means gives its standard error:
//!
//! s.e.² = Σ_r (m_r − m̄)² / (R (R − 1)),
//!
//! unbiased for the variance of m̄ even when the n_r differ by one (the means share their
//! expectation; their variances may differ). The plain s²/n of all samples would not be
//! honest here: scrambled Sobol points are not independent (their variance is lower, which
//! is the point), so only the replicates' spread measures it.
//!
//! Why: at a sensor the first dimensions (wavelength, the cosine direction, the first
//! bounce) carry most of the variance, and stratifying them with a (0, m, 2)-net removes
//! much of it (docs/lighting.md "Speed": 2× less variance per sample than independent
//! samples on the furnished-room benchmark with 32 replicates, 5× with one long sequence).
//! R = 32 keeps 31 degrees of freedom for the standard error (a t₃₁ statistic: its z-scores
//! have variance 31/29 ≈ 1.07) while each replicate still holds enough points to stratify
//! (~300 at 1 % on the benchmark; 16 replicates of twice as many points give ~15 % less
//! variance, 8 of four times ~35 %, at the price of a noisier standard error).

use crate::film::FixedSum;
use crate::sampler::{PixelSampler, SamplerKind};

/// Replicates per point (see the module comment). A point with fewer samples than this
/// uses one sample per replicate: plain Monte Carlo with s²/n.
pub const SENSOR_REPLICATES: u32 = 32;

/// The sampler of replicate `r` of a sensor seeded `sensor_seed`.
pub fn replicate_sampler(sensor_seed: u64, r: u32) -> PixelSampler {
    // SplitMix64 finaliser (Steele et al. 2014) of the seed and the replicate.
    let mut z = sensor_seed ^ (u64::from(r) + 1).wrapping_mul(0xD6E8_FEB8_6659_FD93);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    PixelSampler::with_kind(SamplerKind::Sobol, z ^ (z >> 31))
}

/// Replicates used for `total` samples: `SENSOR_REPLICATES`, or fewer when there are fewer
/// samples.
pub fn replicates_for(total: u32) -> u32 {
    total.clamp(1, SENSOR_REPLICATES)
}

/// Samples of replicate `r` when a point has `total` samples over `replicates`: the first
/// `total mod R` replicates take one more, so growing `total` only appends samples.
pub fn replicate_count(total: u32, replicates: u32, r: u32) -> u32 {
    total / replicates + u32::from(r < total % replicates)
}

/// Per-replicate sums of one point's samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReplicateStats {
    /// Exact (`FixedSum`), so sample-range parts merge into the whole measurement's sums
    /// bit for bit.
    sums: Vec<FixedSum>,
    counts: Vec<u64>,
}

impl ReplicateStats {
    pub fn new(replicates: u32) -> Self {
        Self {
            sums: vec![FixedSum::ZERO; replicates as usize],
            counts: vec![0; replicates as usize],
        }
    }

    /// Adds `count` samples summing to `sum` to replicate `r`.
    pub fn add(&mut self, r: u32, sum: FixedSum, count: u64) {
        self.sums[r as usize] += sum;
        self.counts[r as usize] += count;
    }

    /// Samples in all replicates.
    pub fn samples(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// Σ of each replicate's samples.
    pub fn sums(&self) -> &[FixedSum] {
        &self.sums
    }

    /// Samples of each replicate.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// Replicates with these sums and counts (as `sums` and `counts` gave them); `None`
    /// when the lengths differ.
    pub fn from_parts(sums: Vec<FixedSum>, counts: Vec<u64>) -> Option<Self> {
        (sums.len() == counts.len()).then_some(Self { sums, counts })
    }

    /// Adds the samples of `other`, other samples of the same replicates (a sample range
    /// of the same measurement); `None` when the replicate counts differ.
    pub fn merge(&mut self, other: &ReplicateStats) -> Option<()> {
        if self.sums.len() != other.sums.len() {
            return None;
        }
        for (r, (s, n)) in other.sums.iter().zip(&other.counts).enumerate() {
            self.add(r as u32, *s, *n);
        }
        Some(())
    }

    fn means(&self) -> impl Iterator<Item = f64> + '_ {
        self.sums
            .iter()
            .zip(&self.counts)
            .filter(|(_, &n)| n > 0)
            .map(|(s, &n)| s.to_f64() / n as f64)
    }

    /// The reading: the average of the replicate means (0 before any sample).
    pub fn mean(&self) -> f64 {
        let (sum, n) = self.means().fold((0.0, 0usize), |(s, n), m| (s + m, n + 1));
        if n == 0 {
            0.0
        } else {
            sum / n as f64
        }
    }

    /// Standard error of `mean` from the spread of the replicate means (0 with fewer than
    /// two non-empty replicates).
    pub fn std_error(&self) -> f64 {
        let mean = self.mean();
        let (ss, n) = self
            .means()
            .fold((0.0, 0usize), |(s, n), m| (s + (m - mean).powi(2), n + 1));
        if n < 2 {
            return 0.0;
        }
        (ss / ((n - 1) * n) as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replicate_counts_sum_to_the_total_and_only_grow() {
        for total in [1u32, 5, 16, 17, 100, 1000] {
            let r = replicates_for(total);
            let counts: Vec<u32> = (0..r).map(|k| replicate_count(total, r, k)).collect();
            assert_eq!(counts.iter().sum::<u32>(), total);
            assert!(counts.iter().max().unwrap() - counts.iter().min().unwrap() <= 1);
            if total >= SENSOR_REPLICATES {
                for k in 0..r {
                    assert!(replicate_count(total + 7, r, k) >= counts[k as usize]);
                }
            }
        }
    }

    #[test]
    fn mean_and_standard_error_of_replicate_means() {
        let mut s = ReplicateStats::new(4);
        // Replicate means 1, 2, 3, 6 (mean 3, sample variance 14/3).
        for (r, (sum, n)) in [(2.0, 2), (4.0, 2), (9.0, 3), (12.0, 2)]
            .into_iter()
            .enumerate()
        {
            s.add(r as u32, FixedSum::from_f64(sum), n);
        }
        assert_eq!(s.samples(), 9);
        assert!((s.mean() - 3.0).abs() < 1e-12);
        assert!((s.std_error() - (14.0 / 3.0 / 4.0f64).sqrt()).abs() < 1e-12);
        // Empty replicates do not count.
        let mut t = ReplicateStats::new(3);
        t.add(0, FixedSum::from_f64(5.0), 1);
        assert_eq!((t.mean(), t.std_error()), (5.0, 0.0));
        assert_eq!(ReplicateStats::new(2).mean(), 0.0);
    }
}
