//! Integer hashes shared by the samplers.

/// The SplitMix64 finaliser (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
/// generators"): a bijection of u64 whose output bits each depend on every input bit.
#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Odd constant that spreads a dimension index over all 64 bits before it is mixed with a
/// stream key (the golden-ratio-like increment of Steele et al.'s `mixGamma`).
pub(crate) const DIMENSION_SPREAD: u64 = 0xD6E8_FEB8_6659_FD93;

/// A pixel as one 64-bit word: y in the high half, x in the low half.
#[inline]
pub(crate) fn pixel_word(pixel: glam::UVec2) -> u64 {
    (u64::from(pixel.y) << 32) | u64::from(pixel.x)
}

/// The top 24 bits of a 32-bit fixed-point fraction as an f32 in [0, 1): exactly
/// representable, so the largest value is 1 − 2⁻²⁴ and never rounds up to 1.
#[inline]
pub(crate) fn u32_to_unit_f32(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}
