//! Schlick 1994, "Quantization Techniques for Visualization of High Dynamic Range
//! Pictures", Photorealistic Rendering Techniques (EGWR), rational mapping:
//! L_d = p · L_w / ((p − 1) · L_w + L_max), p ≥ 1.
//! Default p = L_max / (N · L_min) (clamped to ≥ 1), N = 256 display levels, L_min the
//! smallest non-zero luminance: for small x = L_w / L_max the map is ≈ p·x, so this puts
//! the darkest non-black pixel on the first display level 1/N (Schlick's calibration).

use super::pixels::{luminance_stats, map_luminance, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "schlick94",
    reference: "Schlick 1994, Quantization Techniques for Visualization of High Dynamic \
                Range Pictures, EGWR (rational mapping)",
    absolute: false,
    params: &[
        ParamSpec {
            name: "p",
            default: None,
            min: 1.0,
            max: 1e12,
            doc: "rational slope p ≥ 1 (default: L_max / (levels · L_min))",
        },
        ParamSpec {
            name: "levels",
            default: Some(256.0),
            min: 2.0,
            max: 65536.0,
            doc: "number N of display levels for the default p",
        },
    ],
};

/// p L / ((p − 1) L + L_max).
struct Curve {
    p: f32,
    l_max: f32,
}

impl LuminanceCurve for Curve {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        // L_d / L = p / ((p − 1) L + L_max).
        let (p, l_max) = (self.p, self.l_max);
        for v in l {
            *v = p / ((p - 1.0) * *v + l_max);
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let p = ctx.param("p").unwrap_or_else(|| {
        if stats.min_positive > 0.0 {
            (stats.max / (ctx.value("levels") * stats.min_positive)).max(1.0)
        } else {
            1.0
        }
    });
    let (p32, l_max) = (p as f32, stats.max as f32);
    let mapped = map_luminance(ctx, ctx.exposure, ctx.weights, &Curve { p: p32, l_max });
    Output {
        mapped,
        values: vec![("p", p), ("max_luminance", stats.max)],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_formula_and_default_p() {
        let img = small_image();
        let result = ToneOperator::Schlick94
            .apply(&img, &ToneParams::default())
            .unwrap();
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let l_max = lw.iter().cloned().fold(0.0, f64::max);
        let l_min = lw.iter().cloned().fold(f64::INFINITY, f64::min);
        let p = l_max / (256.0 * l_min);
        let p = p.max(1.0);
        assert_close(result.report.values["p"], p, "p");
        for (i, px) in result.image.pixels().iter().enumerate() {
            let ld = p * lw[i] / ((p - 1.0) * lw[i] + l_max);
            assert_close(luminance(&result.image, *px), ld, "L_d");
        }
        let mut params = ToneParams::default();
        params.values.insert("p".into(), 50.0);
        assert_monotone(ToneOperator::Schlick94, &params, None);
        assert_monotone(ToneOperator::Schlick94, &ToneParams::default(), None);
    }
}
