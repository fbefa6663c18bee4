//! RGB colour spaces built from their primaries and white point (the normalised primary
//! matrix of SMPTE RP 177-1993), with their transfer functions.

use glam::{DMat3, DVec3};

/// Chromaticity (x, y) → XYZ with Y = 1.
pub fn xy_to_xyz_unit_y(x: f64, y: f64) -> DVec3 {
    DVec3::new(x / y, 1.0, (1.0 - x - y) / y)
}

/// Opto-electronic transfer (encoding) of a colour space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransferFunction {
    /// No encoding (scene-linear spaces such as ACES2065-1, ACEScg).
    Linear,
    /// IEC 61966-2-1 sRGB piecewise curve (also Display P3).
    Srgb,
    /// ITU-R BT.2020 OETF (12-bit constants).
    Bt2020,
}

impl TransferFunction {
    /// Linear → encoded. Not clipped: values above 1 follow the power segment and values
    /// below 0 the linear segment, as colour-science's `eotf_inverse_sRGB` / `oetf_BT2020` do.
    pub fn encode(self, linear: f64) -> f64 {
        match self {
            TransferFunction::Linear => linear,
            TransferFunction::Srgb => {
                if linear <= 0.0031308 {
                    12.92 * linear
                } else {
                    1.055 * linear.powf(1.0 / 2.4) - 0.055
                }
            }
            TransferFunction::Bt2020 => {
                const ALPHA: f64 = 1.099_296_826_809_44;
                const BETA: f64 = 0.018_053_968_510_807;
                if linear < BETA {
                    4.5 * linear
                } else {
                    ALPHA * linear.powf(0.45) - (ALPHA - 1.0)
                }
            }
        }
    }

    /// Encoded → linear; the inverse of [`TransferFunction::encode`].
    pub fn decode(self, encoded: f64) -> f64 {
        match self {
            TransferFunction::Linear => encoded,
            TransferFunction::Srgb => {
                if encoded <= 0.04045 {
                    encoded / 12.92
                } else {
                    ((encoded + 0.055) / 1.055).powf(2.4)
                }
            }
            TransferFunction::Bt2020 => {
                const ALPHA: f64 = 1.099_296_826_809_44;
                const BETA: f64 = 0.018_053_968_510_807;
                if encoded < 4.5 * BETA {
                    encoded / 4.5
                } else {
                    ((encoded + (ALPHA - 1.0)) / ALPHA).powf(1.0 / 0.45)
                }
            }
        }
    }
}

/// An additive RGB colour space.
#[derive(Debug, Clone, PartialEq)]
pub struct RgbColorSpace {
    pub name: &'static str,
    /// Chromaticities of the red, green and blue primaries.
    pub primaries_xy: [[f64; 2]; 3],
    /// Chromaticity of the white point (RGB = 1, 1, 1).
    pub white_xy: [f64; 2],
    /// The CIE illuminant whose spectrum stands for the white point when spectra are
    /// upsampled from RGB (Jakob & Hanika 2019): D65, or D60 for the ACES spaces.
    pub white_illuminant: &'static str,
    pub transfer: TransferFunction,
    /// Linear RGB → CIE 1931 XYZ (white has Y = 1).
    pub rgb_to_xyz: DMat3,
    /// CIE 1931 XYZ → linear RGB.
    pub xyz_to_rgb: DMat3,
}

impl RgbColorSpace {
    /// Builds the space from primaries and white: columns of `rgb_to_xyz` are the primaries'
    /// XYZ scaled so that RGB (1, 1, 1) maps to the white with Y = 1.
    pub fn from_primaries(
        name: &'static str,
        primaries_xy: [[f64; 2]; 3],
        white_xy: [f64; 2],
        white_illuminant: &'static str,
        transfer: TransferFunction,
    ) -> Self {
        let columns = primaries_xy.map(|[x, y]| xy_to_xyz_unit_y(x, y));
        let primaries = DMat3::from_cols(columns[0], columns[1], columns[2]);
        let white = xy_to_xyz_unit_y(white_xy[0], white_xy[1]);
        let scale = primaries.inverse() * white;
        let rgb_to_xyz = DMat3::from_cols(
            columns[0] * scale.x,
            columns[1] * scale.y,
            columns[2] * scale.z,
        );
        Self {
            name,
            primaries_xy,
            white_xy,
            white_illuminant,
            transfer,
            rgb_to_xyz,
            xyz_to_rgb: rgb_to_xyz.inverse(),
        }
    }

