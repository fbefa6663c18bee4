//! AgX (Troy Sobotka, 2022; Blender 4.0's default view transform) in the minimal form of
//! Benjamin Wrensch (2023, "Minimal AgX implementation"): inset matrix, log2 encoding
//! between −12.47393 and +4.026069 EV around 0.18, a 6th-order polynomial fit of the AgX
//! base contrast sigmoid, the inverse inset, and a 2.2 power back to linear display light:
//! x = (clamp(log2(M_in · rgb), ev_min, ev_max) − ev_min) / (ev_max − ev_min),
//! s(x) = 15.5x⁶ − 40.14x⁵ + 31.96x⁴ − 6.868x³ + 0.4298x² + 0.1191x − 0.00232,
//! rgb_out = max(M_out · s, 0)^2.2. Works in linear sRGB (Rec.709); other spaces are
//! converted there and back.
//!
//! Evaluation: one pass per pixel in registers (8 lanes with AVX2 + FMA, 16 with AVX-512,
//! scalar otherwise, all giving the same bits), the two curves as per-mantissa-segment
//! polynomials whose coefficients sit in registers (see the comment above
//! [`SEGMENT_BITS`]).

use glam::Mat3;
use prism_spectrum::rgb_space::RgbColorSpace;

use super::aces::srgb_matrices;
use super::curve_table::{chebyshev_nodes, poly_through};
use super::pixels::PixelMap;
use super::{Context, OperatorInfo, Output};
use prism_cpu::Simd;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "agx",
    reference: "AgX (Sobotka 2022), minimal polynomial fit of Wrensch 2023",
    absolute: false,
    params: &[],
};

const EV_MIN: f32 = -12.47393;
const EV_MAX: f32 = 4.026069;

/// Inset matrix, column-major as printed in the GLSL source.
#[allow(clippy::excessive_precision)] // the published digits, kept verbatim
const INSET: [f32; 9] = [
    0.842479062253094,
    0.0423282422610123,
    0.0423756549057051,
    0.0784335999999992,
    0.878468636469772,
    0.0784336,
    0.0792237451477643,
    0.0791661274605434,
    0.879142973793104,
];
/// Outset (inverse inset), column-major.
#[allow(clippy::excessive_precision)] // the published digits, kept verbatim
const OUTSET: [f32; 9] = [
    1.19687900512017,
    -0.0528968517574562,
    -0.0529716355144438,
    -0.0980208811401368,
    1.15190312990417,
    -0.0980434501171241,
    -0.0990297440797205,
    -0.0989611768448433,
    1.15107367264116,
];

/// Coefficients of the AgX contrast polynomial as published, constant first.
const CONTRAST: [f64; 7] = [-0.00232, 0.1191, 0.4298, -6.868, 31.96, -40.14, 15.5];

/// The polynomial fit of the AgX default contrast curve on [0, 1], in f64 (Horner's rule).
#[cfg(test)]
fn contrast_f64(x: f64) -> f64 {
    CONTRAST.iter().rev().fold(0.0, |p, c| p * x + c)
}

/// Outset values below 2⁻²⁴ map to 0 instead of y^2.2 ≤ 1.3e-16 (1e-11 of a 16-bit code);
/// the outset never exceeds [`Y_MAX`] (`outset_values_stay_below_y_max`), so the power
/// curve needs no upper clamp: its exponents run from 2⁻²⁴ to below 2.
pub(super) const Y_MIN: f32 = 1.0 / 16_777_216.0;
#[cfg_attr(not(test), allow(dead_code))] // the bound, checked by that test
const Y_MAX: f32 = 2.0;
/// 2⁻²⁵: the AVX-512 power curve clamps to this instead of [`Y_MIN`] and reads a scale of
/// 0 for its biased exponent (102, free modulo 32 next to 103…128), which zeroes
/// everything below Y_MIN (NaN included: `vmaxps` returns its second operand) without a
/// compare and a mask.
#[cfg(target_arch = "x86_64")]
pub(super) const Y_ZERO: f32 = Y_MIN * 0.5;

