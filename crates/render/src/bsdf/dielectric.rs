//! Dielectric interfaces (glass, water): Fresnel reflection plus refraction, both sides.
//!
//! `eta` is the relative index η = η_inside/η_outside per wavelength, "inside" being below
//! the shading normal (−z). The relative index along a transmitted sample is
//! η' = η when ωₒ is outside (cos θₒ > 0) and 1/η when it is inside.
//!
//! - Smooth (max α < `SMOOTH_ALPHA`, or η = 1): a Dirac reflection with weight F and a
//!   Dirac refraction with weight 1 − F, picked with probabilities F and 1 − F (pbrt-v4
//!   §9.5.1). Refracted radiance is scaled by 1/η'² in `Radiance` mode — radiance is not
//!   invariant across an interface, L/η² is (Veach 1997 §5.2, eq. 5.9) — and not in
//!   `Importance` mode (the adjoint BSDF, Veach §5.2.2).
//! - Rough: Walter et al. 2007, "Microfacet models for refraction through rough surfaces":
//!   reflection f_r = D G₂ F / (4 |cos θᵢ cos θₒ|) (eq. 20) and transmission
//!   f_t = |ωᵢ·ωₘ||ωₒ·ωₘ| (1 − F) D G₂ / (|cos θᵢ cos θₒ| (ωᵢ·ωₘ + ωₒ·ωₘ/η')²) (eq. 21,
//!   written with η' = η_i/η_o in pbrt-v4's form, §9.7.2), /η'² in `Radiance` mode, with the
//!   generalised half vector ωₘ = ±(η'ωᵢ + ωₒ) (eq. 16). Sampled through the visible
//!   normals of ωₒ, choosing reflection with probability F(ωₒ·ωₘ): the densities use the
//!   Jacobians 1/(4|ωₒ·ωₘ|) (reflection, eq. 14) and |ωᵢ·ωₘ|/(ωᵢ·ωₘ + ωₒ·ωₘ/η')²
//!   (refraction, eq. 17).
//!
//! Dispersion: `eta` may differ per lane. The sampled direction and every pdf use the hero
//! lane 0's η. `eval` of the rough lobe is exact per lane (each lane's own generalised half
//! vector, D, G and F). For the smooth lobe each lane gets its own Fresnel weight and η'
//! along the hero's direction; only lane 0 is exact there (the other lanes' Dirac
//! refractions point elsewhere), which is why the integrator keeps only the hero wavelength
//! after a dispersive hit (`Material::is_dispersive`).

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::microfacet::MicrofacetDistribution;
use super::{
    bandwidth_from_alpha, estimate_albedo, same_hemisphere, BsdfSample, Bxdf, TransportMode,
};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Relative index of refraction η(λ) = η_inside/η_outside at the path's wavelengths.
    pub eta: SampledSpectrum,
    pub distribution: MicrofacetDistribution,
}

/// The generalised half vector of (ωₒ, ωᵢ) for relative index `eta` (Walter et al. 2007
/// eq. 16), facing +z, with η' along ωᵢ, or `None` for degenerate or back-facing
/// configurations (where f and p are zero).
#[inline]
fn half_vector(wo: Vec3A, wi: Vec3A, eta: f32) -> Option<(Vec3A, f32)> {
    let (cos_o, cos_i) = (wo.z, wi.z);
    if cos_o == 0.0 || cos_i == 0.0 {
        return None;
    }
    let reflection = cos_o * cos_i > 0.0;
    let etap = if reflection {
        1.0
    } else if cos_o > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    let len2 = wm.length_squared();
    if len2 == 0.0 || !len2.is_finite() {
        return None;
    }
    let mut wm = wm / len2.sqrt();
    if wm.z < 0.0 {
        wm = -wm;
    }
    // Microfacets seen from behind by either direction contribute nothing.
    if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
        return None;
    }
    Some((wm, etap))
}

impl Dielectric {
    /// True when every lane has the same η (no dispersion): one evaluation serves all.
    #[inline]
    fn uniform_eta(&self) -> bool {
        self.eta.values.iter().all(|&e| e == self.eta[0])
    }

    /// f(ωₒ, ωᵢ) of the rough lobe at relative index `eta` (one lane).
    #[inline]
    fn eval_lane(&self, wo: Vec3A, wi: Vec3A, eta: f32, mode: TransportMode) -> f32 {
        let Some((wm, etap)) = half_vector(wo, wi, eta) else {
            return 0.0;
        };
        let d = self.distribution;
        let f = fresnel_dielectric(wo.dot(wm), eta);
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o * cos_i > 0.0 {
            return d.d(wm) * d.g(wo, wi) * f / (4.0 * cos_i * cos_o).abs();
        }
        let (dot_i, dot_o) = (wi.dot(wm), wo.dot(wm));
        let denom = (dot_i + dot_o / etap).powi(2) * cos_i * cos_o;
        if denom == 0.0 {
            return 0.0;
        }
        let mut ft = d.d(wm) * (1.0 - f) * d.g(wo, wi) * (dot_i * dot_o / denom).abs();
        if mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        ft
    }

