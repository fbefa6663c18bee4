//! Tumblin & Rushmeier 1993 ("Tone Reproduction for Realistic Images", IEEE CG&A) in the
//! revised form of Tumblin, Hodgins & Guenter 1999 ("Two Methods for Display of High
//! Contrast Images", ACM TOG 18(1)), as given by Reinhard et al., "High Dynamic Range
//! Imaging" (2nd ed. 2010), §8.1:
//! L_d = m · L_da · (L_w / L_wa)^(γ_w / γ_d), shown as L_d / L_dmax, with
//! γ(L) = 2.655 for L > 100 cd/m², else 1.855 + 0.4 log10(L + 2.3·10⁻⁵),
//! γ_w = γ(L_wa), γ_d = γ(L_da), γ_wd = γ_w / (1.855 + 0.4 log10 L_da),
//! m = C_max^((γ_wd − 1) / 2); L_wa = log-average world luminance (cd/m²), L_da the display
//! adaptation luminance, C_max the display contrast. Defaults L_da = 20 cd/m², C_max = 100,
//! L_dmax = 100 cd/m² (those of Banterle's HDR Toolbox).

use super::curve_table::CurveTable;
use super::pixels::{luminance_stats, map_luminance, LuminanceCurve};
use super::power_curve::PowerCurve;
use super::{Context, OperatorInfo, Output, ParamSpec};
use prism_image::Result;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "tumblin-rushmeier",
    reference: "Tumblin, Rushmeier 1993, IEEE CG&A; revised by Tumblin, Hodgins, Guenter \
                1999, Two Methods for Display of High Contrast Images, ACM TOG 18(1)",
    absolute: true,
    params: &[
        ParamSpec {
            name: "display_adaptation",
            default: Some(20.0),
            min: 1e-3,
            max: 1e4,
            doc: "L_da, display adaptation luminance in cd/m²",
        },
        ParamSpec {
            name: "max_contrast",
            default: Some(100.0),
            min: 1.0,
            max: 1e6,
            doc: "C_max, maximum display contrast",
        },
        ParamSpec {
            name: "display_max",
            default: Some(100.0),
            min: 1.0,
            max: 1e5,
            doc: "L_dmax, maximum display luminance in cd/m² (output = L_d / L_dmax)",
        },
    ],
};

/// Stevens' brightness exponent γ(L) as fitted by Tumblin & Rushmeier (L in cd/m²).
pub fn gamma(l: f64) -> f64 {
    if l > 100.0 {
        2.655
    } else {
        1.855 + 0.4 * (l + 2.3e-5).log10()
    }
}

/// L_d = factor · (L / L_wa)^exponent, as the ratio L_d / L = (factor / L_wa) ·
/// (L / L_wa)^(exponent − 1) = c · L^a over the image's luminance range, from the formula
/// in f64: evaluated in registers where the ISA (AVX-512) and the range allow (module
/// [`super::power_curve`]: five permutes and three multiply-adds per 16 pixels), else
/// tabulated (module [`super::curve_table`]: a 16-byte load and three multiply-adds per
/// 8 pixels instead of a fast log and exp).
enum Curve {
    Power(Box<PowerCurve>),
    /// The table and the ISA its slice lookup runs.
    Table(CurveTable, prism_cpu::Simd),
}

