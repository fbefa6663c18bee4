//! Small hand-made images and checks shared by the operators' tests.

use prism_spectrum::rgb_space::RgbColorSpace;

use super::{ToneOperator, ToneParams};
use prism_image::Image;

/// A 4×1 sRGB image of greys and colours with known luminances.
pub fn small_image() -> Image {
    Image::new(
        4,
        1,
        vec![
            [0.05, 0.05, 0.05],
            [1.0, 0.5, 0.25],
            [4.0, 4.0, 4.0],
            [20.0, 30.0, 10.0],
        ],
        RgbColorSpace::srgb(),
    )
    .unwrap()
}

pub fn luminance(image: &Image, p: [f32; 3]) -> f64 {
    let w = image.luminance_weights();
    (0..3).map(|c| w[c] as f64 * p[c] as f64).sum()
}

/// f32 evaluation of a formula vs the f64 reference: a few ulps of the result and of the
/// log-average (a sum of n ln terms): 1e-5 relative is ~100 ulps of f32.
pub const F32_RELATIVE: f64 = 1e-5;

pub fn assert_close(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= F32_RELATIVE * want.abs().max(1e-6),
        "{what}: got {got}, want {want}"
    );
}

/// Output luminance is non-decreasing over an increasing grey and coloured ramp spanning
/// 1e-4 … 1e5 (relative), for the operator's defaults.
pub fn assert_monotone(op: ToneOperator, params: &ToneParams, cd_m2_per_unit: Option<f64>) {
    assert_monotone_within(op, params, cd_m2_per_unit, 0.0);
}

/// As [`assert_monotone`], allowing a relative drop of `tint_drop` on the coloured ramp
/// (per-channel curves followed by a mixing matrix, as AgX's outset, can lower luminance
/// slightly where one channel saturates before the others). Greys stay strictly checked.
pub fn assert_monotone_within(
    op: ToneOperator,
    params: &ToneParams,
    cd_m2_per_unit: Option<f64>,
    tint_drop: f64,
) {
    for (tint, drop) in [([1.0f32, 1.0, 1.0], 0.0), ([1.0, 0.4, 0.1], tint_drop)] {
        let n = 400;
        let pixels = (0..n)
            .map(|i| {
                let v = 10f32.powf(-4.0 + 9.0 * i as f32 / (n - 1) as f32);
                tint.map(|t| t * v)
            })
            .collect();
        let mut img = Image::new(n, 1, pixels, RgbColorSpace::srgb()).unwrap();
        img.cd_m2_per_unit = cd_m2_per_unit;
        let out = op.apply(&img, params).unwrap().image;
        let lum: Vec<f64> = out.pixels().iter().map(|p| luminance(&out, *p)).collect();
        for (i, pair) in lum.windows(2).enumerate() {
            assert!(
                // 1e-6: f32 rounding of equal outputs (a saturated curve).
                pair[1] >= pair[0] * (1.0 - 1e-6 - drop),
                "{}: luminance decreases at {i}: {} → {}",
                op.name(),
                pair[0],
                pair[1]
            );
        }
    }
}

/// A 1-row sRGB image of `n` pixels: a grey ramp and three tinted ramps (one channel
/// dominant each), values spanning 1e-4 … 1e5 relative, interleaved.
pub fn sweep_image(n: usize) -> Image {
    let tints = [
        [1.0f32, 1.0, 1.0],
        [1.0, 0.3, 0.05],
        [0.1, 1.0, 0.4],
        [0.2, 0.25, 1.0],
    ];
    let pixels = (0..n)
        .map(|i| {
            let v = 10f32.powf(-4.0 + 9.0 * i as f32 / (n - 1) as f32);
            tints[i % 4].map(|t| t * v)
        })
        .collect();
    Image::new(n, 1, pixels, RgbColorSpace::srgb()).unwrap()
}

/// Largest difference, in 16-bit sRGB code values (codes of 1/65535), between displayed
/// (clipped to [0, 1] and sRGB-encoded) linear values `got` and references `want`: what
/// changes in a 16-bit PNG (less than one code: at most some values at half-code ties
/// round the other way).
pub fn max_code_error_16(got: &[[f32; 3]], want: &[[f64; 3]]) -> f64 {
    let srgb = RgbColorSpace::srgb().transfer;
    let code = |v: f64| srgb.encode(v.clamp(0.0, 1.0)) * 65535.0;
    got.iter()
        .zip(want)
        .flat_map(|(g, w)| (0..3).map(move |c| (code(g[c] as f64) - code(w[c])).abs()))
        .fold(0.0, f64::max)
}

/// 1000 pixels for bit-identity tests of vector paths: greys and colours over 2^-140 …
/// 2^100 (subnormal to overflowing), plus NaN, ±∞, negative, ±0 components (an odd count,
/// so every path also meets a partial group).
pub fn bit_test_image() -> Image {
    let special = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        -0.0,
        0.0,
        f32::MAX,
        1e-45,
    ];
    let pixels: Vec<[f32; 3]> = (0..1000)
        .map(|i| {
            let v = 2f32.powf(-140.0 + 240.0 * ((i * 7919) % 1000) as f32 / 1000.0);
            match i % 13 {
                0 => [special[i % 8], v, v],
                1 => [v, special[(i / 13) % 8], 0.5 * v],
                2 => [v, v, special[(i / 7) % 8]],
                3 => [v, 0.3 * v, 0.01 * v],
                _ => [v, v, v],
            }
        })
        .collect();
    Image::new(1000, 1, pixels, RgbColorSpace::srgb()).unwrap()
}