// The per-channel curves are evaluated directly, in registers, as polynomials whose
// coefficients are picked per mantissa segment (the top SEGMENT_BITS mantissa bits: 8
// segments per octave, so 8 coefficients per degree fill one AVX register and are looked
// up with one `vpermps` per coefficient instead of a memory table). Inside a segment
// m = 1 + (k + t)/8 with t ∈ [0, 1) the remaining 20 mantissa bits, exactly. The
// polynomials run in the centred variable s = t/8 − 1/16 ∈ [−1/16, 1/16), which is
// exactly (bits & T_MASK | bits of 1.0) − 1.0625: one `vpternlogd` and a subtraction
// (Sterbenz: exact), against and, convert and multiply for t.
//
// - Encoding: with R = ev_max − ev_min and v = 2^e · m, the contrast polynomial's
//   argument is w = R (x − ½) = log2 v − ev_min − R/2 = e + [log2 m − ev_min − R/2]; the
//   bracket is a quartic in s per segment (interpolation error |f⁽⁵⁾| h⁵/(5! 2⁹) with
//   f = log2, h = 1/8: ≤ 5e-10), e enters with one addition (|w| ≤ R/2 = 8.25: its
//   rounding is ≤ 4.8e-7 in w, 2.9e-8 in x, the size of one rounding of x − ½ itself).
//   The published contrast polynomial is then evaluated in w (its coefficients
//   re-expanded about x = ½ and scaled by R^−j in f64: Horner's rule on the published
//   ones cancels terms of size 40 down to values ≤ 1, which cost 0.2 16-bit codes in
//   f32; the scaling changes no relative rounding).
// - Power: y^2.2 with y = 2^e · m is 2^(2.2e) · m^2.2; m^2.2 is a cubic in s per segment
//   (error |a(a−1)(a−2)(a−3)| h⁴/(4! 2⁷) with a = 2.2: ≤ 3.4e-8 relative), and with
//   e + 25 = 5q + r (0 ≤ r < 5), 2^(2.2e) = 2^(2e + q − 5) · 2^(r/5): an exponent built in
//   the bits times one of five constants (another `vpermps`).
//
// All coefficients are fitted here, at start-up, by interpolation at Chebyshev nodes in
// f64 from the formulas, then rounded to f32. Every step is a fused multiply-add, so the
// scalar path (`f32::mul_add`, used where the CPU lacks AVX2 + FMA) gives the same bits
// as the 8- and 16-lane ones (tested).

/// Mantissa bits that select a segment (8 per octave: one register of coefficients).
const SEGMENT_BITS: u32 = 3;
/// Mantissa bits of the position t inside a segment.
pub(super) const T_BITS: u32 = 23 - SEGMENT_BITS;
pub(super) const T_MASK: u32 = (1 << T_BITS) - 1;
/// The bits of 1.0, and the centre of (bits & T_MASK | ONE_BITS) ∈ [1, 1.125).
pub(super) const ONE_BITS: u32 = 0x3f80_0000;
pub(super) const S_CENTRE: f32 = 1.0625;
/// Coefficients of the encoding quartic and of the power cubic.
pub(super) const ENCODE_TERMS: usize = 5;
pub(super) const POWER_TERMS: usize = 4;

/// Per-segment polynomial coefficients: `c[j][k]` multiplies s^j on segment k.
pub(super) type SegmentPoly<const N: usize> = [[f32; 8]; N];

/// s ∈ [−1/16, 1/16) of an f32's low T_BITS mantissa bits, exactly.
#[inline(always)]
fn centred_position(bits: u32) -> f32 {
    f32::from_bits((bits & T_MASK) | ONE_BITS) - S_CENTRE
}

/// Fits `f(m)`, m ∈ [1, 2), per segment by interpolation at N Chebyshev nodes of s.
fn fit_segments<const N: usize>(f: impl Fn(f64) -> f64) -> SegmentPoly<N> {
    let nodes: [f64; N] = chebyshev_nodes::<N>().map(|t| t / 8.0 - 1.0 / 16.0);
    let mut c = [[0.0f32; 8]; N];
    #[allow(clippy::needless_range_loop)] // k is the segment and the column of c
    for k in 0..8 {
        let y = nodes.map(|s| f(1.0 + k as f64 / 8.0 + 1.0 / 16.0 + s));
        for (j, v) in poly_through(&nodes, &y).iter().enumerate() {
            c[j][k] = *v as f32;
        }
    }
    c
}

