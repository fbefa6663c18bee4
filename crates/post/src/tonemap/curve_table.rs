//! A smooth 1-D curve f: x ↦ y tabulated as piecewise cubics indexed by the bits of the
//! f32 argument, for the per-pixel curves whose closed form needs several transcendental
//! functions (drago03: three logarithms and a power; tumblin-rushmeier: a power; agx: a
//! log-encoded polynomial and a 2.2 power per channel).
//!
//! Segments: the f32 bit patterns sharing their top 15 bits (sign, exponent and the top
//! [`MANTISSA_BITS`] mantissa bits), i.e. 2^6 = 64 segments per octave, each 1/64 of its
//! octave wide. Inside a segment x is affine in the remaining 17 low bits (for normal and
//! subnormal numbers alike), so with t = low bits / 2^17 ∈ [0, 1) the curve is a function
//! of t that the table approximates by the cubic interpolating f at the four Chebyshev
//! nodes of [0, 1] (computed in f64, stored as monomial coefficients in t, evaluated in
//! f32 by Horner's rule). For a curve behaving like a power x^a over a segment of
//! relative width h = 1/64 the interpolation error is about
//! |a (a−1) (a−2) (a−3)| h⁴ / (4! · 2⁷) relative — ≈ 1e-9 for |a| ≤ 3 — so what remains
//! is the f32 rounding of the evaluation (a few 1e-7 relative, tested below).
//!
//! The lookup is one 16-byte load per pixel, a transpose and three multiply-adds on 8
//! lanes (AVX2; the 8- and 16-lane forms are in `kernels/`), against the
//! 15–25 vector operations of each fast log or exp it replaces (module
//! [`super::fast_math`]). A table spans the segments from `lo` to `hi` (the curve's
//! domain, e.g. the image's smallest positive and largest luminance): 64 segments of 16
//! bytes per octave, 1 KiB per octave; arguments outside [lo, hi] are clamped to the
//! first or last segment and give meaningless values, so callers clamp or ignore them.
//! Subnormal arguments (< 2⁻¹²⁶) share segments 2⁻¹³² wide, so there the table follows
//! the curve only as far as a cubic over that absolute width can; the operators using it
//! multiply such a luminance by the ratio, which leaves outputs far below a 16-bit code.

/// Mantissa bits that select the segment inside an octave (64 segments per octave).
pub const MANTISSA_BITS: u32 = 6;
/// Low bits that give the position t inside a segment.
pub(super) const LOW_BITS: u32 = 23 - MANTISSA_BITS;
pub(super) const LOW_MASK: u32 = (1 << LOW_BITS) - 1;
/// 2^−LOW_BITS, exact in f32.
pub(super) const T_SCALE: f32 = 1.0 / (1u32 << LOW_BITS) as f32;

/// A curve tabulated as cubics in t per segment (see the module documentation).
pub(crate) struct CurveTable {
    /// Segment index (bits >> LOW_BITS) of the first tabulated segment.
    pub(super) first: u32,
    /// c0, c1, c2, c3 of c0 + t (c1 + t (c2 + t c3)) per segment.
    pub(super) coeffs: Vec<[f32; 4]>,
}

/// The value of the non-negative f32 whose bits are `bits`, in f64. The upper end of a
/// segment is the next segment's first bit pattern: a mantissa carry moves into the
/// exponent field, which is the next octave's first value, and the pattern of +∞ stands
/// for 2^128 (the end of the last octave).
fn value_of_bits(bits: u64) -> f64 {
    let (e, m) = ((bits >> 23) as i32, (bits & 0x7f_ffff) as f64);
    if e == 0 {
        m * 2f64.powi(-149)
    } else {
        2f64.powi(e - 127) * (1.0 + m / 8_388_608.0)
    }
}

