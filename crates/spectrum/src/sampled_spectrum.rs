//! `SampledSpectrum`: a spectral quantity at the four wavelengths a path carries
//! (pbrt-v4 §4.5.4). Every operation is a fixed loop over four f32 lanes with no branches on
//! lane values beyond selects, so LLVM turns it into SIMD; nothing allocates.

use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

/// Number of wavelengths carried together (hero + 3 rotated).
pub const N_SPECTRUM_SAMPLES: usize = 4;

/// Values of a spectral quantity (radiance, throughput, pdf, …) at four wavelengths.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C)]
pub struct SampledSpectrum {
    pub values: [f32; N_SPECTRUM_SAMPLES],
}

impl SampledSpectrum {
    #[inline]
    pub const fn new(values: [f32; N_SPECTRUM_SAMPLES]) -> Self {
        Self { values }
    }

    /// The same value in every lane.
    #[inline]
    pub const fn splat(value: f32) -> Self {
        Self {
            values: [value; N_SPECTRUM_SAMPLES],
        }
    }

    #[inline]
    pub const fn zero() -> Self {
        Self::splat(0.0)
    }

    #[inline]
    pub const fn one() -> Self {
        Self::splat(1.0)
    }

    /// Builds each lane from its index.
    #[inline]
    pub fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        Self {
            values: [f(0), f(1), f(2), f(3)],
        }
    }

    /// Applies `f` to every lane.
    #[inline]
    pub fn map(self, mut f: impl FnMut(f32) -> f32) -> Self {
        Self {
            values: self.values.map(&mut f),
        }
    }

    /// Combines two spectra lane by lane.
    #[inline]
    pub fn zip_map(self, other: Self, mut f: impl FnMut(f32, f32) -> f32) -> Self {
        let mut out = self;
        for i in 0..N_SPECTRUM_SAMPLES {
            out.values[i] = f(self.values[i], other.values[i]);
        }
        out
    }

    #[inline]
    pub fn to_array(self) -> [f32; N_SPECTRUM_SAMPLES] {
        self.values
    }

    #[inline]
    pub fn max_component(self) -> f32 {
        let v = self.values;
        v[0].max(v[1]).max(v[2].max(v[3]))
    }

    #[inline]
    pub fn min_component(self) -> f32 {
        let v = self.values;
        v[0].min(v[1]).min(v[2].min(v[3]))
    }

    #[inline]
    pub fn sum(self) -> f32 {
        let v = self.values;
        (v[0] + v[1]) + (v[2] + v[3])
    }

    /// Mean over the four lanes: with `f / pdf` in the lanes this is the hero-wavelength
    /// estimator (1/4) Σᵢ f(λᵢ)/p(λᵢ) (see `SampledWavelengths`).
    #[inline]
    pub fn average(self) -> f32 {
        self.sum() * (1.0 / N_SPECTRUM_SAMPLES as f32)
    }

    /// True when every lane is exactly zero.
    #[inline]
    pub fn is_black(self) -> bool {
        self.values.iter().fold(true, |acc, &v| acc & (v == 0.0))
    }

    /// True when any lane is NaN or ±∞.
    #[inline]
    pub fn has_non_finite(self) -> bool {
        self.values
            .iter()
            .fold(false, |acc, &v| acc | !v.is_finite())
    }

    #[inline]
    pub fn exp(self) -> Self {
        self.map(f32::exp)
    }

    #[inline]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }

    /// Replaces negative lanes (and NaN) by zero.
    #[inline]
    pub fn clamp_zero(self) -> Self {
        self.map(|v| if v > 0.0 { v } else { 0.0 })
    }

    #[inline]
    pub fn clamp(self, low: f32, high: f32) -> Self {
        self.map(|v| v.clamp(low, high))
    }

    #[inline]
    pub fn min(self, other: Self) -> Self {
        self.zip_map(other, f32::min)
    }

    #[inline]
    pub fn max(self, other: Self) -> Self {
        self.zip_map(other, f32::max)
    }

    /// Lane-wise `self / divisor`, zero in lanes where the divisor is zero
    /// (pbrt-v4 `SafeDiv`: terminated wavelengths have pdf 0 and must contribute 0).
    #[inline]
    pub fn safe_div(self, divisor: Self) -> Self {
        self.zip_map(divisor, |num, den| if den != 0.0 { num / den } else { 0.0 })
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = f32;
    #[inline]
    fn index(&self, lane: usize) -> &f32 {
        &self.values[lane]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    #[inline]
    fn index_mut(&mut self, lane: usize) -> &mut f32 {
        &mut self.values[lane]
    }
}

impl From<[f32; N_SPECTRUM_SAMPLES]> for SampledSpectrum {
    #[inline]
    fn from(values: [f32; N_SPECTRUM_SAMPLES]) -> Self {
        Self { values }
    }
}

impl Neg for SampledSpectrum {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.map(|v| -v)
    }
}

