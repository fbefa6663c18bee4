//! Reinhard, Stark, Shirley & Ferwerda 2002, "Photographic Tone Reproduction for Digital
//! Images", SIGGRAPH, §3 automatic dodging-and-burning (local operator):
//! eq. 1–2: L = a · L_w / L_avg (as the global operator);
//! eq. 5: R_i(x, y, s) = exp(−(x² + y²) / (α_i s)²) / (π (α_i s)²), α_1 = 1/(2√2),
//!        α_2 = 1.6 α_1, i.e. Gaussians of σ = α_i s / √2: σ_1(s) = s/4, σ_2(s) = 1.6 s/4;
//! eq. 6: V_i(x, y, s) = L ⊗ R_i(s);
//! eq. 7: V(x, y, s) = (V_1 − V_2) / (2^φ a / s² + V_1);
//! eq. 8: s_m = the largest scale with |V(x, y, s)| < ε for it and every smaller scale
//!        (scales s = 1.6^i, i = 0 … n−1; s_m = s_0 when the first fails);
//! eq. 9: L_d = L / (1 + V_1(x, y, s_m)).
//! Colour scaled by L_d / L_w. Since σ_2(s_i) = σ_1(s_{i+1}), n scales need n + 1 blurs,
//! computed one at a time while each pixel's selection streams along (five planes of
//! memory whatever n is).
//!
//! Deviation, stated: the kernels are normalised to unit sum on the pixel grid (as in
//! pfstmo's implementation); the continuous normalisation 1/(π(α s)²) would weight the
//! centre pixel by ≈ 2.5 at s = 1. Blurs: [`super::gaussian`] (direct FIR below σ = 3 px,
//! Young–van Vliet recursive above), edges replicated.

use rayon::prelude::*;

use super::gaussian::gaussian_blur;
use super::kernels::avx2;
use super::pixels::{luminance_plane, luminance_stats, map_luminance, LuminanceCurve, CHUNK};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "reinhard02-local",
    reference: "Reinhard, Stark, Shirley, Ferwerda 2002, Photographic Tone Reproduction for \
                Digital Images, SIGGRAPH (§3, eqs. 1, 2, 5–9: automatic dodging and burning)",
    absolute: false,
    params: &[
        ParamSpec {
            name: "key",
            default: Some(0.18),
            min: 1e-6,
            max: 1e3,
            doc: "key value a: the log-average luminance maps to a (middle grey 0.18)",
        },
        ParamSpec {
            name: "phi",
            default: Some(8.0),
            min: 0.0,
            max: 30.0,
            doc: "sharpening parameter φ of the centre-surround denominator (eq. 7)",
        },
        ParamSpec {
            name: "epsilon",
            default: Some(0.05),
            min: 1e-6,
            max: 10.0,
            doc: "threshold ε on |V| for the scale selection (eq. 8)",
        },
        ParamSpec {
            name: "scales",
            default: Some(8.0),
            min: 1.0,
            max: 12.0,
            doc: "number of scales s = 1.6^i, i = 0 … n−1 (rounded to an integer)",
        },
    ],
};

/// Ratio between consecutive scales and between the surround and centre kernels.
pub const SCALE_RATIO: f32 = 1.6;

/// σ in pixels of the centre Gaussian R_1 at scale s: α_1 s / √2 = s / 4 (eq. 5).
pub fn centre_sigma_px(s: f32) -> f32 {
    s / 4.0
}

/// Eqs. 7–8 for one scale over a task's pixels: a pixel still searching (`act`) whose
/// |V| < ε takes V_1 of this scale as its selection; one with |V| ≥ ε stops searching.
/// Branch-free (selects), so it vectorises; returns how many pixels passed.
#[inline(always)]
fn select_scale(
    sel: &mut [f32],
    act: &mut [bool],
    v1: &[f32],
    v2: &[f32],
    denominator_offset: f32,
    epsilon: f32,
) -> usize {
    let n = sel.len();
    let (act, v1, v2) = (&mut act[..n], &v1[..n], &v2[..n]);
    let mut passed = 0u32;
    for k in 0..n {
        let v = (v1[k] - v2[k]) / (denominator_offset + v1[k]);
        let pass = act[k] & (v.abs() < epsilon);
        sel[k] = if pass { v1[k] } else { sel[k] };
        act[k] = pass;
        passed += pass as u32;
    }
    passed as usize
}

/// Eq. 9 with eq. 2: L_d = a L_w / L_avg / (1 + V_1(s_m)).
struct Curve<'a> {
    key_scale: f32,
    selected: &'a [f32],
}