impl CurveTable {
    /// Tabulates `f` over the segments holding `lo ≤ x ≤ hi` (`lo` clamped to
    /// [0, f32::MAX], NaN to 0; `hi` to [lo, f32::MAX], NaN to lo). `f` is evaluated at
    /// four points inside each segment (never at its ends), in f64.
    pub fn new(lo: f32, hi: f32, f: impl Fn(f64) -> f64) -> CurveTable {
        // NaN, negative or infinite bounds never make the table larger than the whole
        // non-negative f32 range (2^15 segments, 512 KiB).
        let lo = if lo.is_nan() {
            0.0
        } else {
            lo.clamp(0.0, f32::MAX)
        };
        let hi = if hi.is_nan() {
            lo
        } else {
            hi.clamp(lo, f32::MAX)
        };
        let first = lo.to_bits() >> LOW_BITS;
        let last = hi.to_bits() >> LOW_BITS;
        let nodes: [f64; 4] = chebyshev_nodes();
        let coeffs = (first..=last)
            .map(|s| {
                let a = value_of_bits((s as u64) << LOW_BITS);
                let b = value_of_bits(((s as u64) + 1) << LOW_BITS);
                let y = nodes.map(|t| f(a + t * (b - a)));
                cubic_through(&nodes, &y).map(|c| c as f32)
            })
            .collect();
        CurveTable { first, coeffs }
    }

    /// Number of segments (16 bytes each).
    #[cfg(test)]
    pub fn segments(&self) -> usize {
        self.coeffs.len()
    }

    /// The tabulated curve at `x` (scalar path; the AVX2 path of [`Self::eval_slice`]
    /// gives the same bits: the same operations in the same order, no FMA).
    #[inline(always)]
    pub fn eval(&self, x: f32) -> f32 {
        let bits = x.to_bits();
        let s =
            ((bits >> LOW_BITS) as i32 - self.first as i32).clamp(0, self.coeffs.len() as i32 - 1);
        let c = self.coeffs[s as usize];
        let t = (bits & LOW_MASK) as i32 as f32 * T_SCALE;
        c[0] + t * (c[1] + t * (c[2] + t * c[3]))
    }

    /// Replaces every `v[j]` by the tabulated curve at `v[j]`, with the kernels of `simd`.
    #[inline]
    pub fn eval_slice(&self, v: &mut [f32], simd: prism_cpu::Simd) {
        self.eval_slice_clamped::<false>(v, f32::NEG_INFINITY, f32::INFINITY, simd);
    }

    /// Replaces every `v[j]` by the tabulated curve at `v[j]` clamped to [lo, hi] (NaN
    /// to lo), or by 0 where `ZERO_BELOW` and `v[j]` is below lo or NaN: the clamp and the
    /// select in the same pass as the lookup. The AVX2 form (8 lanes) where `simd` allows.
    #[inline]
    pub fn eval_slice_clamped<const ZERO_BELOW: bool>(
        &self,
        v: &mut [f32],
        lo: f32,
        hi: f32,
        simd: prism_cpu::Simd,
    ) {
        #[cfg(target_arch = "x86_64")]
        if simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
            unsafe { self.eval_slice_avx2::<ZERO_BELOW>(v, lo, hi) };
            return;
        }
        for x in v {
            *x = self.eval_clamped::<ZERO_BELOW>(*x, lo, hi);
        }
    }

    /// One element of [`Self::eval_slice_clamped`].
    #[inline(always)]
    pub(super) fn eval_clamped<const ZERO_BELOW: bool>(&self, x: f32, lo: f32, hi: f32) -> f32 {
        let y = self.eval(x.max(lo).min(hi));
        if ZERO_BELOW && (x.is_nan() || x < lo) {
            0.0
        } else {
            y
        }
    }
}

/// Monomial coefficients of the cubic through (t_k, y_k), k = 0..3, in f64.
fn cubic_through(t: &[f64; 4], y: &[f64; 4]) -> [f64; 4] {
    poly_through(t, y)
}

/// The biased binary exponents (b_lo, b_hi) of a curve's range [lo, hi] held in AVX-512
/// registers, one entry per exponent mod 32 (power_curve, octave_curve); `None` where
/// `simd` does not allow AVX-512, a bound is not a positive normal f32, lo > hi, or the
/// range spans more than 32 exponents (the curve then keeps its memory table).
pub(crate) fn register_exponent_range(
    simd: prism_cpu::Simd,
    lo: f32,
    hi: f32,
) -> Option<(i32, i32)> {
    if !(simd.avx512() && lo.is_normal() && hi.is_normal() && 0.0 < lo && lo <= hi) {
        return None;
    }
    let (b_lo, b_hi) = ((lo.to_bits() >> 23) as i32, (hi.to_bits() >> 23) as i32);
    (b_hi - b_lo < 32).then_some((b_lo, b_hi))
}

