//! Exponential mapping: L_d = 1 − exp(−(q / k) · L_w / L_wa), with L_wa the log-average
//! luminance (exp mean ln(δ + L_w), δ = 1e-6); q, k ≥ 1 as in Banterle, Artusi, Debattista
//! & Chalmers, "Advanced High Dynamic Range Imaging" (2011), ch. 3 ("exponential
//! mapping"), after Ferschin, Tastl & Purgathofer 1994. The log-average maps to
//! 1 − e^(−q/k) (0.63 by default); compresses bright pixels more than a linear scale.

use super::fast_math;
use super::kernels;
use super::pixels::{luminance_stats, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "exponential",
    reference: "Exponential mapping L_d = 1 − exp(−(q/k) L_w/L_wa); Banterle et al. 2011, \
                Advanced HDR Imaging, ch. 3 (Ferschin et al. 1994)",
    absolute: false,
    params: &[
        ParamSpec {
            name: "q",
            default: Some(1.0),
            min: 1.0,
            max: 1e6,
            doc: "appearance scale q ≥ 1",
        },
        ParamSpec {
            name: "k",
            default: Some(1.0),
            min: 1.0,
            max: 1e6,
            doc: "overall brightness divisor k ≥ 1",
        },
    ],
};

/// 1 − e^{−rate · L}.
pub(super) struct Curve {
    pub(super) rate: f32,
}

impl LuminanceCurve for Curve {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        let rate = self.rate;
        for v in l {
            // (1 − e^{−x}) / L: fast exp (relative error ≤ 3e-7, module fast_math) except
            // for x < 0.01, where the cancellation would cost digits and the series
            // x (1 − x/2 (1 − x/3 (1 − x/4))) is exact to x⁵/120 ≤ 1e-12 (divided by
            // L = x / rate: rate · (1 − …)). Both are evaluated and one selected, so the
            // loop stays branch-free; the selection is made before the one division
            // (numerator and denominator: (rate · (1 − …)) / 1 or (1 − e^{−x}) / L), and
            // x/3 is x · (1/3) (one rounding more on a term ≤ 0.0034 of the series), since
            // a vector division costs several multiplies' time.
            let x = rate * *v;
            let series = rate * (1.0 - 0.5 * x * (1.0 - x * THIRD * (1.0 - 0.25 * x)));
            let small = x < 0.01;
            let numerator = if small {
                series
            } else {
                1.0 - fast_math::exp(-x)
            };
            let denominator = if small { 1.0 } else { *v };
            *v = numerator / denominator;
        }
    }
}

/// 1/3 rounded to f32.
pub(super) const THIRD: f32 = 1.0 / 3.0;

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let (q, k) = (ctx.value("q"), ctx.value("k"));
    let rate = (q / k / stats.log_average) as f32;
    Output {
        mapped: kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Curve { rate }),
        values: vec![("log_average", stats.log_average), ("q", q), ("k", k)],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_formula() {
        let img = small_image();
        let mut params = ToneParams::default();
        params.values.insert("q".into(), 2.0);
        let out = ToneOperator::Exponential
            .apply(&img, &params)
            .unwrap()
            .image;
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let l_wa = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / 4.0).exp();
        for (i, p) in out.pixels().iter().enumerate() {
            let ld = 1.0 - (-2.0 * lw[i] / l_wa).exp();
            assert_close(luminance(&out, *p), ld, "L_d");
        }
        assert_monotone(ToneOperator::Exponential, &ToneParams::default(), None);
    }

    #[test]
    fn vector_path_gives_the_scalar_bits() {
        // Rates on both sides of the series/direct switch at x = 0.01 and into exp2's clamp.
        for rate in [0.18f32, 1.0, 7.3, 1e4] {
            super::super::kernels::tests::same_bits_as_scalar(&bit_test_image(), 1.0, |_| {
                super::Curve { rate }
            });
        }
    }

    #[test]
    fn matches_f64_to_a_fraction_of_a_16_bit_code() {
        let img = sweep_image(40_000);
        let result = ToneOperator::Exponential
            .apply(&img, &ToneParams::default())
            .unwrap();
        // The formula in f64 on the operator's own log-average.
        let l_wa = result.report.values["log_average"];
        let want: Vec<[f64; 3]> = img
            .pixels()
            .iter()
            .map(|p| {
                let l = luminance(&img, *p);
                let ratio = -(-l / l_wa).exp_m1() / l;
                p.map(|c| c as f64 * ratio)
            })
            .collect();
        let err = max_code_error_16(result.image.pixels(), &want);
        eprintln!("exponential: max error {err} 16-bit codes");
        // Measured 0.020 codes (fast exp2 ≤ 1.9e-7 relative on values up to 1, f32
        // arithmetic and log-average): a 16-bit PNG changes at most where a value lies
        // within that distance of a half-code tie.
        assert!(err < 0.03, "{err} 16-bit codes");
    }
}