impl LuminanceCurve for Curve {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        match self {
            Curve::Power(p) => p.eval_slice(l),
            Curve::Table(t, simd) => t.eval_slice(l, *simd),
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Result<Output> {
    let absolute = ctx.exposure * ctx.absolute_scale()? as f32;
    let stats = luminance_stats(ctx, absolute, ctx.weights);
    let l_da = ctx.value("display_adaptation");
    let c_max = ctx.value("max_contrast");
    let l_dmax = ctx.value("display_max");
    let l_wa = stats.log_average;
    let (gamma_w, gamma_d) = (gamma(l_wa), gamma(l_da));
    let gamma_wd = gamma_w / (1.855 + 0.4 * l_da.log10());
    let m = c_max.powf((gamma_wd - 1.0) / 2.0);
    let exponent = gamma_w / gamma_d;
    let factor = m * l_da / l_dmax;
    let ratio = move |l: f64| factor / l_wa * (l / l_wa).powf(exponent - 1.0);
    let (lo, hi) = (stats.min_positive as f32, stats.max as f32);
    let a = exponent - 1.0;
    let curve = match PowerCurve::new(ctx.simd, factor / l_wa * l_wa.powf(-a), a, lo, hi) {
        Some(p) => Curve::Power(Box::new(p)),
        None => Curve::Table(CurveTable::new(lo, hi, ratio), ctx.simd),
    };
    Ok(Output {
        mapped: map_luminance(ctx, absolute, ctx.weights, &curve),
        values: vec![
            ("world_adaptation_cd_m2", l_wa),
            ("m", m),
            ("exponent", exponent),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::super::power_curve::PowerCurve;
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use prism_image::Image;

    #[test]
    fn matches_revised_formula() {
        let mut img = small_image();
        img.cd_m2_per_unit = Some(300.0);
        let out = ToneOperator::TumblinRushmeier
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let lw: Vec<f64> = img
            .pixels()
            .iter()
            .map(|p| 300.0 * luminance(&img, *p))
            .collect();
        let l_wa = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / 4.0).exp();
        let g = |l: f64| {
            if l > 100.0 {
                2.655
            } else {
                1.855 + 0.4 * (l + 2.3e-5).log10()
            }
        };
        let (gw, gd) = (g(l_wa), g(20.0));
        let m = 100f64.powf((gw / (1.855 + 0.4 * 20f64.log10()) - 1.0) / 2.0);
        for (i, p) in out.pixels().iter().enumerate() {
            let ld = m * 20.0 * (lw[i] / l_wa).powf(gw / gd) / 100.0;
            assert_close(luminance(&out, *p), ld, "L_d");
        }
        // γ is continuous at 100 cd/m² to 3 digits (1.855 + 0.4·2 = 2.655).
        assert!((super::gamma(100.0) - 2.655).abs() < 1e-6);
        assert_monotone(
            ToneOperator::TumblinRushmeier,
            &ToneParams::default(),
            Some(1.0),
        );
    }

    #[test]
    fn fast_path_matches_f64_to_a_fraction_of_a_16_bit_code() {
        // The sweep spans 34 binary exponents of luminance (the memory table); the
        // narrower one 23 (the register power curve where the CPU has AVX-512).
        let narrow = {
            let img = sweep_image(40_000);
            let pixels = img
                .pixels()
                .iter()
                .map(|p| p.map(|c| c.powf(0.66)))
                .collect();
            Image::new(img.width(), 1, pixels, img.color_space.clone()).unwrap()
        };
        for (name, mut img) in [("sweep", sweep_image(40_000)), ("narrow", narrow)] {
            img.cd_m2_per_unit = Some(1.0);
            let result = ToneOperator::TumblinRushmeier
                .apply(&img, &ToneParams::default())
                .unwrap();
            let value = |k: &str| result.report.values[k];
            let (l_wa, m, exponent) = (
                value("world_adaptation_cd_m2"),
                value("m"),
                value("exponent"),
            );
            let lum: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
            let (lo, hi) = lum
                .iter()
                .filter(|l| **l > 0.0)
                .fold((f64::INFINITY, 0.0f64), |(a, b), l| (a.min(*l), b.max(*l)));
            let power = PowerCurve::new(
                prism_cpu::active(),
                1.0,
                exponent - 1.0,
                lo as f32,
                hi as f32,
            )
            .is_some();
            let want: Vec<[f64; 3]> = img
                .pixels()
                .iter()
                .zip(&lum)
                .map(|(p, l)| {
                    let ld = m * 20.0 * (l / l_wa).powf(exponent) / 100.0;
                    p.map(|c| c as f64 * ld / l)
                })
                .collect();
            let err = max_code_error_16(result.image.pixels(), &want);
            eprintln!(
                "tumblin-rushmeier ({name}, register power curve: {power}): max error {err} \
                 16-bit codes"
            );
            // Measured 0.0036 codes with the memory table (the curve tabulated from f64,
            // ~1e-7 relative, and f32 sums; the f32 closed form with fast log2/exp2
            // measured 0.007), 0.0040 with the register power curve: a 16-bit PNG
            // changes at most where a value lies within that distance of a half-code tie.
            assert!(err < 0.01, "{name}: {err} 16-bit codes");
        }
    }
}