    /// The smooth interface: reflection with probability F, refraction with 1 − F.
    #[inline]
    fn sample_specular(&self, wo: Vec3A, u_lobe: f32, mode: TransportMode) -> Option<BsdfSample> {
        let eta = self.eta[0];
        let r = fresnel_dielectric(wo.z, eta);
        if u_lobe < r {
            let wi = Vec3A::new(-wo.x, -wo.y, wo.z);
            let f =
                SampledSpectrum::from_fn(|l| fresnel_dielectric(wo.z, self.eta[l])) / wi.z.abs();
            return Some(BsdfSample {
                wi,
                f,
                pdf: r,
                specular: true,
                transmission: false,
                eta: 1.0,
            });
        }
        let (wi, etap) = refract(wo, Vec3A::Z, eta)?;
        if wi.z == 0.0 {
            return None;
        }
        let cos_i = wi.z.abs();
        let f = SampledSpectrum::from_fn(|l| {
            let eta_l = self.eta[l];
            let t = 1.0 - fresnel_dielectric(wo.z, eta_l);
            let etap_l = if wo.z > 0.0 { eta_l } else { 1.0 / eta_l };
            match mode {
                TransportMode::Radiance => t / (cos_i * etap_l * etap_l),
                TransportMode::Importance => t / cos_i,
            }
        });
        Some(BsdfSample {
            wi,
            f,
            pdf: 1.0 - r,
            specular: true,
            transmission: true,
            eta: etap,
        })
    }
}

impl Bxdf for Dielectric {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> SampledSpectrum {
        if self.is_specular() {
            return SampledSpectrum::zero();
        }
        if self.uniform_eta() {
            SampledSpectrum::splat(self.eval_lane(wo, wi, self.eta[0], mode))
        } else {
            SampledSpectrum::from_fn(|l| self.eval_lane(wo, wi, self.eta[l], mode))
        }
    }

    /// Density of `sample` (hero lane's η).
    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if self.is_specular() {
            return 0.0;
        }
        let eta = self.eta[0];
        let Some((wm, etap)) = half_vector(wo, wi, eta) else {
            return 0.0;
        };
        let r = fresnel_dielectric(wo.dot(wm), eta);
        let t = 1.0 - r;
        let d_vis = self.distribution.d_visible(wo, wm);
        if wo.z * wi.z > 0.0 {
            d_vis / (4.0 * wo.dot(wm).abs()) * r
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            if denom == 0.0 {
                return 0.0;
            }
            let dwm_dwi = wi.dot(wm).abs() / denom;
            d_vis * dwm_dwi * t
        }
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.is_specular() {
            return self.sample_specular(wo, u_lobe, mode);
        }
        let eta = self.eta[0];
        let wm = self.distribution.sample_wm(wo, u);
        let r = fresnel_dielectric(wo.dot(wm), eta);
        let (wi, transmission, etap) = if u_lobe < r {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            (wi, false, 1.0)
        } else {
            let (wi, etap) = refract(wo, wm, eta)?;
            if same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            (wi, true, etap)
        };
        let pdf = self.pdf(wo, wi, mode);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi, mode),
            pdf,
            specular: false,
            transmission,
            eta: etap,
        })
    }

    /// Smooth: closed form per lane, F + (1 − F)/η'² (the Dirac reflection and refraction;
    /// no 1/η'² in `Importance` mode, so ρ = 1 there). Rough: `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        if wo.z == 0.0 {
            return SampledSpectrum::zero();
        }
        if !self.is_specular() {
            return estimate_albedo(self, wo, mode);
        }
        SampledSpectrum::from_fn(|l| {
            let eta_l = self.eta[l];
            let r = fresnel_dielectric(wo.z, eta_l);
            let etap_l = if wo.z > 0.0 { eta_l } else { 1.0 / eta_l };
            match mode {
                TransportMode::Radiance => r + (1.0 - r) / (etap_l * etap_l),
                TransportMode::Importance => r + (1.0 - r),
            }
        })
    }

    /// As for `Conductor`: ∞ when Dirac, else from the narrower roughness.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        if self.is_specular() {
            f32::INFINITY
        } else {
            bandwidth_from_alpha(self.distribution.alpha_x.min(self.distribution.alpha_y))
        }
    }

    /// Every lobe is a Dirac delta: smooth, or index-matched (η = 1: straight through).
    #[inline]
    fn is_specular(&self) -> bool {
        self.eta[0] == 1.0 || self.distribution.effectively_smooth()
    }

    #[inline]
    fn has_specular(&self) -> bool {
        self.is_specular()
    }

    /// Reflects and refracts, on both sides.
    #[inline]
    fn is_reflection_only(&self) -> bool {
        false
    }

    /// Isotropic with one roughness for both tangent directions.
    fn is_isotropic(&self) -> bool {
        self.distribution.alpha_x == self.distribution.alpha_y
    }
}
