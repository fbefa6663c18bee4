//! Lambert's ideal diffuse reflector: f = R/π on the upper side, cosine-weighted sampling
//! (Lambert 1760; pbrt-v4 §9.2). One-sided: zero when either direction is below the surface.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::{BsdfSample, Bxdf, TransportMode};
use crate::sampling::sample_cosine_hemisphere;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    /// Reflectance R(λ) ∈ [0, 1] at the path's wavelengths.
    pub reflectance: SampledSpectrum,
}

impl Bxdf for Lambert {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::splat(0.0);
        }
        self.reflectance * std::f32::consts::FRAC_1_PI
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        cosine_pdf(wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3A, _u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        BsdfSample::reflection(wi, self.pdf(wo, wi, mode), || self.eval(wo, wi, mode))
    }

    /// Closed form: ∫ R/π cos θᵢ dωᵢ = R above the surface, 0 below.
    fn albedo(&self, wo: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        self.reflectance
    }

    /// A constant lobe has no angular variation.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        0.0
    }

    fn is_specular(&self) -> bool {
        false
    }

    fn has_specular(&self) -> bool {
        false
    }

    fn is_reflection_only(&self) -> bool {
        true
    }

    #[inline]
    fn is_isotropic(&self) -> bool {
        true
    }
}

/// Solid-angle pdf of cosine-weighted hemisphere sampling above the surface (0 when either
/// direction is below): the sampling of every diffuse lobe (Lambert, Oren–Nayar).
#[inline]
pub(crate) fn cosine_pdf(wo: Vec3A, wi: Vec3A) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    wi.z * std::f32::consts::FRAC_1_PI
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_testkit::chi2::{chi2_test, Chi2Config};

    #[test]
    fn chi2_lambert() {
        let l = Lambert {
            reflectance: SampledSpectrum::splat(0.5),
        };
        let wo = Vec3A::new(0.3, 0.2, 0.9).normalize();
        let r = chi2_test(
            &Chi2Config {
                sample_count: 200_000,
                ..Chi2Config::default()
            },
            |ul, u| l.sample(wo, ul, u, TransportMode::Radiance).map(|s| s.wi),
            |wi| f64::from(l.pdf(wo, wi, TransportMode::Radiance)),
        );
        assert!(r.passed, "{}", r.message);
    }
}
