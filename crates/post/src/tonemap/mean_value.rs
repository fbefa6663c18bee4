//! Mean-value mapping: one linear scale factor that puts the arithmetic mean luminance at
//! a target display value, L_d = target · L_w / mean(L_w), target = 0.5 ("mean value of the
//! histogram is mapped to 0.5"; Wilkie, Rendering lecture notes SS2011, §12.3.1). Values
//! outside the display range are clipped afterwards.

use super::pixels::{luminance_stats, Scale};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "mean-value",
    reference: "Mean-value mapping: L_d = target · L_w / mean(L_w) (linear global scale)",
    absolute: false,
    params: &[ParamSpec {
        name: "target",
        default: Some(0.5),
        min: 1e-6,
        max: 1.0,
        doc: "display value the mean luminance maps to",
    }],
};

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let target = ctx.value("target");
    let factor = if stats.mean > 0.0 {
        (target / stats.mean) as f32
    } else {
        0.0
    };
    Output {
        mapped: super::kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Scale(factor)),
        values: vec![("mean_luminance", stats.mean), ("scale", factor as f64)],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn mean_luminance_maps_to_target() {
        let img = small_image();
        let out = ToneOperator::MeanValue
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let mean_in: f64 = img
            .pixels()
            .iter()
            .map(|p| luminance(&img, *p))
            .sum::<f64>()
            / 4.0;
        let mean_out: f64 = out
            .pixels()
            .iter()
            .map(|p| luminance(&out, *p))
            .sum::<f64>()
            / 4.0;
        assert_close(mean_out, 0.5, "mean output luminance");
        for (a, b) in img.pixels().iter().zip(out.pixels()) {
            assert_close(b[0] as f64, a[0] as f64 * 0.5 / mean_in, "red");
        }
        assert_monotone(ToneOperator::MeanValue, &ToneParams::default(), None);
    }
}
