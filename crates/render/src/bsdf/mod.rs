//! BSDFs, evaluated in the local shading frame: z is the shading normal, x the tangent
//! (dP/du, so anisotropic roughness α_u runs along u). Directions point away from the
//! surface: `wo` towards the viewer (or the previous vertex), `wi` towards the light (or
//! the next vertex). A `Bsdf` is built per hit by `Material::bsdf` with its spectra already
//! evaluated at the path's four wavelengths, so eval/sample/pdf do no spectrum lookups.
//!
//! Conventions (pbrt-v4 §9.1, Veach 1997 §5.2 for the adjoint):
//! - `eval` returns f(wo, wi) without the cosine; the integrator multiplies |cos θᵢ|.
//! - `pdf` is a solid-angle density of the non-Dirac part; Dirac lobes have pdf 0 in `pdf`
//!   and `eval` returns 0 for them.
//! - `sample` returns `BsdfSample::pdf` as the solid-angle density for a non-specular
//!   sample, and as the discrete probability of the chosen lobe for a specular one
//!   (with `f` then the Dirac lobe's weight, so f·|cos|/pdf is the throughput factor).
//! - `TransportMode::Importance` is the adjoint (light tracing / photons): it removes the
//!   1/η² radiance scaling of refraction.
//!
//! Lobes: `Lambert`, `Conductor` (smooth mirror or rough microfacet metal), `Dielectric`
//! (smooth or rough glass, reflection and refraction, optionally dispersive). Their
//! formulas and references are in each file and in docs/materials.md.

mod conductor;
mod dielectric;
pub mod fresnel;
mod lambert;
pub mod microfacet;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use lambert::Lambert;
pub use microfacet::{MicrofacetDistribution, MicrofacetModel};

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

/// Which quantity a path carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera paths carry radiance.
    Radiance,
    /// Light paths carry importance (adjoint BSDF).
    Importance,
}

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit direction in the local frame.
    pub wi: Vec3A,
    /// f(wo, wi) (no cosine); for a specular sample the Dirac lobe's weight.
    pub f: SampledSpectrum,
    /// Solid-angle pdf, or the lobe's discrete probability for a specular sample.
    pub pdf: f32,
    /// A Dirac lobe was sampled (no light sampling can reach it; MIS weight 1).
    pub specular: bool,
    /// `wi` is on the other side of the surface from `wo`.
    pub transmission: bool,
    /// Relative index of refraction η = η_transmitted / η_incident along the sample
    /// (1 for reflection), for Russian roulette's radiance scaling.
    pub eta: f32,
}

impl BsdfSample {
    /// f·|cos θᵢ|/pdf, the throughput factor.
    #[inline]
    pub fn weight(&self) -> SampledSpectrum {
        if self.pdf > 0.0 {
            self.f * (self.wi.z.abs() / self.pdf)
        } else {
            SampledSpectrum::splat(0.0)
        }
    }
}

/// The lobes a material can have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BsdfLobe {
    Lambert(Lambert),
    Conductor(Conductor),
    Dielectric(Dielectric),
}

impl BsdfLobe {
    /// True for lobes that only reflect (one-sided, so `Bsdf::two_sided` applies to them).
    #[inline]
    pub fn is_reflection_only(&self) -> bool {
        match self {
            BsdfLobe::Lambert(_) | BsdfLobe::Conductor(_) => true,
            BsdfLobe::Dielectric(_) => false,
        }
    }
}

/// A BSDF at one hit and four wavelengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    pub lobe: BsdfLobe,
    /// Reflection-only lobes are one-sided (zero seen from below, as in Mitsuba 3) unless
    /// this is set: then a `wo` below the surface is mirrored to the upper side. Ignored
    /// for transmissive lobes (a dielectric already scatters on both sides).
    pub two_sided: bool,
}

impl Bsdf {
    pub fn new(lobe: BsdfLobe) -> Self {
        Self {
            lobe,
            two_sided: false,
        }
    }

    /// True when `wo` is below a two-sided reflection-only lobe, which then sees the
    /// mirrored configuration.
    #[inline]
    fn flips(&self, wo: Vec3A) -> bool {
        self.two_sided && wo.z < 0.0 && self.lobe.is_reflection_only()
    }

    /// Flips both directions to the upper side for two-sided reflection-only lobes.
    #[inline]
    fn oriented(&self, wo: Vec3A, wi: Vec3A) -> (Vec3A, Vec3A) {
        if self.flips(wo) {
            (
                wo * Vec3A::new(1.0, 1.0, -1.0),
                wi * Vec3A::new(1.0, 1.0, -1.0),
            )
        } else {
            (wo, wi)
        }
    }

    /// f(wo, wi), no cosine.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> SampledSpectrum {
        let (wo, wi) = self.oriented(wo, wi);
        match &self.lobe {
            BsdfLobe::Lambert(l) => l.eval(wo, wi, mode),
            BsdfLobe::Conductor(c) => c.eval(wo, wi, mode),
            BsdfLobe::Dielectric(d) => d.eval(wo, wi, mode),
        }
    }

    /// Solid-angle pdf of `sample` producing `wi` (non-Dirac part).
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> f32 {
        let (wo, wi) = self.oriented(wo, wi);
        match &self.lobe {
            BsdfLobe::Lambert(l) => l.pdf(wo, wi, mode),
            BsdfLobe::Conductor(c) => c.pdf(wo, wi, mode),
            BsdfLobe::Dielectric(d) => d.pdf(wo, wi, mode),
        }
    }

    /// Samples `wi` given `wo`; `u_lobe` picks a lobe, `u` the direction within it.
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3A,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let flip = self.flips(wo);
        let wo = if flip {
            wo * Vec3A::new(1.0, 1.0, -1.0)
        } else {
            wo
        };
        let mut s = match &self.lobe {
            BsdfLobe::Lambert(l) => l.sample(wo, u_lobe, u, mode),
            BsdfLobe::Conductor(c) => c.sample(wo, u_lobe, u, mode),
            BsdfLobe::Dielectric(d) => d.sample(wo, u_lobe, u, mode),
        }?;
        if flip {
            s.wi *= Vec3A::new(1.0, 1.0, -1.0);
        }
        Some(s)
    }

    /// True when every lobe is a Dirac delta: light sampling cannot help (no NEE, no MIS).
    #[inline]
    pub fn is_specular(&self) -> bool {
        match &self.lobe {
            BsdfLobe::Lambert(_) => false,
            BsdfLobe::Conductor(c) => c.is_specular(),
            BsdfLobe::Dielectric(d) => d.is_specular(),
        }
    }

    /// True when the lobe has any Dirac component (MIS must treat BSDF samples from it as
    /// unmatched by light sampling).
    #[inline]
    pub fn has_specular(&self) -> bool {
        self.is_specular()
    }
}

#[cfg(test)]
mod tests;

/// cos θ of a local direction.
#[inline]
pub fn cos_theta(w: Vec3A) -> f32 {
    w.z
}

/// Both directions on the same side of the surface.
#[inline]
pub fn same_hemisphere(a: Vec3A, b: Vec3A) -> bool {
    a.z * b.z > 0.0
}
