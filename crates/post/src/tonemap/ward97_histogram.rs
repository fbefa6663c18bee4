//! Ward Larson, Rushmeier & Piatko 1997, "A Visibility Matching Tone Reproduction Operator
//! for High Dynamic Range Scenes", IEEE TVCG 3(4), histogram adjustment with the linear
//! ceiling (their "naive" contrast-matching constraint):
//! 1. Foveal image (§4.1): the absolute luminance (cd/m²) box-averaged over blocks of about
//!    1° of visual angle, `field_of_view` degrees across the image width;
//!    B = ln L of each foveal sample (black samples left out).
//! 2. Histogram f(b_i) of B in `bins` bins of width Δb over [B_min, B_max] (§4.2);
//!    cumulative P(b) = Σ_{b_i < b} f(b_i) / T, T = Σ f (eq. 4), interpolated linearly
//!    within a bin.
//! 3. Mapping (eq. 5): ln L_d = ln L_dmin + (ln L_dmax − ln L_dmin) · P(ln L_w).
//! 4. Ceiling (eqs. 6–9): display contrast must not exceed world contrast,
//!    dL_d/dL_w ≤ L_d/L_w, i.e. f(b_i) ≤ T Δb / (ln L_dmax − ln L_dmin); bins above the
//!    ceiling are truncated and T recomputed until the trimmed counts are ≤ 2.5 % of the
//!    original total (their Fig. 6 procedure); if T falls below that tolerance the scene
//!    range fits the display and a linear scale maps the foveal maximum to L_dmax (their
//!    fallback).
//!
//! Output display values are L_d / L_dmax; colour scaled by L_d / L_w. Needs absolute
//! luminance (`--luminance-scale` or `prism:cd_m2_per_unit`). The human-contrast-
//! sensitivity ceiling (their §5, eq. 10) is not implemented.

use rayon::prelude::*;

use super::fast_math;
use super::pixels::{dot, map_luminance, sanitise, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};
use prism_image::Result;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "ward97-histogram",
    reference: "Ward Larson, Rushmeier, Piatko 1997, A Visibility Matching Tone Reproduction \
                Operator for High Dynamic Range Scenes, IEEE TVCG 3(4) (eqs. 4, 5, 9; linear \
                ceiling)",
    absolute: true,
    params: &[
        ParamSpec {
            name: "display_min",
            default: Some(1.0),
            min: 1e-4,
            max: 1e4,
            doc: "L_dmin, minimum display luminance in cd/m²",
        },
        ParamSpec {
            name: "display_max",
            default: Some(100.0),
            min: 1e-3,
            max: 1e5,
            doc: "L_dmax, maximum display luminance in cd/m² (must exceed display_min)",
        },
        ParamSpec {
            name: "bins",
            default: Some(100.0),
            min: 2.0,
            max: 10000.0,
            doc: "number of log-luminance histogram bins (rounded)",
        },
        ParamSpec {
            name: "field_of_view",
            default: Some(60.0),
            min: 1.0,
            max: 360.0,
            doc: "horizontal field of view in degrees: the foveal image has one sample per \
                  degree across the width",
        },
    ],
};

/// Fraction of the original histogram total that ends the ceiling iteration (their 2.5 %).
pub const CEILING_TOLERANCE: f64 = 0.025;

/// Truncates `hist` (bin width `bin_width` in ln units) to the linear ceiling
/// T Δb / `display_log_range` until the trimmed counts are ≤ 2.5 % of the original total
/// (Ward Larson et al. 1997, Fig. 6). Returns false when the total falls below that
/// tolerance (the scene's range fits the display: use a linear mapping instead).
pub fn histogram_ceiling(hist: &mut [f64], bin_width: f64, display_log_range: f64) -> bool {
    let tolerance = CEILING_TOLERANCE * hist.iter().sum::<f64>();
    loop {
        let total: f64 = hist.iter().sum();
        if total < tolerance || total <= 0.0 {
            return false;
        }
        let ceiling = total * bin_width / display_log_range;
        let mut trimmings = 0.0;
        for f in hist.iter_mut() {
            if *f > ceiling {
                trimmings += *f - ceiling;
                *f = ceiling;
            }
        }
        if trimmings <= tolerance {
            return true;
        }
    }
}

