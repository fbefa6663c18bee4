//! Exponential mapping: L_d = 1 − exp(−(q / k) · L_w / L_wa), with L_wa the log-average
//! luminance (exp mean ln(δ + L_w), δ = 1e-6); q, k ≥ 1 as in Banterle, Artusi, Debattista
//! & Chalmers, "Advanced High Dynamic Range Imaging" (2011), ch. 3 ("exponential
//! mapping"), after Ferschin, Tastl & Purgathofer 1994. The log-average maps to
//! 1 − e^(−q/k) (0.63 by default); compresses bright pixels more than a linear scale.

use super::fast_math;
use super::pixels::{luminance_stats, map_luminance, LuminanceCurve};
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
struct Curve {
    rate: f32,
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
            // loop stays branch-free.
            let x = rate * *v;
            let series = rate * (1.0 - 0.5 * x * (1.0 - x / 3.0 * (1.0 - 0.25 * x)));
            let direct = (1.0 - fast_math::exp(-x)) / *v;
            *v = if x < 0.01 { series } else { direct };
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx.image, ctx.exposure, ctx.weights);
    let (q, k) = (ctx.value("q"), ctx.value("k"));
    let rate = (q / k / stats.log_average) as f32;
    Output {
        mapped: map_luminance(ctx, ctx.exposure, ctx.weights, &Curve { rate }),
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
}
