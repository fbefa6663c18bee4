//! Exact sums: the film's accumulators are integers in units of 2⁻⁶⁰ (i128 fixed point),
//! so adding is associative and the sum of a pixel's samples does not depend on the order
//! or the grouping in which they arrive. That is what makes sample-range parts merge bit
//! for bit into the render of the whole range (`prism merge`): f64 sums of the same
//! samples, grouped as 0..256 + 256..512 instead of one run, differ in the last bit.
//!
//! Each sample's value is rounded once, to the nearest multiple of 2⁻⁶⁰ ≈ 8.7·10⁻¹⁹
//! (ties to even); a sum holds up to 2⁶⁷ ≈ 1.5·10²⁰. A single value of magnitude 2⁶⁶ or
//! more is not representable (`is_representable`), nor, on a splatting film, a sample colour
//! whose taps reach 2⁴³ (`SplatBuffer::admits`): callers treat them like non-finite values.

/// Fractional bits of the fixed point.
pub const FRACTION_BITS: u32 = 60;
/// Largest magnitude a single added value may have (exclusive), 2⁶⁶.
pub const MAX_VALUE: f64 = 73_786_976_294_838_206_464.0;

/// Bits of the low limb of `SplatBuffer::sums` and `SurfaceSums` (the high limb counts units
/// of 2⁻²⁰).
pub(crate) const LOW_LIMB_BITS: u32 = 40;
/// 2^(FRACTION_BITS − LOW_LIMB_BITS): the scale of the high limb.
pub(crate) const HIGH_LIMB_SCALE: f64 = (1u64 << (FRACTION_BITS - LOW_LIMB_BITS)) as f64;
/// 2^LOW_LIMB_BITS.
pub(crate) const LOW_LIMB_SCALE: f64 = (1u64 << LOW_LIMB_BITS) as f64;
/// 1.5 · 2⁵²: x + MAGIC rounds x (|x| < 2⁵¹) to an integer (ties to even) that the low
/// bits of the sum's representation hold.
pub(crate) const MAGIC: f64 = 6_755_399_441_055_744.0;

/// A sum of f64 values in fixed point (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FixedSum(i128);

impl FixedSum {
    pub const ZERO: FixedSum = FixedSum(0);

    /// Whether `v` can be added (finite and |v| < `MAX_VALUE`).
    #[inline(always)]
    pub fn is_representable(v: f64) -> bool {
        v.abs() < MAX_VALUE
    }

    /// `v` rounded to the nearest multiple of 2⁻⁶⁰ (ties to even); zero for a value that
    /// is not representable (callers check `is_representable` where that matters).
    #[inline(always)]
    pub fn from_f64(v: f64) -> FixedSum {
        let x = v * HIGH_LIMB_SCALE;
        if x.abs() < (1u64 << 51) as f64 {
            let (high, low) = split_limbs(x);
            return FixedSum((i128::from(high) << LOW_LIMB_BITS) + i128::from(low));
        }
        Self::from_f64_wide(v)
    }

    /// `from_f64` for |v| ≥ 2³¹ (and non-representable values): from the bits.
    #[cold]
    fn from_f64_wide(v: f64) -> FixedSum {
        if !Self::is_representable(v) {
            return FixedSum::ZERO;
        }
        let bits = v.to_bits();
        let exponent = ((bits >> 52) & 0x7ff) as i32;
        let mantissa = i128::from((bits & ((1u64 << 52) - 1)) | (1u64 << 52));
        // 2³¹ ≤ |v| < 2⁶⁶ here, so v·2⁶⁰ = mantissa · 2^shift with 39 ≤ shift ≤ 73: no
        // rounding, and below 2¹²⁶.
        let shift = exponent - 1075 + FRACTION_BITS as i32;
        debug_assert!((39..=73).contains(&shift), "shift {shift} for {v}");
        let magnitude = mantissa << shift;
        FixedSum(if v < 0.0 { -magnitude } else { magnitude })
    }

