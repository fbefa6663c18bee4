//! Reinhard, Stark, Shirley & Ferwerda 2002, "Photographic Tone Reproduction for Digital
//! Images", SIGGRAPH, global operator:
//! eq. 1: L_avg = exp(mean ln(δ + L_w)), δ = 1e-6;
//! eq. 2: L = key · L_w / L_avg;
//! eq. 4: L_d = L (1 + L / L_white²) / (1 + L);
//! colour scaled by L_d / L_w. Defaults: key 0.18, L_white = the largest scaled L (so the
//! brightest pixel maps to 1).

use super::kernels;
use super::pixels::{luminance_stats, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "reinhard02",
    reference: "Reinhard, Stark, Shirley, Ferwerda 2002, Photographic Tone Reproduction for \
                Digital Images, SIGGRAPH (eqs. 1, 2, 4)",
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
            name: "white",
            default: None,
            min: 1e-6,
            max: 1e30,
            doc: "L_white in scaled units: smallest luminance mapped to white \
                  (default: the largest scaled luminance)",
        },
    ],
};

/// Eqs. 2 and 4: L = s · L_w, L_d = L (1 + L / L_white²) / (1 + L).
pub(super) struct Curve {
    pub(super) s: f32,
    pub(super) inv_white2: f32,
}

impl LuminanceCurve for Curve {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        // L_d / L_w = s (1 + L / L_white²) / (1 + L).
        let (s, inv_white2) = (self.s, self.inv_white2);
        for v in l {
            let x = s * *v;
            *v = s * (1.0 + x * inv_white2) / (1.0 + x);
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let key = ctx.value("key");
    let scale = key / stats.log_average;
    let white = ctx.param("white").unwrap_or(stats.max * scale);
    // L_white → ∞ (eq. 3, L_d = L / (1 + L)) for a black image.
    let inv_white2 = if white > 0.0 {
        (1.0 / (white * white)) as f32
    } else {
        0.0
    };
    let s = scale as f32;
    let mapped =
        kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Curve { s, inv_white2 });
    Output {
        mapped,
        values: vec![
            ("log_average", stats.log_average),
            ("key", key),
            ("white", white),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_equations_1_2_4_with_defaults() {
        let img = small_image();
        let result = ToneOperator::Reinhard02
            .apply(&img, &ToneParams::default())
            .unwrap();
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let l_avg = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / 4.0).exp();
        let scaled: Vec<f64> = lw.iter().map(|l| 0.18 * l / l_avg).collect();
        let white = scaled.iter().cloned().fold(0.0, f64::max);
        assert_close(result.report.values["log_average"], l_avg, "L_avg");
        for (i, p) in result.image.pixels().iter().enumerate() {
            let l = scaled[i];
            let ld = l * (1.0 + l / (white * white)) / (1.0 + l);
            for (got, input) in p.iter().zip(img.pixels()[i]) {
                assert_close(*got as f64, input as f64 * ld / lw[i], "channel");
            }
        }
        // The brightest pixel maps to luminance 1 exactly when L_white = max L.
        assert_close(
            luminance(&result.image, result.image.pixels()[3]),
            1.0,
            "white",
        );
        assert_monotone(ToneOperator::Reinhard02, &ToneParams::default(), None);
    }

    #[test]
    fn vector_path_gives_the_scalar_bits() {
        for (s, inv_white2) in [(0.18f32, 0.0f32), (2.5, 1e-4), (1e3, 3.0)] {
            super::super::kernels::tests::same_bits_as_scalar(&bit_test_image(), 1.0, |_| {
                super::Curve { s, inv_white2 }
            });
        }
    }
}
