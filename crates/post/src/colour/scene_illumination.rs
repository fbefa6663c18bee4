//! The scene illuminant's white from an illumination layer (`--wb scene`).
//!
//! `prism render` writes, per pixel, the CIE 1931 XYZ (beauty normalisation) of the light a
//! neutral white Lambertian surface would reflect at the pixel's first hit: the layer
//! `illumination` with channels `X`, `Y`, `Z`. Its chromaticity at a pixel is that of the
//! light falling there, whatever the surface's own colour, so the image's white can be
//! taken from the lighting itself instead of guessed from the pixels (grey world, white
//! patch), which colourful surfaces fool.
//!
//! The scene white is the luminance-weighted mean chromaticity over the pixels whose
//! illumination is non-zero:
//!
//! ```text
//!     x̄ = Σ Yᵢ xᵢ / Σ Yᵢ,   ȳ = Σ Yᵢ yᵢ / Σ Yᵢ,   xᵢ = Xᵢ / (Xᵢ + Yᵢ + Zᵢ), yᵢ = Yᵢ / (…)
//! ```
//!
//! so brightly lit regions count more and pixels without a hit (zero illumination) not at
//! all; it is returned as XYZ with Y = 1 (CIE 15:2018 eq. 7.4 backwards: X = x/y, Z =
//! (1 − x − y)/y). Pixels with a non-finite or negative component, or Y ≤ 0, are skipped.

use glam::DVec3;
use prism_spectrum::rgb_space::xy_to_xyz_unit_y;
use rayon::prelude::*;

use crate::colour::error::PostColourError;
use crate::colour::white_balance::SceneWhite;
use prism_image::rgb_matrix::CHUNK_PIXELS;

/// The layer's name.
pub const ILLUMINATION_LAYER: &str = "illumination";
/// Its channels.
pub const ILLUMINATION_CHANNELS: [&str; 3] = ["X", "Y", "Z"];

/// Σ Y·(x, y), Σ Y and the pixel count over the usable pixels of `xyz`.
fn weighted_chromaticity_sums(xyz: &[[f32; 3]]) -> (DVec3, usize) {
    // Chunk sums added in chunk order: the result does not depend on the thread count.
    let partial: Vec<(DVec3, usize)> = xyz
        .par_chunks(CHUNK_PIXELS)
        .map(|chunk| {
            chunk.iter().fold((DVec3::ZERO, 0), |(sum, n), p| {
                let [x, y, z] = p.map(f64::from);
                let usable = [x, y, z].iter().all(|c| c.is_finite() && *c >= 0.0) && y > 0.0;
                if !usable {
                    return (sum, n);
                }
                let total = x + y + z;
                // Y · (x, y) = Y · (X, Y) / (X + Y + Z).
                (sum + DVec3::new(y * x / total, y * y / total, y), n + 1)
            })
        })
        .collect();
    partial
        .into_iter()
        .fold((DVec3::ZERO, 0), |(s, n), (ps, pn)| (s + ps, n + pn))
}

/// The scene white (XYZ with Y = 1) of an illumination layer given as per-pixel XYZ; an
/// error when no pixel has non-zero illumination.
pub fn illumination_white_xyz(xyz: &[[f32; 3]]) -> Result<SceneWhite, PostColourError> {
    let (sums, pixels_used) = weighted_chromaticity_sums(xyz);
    if pixels_used == 0 || sums.z <= 0.0 {
        return Err(PostColourError::NoSceneWhite {
            method: "scene".into(),
            reason: "the illumination layer is zero (or unusable) everywhere: the render's \
                     integrator did not record it (the diagnostic integrators leave it 0)"
                .into(),
        });
    }
    let (x, y) = (sums.x / sums.z, sums.y / sums.z);
    Ok(SceneWhite {
        xyz: xy_to_xyz_unit_y(x, y),
        pixels_used,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::colorimetry::xyz_to_xy;

    #[test]
    fn a_uniform_layer_gives_its_own_chromaticity_whatever_its_level() {
        let white = [0.9505f32, 1.0, 1.089];
        let layer: Vec<[f32; 3]> = (1..=10).map(|k| white.map(|c| c * k as f32)).collect();
        let got = illumination_white_xyz(&layer).unwrap();
        let want = xyz_to_xy(DVec3::new(0.9505, 1.0, 1.089)).unwrap();
        let xy = xyz_to_xy(got.xyz).unwrap();
        assert!((xy - want).abs().max_element() < 1e-7, "{xy} vs {want}");
        assert!((got.xyz.y - 1.0).abs() < 1e-12);
        assert_eq!(got.pixels_used, 10);
    }

    #[test]
    fn chromaticities_are_weighted_by_luminance_and_misses_are_skipped() {
        // Equal-energy white (x = y = 1/3) at Y = 3 and a pure-X-ish light at Y = 1:
        // x̄ = (3 · 1/3 + 1 · x₂) / 4.
        let e = [3.0f32, 3.0, 3.0];
        let other = [2.0f32, 1.0, 1.0]; // x₂ = 0.5, y₂ = 0.25
        let layer = vec![e, other, [0.0; 3], [f32::NAN, 1.0, 1.0], [1.0, -1.0, 0.0]];
        let got = illumination_white_xyz(&layer).unwrap();
        let xy = xyz_to_xy(got.xyz).unwrap();
        let want_x = (3.0 / 3.0 + 0.5) / 4.0;
        let want_y = (3.0 / 3.0 + 0.25) / 4.0;
        assert!(
            (xy.x - want_x).abs() < 1e-12 && (xy.y - want_y).abs() < 1e-12,
            "{xy}"
        );
        assert_eq!(got.pixels_used, 2);
    }

    #[test]
    fn a_zero_layer_is_an_error_saying_why() {
        let e = illumination_white_xyz(&[[0.0; 3]; 4])
            .unwrap_err()
            .to_string();
        assert!(e.contains("scene") && e.contains("zero"), "{e}");
        assert!(illumination_white_xyz(&[]).is_err());
    }
}
