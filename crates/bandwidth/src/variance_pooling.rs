//! Pooling V̂_p over neighbouring pixels of the same surface (beyond the paper).
//!
//! Eq. 9's V̂_p is a Monte Carlo mean over n_b probe directions, and its terms are heavy
//! tailed: a probe sample that meets the sun of an environment map carries a bandwidth
//! thousands of times the sky's, so two neighbouring pixels of one Lambertian floor differ
//! by 10⁴ (measured on the fig. 9 scene). Allocating on such an estimate spreads samples at
//! random. Pooling the estimate over the (2r+1)² window around a pixel, among pixels that
//! see the same material (or, for pixels that see the background, among those), gives it
//! (2r+1)²·n_b samples; the shading variance of one surface changes slowly apart from its
//! edges, which the material classes keep apart. Measured (docs/bandwidth.md): with r = 2
//! the allocation's expected relMSE beats uniform sampling's on the three benchmark scenes,
//! where per-pixel V̂ lost to it.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::pixel_neighbours::window;

/// The default pooling radius r in pixels (a 5×5 window).
pub const DEFAULT_POOL_RADIUS_PX: u32 = 2;

/// The surface class of a pixel: pooling only mixes pixels of one class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelClass {
    /// The centre ray hits a surface of this material.
    Material(u32),
    /// The centre ray escapes to the infinite lights.
    Background,
    /// No prediction (no footprint, or nothing hit and no infinite light): kept as it is and
    /// never pooled into a neighbour.
    Unpredicted,
}

/// V̂ pooled per pixel: the mean of `variance` over the (2r+1)² window around each pixel
/// (clipped at the image border) among the pixels of the same [`PixelClass`];
/// `Unpredicted` pixels keep their own value. `radius_px` = 0 returns the input.
pub fn pool_variance(
    resolution: UVec2,
    variance: &[f32],
    class: &[PixelClass],
    radius_px: u32,
) -> Result<Vec<f32>, BandwidthError> {
    pool_scaled(
        resolution,
        variance,
        &vec![1.0; variance.len()],
        class,
        &vec![true; variance.len()],
        radius_px,
    )
}

