//! Von Kries-type chromatic adaptation transforms with full adaptation (D = 1): XYZ is
//! taken to a cone-like space by M, each channel scaled by the ratio of the destination
//! white's response to the source white's, and taken back: M⁻¹ · diag(ρ′_w / ρ_w) · M.
//! This is colour-science 0.4.7's `matrix_chromatic_adaptation_VonKries(XYZ_w, XYZ_wr,
//! transform)`.

use glam::{DMat3, DVec3};

/// A chromatic adaptation transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AdaptationMethod {
    /// Von Kries with the Hunt–Pointer–Estévez cone matrix normalised to D65
    /// (colour-science `CAT_VON_KRIES`; CIE 109-1994, Fairchild 2013).
    VonKries,
    /// Bradford (Lam 1985, linearised; Lindbloom), colour-science `CAT_BRADFORD`.
    Bradford,
    /// CIECAM02's CAT02 (CIE 159:2004), colour-science `CAT_CAT02`.
    Cat02,
    /// CAM16's CAT16 (Li et al. 2017, Color Res. Appl. 42(6)), colour-science `CAT_CAT16`.
    Cat16,
    /// No adaptation: the identity.
    None,
}

/// Names accepted by [`AdaptationMethod::from_name`], for error messages.
const NAMES: &[&str] = &["bradford", "cat16", "cat02", "von-kries", "none"];

impl AdaptationMethod {
    /// Parses `bradford`, `cat16`, `cat02`, `von-kries` or `none` (case-insensitive, exact).
    pub fn from_name(name: &str) -> Option<Self> {
        let lower = name.to_ascii_lowercase();
        match lower.as_str() {
            "bradford" => Some(Self::Bradford),
            "cat16" => Some(Self::Cat16),
            "cat02" => Some(Self::Cat02),
            "von-kries" => Some(Self::VonKries),
            "none" => Some(Self::None),
            _ => None,
        }
    }

    /// The accepted names, in the order error messages list them.
    pub fn names() -> &'static [&'static str] {
        NAMES
    }

    /// The canonical name ([`AdaptationMethod::from_name`] accepts it).
    pub fn name(self) -> &'static str {
        match self {
            Self::VonKries => "von-kries",
            Self::Bradford => "bradford",
            Self::Cat02 => "cat02",
            Self::Cat16 => "cat16",
            Self::None => "none",
        }
    }

    /// XYZ → cone-response matrix (rows as published), or `None` for no adaptation.
    pub fn cone_matrix(self) -> Option<DMat3> {
        let rows: [[f64; 3]; 3] = match self {
            Self::VonKries => [
                [0.400_24, 0.707_6, -0.080_81],
                [-0.226_3, 1.165_32, 0.045_7],
                [0.0, 0.0, 0.918_22],
            ],
            Self::Bradford => [
                [0.8951, 0.2664, -0.1614],
                [-0.7502, 1.7135, 0.0367],
                [0.0389, -0.0685, 1.0296],
            ],
            Self::Cat02 => [
                [0.7328, 0.4296, -0.1624],
                [-0.7036, 1.6975, 0.0061],
                [0.0030, 0.0136, 0.9834],
            ],
            Self::Cat16 => [
                [0.401_288, 0.650_173, -0.051_461],
                [-0.250_268, 1.204_414, 0.045_854],
                [-0.002_079, 0.048_952, 0.953_127],
            ],
            Self::None => return None,
        };
        Some(matrix_from_rows(rows))
    }
}

impl std::fmt::Display for AdaptationMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A DMat3 from row-major entries (glam stores columns).
pub fn matrix_from_rows(rows: [[f64; 3]; 3]) -> DMat3 {
    DMat3::from_cols_array_2d(&rows).transpose()
}

/// The full-adaptation (D = 1) matrix taking XYZ seen under `src_white_xyz` to corresponding
/// XYZ under `dst_white_xyz` (both whites on the same scale):
/// M⁻¹ · diag(M·dst / M·src) · M. A cone channel whose source response is zero or whose
/// ratio is not finite is left unscaled (ratio 1) rather than producing NaN.
pub fn adaptation_matrix(
    method: AdaptationMethod,
    src_white_xyz: DVec3,
    dst_white_xyz: DVec3,
) -> DMat3 {
    let Some(m) = method.cone_matrix() else {
        return DMat3::IDENTITY;
    };
    let src = m * src_white_xyz;
    let dst = m * dst_white_xyz;
    let ratio = |d: f64, s: f64| {
        let r = d / s;
        if r.is_finite() {
            r
        } else {
            1.0
        }
    };
    let gain = DVec3::new(
        ratio(dst.x, src.x),
        ratio(dst.y, src.y),
        ratio(dst.z, src.z),
    );
    m.inverse() * DMat3::from_diagonal(gain) * m
}

#[cfg(test)]
mod tests {
    use super::*;

    const A_WHITE: DVec3 = DVec3::new(1.098_466, 1.0, 0.355_825);
    const D65_WHITE: DVec3 = DVec3::new(0.950_456, 1.0, 1.089_058);

    #[test]
    fn names_parse_case_insensitively_and_exactly() {
        assert_eq!(
            AdaptationMethod::from_name("Bradford"),
            Some(AdaptationMethod::Bradford)
        );
        assert_eq!(
            AdaptationMethod::from_name("VON-KRIES"),
            Some(AdaptationMethod::VonKries)
        );
        assert_eq!(
            AdaptationMethod::from_name("none"),
            Some(AdaptationMethod::None)
        );
        assert_eq!(AdaptationMethod::from_name("von kries"), None);
        assert_eq!(AdaptationMethod::from_name("cat03"), None);
        for name in AdaptationMethod::names() {
            let m = AdaptationMethod::from_name(name).unwrap();
            assert_eq!(m.name(), *name);
        }
    }

    #[test]
    fn source_white_maps_exactly_to_destination_white() {
        for name in AdaptationMethod::names() {
            let method = AdaptationMethod::from_name(name).unwrap();
            let m = adaptation_matrix(method, A_WHITE, D65_WHITE);
            if method == AdaptationMethod::None {
                assert_eq!(m, DMat3::IDENTITY);
                continue;
            }
            let mapped = m * A_WHITE;
            assert!(
                (mapped - D65_WHITE).abs().max_element() < 1e-14,
                "{name}: {mapped}"
            );
            // Adapting back inverts.
            let back = adaptation_matrix(method, D65_WHITE, A_WHITE) * m;
            assert!((back - DMat3::IDENTITY)
                .abs()
                .to_cols_array()
                .iter()
                .all(|v| *v < 1e-14));
        }
    }

    #[test]
    fn same_white_is_identity_and_degenerate_white_is_finite() {
        let m = adaptation_matrix(AdaptationMethod::Cat16, D65_WHITE, D65_WHITE);
        assert!(m.abs_diff_eq(DMat3::IDENTITY, 1e-14));
        let m = adaptation_matrix(AdaptationMethod::Bradford, DVec3::ZERO, D65_WHITE);
        assert!(m.is_finite());
    }
}