/// Monomial coefficients (constant first) of the polynomial of degree N − 1 through
/// (t_k, y_k), k = 0..N (Newton's divided differences, expanded), in f64.
pub(crate) fn poly_through<const N: usize>(t: &[f64; N], y: &[f64; N]) -> [f64; N] {
    let mut d = *y;
    for level in 1..N {
        for k in (level..N).rev() {
            d[k] = (d[k] - d[k - 1]) / (t[k] - t[k - level]);
        }
    }
    // p(t) = d0 + (t − t0)(d1 + (t − t1)(d2 + …)), expanded from the inside.
    let mut c = [0.0; N]; // coefficients of the running polynomial, low first
    c[0] = d[N - 1];
    for (degree, k) in (0..N - 1).rev().enumerate() {
        // c ← c · (t − t_k) + d_k
        let mut next = [0.0; N];
        for j in 0..=degree {
            next[j + 1] += c[j];
            next[j] -= c[j] * t[k];
        }
        next[0] += d[k];
        c = next;
    }
    c
}

/// The N Chebyshev nodes of the first kind on [0, 1].
pub(crate) fn chebyshev_nodes<const N: usize>() -> [f64; N] {
    std::array::from_fn(|k| {
        0.5 - 0.5 * (std::f64::consts::PI * (2 * k + 1) as f64 / (2 * N) as f64).cos()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table against `f`, and every ISA's slice evaluation against the scalar `eval`
    /// bit for bit (each ISA the machine runs).
    fn check(table: &CurveTable, lo: f64, hi: f64, f: impl Fn(f64) -> f64, max_rel: f64) -> f64 {
        let mut worst = 0.0f64;
        let mut x = lo;
        let mut xs = Vec::new();
        while x <= hi {
            xs.push(x as f32);
            x *= 1.000_913;
        }
        xs.push(hi as f32);
        let wide: Vec<(prism_cpu::Simd, Vec<f32>)> = prism_cpu::each_isa()
            .into_iter()
            .map(|simd| {
                let mut v = xs.clone();
                table.eval_slice(&mut v, simd);
                (simd, v)
            })
            .collect();
        for (i, x) in xs.iter().enumerate() {
            let got = table.eval(*x);
            for (simd, w) in &wide {
                assert_eq!(got.to_bits(), w[i].to_bits(), "{simd} x = {x:e}");
            }
            let want = f(*x as f64);
            let rel = (got as f64 - want).abs() / want.abs();
            worst = worst.max(rel);
            assert!(rel <= max_rel, "x = {x:e}: {got:e} vs {want:e} ({rel:e})");
        }
        worst
    }

    #[test]
    fn cubic_through_interpolates() {
        let t = [0.1, 0.3, 0.7, 0.9];
        let c = cubic_through(&t, &[1.0, 2.0, -1.0, 0.5]);
        for (tk, yk) in t.iter().zip([1.0, 2.0, -1.0, 0.5]) {
            let p = c[0] + tk * (c[1] + tk * (c[2] + tk * c[3]));
            assert!((p - yk).abs() < 1e-12, "{p} vs {yk}");
        }
    }

    #[test]
    fn value_of_bits_matches_f32() {
        for x in [0.0f32, 1e-45, 1e-40, f32::MIN_POSITIVE, 0.3, 1.0, 1.5, 3e38] {
            assert_eq!(value_of_bits(x.to_bits() as u64), x as f64);
        }
        // One past the last segment of an octave is the next octave's first value.
        assert_eq!(value_of_bits((1.0f32.to_bits() as u64) + (1 << 23)), 2.0);
        assert_eq!(
            value_of_bits(f32::INFINITY.to_bits() as u64),
            2f64.powi(128)
        );
    }

    #[test]
    fn powers_logs_and_subnormals_to_a_few_f32_roundings() {
        // Relative error budget: interpolation ≲ 1e-9 plus the f32 rounding of the
        // coefficients and of four Horner steps (≲ 6 · 2⁻²⁴ ≈ 3.6e-7).
        for a in [-3.0, -1.2, -0.765, 0.2345, 1.0 / 2.2, 2.2, 3.0] {
            let f = move |x: f64| x.powf(a);
            let table = CurveTable::new(1e-6, 1e6, f);
            // 2^-19.93 .. 2^19.93: 40 octaves of 64 segments (40 KiB), less the ends.
            assert_eq!(table.segments(), 39 * 64 + 58 - 3 + 1);
            let worst = check(&table, 1e-6, 1e6, f, 4e-7);
            eprintln!("x^{a}: worst relative error {worst:e}");
        }
        let f = |x: f64| (1.0 + x).ln() / x;
        check(&CurveTable::new(1e-8, 1e8, f), 1e-8, 1e8, f, 4e-7);
        // Subnormal arguments: x is affine in the low bits there too (segments are
        // 2⁻¹³² wide there, not relatively narrow, so only curves smooth on that
        // absolute scale keep the accuracy; an affine one does).
        let f = |x: f64| 3e30 * x + 1e-9;
        check(&CurveTable::new(1e-44, 1e-36, f), 1.4e-44, 1e-36, f, 4e-7);
        let f = |x: f64| x.sqrt();
        // A single segment and a point.
        check(&CurveTable::new(1.0, 1.01, f), 1.0, 1.01, f, 4e-7);
        assert_eq!(CurveTable::new(f32::NAN, f32::NAN, f).segments(), 1);
        assert_eq!(CurveTable::new(3.0, 1.0, f).segments(), 1);
        let t = CurveTable::new(2.0, 2.0, f);
        assert_eq!(t.segments(), 1);
        assert!((t.eval(2.0) as f64 - 2f64.sqrt()).abs() < 3e-7);
    }

    #[test]
    fn arguments_outside_the_domain_are_clamped_to_the_end_segments() {
        let table = CurveTable::new(1.0, 4.0, |x| x);
        for simd in prism_cpu::each_isa() {
            clamped_at(&table, simd);
        }
    }

    /// `arguments_outside_the_domain_are_clamped_to_the_end_segments` with the kernels of
    /// `simd`.
    fn clamped_at(table: &CurveTable, simd: prism_cpu::Simd) {
        let mut v = [0.0f32, -5.0, f32::INFINITY, 1e30, 0.5, 8.0, 2.0, 3.0, -0.0];
        let scalar: Vec<f32> = v.iter().map(|x| table.eval(*x)).collect();
        table.eval_slice(&mut v, simd);
        for (a, b) in v.iter().zip(&scalar) {
            assert_eq!(a.to_bits(), b.to_bits());
            assert!(a.is_finite());
        }
        assert_eq!(v[6], 2.0);
        // Clamped, and zeroed below lo.
        let src = [
            0.5f32,
            1.0,
            2.5,
            9.0,
            f32::NAN,
            -1.0,
            3.0,
            4.0,
            0.9,
            5.0,
            1.5,
        ];
        let (mut c, mut z) = (src, src);
        table.eval_slice_clamped::<false>(&mut c, 1.0, 4.0, simd);
        table.eval_slice_clamped::<true>(&mut z, 1.0, 4.0, simd);
        for (k, x) in src.iter().enumerate() {
            let want = if x.is_nan() {
                1.0
            } else {
                x.clamp(1.0, 4.0) as f64
            };
            assert!((c[k] as f64 - want).abs() < 1e-6, "{x}: {}", c[k]);
            let want = if *x >= 1.0 { want } else { 0.0 };
            assert!((z[k] as f64 - want).abs() < 1e-6, "{x}: {}", z[k]);
            assert_eq!(
                c[k].to_bits(),
                table.eval_clamped::<false>(*x, 1.0, 4.0).to_bits()
            );
            assert_eq!(
                z[k].to_bits(),
                table.eval_clamped::<true>(*x, 1.0, 4.0).to_bits()
            );
        }
        assert!((v[7] - 3.0).abs() < 1e-6);
    }
}
