//! The per-pixel variance the allocation follows (beyond the paper; docs/bandwidth.md).
//!
//! Eq. 9 predicts the shading integral's variance up to a constant (cycles·Y²/sr): alone it
//! fixes the allocation, whose scale does not matter, but a camera sample's variance also
//! has colour noise (Y²), the background's noise (Y²) and, where a pixel straddles two
//! surfaces, the anti-aliasing of that edge. To add them, eq. 9 is put in Y² by one
//! constant per image: k = Σ measured / Σ eq. 9 over the pixels that see a surface, with
//! "measured" the probe's own sample variance of the direct-light estimator (unbiased, but
//! from n_b samples too noisy per pixel). Then, per pixel:
//!
//! V̂_p = pool(k·eq9_p + colour_p + indirect_p) + edge_p, L̂_p = pool(L_p)
//!
//! (with `Measured`, k·eq9_p is the probe's measured variance, k = 1); V̂_p less colour_p is
//! the luminance part, what a render's `variance.Y` measures.
//!
//! with indirect_p the variance of the probe's one-bounce indirect estimates (Y²), `pool` the
//! mean over the (2r+1)² same-surface window (`variance_pooling`), scaled by the pixel's
//! texture: a textured surface's V̂ goes as ρ_p² and its L̂ as ρ_p, so V̂/ρ² and L̂/ρ are
//! pooled and multiplied back (`pool_scaled`; ρ_p = 1 on untextured surfaces), and
//! edge_p = max over the 4-neighbours q of another surface of ¼ (L̂_p − L̂_q)²: a pixel whose
//! footprint is split between two radiances L̂_p and L̂_q in shares s and 1 − s has the
//! per-sample variance s(1 − s)(L̂_p − L̂_q)², ¼ (L̂_p − L̂_q)² at an even split.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::pixel_neighbours::four_neighbours;
use crate::pixel_prediction::PixelPrediction;
use crate::variance_pooling::{pool_scaled, pool_scaled_each, PixelClass};

/// What the allocation gets, per pixel (row-major), and the constant that put eq. 9 in Y².
#[derive(Clone, Debug, PartialEq)]
pub struct ModelledVariance {
    /// V̂_p, Y² per camera sample.
    pub variance: Vec<f32>,
    /// V̂_p without the colour term (the X and Z lanes' noise is not luminance's): the
    /// per-sample variance of luminance a render's `variance.Y` measures. The background
    /// keeps its own V̂ (its colour noise is the only variance it has).
    pub luminance_variance: Vec<f32>,
    /// L̂_p pooled like V̂_p, Y.
    pub mean_y: Vec<f32>,
    /// Surface pixels where the probe found neither light nor variance (pooled): the
    /// allocation's `uninformed` mask.
    pub uninformed: Vec<bool>,
    /// k: Y² per unit of the shading variance (1 where the shading variance is measured
    /// already; 0 where no pixel has any).
    pub shading_scale: f64,
}