/// The transform's constants, fitted once per process.
pub(super) struct Curves {
    pub(super) encode: SegmentPoly<ENCODE_TERMS>,
    /// The contrast polynomial in w = R (x − ½), constant first.
    pub(super) contrast: [f32; 7],
    pub(super) power: SegmentPoly<POWER_TERMS>,
    /// 2^(r/5) for r = 0…4 (lanes 5–7 unused).
    pub(super) fifths: [f32; 8],
    /// 2^ev_min and 2^ev_max: inset values are clamped to these first (the log2 clamp of
    /// the transform applied to the linear value).
    pub(super) x_min: f32,
    pub(super) x_max: f32,
    /// `encode` and `power` with each row repeated in both halves (16-entry `vpermps`).
    pub(super) encode16: [[f32; 16]; ENCODE_TERMS],
    pub(super) power16: [[f32; 16]; POWER_TERMS],
    /// 2^(2.2 (b − 127)) as 2^(2e + q − 5) · 2^(r/5) (e = b − 127, e + 25 = 5q + r, as
    /// the AVX2 path computes it) at index b mod 32 for the biased exponents b = 103…128
    /// of y ∈ [2⁻²⁴, 2], 0 elsewhere (at 102 in particular: [`Y_ZERO`]).
    pub(super) scales: [f32; 32],
}

fn curves() -> &'static Curves {
    static CURVES: std::sync::OnceLock<Curves> = std::sync::OnceLock::new();
    CURVES.get_or_init(|| {
        let (lo, hi) = (EV_MIN as f64, EV_MAX as f64);
        let range = hi - lo;
        // Binomial re-expansion: Σ c_k x^k = Σ_j (Σ_{k≥j} C(k, j) c_k ½^(k−j)) u^j, u =
        // x − ½ = w / R.
        let contrast = std::array::from_fn(|j| {
            let in_u = (j..7)
                .map(|k| {
                    let binom = (0..j).fold(1.0, |b, i| b * (k - i) as f64 / (i + 1) as f64);
                    CONTRAST[k] * binom * 0.5f64.powi((k - j) as i32)
                })
                .sum::<f64>();
            (in_u / range.powi(j as i32)) as f32
        });
        let encode: SegmentPoly<ENCODE_TERMS> = fit_segments(|m| m.log2() - lo - range / 2.0);
        let power: SegmentPoly<POWER_TERMS> = fit_segments(|m| m.powf(2.2));
        let fifths: [f32; 8] = std::array::from_fn(|r| {
            if r < 5 {
                2f64.powf(r as f64 / 5.0) as f32
            } else {
                1.0
            }
        });
        let twice = |a: &[f32; 8]| -> [f32; 16] { std::array::from_fn(|i| a[i % 8]) };
        Curves {
            encode16: encode.each_ref().map(twice),
            power16: power.each_ref().map(twice),
            scales: std::array::from_fn(|i| {
                let biased = (103..=128).find(|b| b % 32 == i as i32);
                biased.map_or(0.0, |b| {
                    let e = b - 127;
                    let (q, r) = split_fifths(e + 25);
                    f32::from_bits(((2 * e + q - 5 + 127) as u32) << 23) * fifths[r as usize]
                })
            }),
            encode,
            contrast,
            power,
            fifths,
            x_min: lo.exp2() as f32,
            x_max: hi.exp2() as f32,
        }
    })
}

/// Column-major 3×3 matrix as f32s.
pub(super) type Mat = [f32; 9];

pub(super) struct Map {
    pub(super) inset: Mat,
    pub(super) outset: Mat,
    /// Linear sRGB → the image's space; `None` where that is the identity.
    pub(super) from_srgb: Option<Mat>,
    pub(super) curves: &'static Curves,
    /// The kernels of [`PixelMap::map`] (the register pass reads the call's own).
    simd: Simd,
}

/// `m · (x, y, z)` with fused multiply-adds, in the order the 8-lane path uses.
#[inline(always)]
fn mat3(m: &Mat, x: f32, y: f32, z: f32) -> [f32; 3] {
    std::array::from_fn(|row| m[6 + row].mul_add(z, m[3 + row].mul_add(y, m[row] * x)))
}

