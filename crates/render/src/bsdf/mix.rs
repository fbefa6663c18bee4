//! A weighted blend of lobes (Mitsuba 3 `blendbsdf`, pbrt-v3 `MixMaterial` evaluated as one
//! BSDF): f = Σⱼ wⱼ fⱼ with Σ wⱼ = 1, pdf = Σ wⱼ pⱼ, sampled by picking lobe j with
//! probability wⱼ (the lobe variate is rescaled and reused), then — for a non-Dirac
//! sample — evaluating the whole blend's f and pdf at the sampled direction (so MIS sees
//! one consistent density). A Dirac sample of lobe j keeps its own weight: f·wⱼ with
//! discrete probability pⱼ·wⱼ.
//!
//! Nested mixes are flattened when the material builds the BSDF (weights multiply): a
//! component is a `LeafLobe`, whose `Mix` variant holds the valueless `NoMix`, so it is
//! never itself a mix; at most `MIX_MAX_COMPONENTS` leaves. Energy and reciprocity hold
//! when they hold for every component.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::{BsdfSample, Bxdf, Lambert, LeafLobe, TransportMode};

/// Most leaves a (flattened) mix may have.
pub const MIX_MAX_COMPONENTS: usize = 4;

/// The former name of a mix leaf, kept for tools/bench-bsdf: the same type as `LeafLobe`.
pub type MixComponent<'a> = LeafLobe<'a>;

/// The blend: `components[..count]` with `weights[..count]` (each ≥ 0, summing to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mix<'a> {
    pub components: [LeafLobe<'a>; MIX_MAX_COMPONENTS],
    pub weights: [f32; MIX_MAX_COMPONENTS],
    pub count: usize,
}

impl<'a> Mix<'a> {
    /// A blend of `parts` (weights normalised to sum 1); `None` for no part, more than
    /// `MIX_MAX_COMPONENTS`, or weights that are negative, non-finite or all zero.
    pub fn new(parts: &[(LeafLobe<'a>, f32)]) -> Option<Self> {
        if parts.is_empty() || parts.len() > MIX_MAX_COMPONENTS {
            return None;
        }
        let total: f32 = parts.iter().map(|p| p.1).sum();
        if !(total > 0.0 && total.is_finite()) || parts.iter().any(|p| p.1.is_nan() || p.1 < 0.0) {
            return None;
        }
        let filler = LeafLobe::Lambert(Lambert {
            reflectance: SampledSpectrum::zero(),
        });
        let mut components = [filler; MIX_MAX_COMPONENTS];
        let mut weights = [0.0; MIX_MAX_COMPONENTS];
        for (j, (c, w)) in parts.iter().enumerate() {
            components[j] = *c;
            weights[j] = w / total;
        }
        Some(Self {
            components,
            weights,
            count: parts.len(),
        })
    }

    #[inline]
    fn parts(&self) -> impl Iterator<Item = (&LeafLobe<'a>, f32)> {
        self.components[..self.count]
            .iter()
            .zip(self.weights[..self.count].iter().copied())
    }
}

impl Bxdf for Mix<'_> {
    /// Exact composition: ρ = Σⱼ wⱼ ρⱼ, since f is linear in the leaves; each ρⱼ is its
    /// leaf's (closed form or `estimate_albedo`).
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        let mut rho = SampledSpectrum::zero();
        for (c, w) in self.parts() {
            if w > 0.0 {
                rho += c.albedo(wo, mode) * w;
            }
        }
        rho
    }

    /// The sharpest leaf sets the bandwidth.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        self.components[..self.count]
            .iter()
            .map(Bxdf::angular_bandwidth_cycles_per_rad)
            .fold(0.0, f32::max)
    }

    #[inline]
    fn is_specular(&self) -> bool {
        self.parts().all(|(c, w)| w == 0.0 || c.is_specular())
    }

    #[inline]
    fn has_specular(&self) -> bool {
        self.parts().any(|(c, w)| w > 0.0 && c.has_specular())
    }

    #[inline]
    fn is_reflection_only(&self) -> bool {
        self.parts().all(|(c, _)| c.is_reflection_only())
    }

    /// Isotropic when every leaf is.
    fn is_isotropic(&self) -> bool {
        self.components[..self.count].iter().all(Bxdf::is_isotropic)
    }

    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> SampledSpectrum {
        let mut f = SampledSpectrum::zero();
        for (c, w) in self.parts() {
            if w > 0.0 {
                f += c.eval(wo, wi, mode) * w;
            }
        }
        f
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> f32 {
        let mut p = 0.0;
        for (c, w) in self.parts() {
            if w > 0.0 {
                p += c.pdf(wo, wi, mode) * w;
            }
        }
        p
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        // Pick component j with probability wⱼ; reuse the variate inside it.
        let mut chosen = self.count - 1;
        let mut start = 0.0;
        for j in 0..self.count {
            let w = self.weights[j];
            if w > 0.0 && (u_lobe < start + w || j == self.count - 1) {
                chosen = j;
                break;
            }
            start += w;
        }
        let w = self.weights[chosen];
        if w <= 0.0 {
            return None;
        }
        let u_inner = ((u_lobe - start) / w).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let mut s = self.components[chosen].sample(wo, u_inner, u, mode)?;
        if s.specular {
            s.f *= w;
            s.pdf *= w;
            return Some(s);
        }
        s.f = self.eval(wo, s.wi, mode);
        s.pdf = self.pdf(wo, s.wi, mode);
        (s.pdf > 0.0).then_some(s)
    }
}
