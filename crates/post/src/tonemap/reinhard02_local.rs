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
//! computed one at a time while each pixel's selection streams along.
//!
//! Memory, beside the image (12 bytes per pixel for float RGB): two planes, V_1 of the
//! last scale compared and the selection, and one bit per pixel still searching (≈ 8.1
//! bytes per pixel whatever n is). L is computed from the image a row at a time, and the
//! blurs hand V_2 over a band of rows at a time, compared with V_1 as it comes: the FIR
//! blurs of the small scales all in one sweep over the bands
//! ([`fir_blurs_bands`]: each band's selection goes through their scales while the band
//! is in cache, and only the last is kept as a plane), then each recursive blur
//! ([`gaussian_blur_bands`]), whose V_2 takes V_1's place. No plane of L, of V_2 or of a
//! blur's intermediate rows; the same bits as with them (tested against whole-plane
//! blurs and the planes' selection, bit for bit).
//!
//! Deviation, stated: the kernels are normalised to unit sum on the pixel grid (as in
//! pfstmo's implementation); the continuous normalisation 1/(π(α s)²) would weight the
//! centre pixel by ≈ 2.5 at s = 1. Blurs: [`super::gaussian`] (direct FIR below σ = 3 px,
//! Young–van Vliet recursive above), edges replicated.

use rayon::prelude::*;

use super::gaussian::{fir_blurs_bands, gaussian_blur_bands, RECURSIVE_MIN_SIGMA};
use super::kernels::avx2;
use super::pixels::{luminance_chunk, luminance_stats, map_luminance, LuminanceCurve};
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

/// [`select_scale`] over one row, whose pixels still searching are the set bits of `act`
/// (pixel k of the row in bit k % 64 of word k / 64; words where none is are skipped).
/// Returns how many pixels passed.
#[inline(always)]
fn select_row(
    sel: &mut [f32],
    v1: &[f32],
    v2: &[f32],
    act: &mut [u64],
    denominator_offset: f32,
    epsilon: f32,
) -> usize {
    let mut passed = 0;
    for (((sel, v1), v2), word) in sel
        .chunks_mut(64)
        .zip(v1.chunks(64))
        .zip(v2.chunks(64))
        .zip(act.iter_mut())
    {
        if *word == 0 {
            continue;
        }
        let n = sel.len();
        let mut flags = [false; 64];
        for (k, f) in flags[..n].iter_mut().enumerate() {
            *f = (*word >> k) & 1 != 0;
        }
        passed += select_scale(sel, &mut flags[..n], v1, v2, denominator_offset, epsilon);
        let mut bits = 0u64;
        for (k, f) in flags[..n].iter().enumerate() {
            bits |= (*f as u64) << k;
        }
        *word = bits;
    }
    passed
}

