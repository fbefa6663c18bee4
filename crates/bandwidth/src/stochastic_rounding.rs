//! Deterministic stochastic rounding of per-pixel sample counts: ⌊x⌋ + [u < x − ⌊x⌋] with u
//! hashed from (seed, pixel), so the expected count is x (a plan keeps its budget on
//! average, no pixel's fraction is lost to rounding down) and a plan is the same on every run.

/// SplitMix64 (Steele et al. 2014): a well-mixed 64-bit hash of the pixel and the seed.
fn split_mix_64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// x ≥ 0 rounded up with probability x − ⌊x⌋, decided by (seed, index).
pub fn round_stochastic(x: f64, seed: u64, index: u64) -> u32 {
    let floor = x.floor();
    let u = (split_mix_64(seed ^ split_mix_64(index)) >> 11) as f64 / (1u64 << 53) as f64;
    let up = u < x - floor;
    (floor as u32).saturating_add(u32::from(up))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_stay_and_fractions_round_up_in_proportion() {
        for i in 0..100 {
            assert_eq!(round_stochastic(7.0, 3, i), 7);
        }
        let n = 100_000u64;
        let total: u64 = (0..n).map(|i| u64::from(round_stochastic(2.3, 9, i))).sum();
        let mean = total as f64 / n as f64;
        // Binomial: s.e. of the mean = √(0.3·0.7/n) ≈ 0.00145; 4 s.e.
        assert!((mean - 2.3).abs() < 0.006, "{mean}");
        assert_eq!(round_stochastic(2.3, 9, 17), round_stochastic(2.3, 9, 17));
    }
}
