//! AgX (Troy Sobotka, 2022; Blender 4.0's default view transform) in the minimal form of
//! Benjamin Wrensch (2023, "Minimal AgX implementation"): inset matrix, log2 encoding
//! between −12.47393 and +4.026069 EV around 0.18, a 6th-order polynomial fit of the AgX
//! base contrast sigmoid, the inverse inset, and a 2.2 power back to linear display light:
//! x = (clamp(log2(M_in · rgb), ev_min, ev_max) − ev_min) / (ev_max − ev_min),
//! s(x) = 15.5x⁶ − 40.14x⁵ + 31.96x⁴ − 6.868x³ + 0.4298x² + 0.1191x − 0.00232,
//! rgb_out = max(M_out · s, 0)^2.2. Works in linear sRGB (Rec.709); other spaces are
//! converted there and back.

use glam::Mat3;

use super::aces::srgb_matrices;
use super::curve_table::CurveTable;
use super::pixels::{map_pixels, PixelMap};
use super::{Context, OperatorInfo, Output};

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

/// The polynomial fit of the AgX default contrast curve on [0, 1], in f64 (Horner's rule).
fn contrast_f64(x: f64) -> f64 {
    let p = 15.5 * x - 40.14;
    let p = p * x + 31.96;
    let p = p * x - 6.868;
    let p = p * x + 0.4298;
    let p = p * x + 0.1191;
    p * x - 0.00232
}

/// Outset values below 2⁻²⁴ map to 0 instead of y^2.2 ≤ 1.3e-16 (1e-11 of a 16-bit code);
/// the outset never exceeds [`Y_MAX`] (`outset_values_stay_below_y_max`).
const Y_MIN: f32 = 1.0 / 16_777_216.0;
const Y_MAX: f32 = 2.0;

/// The per-channel curves of the transform, tabulated once (module
/// [`super::curve_table`]; the closed forms cost a log2 per channel for the encoding and a
/// log2 and an exp2 per channel for the power, nine transcendental functions per pixel):
/// s(x) = contrast((log2 x − ev_min) / (ev_max − ev_min)) on [2^ev_min, 2^ev_max]
/// (18 octaves, 18 KiB) and y ↦ y^2.2 on [2⁻²⁴, 2] (25 octaves, 25 KiB), both from f64.
struct Tables {
    encode: CurveTable,
    power: CurveTable,
    /// 2^ev_min and 2^ev_max: inset values are clamped to these before the encoding
    /// table (the log2 clamp of the transform applied to the linear value, so the
    /// tabulated curve has no kink inside a segment).
    x_min: f32,
    x_max: f32,
}

fn tables() -> &'static Tables {
    static TABLES: std::sync::OnceLock<Tables> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| {
        let (lo, hi) = (EV_MIN as f64, EV_MAX as f64);
        let (x_min, x_max) = (lo.exp2() as f32, hi.exp2() as f32);
        Tables {
            encode: CurveTable::new(x_min, x_max, |x| contrast_f64((x.log2() - lo) / (hi - lo))),
            power: CurveTable::new(Y_MIN, Y_MAX, |y| y.powf(2.2)),
            x_min,
            x_max,
        }
    })
}

struct Map {
    inset: Mat3,
    outset: Mat3,
    from_srgb: Mat3,
    tables: &'static Tables,
}

/// `m · (r, g, b)` per pixel on planes (8 pixels per vector; the column-major `Mat3` read
/// into locals first so the loop keeps them in registers).
#[inline(always)]
fn mat3_planes(m: Mat3, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
    let [m00, m10, m20, m01, m11, m21, m02, m12, m22] = m.to_cols_array();
    for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
        let (x, y, z) = (*r, *g, *b);
        *r = m00 * x + m01 * y + m02 * z;
        *g = m10 * x + m11 * y + m12 * z;
        *b = m20 * x + m21 * y + m22 * z;
    }
}

impl PixelMap for Map {
    /// The transform as passes over the block's planes (inset matrix, clamp + encoding
    /// table, outset, power table, back to the image's space), each a branch-free loop or
    /// an 8-lane table loop.
    #[inline(always)]
    fn map(&self, _start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        let t = self.tables;
        let (x_min, x_max) = (t.x_min, t.x_max);
        mat3_planes(self.inset, r, g, b);
        // NaN (from ∞ − ∞ in a wide-gamut input) encodes as the bottom, as before.
        for plane in [&mut *r, &mut *g, &mut *b] {
            t.encode.eval_slice_clamped::<false>(plane, x_min, x_max);
        }
        mat3_planes(self.outset, r, g, b);
        for plane in [&mut *r, &mut *g, &mut *b] {
            t.power.eval_slice_clamped::<true>(plane, Y_MIN, Y_MAX);
        }
        mat3_planes(self.from_srgb, r, g, b);
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let (to_srgb, from_srgb) = srgb_matrices(&ctx.image.color_space);
    let map = Map {
        inset: Mat3::from_cols_array(&INSET) * to_srgb,
        outset: Mat3::from_cols_array(&OUTSET),
        from_srgb,
        tables: tables(),
    };
    Output {
        mapped: map_pixels(ctx, ctx.exposure, &map),
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
        // Measured 0.012 codes with the curves tabulated from f64 (curve_table: ~1e-7
        // relative) and the f32 inset/outset sums; the closed forms in f32 (fast log2 and
        // exp2) measured 0.195, the printed power form 0.43.
        assert!(err < 0.03, "{err} 16-bit codes");
    }
}
