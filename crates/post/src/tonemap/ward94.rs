//! Ward 1994, "A Contrast-Based Scalefactor for Luminance Display", Graphics Gems IV:
//! one scale factor that keeps just-noticeable differences, from Blackwell's contrast
//! sensitivity: sf = [(1.219 + (L_dmax / 2)^0.4) / (1.219 + L_wa^0.4)]^2.5,
//! L_d = sf · L_w (cd/m²), shown as L_d / L_dmax. L_wa is the world adaptation luminance,
//! the log-average of absolute luminance; the display adaptation is L_dmax / 2.

use super::pixels::{luminance_stats, Scale};
use super::{Context, OperatorInfo, Output, ParamSpec};
use prism_image::Result;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "ward94",
    reference: "Ward 1994, A Contrast-Based Scalefactor for Luminance Display, Graphics \
                Gems IV",
    absolute: true,
    params: &[ParamSpec {
        name: "display_max",
        default: Some(100.0),
        min: 1.0,
        max: 1e5,
        doc: "L_dmax, maximum display luminance in cd/m²",
    }],
};

/// Ward's scale factor for world adaptation `l_wa` and display maximum `l_dmax` (cd/m²).
pub fn scale_factor(l_wa: f64, l_dmax: f64) -> f64 {
    ((1.219 + (l_dmax / 2.0).powf(0.4)) / (1.219 + l_wa.powf(0.4))).powf(2.5)
}

pub(crate) fn apply(ctx: &Context) -> Result<Output> {
    let absolute = ctx.exposure * ctx.absolute_scale()? as f32;
    let stats = luminance_stats(ctx, absolute, ctx.weights);
    let l_dmax = ctx.value("display_max");
    let sf = scale_factor(stats.log_average, l_dmax);
    let factor = (sf / l_dmax) as f32;
    Ok(Output {
        mapped: super::kernels::map_luminance_fast(ctx, absolute, ctx.weights, &Scale(factor)),
        values: vec![
            ("world_adaptation_cd_m2", stats.log_average),
            ("scale_factor", sf),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_scale_factor_and_needs_absolute_luminance() {
        let img = small_image();
        let err = ToneOperator::Ward94
            .apply(&img, &ToneParams::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("--luminance-scale") && err.contains("prism:cd_m2_per_unit"));
        let params = ToneParams {
            luminance_scale_cd_m2: Some(50.0),
            ..Default::default()
        };
        let out = ToneOperator::Ward94.apply(&img, &params).unwrap().image;
        let lw: Vec<f64> = img
            .pixels()
            .iter()
            .map(|p| 50.0 * luminance(&img, *p))
            .collect();
        let l_wa = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / 4.0).exp();
        let sf = ((1.219 + 50f64.powf(0.4)) / (1.219 + l_wa.powf(0.4))).powf(2.5);
        for (i, p) in out.pixels().iter().enumerate() {
            assert_close(luminance(&out, *p), sf * lw[i] / 100.0, "L_d");
        }
        // When the world adaptation equals the display's (L_dmax/2), sf = 1.
        assert!((super::scale_factor(50.0, 100.0) - 1.0).abs() < 1e-15);
        assert_monotone(ToneOperator::Ward94, &ToneParams::default(), Some(10.0));
    }
}
