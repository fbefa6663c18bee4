//! Normalised Blinn–Phong (J. F. Blinn, "Models of light reflection for computer
//! synthesized pictures", SIGGRAPH 1977), with the exact energy normalisation of the
//! half-vector lobe (F. Giesen, "A note on energy-conserving Blinn-Phong", 2009, after
//! Lafortune & Willems' normalisation of Phong):
//!
//! f(ωₒ, ωᵢ) = k_d/π + k_s N(n) cosⁿθ_h,  N(n) = (n + 2)(n + 4) / (8π (2^{−n/2} + n)),
//!
//! θ_h the angle of the half vector ω_h = (ωₒ + ωᵢ)/|ωₒ + ωᵢ| to the normal. N(n) makes the
//! lobe's directional albedo exactly k_s at normal incidence (∫ cosⁿθ_h cos θᵢ dωᵢ = 1/N
//! there); elsewhere the tests check it stays ≤ k_s, so k_d + k_s ≤ 1 conserves energy
//! (the material builder refuses larger sums). Symmetric in ωₒ, ωᵢ.
//!
//! Sampling: the diffuse lobe with probability k̄_d/(k̄_d + k̄_s), else a half vector with
//! density (n + 1)/(2π) cosⁿθ_h and ωᵢ = reflect(ωₒ, ω_h), whose density is
//! p_h/(4 ωₒ·ω_h) (Walter et al. 2007 eq. 14). One-sided.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::fresnel::reflect;
use super::phong::{diffuse_probability, mixture_pdf};
use super::{bandwidth_from_exponent, estimate_albedo, BsdfSample, Bxdf, TransportMode};
use crate::sampling::{power_cosine_pdf, sample_cosine_hemisphere, sample_power_cosine};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong {
    /// Diffuse reflectance k_d(λ).
    pub diffuse: SampledSpectrum,
    /// Specular reflectance k_s(λ) (k_d + k_s ≤ 1).
    pub specular: SampledSpectrum,
    /// Exponent n ≥ 0 of cos θ_h.
    pub exponent: f32,
}

/// Giesen 2009's exact normalisation of cosⁿθ_h.
#[inline]
pub fn blinn_phong_normalisation(n: f32) -> f32 {
    (n + 2.0) * (n + 4.0) / (8.0 * std::f32::consts::PI * ((-0.5 * n).exp2() + n))
}

impl BlinnPhong {
    #[inline]
    fn half(wo: Vec3A, wi: Vec3A) -> Option<Vec3A> {
        let h = wo + wi;
        let len2 = h.length_squared();
        (len2 > 0.0).then(|| h / len2.sqrt())
    }
}

impl Bxdf for BlinnPhong {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::splat(0.0);
        }
        let lobe = Self::half(wo, wi).map_or(0.0, |h| {
            blinn_phong_normalisation(self.exponent) * h.z.min(1.0).powf(self.exponent)
        });
        self.diffuse * std::f32::consts::FRAC_1_PI + self.specular * lobe
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let pd = diffuse_probability(self.diffuse, self.specular);
        let glossy = Self::half(wo, wi).map_or(0.0, |h| {
            let cos_oh = wo.dot(h);
            if cos_oh > 0.0 {
                power_cosine_pdf(h.z.min(1.0), self.exponent) / (4.0 * cos_oh)
            } else {
                0.0
            }
        });
        mixture_pdf(pd, wi, glossy)
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let pd = diffuse_probability(self.diffuse, self.specular);
        let wi = if u_lobe < pd {
            sample_cosine_hemisphere(u)
        } else {
            let h = sample_power_cosine(u, self.exponent);
            if wo.dot(h) <= 0.0 {
                return None;
            }
            reflect(wo, h)
        };
        BsdfSample::reflection(wi, self.pdf(wo, wi, mode), || self.eval(wo, wi, mode))
    }

    /// No closed form (the lobe is clipped by the horizon away from normal incidence):
    /// `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        estimate_albedo(self, wo, mode)
    }

    /// The cosine power's equivalent roughness; 0 without a specular lobe.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        if self.specular.max_component() > 0.0 {
            bandwidth_from_exponent(self.exponent)
        } else {
            0.0
        }
    }

    #[inline]
    fn is_specular(&self) -> bool {
        false
    }

    #[inline]
    fn has_specular(&self) -> bool {
        false
    }

    #[inline]
    fn is_reflection_only(&self) -> bool {
        true
    }

    #[inline]
    fn is_isotropic(&self) -> bool {
        true
    }
}