/// V̂_p and L̂_p for the allocation (module docs). `measured_shading` is true when the
/// pixels' `shading_variance` is the measured variance already (k = 1). `texture_scale` is
/// ρ_p, the reflectance of each pixel's texture relative to its surface (1 where the surface
/// has no texture, and off surfaces). Only the `probed` pixels' own numbers count
/// (`sparse_probing`): the others get their window's (all true: every pixel's).
pub fn model_variance(
    resolution: UVec2,
    pixels: &[PixelPrediction],
    class: &[PixelClass],
    texture_scale: &[f32],
    probed: &[bool],
    radius_px: u32,
    measured_shading: bool,
) -> Result<ModelledVariance, BandwidthError> {
    let count = pixel_count("modelled V̂", resolution)?;
    check_lengths(
        resolution,
        count,
        &[
            ("pixel predictions", pixels.len()),
            ("pixel classes", class.len()),
            ("texture scales", texture_scale.len()),
            ("probed mask", probed.len()),
        ],
    )?;
    let shading_scale = if measured_shading {
        1.0
    } else {
        let (mut measured, mut predicted) = (0.0f64, 0.0f64);
        for ((p, c), probed) in pixels.iter().zip(class).zip(probed) {
            if let (PixelClass::Material(_), true) = (c, probed) {
                measured += f64::from(p.measured_variance);
                predicted += f64::from(p.shading_variance);
            }
        }
        if predicted > 0.0 {
            measured / predicted
        } else {
            0.0
        }
    };
    let own = |with_colour: bool| -> Vec<f32> {
        pixels
            .iter()
            .zip(class)
            .map(|(p, c)| match c {
                PixelClass::Material(_) => {
                    let colour = if with_colour { p.colour_variance } else { 0.0 };
                    (shading_scale * f64::from(p.shading_variance)) as f32
                        + colour
                        + p.indirect_variance
                }
                PixelClass::Background | PixelClass::Unpredicted => {
                    if with_colour {
                        p.variance
                    } else {
                        p.luminance_variance
                    }
                }
            })
            .collect()
    };
    let squared_scale: Vec<f32> = texture_scale.iter().map(|s| s * s).collect();
    // V̂ with and without the colour noise share their scale ρ²: pooled in one pass.
    let [mut variance, mut luminance_variance] = pool_scaled_each(
        resolution,
        [&own(true), &own(false)],
        &squared_scale,
        class,
        probed,
        radius_px,
    )?;
    let raw_mean: Vec<f32> = pixels.iter().map(|p| p.mean_y).collect();
    let mean_y = pool_scaled(
        resolution,
        &raw_mean,
        texture_scale,
        class,
        probed,
        radius_px,
    )?;
    for i in 0..count {
        let edge = four_neighbours(i, resolution)
            .filter(|&j| class[j] != class[i])
            .map(|j| 0.25 * (mean_y[i] - mean_y[j]).powi(2))
            .fold(0.0f32, f32::max);
        variance[i] += edge;
        luminance_variance[i] += edge;
    }
    let uninformed = (0..count)
        .map(|i| {
            matches!(class[i], PixelClass::Material(_)) && variance[i] == 0.0 && mean_y[i] == 0.0
        })
        .collect();
    Ok(ModelledVariance {
        variance,
        luminance_variance,
        mean_y,
        uninformed,
        shading_scale,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(shading: f32, measured: f32, colour: f32, mean_y: f32) -> PixelPrediction {
        PixelPrediction {
            shading_variance: shading,
            measured_variance: measured,
            colour_variance: colour,
            variance: shading + colour,
            mean_y,
            ..PixelPrediction::default()
        }
    }

    #[test]
    fn eq9_is_scaled_to_the_measured_total() {
        // Eq. 9 says 10 and 30, the probe measured 1 and 3 in sum 4: k = 0.1.
        let pixels = [pixel(10.0, 2.0, 0.5, 1.0), pixel(30.0, 2.0, 0.0, 1.0)];
        let class = [PixelClass::Material(0); 2];
        let m = model_variance(
            UVec2::new(2, 1),
            &pixels,
            &class,
            &[1.0; 2],
            &[true; 2],
            0,
            false,
        )
        .unwrap();
        assert!((m.shading_scale - 0.1).abs() < 1e-12);
        assert_eq!(m.variance, vec![1.5, 3.0]);
        // Less the first pixel's colour noise 0.5.
        assert_eq!(m.luminance_variance, vec![1.0, 3.0]);
        let measured = model_variance(
            UVec2::new(2, 1),
            &pixels,
            &class,
            &[1.0; 2],
            &[true; 2],
            0,
            true,
        )
        .unwrap();
        assert_eq!(measured.shading_scale, 1.0);
    }

    #[test]
    fn an_edge_between_surfaces_adds_a_quarter_of_the_squared_step() {
        // Two surfaces of L̂ 1 and 3 side by side, no shading noise: ¼·2² = 1 on both sides
        // of the edge, 0 inside.
        let pixels = [
            pixel(0.0, 0.0, 0.0, 1.0),
            pixel(0.0, 0.0, 0.0, 1.0),
            pixel(0.0, 0.0, 0.0, 3.0),
            pixel(0.0, 0.0, 0.0, 3.0),
        ];
        let class = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(1),
            PixelClass::Material(1),
        ];
        let m = model_variance(
            UVec2::new(4, 1),
            &pixels,
            &class,
            &[1.0; 4],
            &[true; 4],
            0,
            false,
        )
        .unwrap();
        assert_eq!(m.variance, vec![0.0, 1.0, 1.0, 0.0]);
        assert_eq!(m.shading_scale, 0.0);
        // The two inner pixels know of their edge; the outer ones saw no light at all.
        assert_eq!(m.uninformed, vec![false, false, false, false]);
        let dark = [pixel(0.0, 0.0, 0.0, 0.0); 4];
        let m = model_variance(
            UVec2::new(4, 1),
            &dark,
            &class,
            &[1.0; 4],
            &[true; 4],
            0,
            false,
        )
        .unwrap();
        assert_eq!(m.uninformed, vec![true; 4]);
    }

    #[test]
    fn background_keeps_its_own_variance_and_l_is_pooled() {
        let pixels = [
            pixel(4.0, 1.0, 0.0, 2.0),
            pixel(0.0, 0.0, 0.0, 4.0),
            PixelPrediction {
                variance: 0.7,
                mean_y: 3.0,
                ..PixelPrediction::default()
            },
        ];
        let class = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Background,
        ];
        let m = model_variance(
            UVec2::new(3, 1),
            &pixels,
            &class,
            &[1.0; 3],
            &[true; 3],
            1,
            false,
        )
        .unwrap();
        assert_eq!(m.mean_y, vec![3.0, 3.0, 3.0]);
        // k = 1/4; pooled own variance (1 + 0)/2 = 0.5; the middle pixel meets the
        // background with an equal L̂: no edge term.
        assert_eq!(m.variance, vec![0.5, 0.5, 0.7]);
    }
}
