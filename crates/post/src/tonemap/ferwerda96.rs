//! Ferwerda, Pattanaik, Shirley & Greenberg 1996, "A Model of Visual Adaptation for
//! Realistic Image Synthesis", SIGGRAPH: threshold-versus-intensity matching.
//! Photopic TVI (log10 cd/m²): log t_p = −0.72 (log L_a ≤ −2.6); log L_a − 1.255
//! (log L_a ≥ 1.9); (0.249 log L_a + 0.65)^2.7 − 0.72 otherwise.
//! Scotopic TVI: log t_s = −2.86 (log L_a ≤ −3.94); log L_a − 0.395 (log L_a ≥ −1.44);
//! (0.405 log L_a + 1.6)^2.18 − 2.86 otherwise.
//! Scales m_p = t_p(L_da) / t_p(L_wa), m_s = t_s(L_da) / t_s(L_wa); display RGB =
//! (m_p · RGB_w + k · m_s · L_scot) / L_dmax, the scotopic part achromatic.
//! L_wa = L_wmax / 2 and L_da = L_dmax / 2 (the paper's choice). Scotopic luminance from
//! XYZ by Ward Larson, Rushmeier & Piatko 1997 (TVCG 3(4), eq. 3):
//! L_scot = Y (1.33 (1 + (Y + Z) / X) − 1.68). Mesopic weight k = (1 − t)², t = (L_wa −
//! 0.01) / (10 − 0.01) clamped to [0, 1] (as in Banterle's HDR Toolbox): scotopic below
//! 0.01 cd/m², photopic above 10.

use super::pixels::{luminance_stats, map_pixels, PixelMap};
use super::{Context, OperatorInfo, Output, ParamSpec};
use prism_image::Result;

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "ferwerda96",
    reference: "Ferwerda, Pattanaik, Shirley, Greenberg 1996, A Model of Visual Adaptation \
                for Realistic Image Synthesis, SIGGRAPH",
    absolute: true,
    params: &[
        ParamSpec {
            name: "display_max",
            default: Some(100.0),
            min: 1.0,
            max: 1e5,
            doc: "L_dmax, maximum display luminance in cd/m²",
        },
        ParamSpec {
            name: "world_adaptation",
            default: None,
            min: 1e-8,
            max: 1e9,
            doc: "L_wa in cd/m² (default: half the largest world luminance)",
        },
    ],
};

/// Photopic threshold t_p(L_a) in cd/m².
pub fn photopic_threshold(l_a: f64) -> f64 {
    let x = l_a.log10();
    let log_t = if x <= -2.6 {
        -0.72
    } else if x >= 1.9 {
        x - 1.255
    } else {
        (0.249 * x + 0.65).powf(2.7) - 0.72
    };
    10f64.powf(log_t)
}

/// Scotopic threshold t_s(L_a) in scotopic cd/m².
pub fn scotopic_threshold(l_a: f64) -> f64 {
    let x = l_a.log10();
    let log_t = if x <= -3.94 {
        -2.86
    } else if x >= -1.44 {
        x - 0.395
    } else {
        (0.405 * x + 1.6).powf(2.18) - 2.86
    };
    10f64.powf(log_t)
}

/// Mesopic weight of the scotopic term for world adaptation `l_wa`.
pub fn mesopic_weight(l_wa: f64) -> f64 {
    let t = ((l_wa - 0.01) / (10.0 - 0.01)).clamp(0.0, 1.0);
    (1.0 - t) * (1.0 - t)
}

/// m_p · RGB + k m_s L_scot (both already divided by L_dmax).
struct Map {
    rgb_to_xyz: glam::Mat3,
    photopic: f32,
    scotopic: f32,
}

impl PixelMap for Map {
    #[inline(always)]
    fn map(&self, _start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        let (m, photopic, scotopic) = (self.rgb_to_xyz, self.photopic, self.scotopic);
        for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
            let xyz = m * glam::Vec3::new(*r, *g, *b);
            // Ward Larson et al. 1997, eq. 3; both sides evaluated and one selected.
            let l_scot = (xyz.y * (1.33 * (1.0 + (xyz.y + xyz.z) / xyz.x) - 1.68)).max(0.0);
            let l_scot = if xyz.x > 0.0 { l_scot } else { 0.0 };
            let s = scotopic * l_scot;
            (*r, *g, *b) = (photopic * *r + s, photopic * *g + s, photopic * *b + s);
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Result<Output> {
    let absolute = ctx.exposure * ctx.absolute_scale()? as f32;
    let stats = luminance_stats(ctx, absolute, ctx.weights);
    let l_dmax = ctx.value("display_max");
    let l_wa = ctx
        .param("world_adaptation")
        .unwrap_or(stats.max / 2.0)
        .max(1e-8);
    let l_da = l_dmax / 2.0;
    let m_p = photopic_threshold(l_da) / photopic_threshold(l_wa);
    let m_s = scotopic_threshold(l_da) / scotopic_threshold(l_wa);
    let k = mesopic_weight(l_wa);
    let photopic = (m_p / l_dmax) as f32;
    let scotopic = (k * m_s / l_dmax) as f32;
    let map = Map {
        rgb_to_xyz: ctx.image.color_space.rgb_to_xyz.as_mat3(),
        photopic,
        scotopic,
    };
    let mapped = map_pixels(ctx, absolute, &map);
    Ok(Output {
        mapped,
        values: vec![
            ("world_adaptation_cd_m2", l_wa),
            ("m_photopic", m_p),
            ("m_scotopic", m_s),
            ("mesopic_weight", k),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use super::*;

    #[test]
    fn tvi_curves_are_continuous_at_their_breakpoints() {
        // The published fits join to within 0.015 log units.
        for (f, x) in [
            (photopic_threshold as fn(f64) -> f64, -2.6),
            (photopic_threshold, 1.9),
            (scotopic_threshold, -3.94),
            (scotopic_threshold, -1.44),
        ] {
            let below = f(10f64.powf(x - 1e-9)).log10();
            let above = f(10f64.powf(x + 1e-9)).log10();
            assert!((below - above).abs() < 0.015, "{x}: {below} vs {above}");
        }
    }

    #[test]
    fn photopic_scene_scales_linearly_by_tvi_ratio() {
        // A bright scene: L_wa = L_max/2 ≥ 10 cd/m², so k = 0 and RGB_d = m_p RGB_w / L_dmax.
        let mut img = small_image();
        img.cd_m2_per_unit = Some(100.0);
        let out = ToneOperator::Ferwerda96
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let l_max = img
            .pixels()
            .iter()
            .map(|p| 100.0 * luminance(&img, *p))
            .fold(0.0, f64::max);
        let m_p = photopic_threshold(50.0) / photopic_threshold(l_max / 2.0);
        for (a, b) in img.pixels().iter().zip(out.pixels()) {
            for c in 0..3 {
                assert_close(b[c] as f64, m_p * 100.0 * a[c] as f64 / 100.0, "channel");
            }
        }
        assert_monotone(ToneOperator::Ferwerda96, &ToneParams::default(), Some(1e-3));
    }
}