/// Implements `op` between two spectra and between a spectrum and an f32 (both orders for
/// the commutative case), plus the compound-assignment forms.
macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign_method:ident, $op:tt) => {
        impl $trait for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $method(self, rhs: Self) -> Self {
                self.zip_map(rhs, |a, b| a $op b)
            }
        }
        impl $trait<f32> for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $method(self, rhs: f32) -> Self {
                self.map(|a| a $op rhs)
            }
        }
        impl $trait<SampledSpectrum> for f32 {
            type Output = SampledSpectrum;
            #[inline]
            fn $method(self, rhs: SampledSpectrum) -> SampledSpectrum {
                rhs.map(|b| self $op b)
            }
        }
        impl $assign_trait for SampledSpectrum {
            #[inline]
            fn $assign_method(&mut self, rhs: Self) {
                *self = *self $op rhs;
            }
        }
        impl $assign_trait<f32> for SampledSpectrum {
            #[inline]
            fn $assign_method(&mut self, rhs: f32) {
                *self = *self $op rhs;
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, +);
lane_op!(Sub, sub, SubAssign, sub_assign, -);
lane_op!(Mul, mul, MulAssign, mul_assign, *);
lane_op!(Div, div, DivAssign, div_assign, /);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_lane_wise() {
        let a = SampledSpectrum::new([1.0, 2.0, 3.0, 4.0]);
        let b = SampledSpectrum::new([2.0, 2.0, 2.0, 8.0]);
        assert_eq!((a + b).values, [3.0, 4.0, 5.0, 12.0]);
        assert_eq!((a - b).values, [-1.0, 0.0, 1.0, -4.0]);
        assert_eq!((a * b).values, [2.0, 4.0, 6.0, 32.0]);
        assert_eq!((a / b).values, [0.5, 1.0, 1.5, 0.5]);
        assert_eq!((a * 2.0).values, [2.0, 4.0, 6.0, 8.0]);
        assert_eq!((2.0 * a).values, [2.0, 4.0, 6.0, 8.0]);
        assert_eq!((12.0 / a).values, [12.0, 6.0, 4.0, 3.0]);
        assert_eq!((a - 1.0).values, [0.0, 1.0, 2.0, 3.0]);
        assert_eq!((-a).values, [-1.0, -2.0, -3.0, -4.0]);
        let mut c = a;
        c += b;
        c -= 1.0;
        c *= 2.0;
        c /= b;
        assert_eq!(c.values, [2.0, 3.0, 4.0, 2.75]);
        c[3] = 7.0;
        assert_eq!(c[3], 7.0);
    }

    #[test]
    fn reductions_and_predicates() {
        let a = SampledSpectrum::new([1.0, -2.0, 5.0, 4.0]);
        assert_eq!(a.max_component(), 5.0);
        assert_eq!(a.min_component(), -2.0);
        assert_eq!(a.average(), 2.0);
        assert!(!a.is_black());
        assert!(SampledSpectrum::zero().is_black());
        assert!(!a.has_non_finite());
        assert!(SampledSpectrum::new([0.0, f32::NAN, 0.0, 0.0]).has_non_finite());
        assert!(SampledSpectrum::new([0.0, 0.0, f32::INFINITY, 0.0]).has_non_finite());
        assert_eq!(a.clamp_zero().values, [1.0, 0.0, 5.0, 4.0]);
        assert_eq!(
            SampledSpectrum::splat(f32::NAN).clamp_zero(),
            SampledSpectrum::zero()
        );
        assert_eq!(
            SampledSpectrum::splat(4.0).sqrt(),
            SampledSpectrum::splat(2.0)
        );
        assert_eq!(SampledSpectrum::zero().exp(), SampledSpectrum::one());
    }

    #[test]
    fn safe_div_is_zero_where_the_divisor_is_zero() {
        let num = SampledSpectrum::new([1.0, 2.0, 3.0, 4.0]);
        let den = SampledSpectrum::new([2.0, 0.0, -0.0, 4.0]);
        assert_eq!(num.safe_div(den).values, [0.5, 0.0, 0.0, 1.0]);
    }
}
