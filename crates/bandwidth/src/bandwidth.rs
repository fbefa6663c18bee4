//! Bandwidth values (Bagher et al. 2013 §2, after Durand et al. 2005, "A frequency analysis
//! of light transport").
//!
//! The local light field around a ray is parametrised in flatland by a spatial offset x
//! (metres, across the ray) and an angular offset v (radians). Its bandwidth is the 2-vector
//! ν = [ν_s, ν_a]ᵀ such that the rectangle (−ν_s, −ν_a)…(ν_s, ν_a) holds 95 % of the energy
//! of its 2-D Fourier spectrum (Bagher §2, Fig. 2).
//!
//! Units, fixed here for the whole crate: **ordinary frequencies, in cycles per unit** —
//! ν_s in cycles/m, ν_a in cycles/rad. (Where Bagher writes an angular frequency as
//! 2π/period, e.g. ν_a = 2π / (2^{I_w} λ_max) for environment maps, divide by 2π.) With
//! cycles, Nyquist is "two samples per cycle": the image-space rate of eq. 6,
//! b_p = ν_a · max(f_x/W, f_y/H) (fields of view in rad), is in cycles per pixel and a pixel
//! needs 2 b_p samples per pixel length. A value of +∞ means "not band-limited" (Bagher
//! stores an arbitrarily large value and clamps in image space); NaN and negative values
//! are rejected.

use crate::error::BandwidthError;

/// ν = [ν_s, ν_a]: the bandwidth of a local light field.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bandwidth {
    /// ν_s, cycles per metre (m⁻¹) across the ray.
    pub spatial_cycles_per_m: f32,
    /// ν_a, cycles per radian (rad⁻¹).
    pub angular_cycles_per_rad: f32,
}

/// `Ok(v)` for v ≥ 0 (+∞ allowed), else an error naming `parameter`.
fn non_negative(
    context: &'static str,
    parameter: &'static str,
    v: f32,
) -> Result<f32, BandwidthError> {
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(BandwidthError::invalid(
            context,
            parameter,
            v,
            "≥ 0 (+∞ for a signal that is not band-limited)",
        ))
    }
}

impl Bandwidth {
    /// A constant signal: no variation in space or angle.
    pub const ZERO: Bandwidth = Bandwidth {
        spatial_cycles_per_m: 0.0,
        angular_cycles_per_rad: 0.0,
    };

    /// A point or spot light: a delta in space, unbounded spatial spectrum and no angular
    /// variation, ν_l = [∞, 0] (Bagher eq. 4's ν_l for delta local lights).
    pub const POINT_LIGHT: Bandwidth = Bandwidth {
        spatial_cycles_per_m: f32::INFINITY,
        angular_cycles_per_rad: 0.0,
    };

    /// ν = [spatial, angular]; both ≥ 0 (+∞ allowed).
    pub fn new(
        spatial_cycles_per_m: f32,
        angular_cycles_per_rad: f32,
    ) -> Result<Self, BandwidthError> {
        Ok(Self {
            spatial_cycles_per_m: non_negative(
                "bandwidth",
                "spatial_cycles_per_m",
                spatial_cycles_per_m,
            )?,
            angular_cycles_per_rad: non_negative(
                "bandwidth",
                "angular_cycles_per_rad",
                angular_cycles_per_rad,
            )?,
        })
    }

    /// The bandwidth leaving a local (area) light: purely spatial (Bagher §2.1, "At the
    /// light"; ν_a = 0).
    pub fn area_light(spatial_cycles_per_m: f32) -> Result<Self, BandwidthError> {
        Self::new(spatial_cycles_per_m, 0.0)
    }

    /// The bandwidth of distant illumination along a direction: purely angular (Bagher
    /// §2.3, ν(ω) = [0, ν_a(ω)]).
    pub fn distant_light(angular_cycles_per_rad: f32) -> Result<Self, BandwidthError> {
        Self::new(0.0, angular_cycles_per_rad)
    }
}

/// What a material contributes at a hit for one pair of directions (Bagher eq. 3, the
/// operator B_{t,ρ}: ν ↦ [ν_s + t, min(ρ, ν_a)]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialBandwidth {
    /// ρ (in eq. 9 ν_ρa): the angular bandwidth of the BSDF lobe for the incident and
    /// outgoing directions, cycles per radian. 0 for a Lambertian lobe (constant in angle),
    /// growing as the lobe narrows; +∞ for a perfect mirror or glass.
    pub angular_cycles_per_rad: f32,
    /// t: the spatial bandwidth of the material's texture at the hit, cycles per metre on
    /// the surface (0 without a texture).
    pub texture_cycles_per_m: f32,
}

impl MaterialBandwidth {
    /// ρ and t, both ≥ 0 (+∞ allowed).
    pub fn new(
        angular_cycles_per_rad: f32,
        texture_cycles_per_m: f32,
    ) -> Result<Self, BandwidthError> {
        Ok(Self {
            angular_cycles_per_rad: non_negative(
                "material bandwidth",
                "angular_cycles_per_rad",
                angular_cycles_per_rad,
            )?,
            texture_cycles_per_m: non_negative(
                "material bandwidth",
                "texture_cycles_per_m",
                texture_cycles_per_m,
            )?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_are_purely_spatial_or_purely_angular() {
        let area = Bandwidth::area_light(12.0).unwrap();
        assert_eq!(
            (area.spatial_cycles_per_m, area.angular_cycles_per_rad),
            (12.0, 0.0)
        );
        let distant = Bandwidth::distant_light(f32::INFINITY).unwrap();
        assert_eq!(distant.spatial_cycles_per_m, 0.0);
        assert!(distant.angular_cycles_per_rad.is_infinite());
        assert_eq!(Bandwidth::default(), Bandwidth::ZERO);
    }

    #[test]
    fn negative_and_nan_values_are_rejected_by_name() {
        let e = Bandwidth::new(-1.0, 0.0).unwrap_err().to_string();
        assert!(e.contains("spatial_cycles_per_m"), "{e}");
        let e = Bandwidth::new(0.0, f32::NAN).unwrap_err().to_string();
        assert!(e.contains("angular_cycles_per_rad"), "{e}");
        let e = MaterialBandwidth::new(1.0, -2.0).unwrap_err().to_string();
        assert!(e.contains("texture_cycles_per_m"), "{e}");
        // A mirror (+∞ angular bandwidth) without a texture is valid and kept as given.
        let mirror = MaterialBandwidth::new(f32::INFINITY, 0.0).unwrap();
        assert!(mirror.angular_cycles_per_rad.is_infinite());
        assert_eq!(mirror.texture_cycles_per_m, 0.0);
    }
}