/// Box-averaged absolute luminance over a `fw × fh` foveal grid (one pass, rows in
/// parallel).
fn foveal_means(ctx: &Context, scale: f32, fw: usize, fh: usize) -> Vec<f64> {
    let (w, h) = (ctx.image.width(), ctx.image.height());
    let sums = ctx.read_pixels(|pixels| {
        pixels
            .par_chunks(w)
            .enumerate()
            .fold(
                || vec![(0.0f64, 0u64); fw * fh],
                |mut acc, (y, row)| {
                    let by = y * fh / h;
                    let mut x0 = 0;
                    for bx in 0..fw {
                        let x1 = (bx + 1) * w / fw;
                        let s: f32 = row[x0..x1]
                            .iter()
                            .map(|p| dot(ctx.weights, sanitise(*p, scale)))
                            .sum();
                        let cell = &mut acc[by * fw + bx];
                        cell.0 += s as f64;
                        cell.1 += (x1 - x0) as u64;
                        x0 = x1;
                    }
                    acc
                },
            )
            .reduce(
                || vec![(0.0, 0); fw * fh],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(a, b)| {
                        a.0 += b.0;
                        a.1 += b.1;
                    });
                    a
                },
            )
    });
    sums.into_iter()
        .map(|(s, n)| if n > 0 { s / n as f64 } else { 0.0 })
        .collect()
}

/// Linear fallback: min(factor · L, 1).
struct Linear(f32);

impl LuminanceCurve for Linear {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        let factor = self.0;
        for v in l {
            *v = (factor * *v).min(1.0) / *v;
        }
    }
}

/// Eq. 5: L_d = exp(ln L_dmin + ln(L_dmax / L_dmin) P(ln L)) / L_dmax, P the cumulative
/// histogram interpolated linearly within a bin.
struct Histogram<'a> {
    cdf: &'a [f32],
    bins: usize,
    b_min: f32,
    inv_bw: f32,
    ln_dmin: f32,
    range: f32,
    inv_dmax: f32,
}

