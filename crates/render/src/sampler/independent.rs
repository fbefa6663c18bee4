//! The independent sampler: every value is SplitMix64 of (seed, pixel, sample index,
//! dimension), applied to each input word in turn — uniform, uncorrelated, no
//! stratification.

use super::hash::{mix64, DIMENSION_SPREAD};

/// The key of one pixel sample from the key of its pixel.
#[inline]
pub(crate) fn sample_key(pixel_key: u64, sample_index: u32) -> u64 {
    mix64(pixel_key ^ u64::from(sample_index))
}

/// Dimension `dimension` of the sample with `key`, as a 32-bit fraction.
#[inline(always)]
pub(crate) fn value(key: u64, dimension: u32) -> u32 {
    (mix64(key ^ u64::from(dimension).wrapping_mul(DIMENSION_SPREAD)) >> 32) as u32
}