    /// The sum as the nearest f64 (ties to even).
    #[inline]
    pub fn to_f64(self) -> f64 {
        if let Ok(small) = i64::try_from(self.0) {
            // One conversion instruction; the power-of-two scale is exact.
            return small as f64 * pow2(-(FRACTION_BITS as i32));
        }
        // `i128 as f64` is a library call; instead keep the top 62 bits with a sticky bit
        // for the rest (so u64 → f64 rounds as the whole would) and scale.
        let magnitude = self.0.unsigned_abs();
        let shift = 128 - magnitude.leading_zeros() - 62;
        let sticky = u64::from(magnitude & ((1u128 << shift) - 1) != 0);
        let kept = (magnitude >> shift) as u64 | sticky;
        let f = kept as f64 * pow2(shift as i32 - FRACTION_BITS as i32);
        if self.0 < 0 {
            -f
        } else {
            f
        }
    }

    /// The integer in units of 2⁻⁶⁰ (what partial files store).
    pub fn to_bits(self) -> i128 {
        self.0
    }

    pub fn from_bits(bits: i128) -> FixedSum {
        FixedSum(bits)
    }

    /// The sum of the limbs a `SplatBuffer` kept (high limb in units of 2⁻²⁰, low in 2⁻⁶⁰).
    #[inline]
    pub(crate) fn from_limbs(high: i64, low: i64) -> FixedSum {
        FixedSum((i128::from(high) << LOW_LIMB_BITS) + i128::from(low))
    }

    /// The limbs of this single value, for a `SplatBuffer` (inverse of `from_limbs`).
    #[inline]
    pub(crate) fn to_limbs(self) -> (i64, i64) {
        let low = (self.0 & ((1i128 << LOW_LIMB_BITS) - 1)) as i64;
        ((self.0 >> LOW_LIMB_BITS) as i64, low)
    }
}