/// [`select_row`] over a band of rows `width` long, rows in parallel, with the
/// (denominator offset, ε) of the scale. The one place that runs [`select_row`], so that
/// its kernel is compiled once, inlined in its wide form.
fn select_band(
    width: usize,
    sel: &mut [f32],
    v1: &[f32],
    v2: &[f32],
    act: &mut [u64],
    (denominator_offset, epsilon): (f32, f32),
    simd: prism_cpu::Simd,
) -> usize {
    let words = width.div_ceil(64);
    sel.par_chunks_mut(width)
        .zip(v1.par_chunks(width))
        .zip(v2.par_chunks(width))
        .zip(act.par_chunks_mut(words))
        .map(|(((sel, v1), v2), act)| {
            avx2!(
                simd,
                select_row(sel, v1, v2, act, denominator_offset, epsilon)
            )
        })
        .sum()
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

/// Eqs. 6–8 for the `width × height` luminance whose row y `source(y, row)` writes:
/// V_1(s_m) of every pixel (row-major), s_0's until a larger scale passes, and how many
/// scales were evaluated (fewer than `scales` when every pixel has stopped searching).
fn select_scales<S>(
    source: &S,
    width: usize,
    height: usize,
    scales: usize,
    sharpen: f32,
    epsilon: f32,
    simd: prism_cpu::Simd,
) -> (Vec<f32>, usize)
where
    S: Fn(usize, &mut [f32]) + Sync,
{
    let w = width;
    let n = w * height;
    let words = w.div_ceil(64);
    // Scale i compares blurs i and i + 1 (σ_2(s_i) = σ_1(s_{i+1})) at s_i = 1.6^i, the
    // powers taken by repeated multiplication.
    let mut s_of = vec![1.0f32];
    for i in 1..=scales {
        s_of.push(s_of[i - 1] * SCALE_RATIO);
    }
    let sigma_of = |j: usize| centre_sigma_px(s_of[j]);
    // Blurs 0 … m − 1 are FIRs, made in one sweep (one read of the image, each band's
    // selection through their scales in cache); the recursive ones follow one by one.
    let m = (0..=scales)
        .take_while(|j| sigma_of(*j) < RECURSIVE_MIN_SIGMA)
        .count();
    let fir_sigmas: Vec<f32> = (0..m).map(sigma_of).collect();
    let mut selected = vec![0.0f32; n];
    // One bit per pixel still searching, rows starting on a word.
    let mut active = vec![u64::MAX; height * words];
    // V_1 of the last blur of the sweep, where recursive blurs follow.
    let mut v1 = if m <= scales {
        vec![0.0f32; n]
    } else {
        Vec::new()
    };
    // Pixels passing each scale of the sweep.
    let mut passed = vec![0usize; m.saturating_sub(1)];
    fir_blurs_bands(
        source,
        w,
        height,
        &fir_sigmas,
        simd,
        |y0, j, v1_rows, v2| {
            let (at, rows) = (y0 * w..y0 * w + v2.len(), v2.len() / w);
            if j == 0 {
                selected[at.clone()].copy_from_slice(v2);
            } else {
                let i = j - 1;
                let denominator_offset = sharpen / (s_of[i] * s_of[i]);
                passed[i] += select_band(
                    w,
                    &mut selected[at.clone()],
                    v1_rows,
                    v2,
                    &mut active[y0 * words..(y0 + rows) * words],
                    (denominator_offset, epsilon),
                    simd,
                );
            }
            if j + 1 == m && !v1.is_empty() {
                v1[at].copy_from_slice(v2);
            }
        },
    );
    // Every pixel has found its scale: larger scales cannot change the result.
    if let Some(i) = passed.iter().position(|p| *p == 0) {
        return (selected, i + 1);
    }
    for (i, s) in s_of
        .iter()
        .enumerate()
        .take(scales)
        .skip(m.saturating_sub(1))
    {
        let denominator_offset = sharpen / (s * s);
        let mut still_active = 0usize;
        gaussian_blur_bands(source, w, height, sigma_of(i + 1), simd, |y0, v2| {
            let (at, rows) = (y0 * w..y0 * w + v2.len(), v2.len() / w);
            still_active += select_band(
                w,
                &mut selected[at.clone()],
                &v1[at.clone()],
                v2,
                &mut active[y0 * words..(y0 + rows) * words],
                (denominator_offset, epsilon),
                simd,
            );
            // V_2 is the next scale's V_1.
            v1[at].copy_from_slice(v2);
        });
        if still_active == 0 {
            return (selected, i + 1);
        }
    }
    (selected, scales)
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let key = ctx.value("key");
    let phi = ctx.value("phi");
    let epsilon = ctx.value("epsilon") as f32;
    let scales = ctx.value("scales").round().clamp(1.0, 12.0) as usize;
    let key_scale = (key / stats.log_average) as f32;
    let (w, h) = (ctx.image.width(), ctx.image.height());
    let (simd, weights, l_scale) = (ctx.simd, ctx.weights, ctx.exposure * key_scale);
    let sharpen = (2f64.powf(phi) * key) as f32;
    let (selected, scales_done) = ctx.read_pixels(|pixels| {
        // Row y of L (eq. 2), from the image, for every blur.
        let source = |y: usize, row: &mut [f32]| {
            let input = &pixels[y * w..(y + 1) * w];
            avx2!(simd, luminance_chunk(input, row, l_scale, weights))
        };
        select_scales(&source, w, h, scales, sharpen, epsilon, simd)
    });
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
    use super::super::gaussian::{sampled_kernel, whole_plane_blur};
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use super::{centre_sigma_px, select_scale, select_scales, SCALE_RATIO};
    use prism_cpu::Simd;
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

    /// The selection of the planes' algorithm (earlier versions: L, V_1, V_2 and the
    /// selection as whole planes, whole-plane blurs, a flag per pixel), which the bands
    /// and the bit per pixel must reproduce bit for bit.
    fn selected_with_planes(
        l: &[f32],
        w: usize,
        h: usize,
        scales: usize,
        sharpen: f32,
        epsilon: f32,
        simd: Simd,
    ) -> (Vec<f32>, usize) {
        let n = l.len();
        let (mut v1, mut v2, mut scratch) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let blur = |dst: &mut [f32], scratch: &mut [f32], sigma| {
            whole_plane_blur(l, dst, scratch, w, h, sigma, simd)
        };
        blur(&mut v1, &mut scratch, centre_sigma_px(1.0));
        let mut selected = v1.clone();
        let mut active = vec![true; n];
        let (mut s, mut done) = (1.0f32, 0);
        for _ in 0..scales {
            blur(&mut v2, &mut scratch, centre_sigma_px(s * SCALE_RATIO));
            let offset = sharpen / (s * s);
            let still = select_scale(&mut selected, &mut active, &v1, &v2, offset, epsilon);
            done += 1;
            if still == 0 {
                break;
            }
            std::mem::swap(&mut v1, &mut v2);
            s *= SCALE_RATIO;
        }
        (selected, done)
    }

    #[test]
    fn bands_and_bits_select_as_whole_planes_bit_for_bit() {
        for (w, h) in [(1usize, 9usize), (70, 3), (131, 77), (200, 150)] {
            // Bright spots and a dark corner on a ramp: pixels stop at every scale.
            let l: Vec<f32> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let spot = if (x * 7 + y * 3) % 29 == 0 { 30.0 } else { 0.0 };
                    let dark = if x < w / 4 && y > h / 2 { 0.01 } else { 1.0 };
                    dark * (0.05 + 0.02 * x as f32 + 0.01 * y as f32) + spot
                })
                .collect();
            let source = |y: usize, row: &mut [f32]| row.copy_from_slice(&l[y * w..(y + 1) * w]);
            for (scales, sharpen, epsilon) in
                [(8, 46.08f32, 0.05f32), (12, 46.08, 0.2), (3, 1.0, 1e-6)]
            {
                for simd in prism_cpu::each_isa() {
                    let want = selected_with_planes(&l, w, h, scales, sharpen, epsilon, simd);
                    let got = select_scales(&source, w, h, scales, sharpen, epsilon, simd);
                    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert!(
                        bits(&got.0) == bits(&want.0) && got.1 == want.1,
                        "{w}×{h}, {scales} scales, ε {epsilon}, {simd}"
                    );
                }
            }
        }
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
