//! c · x^a evaluated in registers with AVX-512, for luminance curves that are a pure
//! power over the image's range (tumblin-rushmeier's ratio L_d / L): with x = 2^e · m,
//! m ∈ [1, 2), c · x^a = [c · 2^(a e)] · m^a, where
//!
//! - c · 2^(a e) comes from a 32-entry table indexed by the biased exponent modulo 32
//!   (one two-register `vpermt2ps`), so the curve's domain [lo, hi] may span at most 32
//!   binary exponents ([`PowerCurve::new`] returns `None` otherwise, and where the ISA is
//!   not AVX-512, where the caller keeps its memory table);
//! - m^a is a cubic in t per mantissa segment (the top 4 mantissa bits: 16 segments, one
//!   16-entry `vpermps` per coefficient; m = 1 + (k + t)/16, t ∈ [0, 1) the low 19 bits),
//!   interpolating at Chebyshev nodes in f64. Interpolation error ≈ |a(a−1)(a−2)(a−3)|
//!   h⁴/(4! · 2⁷) with h = 1/16 (3e-8 relative at |a| ≤ ½); the fit is checked at build
//!   time against the formula and refused (`None`) above [`MAX_FIT_ERROR`].
//!
//! The scalar [`PowerCurve::eval`] performs the same operations in the same order
//! (`f32::mul_add` for each fused multiply-add) as the 16-lane slice evaluation (in
//! `kernels/avx512.rs`), so both paths give the same bits.

use super::curve_table::{chebyshev_nodes, poly_through, register_exponent_range};

/// Mantissa bits that select a segment (16 per octave: one AVX-512 register).
const SEGMENT_BITS: u32 = 4;
pub(super) const T_BITS: u32 = 23 - SEGMENT_BITS;
pub(super) const T_MASK: u32 = (1 << T_BITS) - 1;
/// 2^−T_BITS, exact in f32.
pub(super) const T_SCALE: f32 = 1.0 / (1u32 << T_BITS) as f32;
/// Largest relative error of the fitted cubics (in f64, before rounding to f32) accepted.
pub const MAX_FIT_ERROR: f64 = 1e-7;

pub(crate) struct PowerCurve {
    /// `coeffs[j][k]`: coefficient of t^j on segment k of m^a.
    pub(super) coeffs: [[f32; 16]; 4],
    /// c · 2^(a (b − 127)) at index b mod 32 for the biased exponents b of [lo, hi].
    pub(super) scales: [f32; 32],
    pub(super) lo: f32,
    pub(super) hi: f32,
    /// The ISA it was made for (one that allows AVX-512: `new` refuses the others).
    simd: prism_cpu::Simd,
}

impl PowerCurve {
    /// c · x^a for x ∈ [lo, hi] (0 < lo ≤ hi, both normal), arguments clamped to that
    /// range; `None` where the range spans more than 32 binary exponents, the fit misses
    /// [`MAX_FIT_ERROR`], a scale is not a normal f32, or `simd` does not allow AVX-512.
    pub fn new(simd: prism_cpu::Simd, c: f64, a: f64, lo: f32, hi: f32) -> Option<PowerCurve> {
        let (b_lo, b_hi) = register_exponent_range(simd, lo, hi)?;
        let mut scales = [0.0f32; 32];
        for b in b_lo..=b_hi {
            let s = c * (a * (b - 127) as f64).exp2();
            let s32 = s as f32;
            if !s32.is_normal() {
                return None;
            }
            scales[(b % 32) as usize] = s32;
        }
        let nodes: [f64; 4] = chebyshev_nodes();
        let mut coeffs = [[0.0f32; 16]; 4];
        #[allow(clippy::needless_range_loop)] // k is the segment and the column of coeffs
        for k in 0..16 {
            let m = |t: f64| 1.0 + (k as f64 + t) / 16.0;
            let y = nodes.map(|t| m(t).powf(a));
            let p = poly_through(&nodes, &y);
            // The fit in f64 between and beyond the nodes.
            let worst = (0..=32)
                .map(|i| {
                    let t = i as f64 / 32.0;
                    let v = p[0] + t * (p[1] + t * (p[2] + t * p[3]));
                    (v / m(t).powf(a) - 1.0).abs()
                })
                .fold(0.0, f64::max);
            // NaN (a = NaN) is refused too.
            if worst.is_nan() || worst > MAX_FIT_ERROR {
                return None;
            }
            for (j, v) in p.iter().enumerate() {
                coeffs[j][k] = *v as f32;
            }
        }
        Some(PowerCurve {
            coeffs,
            scales,
            lo,
            hi,
            simd,
        })
    }

