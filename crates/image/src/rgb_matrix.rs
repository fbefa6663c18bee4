//! Linear 3×3 transforms of RGB pixel slices: RGB → RGB between colour spaces (through
//! CIE 1931 XYZ, with a chromatic adaptation transform when the whites differ) and their
//! parallel application. Matrices are applied in f64 and stored back as f32.

use glam::{DMat3, DVec3};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::{adaptation_matrix, AdaptationMethod};
use rayon::prelude::*;

/// Pixels per rayon task: large enough to amortise scheduling, small enough to balance
/// load on a few cores. Chunking is fixed, so results do not depend on the thread count.
pub const CHUNK_PIXELS: usize = 4096;

/// True when both spaces have the same primaries and white (their RGB values mean the same
/// colours, so no conversion is needed and pixels can be left bit-for-bit untouched).
pub fn same_colorimetry(a: &RgbColorSpace, b: &RgbColorSpace) -> bool {
    a.primaries_xy == b.primaries_xy && a.white_xy == b.white_xy
}

/// The matrix taking linear RGB in `source` to linear RGB in `target`:
/// `target.xyz_to_rgb · CAT(source white → target white) · source.rgb_to_xyz`. The
/// adaptation is the identity when the whites are equal (or `adaptation` is `None`).
pub fn rgb_to_rgb_matrix(
    source: &RgbColorSpace,
    target: &RgbColorSpace,
    adaptation: AdaptationMethod,
) -> DMat3 {
    let cat = if source.white_xy == target.white_xy {
        DMat3::IDENTITY
    } else {
        adaptation_matrix(adaptation, source.white_xyz(), target.white_xyz())
    };
    target.xyz_to_rgb * cat * source.rgb_to_xyz
}

/// `m · rgb` in f64.
#[inline]
pub fn mul(m: &DMat3, rgb: [f32; 3]) -> DVec3 {
    *m * DVec3::new(f64::from(rgb[0]), f64::from(rgb[1]), f64::from(rgb[2]))
}

/// f64 RGB → stored f32 pixel.
#[inline]
pub fn to_pixel(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Applies `m` to every pixel in place, in parallel (allocation-free per pixel).
pub fn apply_rgb_matrix(pixels: &mut [[f32; 3]], m: DMat3) {
    pixels.par_chunks_mut(CHUNK_PIXELS).for_each(|chunk| {
        for p in chunk {
            *p = to_pixel(mul(&m, *p));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_space_matrix_is_identity_to_rounding() {
        let s = RgbColorSpace::srgb();
        let m = rgb_to_rgb_matrix(&s, &s, AdaptationMethod::Bradford);
        assert!(m.abs_diff_eq(DMat3::IDENTITY, 1e-12));
        assert!(same_colorimetry(&s, &RgbColorSpace::srgb()));
        assert!(!same_colorimetry(&s, &RgbColorSpace::rec2020()));
    }

    #[test]
    fn white_maps_to_white_across_whites() {
        // ACEScg (D60-ish) white → sRGB (D65) white under full adaptation.
        let m = rgb_to_rgb_matrix(
            &RgbColorSpace::acescg(),
            &RgbColorSpace::srgb(),
            AdaptationMethod::Bradford,
        );
        let w = mul(&m, [1.0, 1.0, 1.0]);
        assert!(w.abs_diff_eq(DVec3::ONE, 1e-9), "{w}");
    }
}
