//! An isotropic point light: intensity I(λ) in W·sr⁻¹·nm⁻¹ in every direction; the
//! irradiance at distance d on a surface facing it is I/d² (inverse-square law).

use glam::{Vec2, Vec3A};
use prism_spectrum::{SampledWavelengths, Spectrum};

use super::{LightSample, LightSampleContext};

#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    /// Position, metres (world).
    pub position_m: Vec3A,
    /// Radiant intensity I(λ), W·sr⁻¹·nm⁻¹ (absolute: photometric strengths are applied).
    pub intensity: Spectrum,
}

impl PointLight {
    #[inline]
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        let to = self.position_m - ctx.p;
        let d2 = to.length_squared();
        if d2 <= 0.0 || !d2.is_finite() {
            return None;
        }
        let d = d2.sqrt();
        Some(LightSample {
            wi: to / d,
            radiance: self.intensity.eval(wavelengths) * (1.0 / d2),
            pdf: 1.0,
            p_light: self.position_m,
            distance_m: d,
            delta: true,
        })
    }

    /// Φ = 4π ∫ I(λ) dλ, W.
    pub fn power_w(&self) -> f64 {
        4.0 * std::f64::consts::PI * integrate_nm(&self.intensity)
    }
}

/// ∫ S(λ) dλ over 360–830 nm at 1 nm (trapezoid), for light powers.
pub(crate) fn integrate_nm(s: &Spectrum) -> f64 {
    let mut sum = 0.0;
    for wl in 360..=830 {
        let w = if wl == 360 || wl == 830 { 0.5 } else { 1.0 };
        sum += w * s.eval_nm(f64::from(wl));
    }
    sum
}