impl Map {
    /// The map for an image in `space`: the inset from it (through linear sRGB), the
    /// outset, and the way back where `space` is not sRGB; [`PixelMap::map`] runs the
    /// kernels of `simd`.
    fn for_space(space: &RgbColorSpace, simd: Simd) -> Self {
        let (to_srgb, from_srgb) = srgb_matrices(space);
        Self {
            inset: (Mat3::from_cols_array(&INSET) * to_srgb).to_cols_array(),
            outset: OUTSET,
            from_srgb: (!is_identity(from_srgb)).then(|| from_srgb.to_cols_array()),
            curves: curves(),
            simd,
        }
    }

    /// The encoding and contrast curve s of one inset value (scalar path).
    #[inline(always)]
    fn encode(&self, v: f32) -> f32 {
        let c = self.curves;
        // f32::max returns the number for a NaN operand: NaN (from ∞ − ∞ in a wide-gamut
        // input) encodes as the bottom, as `vmaxps(v, x_min)` does.
        let v = v.max(c.x_min).min(c.x_max);
        let bits = v.to_bits();
        let e = ((bits >> 23) as i32 - 127) as f32;
        let k = ((bits >> T_BITS) & 7) as usize;
        let s = centred_position(bits);
        let p = (0..ENCODE_TERMS - 1)
            .rev()
            .fold(c.encode[ENCODE_TERMS - 1][k], |p, j| {
                p.mul_add(s, c.encode[j][k])
            });
        let w = e + p;
        (0..6)
            .rev()
            .fold(c.contrast[6], |p, j| p.mul_add(w, c.contrast[j]))
    }

    /// max(y, 0)^2.2 of one outset value, 0 below [`Y_MIN`] or for NaN (scalar path).
    #[inline(always)]
    fn power(&self, y: f32) -> f32 {
        let c = self.curves;
        let keep = y >= Y_MIN;
        // NaN goes to Y_MIN here (f32::max), as with vmaxps; no upper clamp (Y_MAX).
        let bits = y.max(Y_MIN).to_bits();
        let k = ((bits >> T_BITS) & 7) as usize;
        let s = centred_position(bits);
        let p = (0..POWER_TERMS - 1)
            .rev()
            .fold(c.power[POWER_TERMS - 1][k], |p, j| {
                p.mul_add(s, c.power[j][k])
            });
        let scale = c.scales[((bits >> 23) & 31) as usize];
        if keep {
            p * scale
        } else {
            0.0
        }
    }

    /// One pixel, scalar.
    #[inline(always)]
    pub(super) fn pixel(&self, r: f32, g: f32, b: f32) -> [f32; 3] {
        let [x, y, z] = mat3(&self.inset, r, g, b).map(|v| self.encode(v));
        let out = mat3(&self.outset, x, y, z).map(|v| self.power(v));
        match &self.from_srgb {
            Some(m) => mat3(m, out[0], out[1], out[2]),
            None => out,
        }
    }
}

/// (q, r) with n = 5q + r, 0 ≤ r < 5, for 0 ≤ n ≤ 26 (q = ⌊205 n / 1024⌋: 205/1024 =
/// 0.2002 is exact enough below n = 256; checked for every n used).
#[inline(always)]
fn split_fifths(n: i32) -> (i32, i32) {
    let q = (n * 205) >> 10;
    (q, n - q * 5)
}

impl PixelMap for Map {
    /// The whole transform (inset, encoding, contrast, outset, power, back to the image's
    /// space) per pixel in one pass over the block's planes, in registers.
    #[inline(always)]
    fn map(&self, _start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx512() {
            // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
            unsafe { self.map_avx512(r, g, b) };
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
            unsafe { self.map_avx2(r, g, b) };
            return;
        }
        for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
            [*r, *g, *b] = self.pixel(*r, *g, *b);
        }
    }
}

