//! Oklab (Björn Ottosson, "A perceptual color space for image processing", 2020,
//! https://bottosson.github.io/posts/oklab/): CIE 1931 XYZ (D65, Y_white = 1) → LMS by M₁,
//! a cube root per channel, then M₂. The matrices are the published XYZ ones; the cube
//! root is sign-preserving so negative (out-of-gamut) LMS values stay invertible.

use glam::{DMat3, DVec3};
use prism_spectrum::adaptation::matrix_from_rows;
use prism_spectrum::rgb_space::RgbColorSpace;

/// M₁: XYZ (D65) → LMS, rows as published by Ottosson (2020).
pub const OKLAB_M1_XYZ_TO_LMS: [[f64; 3]; 3] = [
    [0.818_933_010_1, 0.361_866_742_4, -0.128_859_713_7],
    [0.032_984_543_6, 0.929_311_871_5, 0.036_145_638_7],
    [0.048_200_301_8, 0.264_366_269_1, 0.633_851_707_0],
];

/// M₂: LMS′ (cube roots) → (L, a, b), rows as published by Ottosson (2020).
pub const OKLAB_M2_LMS_TO_LAB: [[f64; 3]; 3] = [
    [0.210_454_255_3, 0.793_617_785_0, -0.004_072_046_8],
    [1.977_998_495_1, -2.428_592_205_0, 0.450_593_709_9],
    [0.025_904_037_1, 0.782_771_766_2, -0.808_675_766_0],
];

/// Linear RGB ↔ Oklab for one RGB space (whose white should be D65, as for sRGB,
/// Display P3 and Rec.2020; Oklab is defined for D65).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OklabConverter {
    rgb_to_lms: DMat3,
    lms_to_rgb: DMat3,
    m2: DMat3,
    m2_inverse: DMat3,
    /// Oklab L of the space's white, RGB (1, 1, 1) (1 to about 1e-6 for D65).
    pub l_white: f64,
    /// (a, b) / L of the space's white: the published matrices put D65 at
    /// (a, b) ≈ (−2·10⁻⁵, −1.2·10⁻⁴), not exactly on a = b = 0, and the greys of the space
    /// lie on the line (L, L·a_w/L_w, L·b_w/L_w).
    pub neutral_ab_per_l: [f64; 2],
}

impl OklabConverter {
    pub fn new(space: &RgbColorSpace) -> Self {
        let m1 = matrix_from_rows(OKLAB_M1_XYZ_TO_LMS);
        let m2 = matrix_from_rows(OKLAB_M2_LMS_TO_LAB);
        let rgb_to_lms = m1 * space.rgb_to_xyz;
        let mut c = Self {
            rgb_to_lms,
            lms_to_rgb: rgb_to_lms.inverse(),
            m2,
            m2_inverse: m2.inverse(),
            l_white: 1.0,
            neutral_ab_per_l: [0.0, 0.0],
        };
        let white = c.rgb_to_oklab(DVec3::ONE);
        c.l_white = white.x;
        c.neutral_ab_per_l = [white.y / white.x, white.z / white.x];
        c
    }

    /// Linear RGB → Oklab (L, a, b).
    #[inline]
    pub fn rgb_to_oklab(&self, rgb: DVec3) -> DVec3 {
        let lms = self.rgb_to_lms * rgb;
        self.m2 * DVec3::new(lms.x.cbrt(), lms.y.cbrt(), lms.z.cbrt())
    }

    /// Oklab (L, a, b) → linear RGB.
    #[inline]
    pub fn oklab_to_rgb(&self, lab: DVec3) -> DVec3 {
        let lms_root = self.m2_inverse * lab;
        self.lms_to_rgb * (lms_root * lms_root * lms_root)
    }
}

/// CIE 1931 XYZ (D65, Y_white = 1) → Oklab.
pub fn xyz_to_oklab(xyz: DVec3) -> DVec3 {
    let lms = matrix_from_rows(OKLAB_M1_XYZ_TO_LMS) * xyz;
    matrix_from_rows(OKLAB_M2_LMS_TO_LAB) * DVec3::new(lms.x.cbrt(), lms.y.cbrt(), lms.z.cbrt())
}

/// Oklab → CIE 1931 XYZ (D65, Y_white = 1).
pub fn oklab_to_xyz(lab: DVec3) -> DVec3 {
    let lms_root = matrix_from_rows(OKLAB_M2_LMS_TO_LAB).inverse() * lab;
    matrix_from_rows(OKLAB_M1_XYZ_TO_LMS).inverse() * (lms_root * lms_root * lms_root)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// colour-science 0.4.7: `colour.XYZ_to_Oklab(np.array([0.2, 0.3, 0.4]))` and
    /// `colour.XYZ_to_Oklab(np.array([0.950456, 1.0, 1.089058]))`.
    #[test]
    fn matches_colour_science_0_4_7() {
        let lab = xyz_to_oklab(DVec3::new(0.2, 0.3, 0.4));
        let expected = DVec3::new(0.655_537_15, -0.114_716_13, -0.026_210_79);
        assert!(lab.abs_diff_eq(expected, 1e-7), "{lab}");
        let white = xyz_to_oklab(DVec3::new(0.950_456, 1.0, 1.089_058));
        let expected = DVec3::new(0.999_998_807, -2.172_233_11e-5, -1.231_953_59e-4);
        assert!(white.abs_diff_eq(expected, 1e-8), "{white}");
    }

    #[test]
    fn round_trips_including_negative_lms() {
        let xyz = DVec3::new(0.3, 0.2, -0.05);
        assert!(oklab_to_xyz(xyz_to_oklab(xyz)).abs_diff_eq(xyz, 1e-12));
        let c = OklabConverter::new(&RgbColorSpace::srgb());
        let rgb = DVec3::new(1.2, -0.1, 0.4);
        assert!(c.oklab_to_rgb(c.rgb_to_oklab(rgb)).abs_diff_eq(rgb, 1e-12));
        assert!((c.l_white - 1.0).abs() < 1e-5);
        // Greys of the space lie on the neutral line.
        let grey = c.rgb_to_oklab(DVec3::splat(0.2));
        let [na, nb] = c.neutral_ab_per_l;
        assert!((grey.y - na * grey.x).abs() < 1e-12 && (grey.z - nb * grey.x).abs() < 1e-12);
    }
}
