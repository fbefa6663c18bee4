//! CIELAB and its polar form LCh(ab) of linear RGB pixels, relative to the RGB space's own
//! white (D65 for sRGB, Display P3 and Rec.2020) with Y_white = 1, so RGB (1, 1, 1) has
//! L* = 100 (CIE 15:2018 §8.2.1). The XYZ ↔ CIELAB formulas are prism-spectrum's
//! [`xyz_to_lab`] and [`lab_to_xyz`].

use glam::{DMat3, DVec3};
use prism_spectrum::colorimetry::{lab_to_xyz, xyz_to_lab};
use prism_spectrum::rgb_space::RgbColorSpace;

/// L* of the RGB space's white (and the top of the lightness range).
pub const CIELAB_L_WHITE: f64 = 100.0;

/// Linear RGB ↔ CIELAB for one RGB space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CielabConverter {
    rgb_to_xyz: DMat3,
    xyz_to_rgb: DMat3,
    white_xyz: DVec3,
}

impl CielabConverter {
    pub fn new(space: &RgbColorSpace) -> Self {
        Self {
            rgb_to_xyz: space.rgb_to_xyz,
            xyz_to_rgb: space.xyz_to_rgb,
            white_xyz: space.white_xyz(),
        }
    }

    /// Linear RGB → (L*, a*, b*).
    #[inline]
    pub fn rgb_to_lab(&self, rgb: DVec3) -> DVec3 {
        xyz_to_lab(self.rgb_to_xyz * rgb, self.white_xyz)
    }

    /// (L*, a*, b*) → linear RGB.
    #[inline]
    pub fn lab_to_rgb(&self, lab: DVec3) -> DVec3 {
        self.xyz_to_rgb * lab_to_xyz(lab, self.white_xyz)
    }
}

/// (L, a, b) → (L, C, h) with chroma C = √(a² + b²) and hue angle h in degrees in [0, 360)
/// (CIE 15:2018 eqs. 8.9–8.10). Works for Oklab's (L, a, b) too.
pub fn lab_to_lch_deg(lab: DVec3) -> DVec3 {
    let chroma = lab.y.hypot(lab.z);
    let hue_deg = lab.z.atan2(lab.y).to_degrees().rem_euclid(360.0);
    DVec3::new(lab.x, chroma, hue_deg)
}

/// (L, C, h in degrees) → (L, a, b).
pub fn lch_deg_to_lab(lch: DVec3) -> DVec3 {
    let (sin, cos) = lch.z.to_radians().sin_cos();
    DVec3::new(lch.x, lch.y * cos, lch.y * sin)
}

/// Smallest absolute difference of two hue angles in degrees, in [0, 180].
pub fn hue_difference_deg(h1_deg: f64, h2_deg: f64) -> f64 {
    let d = (h1_deg - h2_deg).rem_euclid(360.0);
    d.min(360.0 - d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_is_l100_and_round_trips() {
        let c = CielabConverter::new(&RgbColorSpace::srgb());
        let lab = c.rgb_to_lab(DVec3::ONE);
        assert!(lab.abs_diff_eq(DVec3::new(100.0, 0.0, 0.0), 1e-9), "{lab}");
        let rgb = DVec3::new(0.8, 0.1, 0.3);
        assert!(c.lab_to_rgb(c.rgb_to_lab(rgb)).abs_diff_eq(rgb, 1e-12));
    }

    #[test]
    fn lch_round_trips_and_hue_wraps() {
        let lab = DVec3::new(50.0, -20.0, -5.0);
        let lch = lab_to_lch_deg(lab);
        assert!((0.0..360.0).contains(&lch.z));
        assert!(lch_deg_to_lab(lch).abs_diff_eq(lab, 1e-12));
        assert_eq!(hue_difference_deg(359.5, 0.5), 1.0);
        assert_eq!(hue_difference_deg(10.0, 200.0), 170.0);
    }
}
