//! Exponential mapping: L_d = 1 − exp(−(q / k) · L_w / L_wa), with L_wa the log-average
//! luminance (exp mean ln(δ + L_w), δ = 1e-6); q, k ≥ 1 as in Banterle, Artusi, Debattista
//! & Chalmers, "Advanced High Dynamic Range Imaging" (2011), ch. 3 ("exponential
//! mapping"), after Ferschin, Tastl & Purgathofer 1994. The log-average maps to
//! 1 − e^(−q/k) (0.63 by default); compresses bright pixels more than a linear scale.

use super::fast_math;
use super::map512::{self, RegisterCurve};
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
const THIRD: f32 = 1.0 / 3.0;

impl RegisterCurve for Curve {
    /// [`LuminanceCurve::ratio`] on 16 lanes (same operations, same order).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
        use std::arch::x86_64::*;
        let (one, rate) = (_mm512_set1_ps(1.0), _mm512_set1_ps(self.rate));
        let x = _mm512_mul_ps(rate, l);
        let small = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, _mm512_set1_ps(0.01));
        // Each branch only where some lane selects it (dark and bright pixels come in
        // runs, so the branches predict well); a lane's value is that of the scalar path
        // either way, since the blend below only reads the selected side.
        let series = if small != 0 {
            let inner = _mm512_sub_ps(one, _mm512_mul_ps(_mm512_set1_ps(0.25), x));
            let third = _mm512_mul_ps(_mm512_mul_ps(x, _mm512_set1_ps(THIRD)), inner);
            let half = _mm512_mul_ps(
                _mm512_mul_ps(_mm512_set1_ps(0.5), x),
                _mm512_sub_ps(one, third),
            );
            _mm512_mul_ps(rate, _mm512_sub_ps(one, half))
        } else {
            one
        };
        let e = if small != 0xffff {
            // exp(−x) = exp2((−x) · log2 e), −x by flipping the sign bit as `-x` does.
            let minus_x = _mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(x),
                _mm512_set1_epi32(i32::MIN),
            ));
            map512::exp2_16(_mm512_mul_ps(
                minus_x,
                _mm512_set1_ps(std::f32::consts::LOG2_E),
            ))
        } else {
            one
        };
        let numerator = _mm512_mask_blend_ps(small, _mm512_sub_ps(one, e), series);
        let denominator = _mm512_mask_blend_ps(small, l, one);
        _mm512_div_ps(numerator, denominator)
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx.image, ctx.exposure, ctx.weights);
    let (q, k) = (ctx.value("q"), ctx.value("k"));
    let rate = (q / k / stats.log_average) as f32;
    Output {
        mapped: map512::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Curve { rate }),
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
            super::super::map512::same_bits_as_scalar(
                &bit_test_image(),
                1.0,
                &super::Curve { rate },
            );
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
