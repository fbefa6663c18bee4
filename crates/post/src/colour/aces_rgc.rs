//! ACES Reference Gamut Compression 1.0 (Academy of Motion Picture Arts and Sciences 2021,
//! ACES 1.3 LMT `LMT.Academy.ReferenceGamutCompress.ctl`, transform ID
//! `urn:ampas:aces:transformId:v1.5:LMT.Academy.ReferenceGamutCompress.a1.v1.0`; the
//! "ACES Gamut Mapping Architecture VWG – Technical Documentation Deliverable", 2021).
//!
//! In ACEScg (AP1), per pixel: the achromatic value is ach = max(r, g, b); each channel's
//! distance from the achromatic axis is d = (ach − c) / |ach| (0 when ach = 0); distances
//! beyond a threshold are compressed with a power curve so that the distance `limit` lands
//! on 1 (the AP1 boundary); c′ = ach − d′ |ach|. Red uses the cyan parameters, green the
//! magenta ones and blue the yellow ones.

use glam::DVec3;

/// Parameters of the compression curve per channel (red, green, blue ↔ cyan, magenta,
/// yellow), dimensionless distances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcesRgcParameters {
    /// Distance from achromatic that is compressed to the gamut boundary (distance 1).
    pub limit_cmy: [f64; 3],
    /// Distance below which nothing moves ("percentage of the core gamut to protect").
    pub threshold_cmy: [f64; 3],
    /// Aggressiveness of the compression curve.
    pub power: f64,
}

impl AcesRgcParameters {
    /// The published RGC 1.0 constants (`LIM_CYAN = 1.147`, `LIM_MAGENTA = 1.264`,
    /// `LIM_YELLOW = 1.312`, `THR_CYAN = 0.815`, `THR_MAGENTA = 0.803`,
    /// `THR_YELLOW = 0.880`, `PWR = 1.2`).
    pub const REFERENCE: Self = Self {
        limit_cmy: [1.147, 1.264, 1.312],
        threshold_cmy: [0.815, 0.803, 0.880],
        power: 1.2,
    };
}

impl Default for AcesRgcParameters {
    fn default() -> Self {
        Self::REFERENCE
    }
}

/// The RGC `compress(dist, lim, thr, pwr)` function (forward direction):
/// d for d < thr, else thr + s·n / (1 + nᵖ)^(1/p) with n = (d − thr)/s and the scale
/// s = (lim − thr) / (((1 − thr)/(lim − thr))^(−p) − 1)^(1/p) that puts lim on 1.
#[inline]
pub fn compress_distance(distance: f64, limit: f64, threshold: f64, power: f64) -> f64 {
    if distance < threshold {
        return distance;
    }
    let scale = (limit - threshold)
        / (((1.0 - threshold) / (limit - threshold)).powf(-power) - 1.0).powf(1.0 / power);
    let normalised = (distance - threshold) / scale;
    threshold + scale * normalised / (1.0 + normalised.powf(power)).powf(1.0 / power)
}

/// Applies the gamut compression to one ACEScg (AP1) linear RGB value.
#[inline]
pub fn aces_rgc_acescg(rgb_ap1: DVec3, params: &AcesRgcParameters) -> DVec3 {
    let achromatic = rgb_ap1.max_element();
    if achromatic == 0.0 || !achromatic.is_finite() {
        return rgb_ap1;
    }
    let magnitude = achromatic.abs();
    let channel = |c: f64, i: usize| {
        let distance = (achromatic - c) / magnitude;
        let compressed = compress_distance(
            distance,
            params.limit_cmy[i],
            params.threshold_cmy[i],
            params.power,
        );
        achromatic - compressed * magnitude
    };
    DVec3::new(
        channel(rgb_ap1.x, 0),
        channel(rgb_ap1.y, 1),
        channel(rgb_ap1.z, 2),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: AcesRgcParameters = AcesRgcParameters::REFERENCE;

    const EXPECTED_BLUE: f64 = 0.008_588_461_205_588_094;
    const EXPECTED_RED: f64 = -0.009_690_182_791_683_71;
    const EXPECTED_NEG_RED: f64 = -0.973_321_672_224_975_8;
    const EXPECTED_NEG_BLUE: f64 = -1.012_310_125_670_060_4;

    #[test]
    fn limit_lands_on_the_boundary_and_threshold_is_protected() {
        for i in 0..3 {
            let (lim, thr) = (P.limit_cmy[i], P.threshold_cmy[i]);
            assert!((compress_distance(lim, lim, thr, P.power) - 1.0).abs() < 1e-12);
            assert_eq!(compress_distance(thr - 1e-9, lim, thr, P.power), thr - 1e-9);
            assert!((compress_distance(thr, lim, thr, P.power) - thr).abs() < 1e-15);
        }
    }

    /// Hand-computed from the published formula (Python float64, independent of this code):
    /// scl = (lim-thr)/(((1-thr)/(lim-thr))**-p - 1)**(1/p); nd = (d-thr)/scl;
    /// thr + scl*nd/(1+nd**p)**(1/p).
    #[test]
    fn matches_hand_computed_values() {
        // AP1 (0.5, 1.0, -0.2): ach = 1, distances (0.5, 0, 1.2); only blue (yellow) moves.
        let out = aces_rgc_acescg(DVec3::new(0.5, 1.0, -0.2), &P);
        assert_eq!(out.x, 0.5);
        assert_eq!(out.y, 1.0);
        assert!((out.z - EXPECTED_BLUE).abs() < 1e-12, "{}", out.z);
        // AP1 (-0.1, 0.2, 0.4): ach = 0.4, distances (1.25, 0.5, 0); red (cyan) moves.
        let out = aces_rgc_acescg(DVec3::new(-0.1, 0.2, 0.4), &P);
        assert!((out.x - EXPECTED_RED).abs() < 1e-12, "{}", out.x);
        assert!((out.y - 0.2).abs() < 1e-15);
        assert_eq!(out.z, 0.4);
        // Negative achromatic: |ach| normalises. AP1 (-1, -0.5, -3): ach = -0.5,
        // distances (1, 0, 5); red and blue move.
        let out = aces_rgc_acescg(DVec3::new(-1.0, -0.5, -3.0), &P);
        assert!((out.x - EXPECTED_NEG_RED).abs() < 1e-12, "{}", out.x);
        assert!((out.z - EXPECTED_NEG_BLUE).abs() < 1e-12, "{}", out.z);
        // Black stays black.
        assert_eq!(aces_rgc_acescg(DVec3::ZERO, &P), DVec3::ZERO);
    }
}
