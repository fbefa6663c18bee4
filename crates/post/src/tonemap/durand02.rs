//! Durand & Dorsey 2002, "Fast Bilateral Filtering for the Display of High-Dynamic-Range
//! Images", SIGGRAPH, §5 (and the pseudo-code on Durand's project page):
//! I = log10 L_w (luminance of the image's colour space instead of their
//! (20 R + 40 G + B)/61);
//! base B = bilateral(I) with σ_s = 2 % of the image size (the larger side) and σ_r = 0.4
//! (their values); detail D = I − B;
//! γ = log10(base_contrast) / (max B − min B), base_contrast = 5 (their default, also
//! pfstmo_durand02's); log10 L_d = γ B + D − γ max B, so the brightest base maps to 1;
//! colour: c_d = c_w · L_d / L_w (their "colour ratio").
//! The bilateral filter is the bilateral grid of Paris & Durand 2006 ([`super::bilateral_grid`]),
//! not the paper's piecewise-linear approximation: both sample space at σ_s and range at
//! σ_r; the grid needs one splat and one slice pass instead of one pass per range segment.
//!
//! Deviation, stated: γ is capped at 1 (an image whose base range already fits the target
//! contrast is not expanded). Black pixels (L_w = 0) stay black and take no part in the
//! filter.

use super::bilateral_grid::bilateral_grid;
use super::fast_math;
use super::kernels::avx2;
use super::pixels::{luminance_plane, map_luminance, LuminanceCurve, CHUNK};
use super::{Context, OperatorInfo, Output, ParamSpec};
use rayon::prelude::*;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "durand02",
    reference: "Durand, Dorsey 2002, Fast Bilateral Filtering for the Display of \
                High-Dynamic-Range Images, SIGGRAPH (§5); bilateral grid of Paris, Durand \
                2006, ECCV",
    absolute: false,
    params: &[
        ParamSpec {
            name: "base_contrast",
            default: Some(5.0),
            min: 1.0001,
            max: 1e6,
            doc: "target contrast of the base layer (ratio; its log10 is the base range)",
        },
        ParamSpec {
            name: "sigma_space",
            default: Some(0.02),
            min: 1e-4,
            max: 1.0,
            doc: "spatial σ_s as a fraction of the larger image side (2 %)",
        },
        ParamSpec {
            name: "sigma_range",
            default: Some(0.4),
            min: 0.01,
            max: 10.0,
            doc: "range σ_r in log10 luminance units",
        },
    ],
};

/// L_d = L_w · 10^{(γ − 1) B − γ max B}, as exp(g1 B + offset).
struct Curve<'a> {
    g1: f32,
    offset: f32,
    base: &'a [f32],
}

impl LuminanceCurve for Curve<'_> {
    #[inline(always)]
    fn ratio(&self, start: usize, l: &mut [f32]) {
        // L_d / L_w = 10^{(γ − 1) B − γ max B}.
        let base = &self.base[start..start + l.len()];
        let (g1, offset) = (self.g1, self.offset);
        for (v, b) in l.iter_mut().zip(base) {
            *v = fast_math::exp(g1 * b + offset);
        }
    }
}

