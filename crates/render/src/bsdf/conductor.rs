//! Conductors (metals): Fresnel reflection with a complex index of refraction η + ik per
//! wavelength (`fresnel_complex`), no transmission.
//!
//! - Smooth (max α < `SMOOTH_ALPHA`): a Dirac mirror, f = F(cos θ) δ(ωᵢ − R(ωₒ)) / |cos θᵢ|.
//! - Rough: Torrance–Sparrow / Cook–Torrance, f = D(ωₕ) G₂(ωₒ, ωᵢ) F(ωₒ·ωₕ) /
//!   (4 cos θₒ cos θᵢ) with ωₕ = (ωₒ + ωᵢ)/|ωₒ + ωᵢ| (Walter et al. 2007 eq. 20; Torrance
//!   & Sparrow 1967), GGX or Beckmann D, height-correlated Smith G₂ (see `microfacet`).
//!   Sampled through the visible normals: ωₘ ~ D_ωₒ, ωᵢ = reflect(ωₒ, ωₘ), so
//!   p(ωᵢ) = D_ωₒ(ωₘ) / (4 |ωₒ·ωₘ|) (Heitz & d'Eon 2014 eq. 17; the 1/(4|ωₒ·ωₘ|) is the
//!   reflection Jacobian, Walter et al. 2007 eq. 14).
//!
//! One-sided: zero when ωₒ or ωᵢ is below the surface (`Bsdf::two_sided` mirrors them).

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::fresnel::{fresnel_complex_spectrum, reflect};
use super::microfacet::MicrofacetDistribution;
use super::{bandwidth_from_alpha, estimate_albedo, BsdfSample, Bxdf, TransportMode};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part η(λ) of the complex index of refraction, relative to the outside medium.
    pub eta: SampledSpectrum,
    /// Extinction coefficient k(λ) ≥ 0 (imaginary part).
    pub k: SampledSpectrum,
    pub distribution: MicrofacetDistribution,
}

impl Bxdf for Conductor {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if self.is_specular() || wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        let wh = wo + wi;
        let len2 = wh.length_squared();
        if len2 == 0.0 {
            return SampledSpectrum::zero();
        }
        let wh = wh / len2.sqrt();
        let d = self.distribution;
        let f = fresnel_complex_spectrum(wo.dot(wh).abs(), self.eta, self.k);
        f * (d.d(wh) * d.g(wo, wi) / (4.0 * wo.z * wi.z))
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if self.is_specular() || wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let wh = wo + wi;
        let len2 = wh.length_squared();
        if len2 == 0.0 {
            return 0.0;
        }
        let wh = wh / len2.sqrt();
        let cos_oh = wo.dot(wh);
        if cos_oh <= 0.0 {
            return 0.0;
        }
        self.distribution.d_visible(wo, wh) / (4.0 * cos_oh)
    }

    #[inline]
    fn sample(&self, wo: Vec3A, _u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if self.is_specular() {
            let wi = Vec3A::new(-wo.x, -wo.y, wo.z);
            let f = fresnel_complex_spectrum(wo.z, self.eta, self.k) / wi.z;
            return Some(BsdfSample {
                wi,
                f,
                pdf: 1.0,
                specular: true,
                transmission: false,
                eta: 1.0,
            });
        }
        let wm = self.distribution.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi, mode);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi, mode),
            pdf,
            specular: false,
            transmission: false,
            eta: 1.0,
        })
    }

    /// Smooth: closed form, the Fresnel reflectance F(cos θₒ) of the mirror. Rough: no
    /// closed form (masking and Fresnel vary over the lobe): `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        if self.is_specular() {
            return fresnel_complex_spectrum(wo.z, self.eta, self.k);
        }
        estimate_albedo(self, wo, mode)
    }

    /// ∞ for the mirror; else from the narrower of the two roughnesses α (radians of
    /// slope spread), which sets the anisotropic lobe's sharpest direction.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        if self.is_specular() {
            f32::INFINITY
        } else {
            bandwidth_from_alpha(self.distribution.alpha_x.min(self.distribution.alpha_y))
        }
    }

    /// A perfect mirror (no microfacet lobe).
    #[inline]
    fn is_specular(&self) -> bool {
        self.distribution.effectively_smooth()
    }

    #[inline]
    fn has_specular(&self) -> bool {
        self.is_specular()
    }

    #[inline]
    fn is_reflection_only(&self) -> bool {
        true
    }

    /// Isotropic with one roughness for both tangent directions.
    fn is_isotropic(&self) -> bool {
        self.distribution.alpha_x == self.distribution.alpha_y
    }
}