/// Whether `m` is the identity to 1e-9 (applying such a matrix would move a channel by
/// at most 1e-9 of the pixel's largest channel, 1/60 of an f32 rounding step).
fn is_identity(m: Mat3) -> bool {
    m.abs_diff_eq(Mat3::IDENTITY, 1e-9)
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let map = Map::for_space(&ctx.image.color_space, ctx.simd);
    Output {
        mapped: super::kernels::map_pixels_registers(ctx, ctx.exposure, &map),
        values: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use super::*;

    #[test]
    fn outset_inverts_inset_and_mid_grey_lands_mid_display() {
        let product = Mat3::from_cols_array(&OUTSET) * Mat3::from_cols_array(&INSET);
        // The printed matrices are inverse to ~1e-7 (f32 of 15 printed digits).
        assert!(product.abs_diff_eq(Mat3::IDENTITY, 1e-5));
        // 0.18 is 2.474 EV below 1: x = 10.0/16.5; s(x) ≈ 0.4967 (hand evaluation).
        let encode = |v: f64| contrast_f64((v.log2() - EV_MIN as f64) / (EV_MAX - EV_MIN) as f64);
        assert!((encode(0.18) - 0.4967).abs() < 1e-3);
        let img = small_image();
        let out = ToneOperator::Agx
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        // A grey stays (nearly) grey: inset rows sum to 1 within 1e-4.
        let g = out.pixels()[2];
        assert!(
            (g[0] - g[1]).abs() < 1e-3 && (g[1] - g[2]).abs() < 1e-3,
            "{g:?}"
        );
        let v = 4.0f64 * 1.0001;
        let want = encode(v).powf(2.2) as f32;
        assert!((g[1] - want).abs() < 2e-3, "{g:?} vs {want}");
        // Where red saturates first, the outset's negative off-diagonal terms lower the
        // output by < 1e-4 relative (measured 7e-5): a property of the published transform.
        assert_monotone_within(ToneOperator::Agx, &ToneParams::default(), None, 1e-4);
    }

    #[test]
    fn outset_values_stay_below_y_max() {
        // The encoding maps onto contrast([0, 1]); the largest outset value any mix of
        // those can reach bounds what the power table must cover.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..=100_000 {
            let c = contrast_f64(k as f64 / 100_000.0);
            lo = lo.min(c);
            hi = hi.max(c);
        }
        for row in 0..3 {
            let top: f64 = (0..3)
                .map(|col| {
                    let o = OUTSET[3 * col + row] as f64;
                    (o * lo).max(o * hi)
                })
                .sum();
            assert!(top < Y_MAX as f64 * 0.9, "row {row}: {top}");
        }
    }

    /// The published transform in f64 with the library's log2 and powf.
    fn agx_f64(rgb: [f32; 3]) -> [f64; 3] {
        let m = |a: &[f32; 9], v: [f64; 3]| {
            [0, 1, 2].map(|r| (0..3).map(|c| a[3 * c + r] as f64 * v[c]).sum::<f64>())
        };
        let (lo, hi) = (EV_MIN as f64, EV_MAX as f64);
        let s = m(&INSET, rgb.map(|c| c as f64)).map(|v| {
            let x = (v.log2().clamp(lo, hi) - lo) / (hi - lo);
            let x2 = x * x;
            let x4 = x2 * x2;
            15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
                - 0.00232
        });
        m(&OUTSET, s).map(|d| d.max(0.0).powf(2.2))
    }

    #[test]
    fn fast_path_matches_the_f64_transform_to_a_fraction_of_a_16_bit_code() {
        let img = sweep_image(40_000);
        let out = ToneOperator::Agx
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let want: Vec<[f64; 3]> = img.pixels().iter().map(|p| agx_f64(*p)).collect();
        let err = max_code_error_16(out.pixels(), &want);
        eprintln!("agx: max error {err} 16-bit codes");
        // Measured 0.0154 codes with the polynomials in s and the contrast in w (power
        // ≤ 1.95e-7 relative, encoding ≤ 1.39e-7 absolute: `fifths_split_and_fitted_curves`;
        // seventh pass, docs/history/post-speed.md), 0.0122 before them with t and u (1.8e-7, 9.7e-8)
        // and the f32 inset/outset sums; 0.012 with the memory tables of curve_table
        // (until 2026-12-01); the closed forms in f32 (fast log2 and exp2) measured 0.195,
        // the printed power form 0.43.
        assert!(err < 0.03, "{err} 16-bit codes");
    }

    #[test]
    fn vector_paths_give_the_scalar_bits() {
        // Every octave and segment of both curves, NaN, ±∞, negatives, zeros, and a
        // wide-gamut image (so the matrix back from sRGB runs too).
        let mut values = vec![0.0f32, -0.0, -1.0, f32::NAN, f32::INFINITY, 1e-30, 3e38];
        let mut v = 1e-6f32;
        while v < 1e3 {
            values.push(v);
            v *= 1.0137;
        }
        for (space, simd) in [RgbColorSpace::srgb(), RgbColorSpace::rec2020()]
            .into_iter()
            .flat_map(|space| {
                prism_cpu::each_isa()
                    .into_iter()
                    .map(move |s| (space.clone(), s))
            })
        {
            let map = Map::for_space(&space, simd);
            assert_eq!(map.from_srgb.is_none(), space == RgbColorSpace::srgb());
            let n = values.len();
            let mut r: Vec<f32> = values.clone();
            let mut g: Vec<f32> = (0..n).map(|i| values[(i * 7 + 3) % n]).collect();
            let mut b: Vec<f32> = (0..n).map(|i| values[(i * 13 + 5) % n]).collect();
            let want: Vec<[f32; 3]> = (0..n).map(|i| map.pixel(r[i], g[i], b[i])).collect();
            // `PixelMap::map` at this ISA: the AVX-512 or AVX2 kernel, or `pixel` per pixel.
            map.map(0, &mut r, &mut g, &mut b);
            for i in 0..n {
                let got = [r[i], g[i], b[i]];
                assert_eq!(
                    got.map(f32::to_bits),
                    want[i].map(f32::to_bits),
                    "{simd} {i}: {got:?}"
                );
            }
        }
    }

    #[test]
    fn register_pass_gives_the_scalar_bits() {
        // The whole pass at every ISA (with AVX-512: sanitising, the map in registers with
        // its output cleaning skipped, zero-padded head and tail groups, the counts)
        // against the scalar one, on the special values and on every octave of the curves.
        let special = bit_test_image();
        let mut pixels = special.pixels().to_vec();
        let mut v = 1e-7f32;
        while v < 1e4 {
            pixels.push([v, 0.37 * v, 2.9 * v]);
            v *= 1.0093;
        }
        for space in [RgbColorSpace::srgb(), RgbColorSpace::rec2020()] {
            for scale in [1.0f32, 0.37, 3e30] {
                super::super::kernels::tests::register_pass_gives_the_scalar_bits(
                    &pixels,
                    scale,
                    |simd| Map::for_space(&space, simd),
                );
            }
        }
    }

    #[test]
    fn fifths_split_and_fitted_curves() {
        for n in 0..=26 {
            let (q, r) = split_fifths(n);
            assert_eq!((q, r), (n / 5, n % 5), "{n}");
        }
        let map = Map {
            inset: Mat3::IDENTITY.to_cols_array(),
            outset: Mat3::IDENTITY.to_cols_array(),
            from_srgb: None,
            curves: curves(),
            simd: Simd::SCALAR,
        };
        // Power: every octave from 2⁻²⁴ to 2, against f64 (relative error).
        let mut worst_power = 0.0f64;
        let mut y = Y_MIN;
        while y <= Y_MAX {
            let want = (y as f64).powf(2.2);
            worst_power = worst_power.max((map.power(y) as f64 / want - 1.0).abs());
            y *= 1.000_31;
        }
        eprintln!("agx power: worst relative error {worst_power:e}");
        assert!(worst_power < 3e-7, "{worst_power:e}");
        assert_eq!(map.power(Y_MIN * 0.99), 0.0);
        assert_eq!(map.power(f32::NAN), 0.0);
        // Encoding and contrast: absolute error against the published curve in f64.
        let (lo, hi) = (EV_MIN as f64, EV_MAX as f64);
        let mut worst_encode = 0.0f64;
        let mut v = 1e-5f32;
        while v < 40.0 {
            let x = ((v as f64).log2().clamp(lo, hi) - lo) / (hi - lo);
            worst_encode = worst_encode.max((map.encode(v) as f64 - contrast_f64(x)).abs());
            v *= 1.000_29;
        }
        eprintln!("agx encoding: worst absolute error {worst_encode:e}");
        assert!(worst_encode < 3e-7, "{worst_encode:e}");
    }
}