/// log10 L, NaN for L = 0 (black pixels take no part in the filter).
#[inline(always)]
fn log10_or_nan(plane: &mut [f32]) {
    for v in plane {
        let log = fast_math::log2(*v) * std::f32::consts::LOG10_2;
        *v = if *v > 0.0 { log } else { f32::NAN };
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let (w, h) = (ctx.image.width(), ctx.image.height());
    let contrast = ctx.value("base_contrast");
    let sigma_space_px = (ctx.value("sigma_space") * w.max(h) as f64) as f32;
    let sigma_range = ctx.value("sigma_range") as f32;
    let mut log_l = luminance_plane(ctx, ctx.exposure, ctx.weights);
    log_l
        .par_chunks_mut(CHUNK)
        .for_each(|c| avx2!(ctx.simd, log10_or_nan(c)));
    let (base, [base_min, base_max]) =
        bilateral_grid(&log_l, w, h, sigma_space_px, sigma_range, ctx.simd);
    drop(log_l);
    let range = (base_max - base_min) as f64;
    let gamma = if range > 0.0 {
        (contrast.log10() / range).min(1.0)
    } else {
        1.0
    };
    // L_d / L_w = 10^{(γ − 1) B − γ max B} = exp(ln 10 · ((γ − 1) B − γ max B)).
    let (g1, offset) = (
        (gamma - 1.0) as f32 * std::f32::consts::LN_10,
        -(gamma * base_max as f64) as f32 * std::f32::consts::LN_10,
    );
    let curve = Curve {
        g1,
        offset,
        base: &base,
    };
    let mapped = map_luminance(ctx, ctx.exposure, ctx.weights, &curve);
    Output {
        mapped,
        values: vec![
            ("compression_factor", gamma),
            ("base_log10_min", base_min as f64),
            ("base_log10_max", base_max as f64),
            ("sigma_space_px", sigma_space_px as f64),
            ("sigma_range", sigma_range as f64),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use prism_image::Image;
    use prism_spectrum::rgb_space::RgbColorSpace;

    #[test]
    fn two_level_image_compresses_base_to_the_target_contrast() {
        // Left half 0.01, right half 10 (3 decades ≫ σ_r): the base is the image itself,
        // γ = log10 5 / 3, so the right maps to 1 and the left to 10^{-log10 5} = 1/5.
        let (w, h) = (64, 32);
        let pixels = (0..w * h)
            .map(|i| {
                let v = if i % w < 32 { 0.01f32 } else { 10.0 };
                [v, 0.5 * v, 0.25 * v]
            })
            .collect();
        let img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        let out = ToneOperator::Durand02
            .apply(&img, &ToneParams::default())
            .unwrap();
        let l_right = luminance(&img, img.pixels()[40]);
        let l_left = luminance(&img, img.pixels()[0]);
        // log10 of both luminances through f32: ~1e-6 relative; 1e-4 after 10^x.
        let gamma = 5f64.log10() / (l_right / l_left).log10();
        assert!((out.report.values["compression_factor"] - gamma).abs() < 1e-5);
        for (k, p) in out.image.pixels().iter().enumerate() {
            let want = if k % w < 32 { 0.2 } else { 1.0 };
            let got = luminance(&out.image, *p);
            assert!((got - want).abs() < 1e-4 * want, "{k}: {got} vs {want}");
            // Colour ratio kept.
            assert!((p[1] / p[0] - 0.5).abs() < 1e-5);
        }
    }

    #[test]
    fn detail_on_a_smooth_base_is_kept() {
        // A ±10 % checkerboard on a 4-decade horizontal ramp: the base follows the ramp,
        // the detail (±0.04 in log10, ≪ σ_r) passes through, so neighbouring pixels keep
        // their ratio while the ramp is compressed.
        let (w, h) = (128, 16);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let ramp = 10f32.powf(-2.0 + 4.0 * x as f32 / (w - 1) as f32);
                let v = ramp * if (x + y) % 2 == 0 { 1.1 } else { 0.9 };
                [v; 3]
            })
            .collect();
        let img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        let out = ToneOperator::Durand02
            .apply(&img, &ToneParams::default())
            .unwrap();
        let gamma = out.report.values["compression_factor"];
        assert!(gamma < 0.25, "γ = {gamma}");
        let px = |x: usize| luminance(&out.image, out.image.pixels()[8 * w + x]);
        // Detail (the checker, 1.1/0.9) kept; the ramp's step 10^{-4/127} compressed to
        // 10^{-4γ/127}. The grid smooths the ±0.04 checker only partly into the base and
        // quantises positions to σ_s: allow 3 % on a 22 % ratio.
        let want = 1.1 / 0.9 * 10f64.powf(-4.0 * gamma / 127.0);
        let ratio_out = px(64) / px(65);
        assert!(
            (ratio_out / want - 1.0).abs() < 0.03,
            "{ratio_out} vs {want}"
        );
        // Global range compressed: end-to-end ratio ≪ the input's 10^4.
        assert!(px(w - 2) / px(1) < 100.0);
    }
}