/// 2^e for a normal-range exponent.
#[inline(always)]
fn pow2(e: i32) -> f64 {
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// x (|x| < 2⁵¹, in units of 2⁻²⁰) as round(x) and round((x − round(x)) · 2⁴⁰): together
/// round-to-nearest-even of x · 2⁴⁰, since round(x) · 2⁴⁰ is even. Every step is exact
/// but the two roundings, which the magic-number additions do.
#[inline(always)]
pub(crate) fn split_limbs(x: f64) -> (i64, i64) {
    let t = x + MAGIC;
    let high = t.to_bits() as i64 - MAGIC.to_bits() as i64;
    let rest = (x - (t - MAGIC)) * LOW_LIMB_SCALE;
    let low = (rest + MAGIC).to_bits() as i64 - MAGIC.to_bits() as i64;
    (high, low)
}

impl std::ops::AddAssign for FixedSum {
    /// Wrapping: integer addition modulo 2¹²⁸ stays associative even past the range.
    #[inline(always)]
    fn add_assign(&mut self, other: FixedSum) {
        self.0 = self.0.wrapping_add(other.0);
    }
}

impl std::ops::Add for FixedSum {
    type Output = FixedSum;
    #[inline(always)]
    fn add(mut self, other: FixedSum) -> FixedSum {
        self += other;
        self
    }
}

impl std::iter::Sum for FixedSum {
    fn sum<I: Iterator<Item = FixedSum>>(iter: I) -> FixedSum {
        iter.fold(FixedSum::ZERO, |a, b| a + b)
    }
}

/// Three fixed sums (XYZ, RGB or a vector).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FixedSum3(pub [FixedSum; 3]);

impl FixedSum3 {
    #[inline(always)]
    pub fn add_f64(&mut self, v: glam::DVec3) {
        self.0[0] += FixedSum::from_f64(v.x);
        self.0[1] += FixedSum::from_f64(v.y);
        self.0[2] += FixedSum::from_f64(v.z);
    }

    #[inline]
    pub fn to_dvec3(self) -> glam::DVec3 {
        glam::DVec3::new(self.0[0].to_f64(), self.0[1].to_f64(), self.0[2].to_f64())
    }
}

impl std::ops::AddAssign for FixedSum3 {
    #[inline(always)]
    fn add_assign(&mut self, other: FixedSum3) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact(v: f64) -> i128 {
        // Reference: v · 2⁶⁰ rounded to nearest, ties to even, through the bits.
        let scaled = v * (FRACTION_BITS as f64).exp2();
        let r = scaled.round_ties_even();
        r as i128
    }

    #[test]
    fn rounds_to_the_nearest_multiple() {
        for v in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            -0.1,
            1e-18,
            3.7e-19,
            -4.4e-19,
            1e-300,
            123_456.789,
            -2.0f64.powi(31) + 0.25,
            2.0f64.powi(31),
            5.0e11,
            -8.0e12,
            6.0e19,
        ] {
            assert_eq!(FixedSum::from_f64(v).to_bits(), exact(v), "{v}");
        }
        // Halfway between multiples: ties to even.
        let half = (-61f64).exp2();
        assert_eq!(FixedSum::from_f64(half).to_bits(), 0);
        assert_eq!(FixedSum::from_f64(3.0 * half).to_bits(), 2);
        assert_eq!(FixedSum::from_f64(-3.0 * half).to_bits(), -2);
    }

    #[test]
    fn out_of_range_values_are_zero_and_flagged() {
        for v in [f64::NAN, f64::INFINITY, -f64::INFINITY, MAX_VALUE, -1e20] {
            assert!(!FixedSum::is_representable(v));
            assert_eq!(FixedSum::from_f64(v), FixedSum::ZERO);
        }
        assert!(FixedSum::is_representable(MAX_VALUE * 0.999));
    }

    #[test]
    fn sums_do_not_depend_on_grouping() {
        let values: Vec<f64> = (0..1000)
            .map(|k| ((k as f64) * 0.618_033_988_7).fract() * 10f64.powi(k % 9 - 4))
            .collect();
        let whole: FixedSum = values.iter().map(|&v| FixedSum::from_f64(v)).sum();
        let first: FixedSum = values[..377].iter().map(|&v| FixedSum::from_f64(v)).sum();
        let second: FixedSum = values[377..]
            .iter()
            .rev()
            .map(|&v| FixedSum::from_f64(v))
            .sum();
        assert_eq!(whole, first + second);
        // And it is the exact sum to within the rounding of each value.
        let f64_sum: f64 = values.iter().sum();
        assert!((whole.to_f64() - f64_sum).abs() <= 1e-12 * f64_sum.abs());
    }

    #[test]
    fn converts_back_to_the_nearest_f64() {
        for bits in [
            0i128,
            1,
            -1,
            (1i128 << 63) - 1,
            1i128 << 63,
            -(1i128 << 63) - 1,
            (1i128 << 100) + 1,
            (1i128 << 100) + (1i128 << 47),
            (1i128 << 100) + (1i128 << 47) + 1,
            -((1i128 << 120) + (3i128 << 66)),
            i128::MAX,
            i128::MIN + 1,
        ] {
            let want = bits as f64 * (-(FRACTION_BITS as f64)).exp2();
            assert_eq!(FixedSum::from_bits(bits).to_f64(), want, "{bits}");
        }
    }

    #[test]
    fn limbs_round_trip() {
        for v in [0.3, -0.3, 1e6, -7.25e9, 2.0f64.powi(42)] {
            let f = FixedSum::from_f64(v);
            let (h, l) = f.to_limbs();
            assert_eq!(FixedSum::from_limbs(h, l), f, "{v}");
            let (h, l) = split_limbs(v.clamp(-1e9, 1e9) * HIGH_LIMB_SCALE);
            assert_eq!(
                FixedSum::from_limbs(h, l),
                FixedSum::from_f64(v.clamp(-1e9, 1e9)),
                "{v}"
            );
        }
    }
}
