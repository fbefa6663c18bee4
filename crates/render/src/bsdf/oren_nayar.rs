//! Oren & Nayar's rough diffuse reflector (M. Oren and S. K. Nayar, "Generalization of
//! Lambert's reflectance model", SIGGRAPH 1994): a surface of long symmetric V-cavities,
//! each face Lambertian with albedo ρ, whose facet slopes are normally distributed with
//! standard deviation σ (radians).
//!
//! Two forms, named apart:
//! - `Full`: the paper's eq. 8 direct term L₁ with its three coefficients C₁, C₂, C₃ plus
//!   the eq. 9 inter-reflection term L₂ (proportional to ρ²). As a BRDF (L/(E₀ cos θᵢ)),
//!   with α = max(θᵢ, θᵣ), β = min(θᵢ, θᵣ), Δφ = φᵣ − φᵢ:
//!
//!   ```text
//!   f  = ρ/π [C₁ + cos(Δφ) C₂ tan β + (1 − |cos Δφ|) C₃ tan((α+β)/2)]
//!        + 0.17 ρ²/π · σ²/(σ² + 0.13) · [1 − cos(Δφ) (2β/π)²]
//!   C₁ = 1 − 0.5 σ²/(σ² + 0.33)
//!   C₂ = 0.45 σ²/(σ² + 0.09) sin α                when cos Δφ ≥ 0
//!      = 0.45 σ²/(σ² + 0.09) (sin α − (2β/π)³)    otherwise
//!   C₃ = 0.125 σ²/(σ² + 0.09) (4αβ/π²)²
//!   ```
//! - `Qualitative`: the paper's simplified eq. 30,
//!   f = ρ/π [A + B max(0, cos Δφ) sin α tan β], A = 1 − 0.5 σ²/(σ² + 0.33),
//!   B = 0.45 σ²/(σ² + 0.09).
//!
//! Both are symmetric in the two directions (reciprocal) and reduce to Lambert at σ = 0.
//! Sampling is cosine-weighted, as for Lambert (pbrt-v3 `OrenNayar`, Mitsuba 3 `roughdiffuse`).
//! One-sided: zero when either direction is below the surface.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::{estimate_albedo, BsdfSample, Bxdf, TransportMode};
use crate::sampling::sample_cosine_hemisphere;

/// Which of the paper's two forms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrenNayarForm {
    /// Eqs. 8 and 9: C₁, C₂, C₃ and the inter-reflection term.
    Full,
    /// Eq. 30: A + B max(0, cos Δφ) sin α tan β.
    Qualitative,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrenNayar {
    /// Facet albedo ρ(λ) ∈ [0, 1].
    pub reflectance: SampledSpectrum,
    /// Standard deviation σ of the facet slope angle, radians (≥ 0).
    pub sigma_rad: f32,
    pub form: OrenNayarForm,
}

impl Bxdf for OrenNayar {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::splat(0.0);
        }
        let s2 = self.sigma_rad * self.sigma_rad;
        if s2 == 0.0 {
            return self.reflectance * std::f32::consts::FRAC_1_PI;
        }
        let (cos_i, cos_o) = (wi.z.min(1.0), wo.z.min(1.0));
        let (sin_i, sin_o) = (
            (1.0 - cos_i * cos_i).max(0.0).sqrt(),
            (1.0 - cos_o * cos_o).max(0.0).sqrt(),
        );
        // cos Δφ from the tangent-plane projections (0 when either is along the normal).
        let cos_dphi = if sin_i > 1e-6 && sin_o > 1e-6 {
            ((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o)).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        // α = max(θᵢ, θᵣ) has the smaller cosine; β = min has the larger.
        let (sin_alpha, tan_beta) = if cos_i < cos_o {
            (sin_i, sin_o / cos_o)
        } else {
            (sin_o, sin_i / cos_i)
        };
        let inv_pi = std::f32::consts::FRAC_1_PI;
        match self.form {
            OrenNayarForm::Qualitative => {
                let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
                let b = 0.45 * s2 / (s2 + 0.09);
                self.reflectance * (inv_pi * (a + b * cos_dphi.max(0.0) * sin_alpha * tan_beta))
            }
            OrenNayarForm::Full => {
                let (theta_i, theta_o) = (cos_i.acos(), cos_o.acos());
                let (alpha, beta) = (theta_i.max(theta_o), theta_i.min(theta_o));
                let two_beta_pi = 2.0 * beta * inv_pi;
                let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
                let c2 = if cos_dphi >= 0.0 {
                    0.45 * s2 / (s2 + 0.09) * sin_alpha
                } else {
                    0.45 * s2 / (s2 + 0.09) * (sin_alpha - two_beta_pi.powi(3))
                };
                let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * alpha * beta * inv_pi * inv_pi).powi(2);
                // Oren & Nayar 1994 eq. 8 (direct) over E₀ cos θᵢ.
                let direct = c1
                    + cos_dphi * c2 * tan_beta
                    + (1.0 - cos_dphi.abs()) * c3 * (0.5 * (alpha + beta)).tan();
                // Eq. 9 (inter-reflection), ∝ ρ².
                let inter =
                    0.17 * inv_pi * s2 / (s2 + 0.13) * (1.0 - cos_dphi * two_beta_pi * two_beta_pi);
                self.reflectance * (inv_pi * direct) + self.reflectance * self.reflectance * inter
            }
        }
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        super::lambert::cosine_pdf(wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3A, _u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        BsdfSample::reflection(wi, self.pdf(wo, wi, mode), || self.eval(wo, wi, mode))
    }

    /// Closed form at σ = 0 (Lambert: ρ); otherwise no closed form for either form
    /// (eq. 8's coefficients vary with both angles): `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        if self.sigma_rad == 0.0 {
            return self.reflectance;
        }
        estimate_albedo(self, wo, mode)
    }

    /// A diffuse lobe: no angular detail to resolve.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        0.0
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