impl LuminanceCurve for Histogram<'_> {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        let (cdf, bins, b_min, inv_bw) = (self.cdf, self.bins, self.b_min, self.inv_bw);
        let (ln_dmin, range, inv_dmax) = (self.ln_dmin, self.range, self.inv_dmax);
        for v in l {
            let t = ((fast_math::ln(*v) - b_min) * inv_bw).clamp(0.0, bins as f32);
            let k = (t as usize).min(bins - 1);
            let p = cdf[k] + (t - k as f32) * (cdf[k + 1] - cdf[k]);
            *v = fast_math::exp(ln_dmin + range * p) * inv_dmax / *v;
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Result<Output> {
    let scale = ctx.exposure * ctx.absolute_scale()? as f32;
    let l_dmin = ctx.value("display_min");
    let l_dmax = ctx.value("display_max");
    if l_dmax <= l_dmin {
        return Err(prism_image::ImageError::invalid(format!(
            "ward97-histogram: display_max = {l_dmax} cd/m² must exceed display_min = \
             {l_dmin} cd/m²"
        )));
    }
    let bins = ctx.value("bins").round().max(2.0) as usize;
    let (w, h) = (ctx.image.width(), ctx.image.height());
    let fw = (ctx.value("field_of_view").round() as usize).clamp(1, w);
    let fh = ((fw as f64 * h as f64 / w as f64).round() as usize).clamp(1, h);
    let foveal: Vec<f64> = foveal_means(ctx, scale, fw, fh)
        .into_iter()
        .filter(|l| *l > 0.0 && l.is_finite())
        .map(f64::ln)
        .collect();
    let (b_min, b_max) = foveal
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let display_range = (l_dmax / l_dmin).ln();
    let mut values = vec![
        ("foveal_samples", foveal.len() as f64),
        ("foveal_log_min", b_min),
        ("foveal_log_max", b_max),
    ];
    let mut hist = vec![0.0f64; bins];
    let bin_width = (b_max - b_min) / bins as f64;
    let histogram_ok = if foveal.is_empty() || bin_width <= 0.0 {
        false
    } else {
        for b in &foveal {
            let k = (((b - b_min) / bin_width) as usize).min(bins - 1);
            hist[k] += 1.0;
        }
        histogram_ceiling(&mut hist, bin_width, display_range)
    };
    values.push(("histogram_adjusted", histogram_ok as u8 as f64));
    if !histogram_ok {
        // Linear fallback: the foveal maximum (or 1 cd/m² for a black image) to L_dmax.
        let top = if b_max.is_finite() { b_max.exp() } else { 1.0 };
        let factor = (1.0 / top) as f32;
        values.push(("linear_factor", factor as f64));
        return Ok(Output {
            mapped: map_luminance(ctx, scale, ctx.weights, &Linear(factor)),
            values,
        });
    }
    // Cumulative distribution at bin edges, normalised: cdf[k] = P(b_min + k Δb).
    let total: f64 = hist.iter().sum();
    values.push(("histogram_total_kept", total / foveal.len() as f64));
    let mut cdf = Vec::with_capacity(bins + 1);
    let mut acc = 0.0;
    cdf.push(0.0f32);
    for f in &hist {
        acc += f;
        cdf.push((acc / total) as f32);
    }
    let (b_min32, inv_bw) = (b_min as f32, (1.0 / bin_width) as f32);
    let (ln_dmin, range32, inv_dmax) = (l_dmin.ln() as f32, display_range as f32, 1.0 / l_dmax);
    let inv_dmax = inv_dmax as f32;
    let curve = Histogram {
        cdf: &cdf,
        bins,
        b_min: b_min32,
        inv_bw,
        ln_dmin,
        range: range32,
        inv_dmax,
    };
    let mapped = map_luminance(ctx, scale, ctx.weights, &curve);
    Ok(Output { mapped, values })
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use super::histogram_ceiling;
    use prism_image::Image;
    use prism_spectrum::rgb_space::RgbColorSpace;

    #[test]
    fn ceiling_iterates_to_the_hand_computed_histogram() {
        // T = 12, Δb = 1, range 2.5, tolerance 0.3: ceilings 4.8, 3.52, 3.008, 2.8032
        // (trimmings 3.2, 1.28, 0.512, 0.2048 ≤ 0.3 stops).
        let mut h = [1.0, 1.0, 8.0, 1.0, 1.0];
        assert!(histogram_ceiling(&mut h, 1.0, 2.5));
        let want = [1.0, 1.0, 2.8032, 1.0, 1.0];
        for (g, w) in h.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{h:?}");
        }
        // A range that fits the display: trimmed to nothing → linear fallback.
        let mut flat = [5.0; 4];
        assert!(!histogram_ceiling(&mut flat, 0.1, 10.0));
    }

    fn scene() -> Image {
        // 16×4, one foveal sample per pixel with field_of_view = 16: a sky of 10^3–10^4,
        // a room of 1–10, a few dark 10^-2 pixels (cd/m² with a scale of 1).
        let (w, h) = (16usize, 4usize);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let v = match y {
                    0 => 1e3 * 10f32.powf(x as f32 / 15.0),
                    3 if x < 4 => 1e-2,
                    _ => 1.0 + 9.0 * (x as f32 / 15.0) * (y as f32 / 2.0),
                };
                [v; 3]
            })
            .collect();
        let mut img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        img.cd_m2_per_unit = Some(1.0);
        img
    }

    #[test]
    fn maps_by_the_cumulative_histogram_of_equation_5() {
        let img = scene();
        let mut params = ToneParams::default();
        params.values.insert("field_of_view".into(), 16.0);
        // 23 bins: no luminance of the scene falls on a bin edge (where f32 and f64 could
        // disagree on the bin).
        params.values.insert("bins".into(), 23.0);
        let out = ToneOperator::Ward97Histogram.apply(&img, &params).unwrap();
        assert_eq!(out.report.values["histogram_adjusted"], 1.0);
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let b: Vec<f64> = lw.iter().map(|l| l.ln()).collect();
        let (lo, hi) = b
            .iter()
            .fold((f64::MAX, f64::MIN), |a, v| (a.0.min(*v), a.1.max(*v)));
        let n = 23;
        let bw = (hi - lo) / n as f64;
        let mut hist = vec![0.0; n];
        for v in &b {
            hist[(((v - lo) / bw) as usize).min(n - 1)] += 1.0;
        }
        let range = 100f64.ln();
        assert!(histogram_ceiling(&mut hist, bw, range));
        let total: f64 = hist.iter().sum();
        for (k, p) in out.image.pixels().iter().enumerate() {
            let t = ((b[k] - lo) / bw).clamp(0.0, n as f64);
            let i = (t as usize).min(n - 1);
            let below: f64 = hist[..i].iter().sum();
            let cdf = (below + (t - i as f64) * hist[i]) / total;
            let ld = (range * cdf).exp(); // L_dmin = 1
                                          // f32 ln/exp of values up to ln 100: ~1e-6 relative; 1e-5 with the CDF sums.
            assert_close(luminance(&out.image, *p), ld / 100.0, &format!("pixel {k}"));
        }
    }

    #[test]
    fn display_contrast_never_exceeds_world_contrast() {
        // The ceiling's purpose (eq. 9): |Δ ln L_d| ≤ |Δ ln L_w| between any two pixels, up to
        // the trimming tolerance: the last pass may leave ≤ 2.5 % of the original total T_0
        // above the final ceiling, so slopes ≤ 1 + 0.025 T_0 / T (T: the final total).
        let img = scene();
        let mut params = ToneParams::default();
        params.values.insert("field_of_view".into(), 16.0);
        let out = ToneOperator::Ward97Histogram.apply(&img, &params).unwrap();
        let slope = 1.0 + 0.025 / out.report.values["histogram_total_kept"];
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let ld: Vec<f64> = out
            .image
            .pixels()
            .iter()
            .map(|p| luminance(&out.image, *p))
            .collect();
        for i in 0..lw.len() {
            for j in 0..lw.len() {
                let dw = (lw[i] / lw[j]).ln().abs();
                let dd = (ld[i] / ld[j]).ln().abs();
                assert!(dd <= dw * slope + 1e-5, "{i},{j}: {dd} > {dw}");
            }
        }
        assert_monotone(
            ToneOperator::Ward97Histogram,
            &ToneParams::default(),
            Some(10.0),
        );
    }
}
