//! Logarithmic mapping: L_d = log10(1 + q · L_w) / log10(1 + k · L_max), q, k ≥ 1
//! (Banterle, Artusi, Debattista & Chalmers, "Advanced High Dynamic Range Imaging" (2011),
//! ch. 3, "logarithmic mapping"; the base of Drago et al. 2003). The brightest pixel maps
//! to 1 when q = k.

use super::fast_math;
use super::kernels;
use super::pixels::{luminance_stats, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "logarithmic",
    reference: "Logarithmic mapping L_d = log10(1 + q L_w) / log10(1 + k L_max); Banterle \
                et al. 2011, Advanced HDR Imaging, ch. 3",
    absolute: false,
    params: &[
        ParamSpec {
            name: "q",
            default: Some(1.0),
            min: 1.0,
            max: 1e6,
            doc: "input scale q ≥ 1",
        },
        ParamSpec {
            name: "k",
            default: Some(1.0),
            min: 1.0,
            max: 1e6,
            doc: "maximum scale k ≥ 1",
        },
    ],
};

/// ln(1 + q L) / ln(1 + k L_max) (log10 a / log10 b = ln a / ln b).
pub(super) struct Curve {
    pub(super) q: f32,
    pub(super) inv: f32,
}

impl LuminanceCurve for Curve {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        // ln(1 + qL) · inv / L = log2(1 + qL) · (ln 2 · inv) · (1/L), the log's division
        // and 1/L sharing one (fast_math::log2_and_recip).
        let (q, inv) = (self.q, self.inv * std::f32::consts::LN_2);
        for v in l {
            let (log, recip) = fast_math::log2_and_recip(1.0 + q * *v, *v);
            *v = log * inv * recip;
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let (q, k) = (ctx.value("q"), ctx.value("k"));
    let denominator = (k * stats.max).ln_1p();
    let inv = if denominator > 0.0 {
        (1.0 / denominator) as f32
    } else {
        0.0
    };
    let q32 = q as f32;
    Output {
        mapped: kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Curve { q: q32, inv }),
        values: vec![("max_luminance", stats.max), ("q", q), ("k", k)],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_formula() {
        let img = small_image();
        let out = ToneOperator::Logarithmic
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let l_max = lw.iter().cloned().fold(0.0, f64::max);
        for (i, p) in out.pixels().iter().enumerate() {
            let ld = (1.0 + lw[i]).log10() / (1.0 + l_max).log10();
            assert_close(luminance(&out, *p), ld, "L_d");
        }
        assert_monotone(ToneOperator::Logarithmic, &ToneParams::default(), None);
    }

    #[test]
    fn vector_path_gives_the_scalar_bits() {
        for (q, inv) in [(1.0f32, 0.2f32), (37.0, 0.05), (1e6, 0.0)] {
            super::super::kernels::tests::same_bits_as_scalar(&bit_test_image(), 1.0, |_| {
                super::Curve { q, inv }
            });
        }
    }

    #[test]
    fn matches_f64_to_a_fraction_of_a_16_bit_code() {
        let img = sweep_image(40_000);
        let result = ToneOperator::Logarithmic
            .apply(&img, &ToneParams::default())
            .unwrap();
        // The formula in f64 on the operator's own maximum.
        let l_max = result.report.values["max_luminance"];
        let want: Vec<[f64; 3]> = img
            .pixels()
            .iter()
            .map(|p| {
                let l = luminance(&img, *p);
                let ratio = l.ln_1p() / (l_max.ln_1p() * l);
                p.map(|c| c as f64 * ratio)
            })
            .collect();
        let err = max_code_error_16(result.image.pixels(), &want);
        eprintln!("logarithmic: max error {err} 16-bit codes");
        // Measured 0.015 codes (fast log2 ≤ 1.5e-7 absolute, f32 arithmetic).
        assert!(err < 0.025, "{err} 16-bit codes");
    }
}
