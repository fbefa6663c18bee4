//! The modified Phong model in its energy-conserving normalisation (E. P. Lafortune and
//! Y. D. Willems, "Using the modified Phong reflectance model for physically based
//! rendering", Tech. Rep. CW 197, KU Leuven, 1994; R. R. Lewis 1994 for the reciprocity of
//! the "modified" form):
//!
//! f(ωₒ, ωᵢ) = k_d/π + k_s (n + 2)/(2π) cosⁿ α,  α = ∠(ωᵢ, R(ωₒ)),
//!
//! R(ωₒ) the mirror direction of ωₒ about the normal. The (n + 2)/(2π) factor makes the
//! specular lobe's directional albedo exactly k_s at normal incidence and less elsewhere,
//! so k_d + k_s ≤ 1 guarantees energy conservation (Lafortune & Willems §3); the material
//! builder refuses larger sums. cos α = ωᵢ·R(ωₒ) = ωₒ·R(ωᵢ), so f is reciprocal.
//!
//! Sampling (Lafortune & Willems §4): the diffuse lobe (cosine-weighted) with probability
//! p_d = k̄_d/(k̄_d + k̄_s) (lane means), else the lobe (n + 1)/(2π) cosⁿ α about R(ωₒ);
//! the pdf is the mixture of both densities. Lobe samples below the horizon fail.
//! One-sided.

use glam::{Vec2, Vec3A};
use prism_geometry::Frame;
use prism_spectrum::SampledSpectrum;

use super::{bandwidth_from_exponent, estimate_albedo, BsdfSample, Bxdf, TransportMode};
use crate::sampling::{power_cosine_pdf, sample_cosine_hemisphere, sample_power_cosine};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Diffuse reflectance k_d(λ).
    pub diffuse: SampledSpectrum,
    /// Specular reflectance k_s(λ) (k_d + k_s ≤ 1).
    pub specular: SampledSpectrum,
    /// Phong exponent n ≥ 0.
    pub exponent: f32,
}

/// Probability of sampling the diffuse lobe of a diffuse + glossy pair: the ratio of the
/// lane means (1 when both are black, so sampling still succeeds).
#[inline]
pub(crate) fn diffuse_probability(diffuse: SampledSpectrum, glossy: SampledSpectrum) -> f32 {
    let (d, s) = (diffuse.average().max(0.0), glossy.average().max(0.0));
    if d + s > 0.0 {
        d / (d + s)
    } else {
        1.0
    }
}

/// Pdf of a diffuse/glossy mixture: cosine sampling with probability `pd`, the glossy
/// lobe (solid-angle pdf `glossy`) otherwise.
#[inline]
pub(crate) fn mixture_pdf(pd: f32, wi: Vec3A, glossy: f32) -> f32 {
    pd * wi.z * std::f32::consts::FRAC_1_PI + (1.0 - pd) * glossy
}

impl Phong {
    #[inline]
    fn mirror(wo: Vec3A) -> Vec3A {
        Vec3A::new(-wo.x, -wo.y, wo.z)
    }
}

impl Bxdf for Phong {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::splat(0.0);
        }
        let cos_alpha = wi.dot(Self::mirror(wo)).min(1.0);
        let lobe = if cos_alpha > 0.0 {
            (self.exponent + 2.0)
                * 0.5
                * std::f32::consts::FRAC_1_PI
                * cos_alpha.powf(self.exponent)
        } else {
            0.0
        };
        self.diffuse * std::f32::consts::FRAC_1_PI + self.specular * lobe
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let pd = diffuse_probability(self.diffuse, self.specular);
        let cos_alpha = wi.dot(Self::mirror(wo)).min(1.0);
        pd * wi.z * std::f32::consts::FRAC_1_PI
            + (1.0 - pd) * power_cosine_pdf(cos_alpha, self.exponent)
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
            let frame = Frame::from_z(Self::mirror(wo));
            frame.from_local(sample_power_cosine(u, self.exponent))
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