impl LuminanceCurve for Curve<'_> {
    #[inline(always)]
    fn ratio(&self, start: usize, l: &mut [f32]) {
        // L_d / L_w = (a / L_avg) / (1 + V_1(s_m)).
        let selected = &self.selected[start..start + l.len()];
        let key_scale = self.key_scale;
        for (v, s) in l.iter_mut().zip(selected) {
            *v = key_scale / (1.0 + s);
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let key = ctx.value("key");
    let phi = ctx.value("phi");
    let epsilon = ctx.value("epsilon") as f32;
    let scales = ctx.value("scales").round().clamp(1.0, 12.0) as usize;
    let key_scale = (key / stats.log_average) as f32;
    let (w, h) = (ctx.image.width(), ctx.image.height());
    let l = luminance_plane(ctx, ctx.exposure * key_scale, ctx.weights);
    let n = l.len();
    let mut v1 = vec![0.0f32; n];
    let mut v2 = vec![0.0f32; n];
    let mut scratch = vec![0.0f32; n];
    gaussian_blur(
        &l,
        &mut v1,
        &mut scratch,
        w,
        h,
        centre_sigma_px(1.0),
        ctx.simd,
    );
    // Selected V_1(s_m); s_0 until a larger scale passes.
    let mut selected = v1.clone();
    let mut active = vec![true; n];
    let sharpen = (2f64.powf(phi) * key) as f32;
    let mut s = 1.0f32;
    let mut scales_done = 0usize;
    for _ in 0..scales {
        gaussian_blur(
            &l,
            &mut v2,
            &mut scratch,
            w,
            h,
            centre_sigma_px(s * SCALE_RATIO),
            ctx.simd,
        );
        let denominator_offset = sharpen / (s * s);
        let still_active: usize = selected
            .par_chunks_mut(CHUNK)
            .zip(active.par_chunks_mut(CHUNK))
            .zip(v1.par_chunks(CHUNK).zip(v2.par_chunks(CHUNK)))
            .map(|((sel, act), (a, b))| {
                avx2!(
                    ctx.simd,
                    select_scale(sel, act, a, b, denominator_offset, epsilon)
                )
            })
            .sum();
        scales_done += 1;
        // Every pixel has found its scale: larger scales cannot change the result.
        if still_active == 0 {
            break;
        }
        std::mem::swap(&mut v1, &mut v2);
        s *= SCALE_RATIO;
    }
    drop((v1, v2, scratch, active));
    let curve = Curve {
        key_scale,
        selected: &selected,
    };
    let mapped = map_luminance(ctx, ctx.exposure, ctx.weights, &curve);
    Output {
        mapped,
        values: vec![
            ("log_average", stats.log_average),
            ("key", key),
            ("phi", phi),
            ("epsilon", epsilon as f64),
            ("scales", scales as f64),
            ("scales_evaluated", scales_done as f64),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::super::gaussian::sampled_kernel;
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use prism_image::Image;
    use prism_spectrum::rgb_space::RgbColorSpace;

    /// f64 reference blur: the sampled unit-sum Gaussian, edges replicated.
    fn blur(l: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
        let k: Vec<f64> = sampled_kernel(sigma as f32)
            .iter()
            .map(|v| *v as f64)
            .collect();
        let r = (k.len() / 2) as isize;
        let at = |x: isize, y: isize| {
            l[y.clamp(0, h as isize - 1) as usize * w + x.clamp(0, w as isize - 1) as usize]
        };
        let mut out = vec![0.0; l.len()];
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut acc = 0.0;
                for (j, kj) in k.iter().enumerate() {
                    for (i, ki) in k.iter().enumerate() {
                        acc += kj * ki * at(x + i as isize - r, y + j as isize - r);
                    }
                }
                out[(y * w as isize + x) as usize] = acc;
            }
        }
        out
    }

    #[test]
    fn matches_equations_5_to_9_on_a_hand_made_image() {
        // 14×10: a bright window, a dark corner and a gradient, so that different pixels
        // select different scales.
        let (w, h) = (14usize, 10usize);
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let v = if (4..8).contains(&x) && (3..6).contains(&y) {
                    40.0
                } else if x < 3 && y > 6 {
                    0.01
                } else {
                    0.2 + 0.15 * x as f32 + 0.05 * y as f32
                };
                [v, 0.8 * v, 0.5 * v]
            })
            .collect();
        let img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        // Five scales keep every σ (≤ 1.6^5 / 4 = 2.6 px) on the exact FIR path.
        let mut params = ToneParams::default();
        params.values.insert("scales".into(), 5.0);
        let out = ToneOperator::Reinhard02Local.apply(&img, &params).unwrap();
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let n = lw.len() as f64;
        let l_avg = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / n).exp();
        let a = 0.18;
        let l: Vec<f64> = lw.iter().map(|v| a * v / l_avg).collect();
        let blurs: Vec<Vec<f64>> = (0..=5)
            .map(|i| blur(&l, w, h, 1.6f64.powi(i) / 4.0))
            .collect();
        let mut scales_used = std::collections::BTreeSet::new();
        for (k, p) in out.image.pixels().iter().enumerate() {
            let mut chosen = (0, blurs[0][k]);
            for i in 0..5 {
                let s = 1.6f64.powi(i as i32);
                let v = (blurs[i][k] - blurs[i + 1][k]) / (256.0 * a / (s * s) + blurs[i][k]);
                if v.abs() >= 0.05 {
                    break;
                }
                chosen = (i, blurs[i][k]);
            }
            scales_used.insert(chosen.0);
            let ld = l[k] / (1.0 + chosen.1);
            assert_close(luminance(&out.image, *p), ld, &format!("pixel {k}"));
        }
        assert!(scales_used.len() >= 3, "scales used: {scales_used:?}");
    }

    #[test]
    fn uniform_image_reduces_to_the_global_curve() {
        // V = 0 everywhere, so s_m is the largest scale and V_1 = L: L_d = L / (1 + L)
        // (eq. 3), with L = a for a uniform image (L_avg = L_w up to δ).
        let img = Image::filled(40, 30, [2.0, 2.0, 2.0], RgbColorSpace::srgb()).unwrap();
        let out = ToneOperator::Reinhard02Local
            .apply(&img, &ToneParams::default())
            .unwrap();
        let l = 0.18 * 2.0 / (2.0f64 + 1e-6);
        for p in out.image.pixels() {
            // The recursive filter at the largest scales preserves constants to ~1e-6.
            assert!((luminance(&out.image, *p) - l / (1.0 + l)).abs() < 1e-5);
        }
    }
}
