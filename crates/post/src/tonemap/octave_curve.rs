//! A smooth positive curve f: x ↦ y evaluated in registers with AVX-512, one polynomial
//! per binary octave of x, for luminance curves that do not split into an exponent
//! factor and a mantissa factor (drago03's eq. 4; a pure power uses
//! [`super::power_curve`]): with x = 2^e · (1.5 + s), s ∈ [−½, ½) taken from the 23
//! mantissa bits, f(x) ≈ Σ_j c_j(e) s^j, where
//!
//! - the coefficients c_j(e) of each octave come from a 32-entry table indexed by the
//!   biased exponent modulo 32 (one two-register `vpermt2ps` per coefficient, no memory
//!   load per pixel), so the curve's domain [lo, hi] may span at most 32 binary exponents
//!   ([`OctaveCurve::new`] returns `None` otherwise, and where the ISA is not AVX-512,
//!   where the caller keeps its memory table);
//! - the polynomial has degree [`TERMS`] − 1 = 9, interpolating f at the Chebyshev nodes
//!   of the octave in f64. A whole octave is a wide segment (relative width 1, against
//!   1/64 for [`super::curve_table`]), so the degree is high; centring s on the octave's
//!   middle keeps the monomial coefficients decreasing (≈ (2/3)^j for a curve like 1/x),
//!   so Horner's rule in f32 loses little. Measured for eq. 4 (b = 0.85, 34 octaves
//!   below L_wmax): degree 8 fits to 2.5e-7 relative, degree 9 to 4.2e-8. The fit is
//!   checked at build time against the formula and refused (`None`) above
//!   [`MAX_FIT_ERROR`].
//!
//! The scalar [`OctaveCurve::eval`] performs the same operations in the same order
//! (`f32::mul_add` for each fused multiply-add) as the 16-lane `eval16` (in
//! `kernels/avx512.rs`), so both paths give the same bits.

use super::curve_table::{chebyshev_nodes, poly_through, register_exponent_range};

/// Coefficients per octave (degree 9).
pub const TERMS: usize = 10;
pub(super) const MANTISSA_MASK: u32 = 0x7f_ffff;
/// The bits of 1.0: the mantissa under them is m ∈ [1, 2), and s = m − 1.5 is exact
/// (both are multiples of 2^−23 and |s| ≤ ½).
pub(super) const ONE_BITS: u32 = 0x3f80_0000;
/// Largest relative error of the fitted polynomials (in f64, before rounding to f32)
/// accepted.
pub const MAX_FIT_ERROR: f64 = 1e-7;

pub(crate) struct OctaveCurve {
    /// `coeffs[j][b % 32]`: coefficient of s^j on the octave of biased exponent b.
    pub(super) coeffs: [[f32; 32]; TERMS],
    pub(super) lo: f32,
    pub(super) hi: f32,
}

impl OctaveCurve {
    /// f(x) for x ∈ [lo, hi] (0 < lo ≤ hi, both normal), arguments clamped to that
    /// range; `None` where the range spans more than 32 binary exponents, a fit misses
    /// [`MAX_FIT_ERROR`] or is not finite, or `simd` does not allow AVX-512.
    pub fn new(
        simd: prism_cpu::Simd,
        lo: f32,
        hi: f32,
        f: impl Fn(f64) -> f64,
    ) -> Option<OctaveCurve> {
        let (b_lo, b_hi) = register_exponent_range(simd, lo, hi)?;
        let nodes: [f64; TERMS] = chebyshev_nodes::<TERMS>().map(|t| t - 0.5);
        let mut coeffs = [[0.0f32; 32]; TERMS];
        for b in b_lo..=b_hi {
            let scale = 2f64.powi(b - 127);
            let x = |s: f64| scale * (1.5 + s);
            let y = nodes.map(|s| f(x(s)));
            let p = poly_through(&nodes, &y);
            // The fit in f64 between and beyond the nodes (including both ends).
            let worst = (0..=64)
                .map(|i| {
                    let s = i as f64 / 64.0 - 0.5;
                    let v = p.iter().rev().fold(0.0, |acc, c| acc * s + c);
                    (v / f(x(s)) - 1.0).abs()
                })
                .fold(0.0, f64::max);
            // NaN (a non-finite curve) is refused too.
            if worst.is_nan() || worst > MAX_FIT_ERROR {
                return None;
            }
            for (j, v) in p.iter().enumerate() {
                let v32 = *v as f32;
                if !v32.is_finite() {
                    return None;
                }
                coeffs[j][(b % 32) as usize] = v32;
            }
        }
        Some(OctaveCurve { coeffs, lo, hi })
    }

    /// f(clamp(x, lo, hi)) (NaN → lo), scalar.
    #[inline(always)]
    pub fn eval(&self, x: f32) -> f32 {
        let bits = x.max(self.lo).min(self.hi).to_bits();
        let b = ((bits >> 23) & 31) as usize;
        let s = f32::from_bits((bits & MANTISSA_MASK) | ONE_BITS) - 1.5;
        let c = &self.coeffs;
        (0..TERMS - 1)
            .rev()
            .fold(c[TERMS - 1][b], |p, j| p.mul_add(s, c[j][b]))
    }

    /// Replaces every `v[j]` by [`Self::eval`]`(v[j])` (scalar: the curve exists only
    /// where the AVX-512 pass runs, which leaves the scalar path the ends of a plane).
    #[inline]
    pub fn eval_slice(&self, v: &mut [f32]) {
        for x in v {
            *x = self.eval(*x);
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// drago03's eq. 4-like curve over 31 binary exponents, and arguments that cover it
    /// densely plus the clamped and special values.
    pub(in crate::tonemap) fn eq4_like() -> (impl Fn(f64) -> f64, f32, f32, Vec<f32>) {
        let f = |l: f64| (1.0 + l).ln() / (l * (2.0 + 8.0 * (l / 2e5).powf(0.234)).ln());
        let (lo, hi) = (1.3e-4f32, 2.1e5f32);
        let mut xs = vec![0.0f32, -1.0, f32::NAN, f32::INFINITY, 1e-30, 1e30, lo, hi];
        let mut x = lo;
        while x <= hi {
            xs.push(x);
            x *= 1.000_71;
        }
        (f, lo, hi, xs)
    }

    /// The fit against the curve (the 16-lane form's bits: `kernels/tests.rs`). The curve
    /// is made only where the ISA allows AVX-512, and refused at the others (drago03 then
    /// keeps its memory table).
    #[test]
    fn matches_the_curve() {
        let (f, lo, hi, xs) = eq4_like();
        for simd in prism_cpu::each_isa() {
            let curve = OctaveCurve::new(simd, lo, hi, &f);
            if !simd.avx512() {
                assert!(curve.is_none(), "{simd}");
                continue;
            }
            let curve = curve.expect("eq. 4-like curve should fit");
            let mut worst = 0.0f64;
            for x in &xs {
                let got = curve.eval(*x);
                let xc = if x.is_nan() { lo } else { x.clamp(lo, hi) };
                worst = worst.max((got as f64 / f(xc as f64) - 1.0).abs());
            }
            eprintln!("octave curve: worst relative error {worst:e}");
            // Fit ≤ 1e-7 plus the f32 roundings of the coefficients and Horner steps.
            assert!(worst < 5e-7, "{worst:e}");
            // Refused: more than 32 binary exponents, or a curve no polynomial fits.
            assert!(OctaveCurve::new(simd, 1e-6, 1e6, &f).is_none());
            assert!(OctaveCurve::new(simd, 1.0, 2.0, |x| (x - 1.3).abs()).is_none());
        }
    }
}