    /// sRGB / ITU-R BT.709 primaries, D65, sRGB transfer.
    pub fn srgb() -> Self {
        Self::from_primaries(
            "sRGB",
            [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]],
            [0.3127, 0.3290],
            "D65",
            TransferFunction::Srgb,
        )
    }

    /// Display P3 (DCI-P3 primaries, D65, sRGB transfer).
    pub fn display_p3() -> Self {
        Self::from_primaries(
            "Display P3",
            [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
            [0.3127, 0.3290],
            "D65",
            TransferFunction::Srgb,
        )
    }

    /// ITU-R BT.2020, D65, BT.2020 OETF.
    pub fn rec2020() -> Self {
        Self::from_primaries(
            "Rec.2020",
            [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
            [0.3127, 0.3290],
            "D65",
            TransferFunction::Bt2020,
        )
    }

    /// ACES2065-1 (AP0 primaries, ACES white ≈ D60), linear (SMPTE ST 2065-1).
    pub fn aces2065_1() -> Self {
        Self::from_primaries(
            "ACES2065-1",
            [[0.7347, 0.2653], [0.0, 1.0], [0.0001, -0.0770]],
            [0.32168, 0.33767],
            "D60",
            TransferFunction::Linear,
        )
    }

    /// ACEScg (AP1 primaries, ACES white ≈ D60), linear (Academy S-2014-004).
    pub fn acescg() -> Self {
        Self::from_primaries(
            "ACEScg",
            [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
            [0.32168, 0.33767],
            "D60",
            TransferFunction::Linear,
        )
    }

    /// Every built-in space.
    pub fn all() -> Vec<Self> {
        vec![
            Self::srgb(),
            Self::display_p3(),
            Self::rec2020(),
            Self::aces2065_1(),
            Self::acescg(),
        ]
    }

    /// Looks a space up by name, case-insensitive, ignoring `-`, `_`, `.` and spaces
    /// (`srgb`, `rec709`, `p3`, `display-p3`, `rec2020`, `aces2065-1`, `acescg`).
    pub fn by_name(name: &str) -> Option<Self> {
        let key: String = name
            .chars()
            .filter(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase();
        match key.as_str() {
            "srgb" | "rec709" | "bt709" | "itur bt709" => Some(Self::srgb()),
            "p3" | "displayp3" => Some(Self::display_p3()),
            "rec2020" | "bt2020" => Some(Self::rec2020()),
            "aces20651" | "aces" | "ap0" => Some(Self::aces2065_1()),
            "acescg" | "ap1" => Some(Self::acescg()),
            _ => None,
        }
    }

    /// White point XYZ with Y = 1.
    pub fn white_xyz(&self) -> DVec3 {
        xy_to_xyz_unit_y(self.white_xy[0], self.white_xy[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_matrix_matches_iec_61966_2_1_to_its_printed_digits() {
        let m = RgbColorSpace::srgb().rgb_to_xyz;
        let printed = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        for (row, values) in printed.iter().enumerate() {
            for (col, v) in values.iter().enumerate() {
                assert!((m.col(col)[row] - v).abs() < 6e-5, "({row},{col})");
            }
        }
    }

    #[test]
    fn white_maps_to_unit_rgb_in_every_space() {
        for space in RgbColorSpace::all() {
            let rgb = space.xyz_to_rgb * space.white_xyz();
            assert!(
                (rgb - DVec3::ONE).abs().max_element() < 1e-12,
                "{}",
                space.name
            );
        }
    }

    #[test]
    fn transfer_functions_invert() {
        for tf in [
            TransferFunction::Srgb,
            TransferFunction::Bt2020,
            TransferFunction::Linear,
        ] {
            for i in 0..=100 {
                let v = i as f64 / 100.0;
                assert!((tf.decode(tf.encode(v)) - v).abs() < 1e-12);
            }
        }
        assert!((TransferFunction::Srgb.encode(1.0) - 1.0).abs() < 1e-12);
        assert!((TransferFunction::Bt2020.encode(1.0) - 1.0).abs() < 1e-12);
    }
}