/// [`pool_variance`] of values that scale with a known per-pixel factor (V̂ and L̂ of a
/// textured surface go as ρ² and ρ): pixel p gets scale_p · Σ_q value_q / Σ_q scale_q over
/// its same-class window, the least-squares fit of value = c · scale there, so a texture's
/// pattern survives the pooling that removes the probe's noise. Where the window's scales
/// sum to 0 the plain mean is kept. All scales 1 is [`pool_variance`].
///
/// Only pixels marked in `probed` lend their value (`sparse_probing`: the others were not
/// sampled and carry none); a pixel with no probed pixel of its class in its window keeps
/// its own value. All true pools every pixel.
pub fn pool_scaled(
    resolution: UVec2,
    values: &[f32],
    scale: &[f32],
    class: &[PixelClass],
    probed: &[bool],
    radius_px: u32,
) -> Result<Vec<f32>, BandwidthError> {
    let count = pixel_count("pooled V̂", resolution)?;
    check_lengths(
        resolution,
        count,
        &[
            ("V̂ to pool", values.len()),
            ("pooling scales", scale.len()),
            ("pixel classes", class.len()),
            ("probed mask", probed.len()),
        ],
    )?;
    if radius_px == 0 {
        return Ok(values.to_vec());
    }
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let r = radius_px as usize;
    let mut pooled = Vec::with_capacity(count);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let own = class[i];
            if own == PixelClass::Unpredicted {
                pooled.push(values[i]);
                continue;
            }
            let (mut sum, mut scale_sum, mut n) = (0.0f64, 0.0f64, 0u32);
            for (xx, yy) in window((x, y), r, (w, h)) {
                let j = yy * w + xx;
                if class[j] == own && probed[j] {
                    sum += f64::from(values[j]);
                    scale_sum += f64::from(scale[j]);
                    n += 1;
                }
            }
            let value = if n == 0 {
                f64::from(values[i])
            } else if scale_sum > 0.0 {
                f64::from(scale[i]) * (sum / scale_sum)
            } else {
                sum / f64::from(n)
            };
            pooled.push(value as f32);
        }
    }
    Ok(pooled)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_zero_is_the_identity() {
        let v = [1.0, 5.0, 0.0, 2.0];
        let c = [PixelClass::Material(0); 4];
        assert_eq!(pool_variance(UVec2::new(2, 2), &v, &c, 0).unwrap(), v);
    }

    #[test]
    fn pools_within_a_class_only() {
        // 4×1: two materials, then the background.
        let v = [1.0, 3.0, 100.0, 7.0];
        let c = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(1),
            PixelClass::Background,
        ];
        let p = pool_variance(UVec2::new(4, 1), &v, &c, 2).unwrap();
        assert_eq!(p, vec![2.0, 2.0, 100.0, 7.0]);
    }

    #[test]
    fn unpredicted_pixels_keep_their_value_and_are_not_pooled() {
        let v = [4.0, 1000.0, 8.0];
        let c = [
            PixelClass::Material(2),
            PixelClass::Unpredicted,
            PixelClass::Material(2),
        ];
        let p = pool_variance(UVec2::new(3, 1), &v, &c, 1).unwrap();
        assert_eq!(p, vec![4.0, 1000.0, 8.0]);
        let p = pool_variance(UVec2::new(3, 1), &v, &c, 2).unwrap();
        assert_eq!(p, vec![6.0, 1000.0, 6.0]);
    }

    #[test]
    fn window_is_clipped_at_the_border_and_keeps_the_mean() {
        // A 5×5 image of one class: the pooled image's corner is the mean of its 3×3 corner
        // window (r = 2), and a spike's total is spread, not lost.
        let mut v = vec![0.0f32; 25];
        v[12] = 25.0;
        let c = vec![PixelClass::Material(0); 25];
        let p = pool_variance(UVec2::new(5, 5), &v, &c, 2).unwrap();
        assert_eq!(p[0], 25.0 / 9.0);
        assert_eq!(p[12], 1.0);
        assert!(p.iter().all(|x| *x > 0.0));
    }

    /// A texture's pattern survives: values that are exactly c · scale come back unchanged,
    /// and noise on them is averaged in proportion to the scale.
    #[test]
    fn scaled_pooling_keeps_a_pattern_proportional_to_the_scale() {
        let scale = [0.2, 1.0, 0.5, 0.8, 0.1];
        let values: Vec<f32> = scale.iter().map(|s| 3.0 * s).collect();
        let c = [PixelClass::Material(0); 5];
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &[true; 5], 2).unwrap();
        for (got, want) in p.iter().zip(&values) {
            assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        }
        // One pixel twice too high: its excess is shared by scale, not evenly.
        let mut noisy = values.clone();
        noisy[2] *= 2.0;
        let p = pool_scaled(UVec2::new(5, 1), &noisy, &scale, &c, &[true; 5], 4).unwrap();
        let ratio: Vec<f32> = p.iter().zip(&scale).map(|(v, s)| v / s).collect();
        assert!(
            ratio.iter().all(|r| (r - ratio[0]).abs() < 1e-5),
            "{ratio:?}"
        );
        // A window whose scales are all 0 keeps the plain mean.
        let p = pool_scaled(
            UVec2::new(2, 1),
            &[1.0, 3.0],
            &[0.0, 0.0],
            &c[..2],
            &[true; 2],
            1,
        )
        .unwrap();
        assert_eq!(p, vec![2.0, 2.0]);
    }

    /// Sparse probing: pixels that were not probed lend nothing and take their probed
    /// neighbours' mean, scaled by their own texture.
    #[test]
    fn only_probed_pixels_lend_their_value() {
        let values = [2.0, 0.0, 4.0, 0.0, 9.0];
        let scale = [1.0, 0.5, 1.0, 1.0, 1.0];
        let c = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(1),
        ];
        let probed = [true, false, true, false, true];
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &probed, 1).unwrap();
        // Pixel 1: (2 + 4)/(1 + 1) × 0.5; pixel 3: its only probed neighbour of class 0 is
        // pixel 2; pixel 4 is alone in its class.
        assert_eq!(p, vec![2.0, 1.5, 4.0, 4.0, 9.0]);
        // A pixel with no probed pixel of its class in the window keeps its own value.
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &[false; 5], 1).unwrap();
        assert_eq!(p, values.to_vec());
    }

    #[test]
    fn wrong_sizes_are_refused_by_name() {
        let e = pool_variance(UVec2::new(2, 2), &[1.0; 3], &[PixelClass::Background; 4], 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("V̂ to pool"), "{e}");
    }
}