    /// c · clamp(x, lo, hi)^a (NaN → lo), scalar.
    #[inline(always)]
    pub fn eval(&self, x: f32) -> f32 {
        let bits = x.max(self.lo).min(self.hi).to_bits();
        let k = ((bits >> T_BITS) & 15) as usize;
        let t = (bits & T_MASK) as i32 as f32 * T_SCALE;
        let c = &self.coeffs;
        let p = c[3][k]
            .mul_add(t, c[2][k])
            .mul_add(t, c[1][k])
            .mul_add(t, c[0][k]);
        p * self.scales[((bits >> 23) & 31) as usize]
    }

    /// Replaces every `v[j]` by [`Self::eval`]`(v[j])`, 16 lanes at a time.
    #[inline]
    pub fn eval_slice(&self, v: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx512() {
            // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it (and `new` made
            // this curve only for one that does).
            unsafe { self.eval_slice_avx512(v) };
            return;
        }
        for x in v {
            *x = self.eval(*x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 16-lane slice evaluation against the scalar `eval`, bit for bit, and the fit
    /// against the power; at the ISAs without AVX-512 the curve is refused
    /// (tumblin-rushmeier then keeps its memory table).
    #[test]
    fn matches_the_power_and_the_scalar_bits() {
        for simd in prism_cpu::each_isa() {
            if simd.avx512() {
                matches_at(simd);
            } else {
                assert!(
                    PowerCurve::new(simd, 1.0, 0.5, 1.0, 2.0).is_none(),
                    "{simd}"
                );
            }
        }
    }

    fn matches_at(simd: prism_cpu::Simd) {
        for (c, a) in [
            (0.37, -0.72),
            (2.0, 0.45),
            (1e-3, -0.2),
            (5.0, 0.0),
            (1.0, 0.9),
        ] {
            let (lo, hi) = (1.3e-4f32, 2.1e5f32); // 31 binary exponents
            let curve = PowerCurve::new(simd, c, a, lo, hi).expect("fits");
            let mut xs = vec![0.0f32, -1.0, f32::NAN, f32::INFINITY, 1e-30, 1e30, lo, hi];
            let mut x = lo;
            while x <= hi {
                xs.push(x);
                x *= 1.000_71;
            }
            let mut v = xs.clone();
            curve.eval_slice(&mut v);
            let mut worst = 0.0f64;
            for (x, got) in xs.iter().zip(&v) {
                assert_eq!(got.to_bits(), curve.eval(*x).to_bits(), "x = {x:e}");
                let xc = if x.is_nan() { lo } else { x.clamp(lo, hi) };
                let want = c * (xc as f64).powf(a);
                worst = worst.max((*got as f64 / want - 1.0).abs());
            }
            eprintln!("c x^{a}: worst relative error {worst:e}");
            // Fit ≤ 1e-7 plus the f32 roundings of coefficients, Horner steps and scale.
            assert!(worst < 4e-7, "a = {a}: {worst:e}");
        }
        // Refused: more than 32 binary exponents, or a fit off by more than the bound.
        assert!(PowerCurve::new(simd, 1.0, 0.5, 1e-6, 1e6).is_none());
        assert!(PowerCurve::new(simd, 1.0, -3.0, 1.0, 2.0).is_none());
    }
}
