//! A deterministic per-pixel sampler: every sample value is a hash of (seed, pixel, sample
//! index, dimension), so a pixel's samples never depend on which thread or tile draws them
//! (DESIGN.md "Deterministic"). Independent uniform samples, not low-discrepancy: it drives
//! the tests and simple renders until the Sobol sampler (pbrt-v4 §8.7) replaces it.
//!
//! The hash is the SplitMix64 finaliser (Steele, Lea & Flood 2014, "Fast splittable
//! pseudorandom number generators"), applied to each input word in turn.

use glam::{UVec2, Vec2};

/// Seeds per-pixel sample streams.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelSampler {
    seed: u64,
}

/// The samples of one pixel sample (one camera path): consecutive dimensions.
#[derive(Clone, Copy, Debug)]
pub struct SampleStream {
    key: u64,
    dimension: u32,
}

#[inline]
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Top 24 bits of `bits` as an f32 in [0, 1) (exactly representable, never 1).
#[inline]
fn to_unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

impl PixelSampler {
    pub fn new(seed: u64) -> Self {
        Self { seed }
    }

    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The stream of sample `sample_index` of `pixel`.
    #[inline]
    pub fn stream(&self, pixel: UVec2, sample_index: u32) -> SampleStream {
        let pixel_word = (u64::from(pixel.y) << 32) | u64::from(pixel.x);
        let key = mix64(mix64(mix64(self.seed) ^ pixel_word) ^ u64::from(sample_index));
        SampleStream { key, dimension: 0 }
    }
}

impl SampleStream {
    /// The next dimension, uniform in [0, 1).
    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        let bits = mix64(self.key ^ u64::from(self.dimension).wrapping_mul(0xD6E8_FEB8_6659_FD93));
        self.dimension += 1;
        to_unit_f32(bits)
    }

    /// The next two dimensions.
    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.get_1d();
        Vec2::new(x, self.get_1d())
    }

    /// Dimensions used so far.
    pub fn dimension(&self) -> u32 {
        self.dimension
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_values_and_values_in_unit_interval() {
        let s = PixelSampler::new(7);
        let mut a = s.stream(UVec2::new(3, 4), 5);
        let mut b = s.stream(UVec2::new(3, 4), 5);
        for _ in 0..100 {
            let (x, y) = (a.get_1d(), b.get_1d());
            assert_eq!(x.to_bits(), y.to_bits());
            assert!((0.0..1.0).contains(&x));
        }
    }

    #[test]
    fn streams_differ_by_pixel_index_and_seed() {
        let v = |seed, px: u32, i| {
            PixelSampler::new(seed)
                .stream(UVec2::new(px, 0), i)
                .get_1d()
        };
        assert_ne!(v(1, 0, 0), v(1, 1, 0));
        assert_ne!(v(1, 0, 0), v(1, 0, 1));
        assert_ne!(v(1, 0, 0), v(2, 0, 0));
    }

    #[test]
    fn mean_and_variance_are_uniform() {
        let s = PixelSampler::new(42);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for i in 0..n {
            let x = f64::from(s.stream(UVec2::new(i % 317, i / 317), i % 3).get_1d());
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / f64::from(n);
        let var = sum2 / f64::from(n) - mean * mean;
        // Standard error of the mean of U(0,1): sqrt(1/12 / n) ≈ 6.5e-4; allow 5σ.
        assert!((mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / f64::from(n)).sqrt());
        // Standard error of the sample variance of U(0,1): sqrt((μ₄ − σ⁴) / n) with
        // μ₄ = 1/80, σ⁴ = 1/144 (≈ 1.7e-4 here); allow 5σ.
        let variance_se = ((1.0 / 80.0 - 1.0 / 144.0) / f64::from(n)).sqrt();
        assert!((var - 1.0 / 12.0).abs() < 5.0 * variance_se, "{var}");
    }
}
