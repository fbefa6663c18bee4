//! A weighted blend of lobes (Mitsuba 3 `blendbsdf`, pbrt-v3 `MixMaterial` evaluated as one
//! BSDF): f = Σⱼ wⱼ fⱼ with Σ wⱼ = 1, pdf = Σ wⱼ pⱼ, sampled by picking lobe j with
//! probability wⱼ (the lobe variate is rescaled and reused), then — for a non-Dirac
//! sample — evaluating the whole blend's f and pdf at the sampled direction (so MIS sees
//! one consistent density). A Dirac sample of lobe j keeps its own weight: f·wⱼ with
//! discrete probability pⱼ·wⱼ.
//!
//! Nested mixes are flattened when the material builds the BSDF (weights multiply), so a
//! component is never itself a mix; at most `MIX_MAX_COMPONENTS` leaves. Energy and
//! reciprocity hold when they hold for every component.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::{
    dispatch_lobe, BlinnPhong, BsdfLobe, BsdfSample, Coated, Conductor, Dielectric, Lafortune,
    Lambert, LobeKind, Measured, OrenNayar, Phong, ThinDielectric, TransportMode, Ward,
};

/// Most leaves a (flattened) mix may have.
pub const MIX_MAX_COMPONENTS: usize = 4;

/// A lobe inside a mix: every `BsdfLobe` but `Mix`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MixComponent<'a> {
    Lambert(Lambert),
    Conductor(Conductor),
    Dielectric(Dielectric),
    OrenNayar(OrenNayar),
    Phong(Phong),
    BlinnPhong(BlinnPhong),
    Ward(Ward),
    Lafortune(Lafortune),
    Coated(Coated),
    ThinDielectric(ThinDielectric),
    Measured(Measured<'a>),
}

impl<'a> MixComponent<'a> {
    /// The same lobe as a stand-alone `BsdfLobe`.
    pub fn as_lobe(&self) -> BsdfLobe<'a> {
        match *self {
            MixComponent::Lambert(l) => BsdfLobe::Lambert(l),
            MixComponent::Conductor(l) => BsdfLobe::Conductor(l),
            MixComponent::Dielectric(l) => BsdfLobe::Dielectric(l),
            MixComponent::OrenNayar(l) => BsdfLobe::OrenNayar(l),
            MixComponent::Phong(l) => BsdfLobe::Phong(l),
            MixComponent::BlinnPhong(l) => BsdfLobe::BlinnPhong(l),
            MixComponent::Ward(l) => BsdfLobe::Ward(l),
            MixComponent::Lafortune(l) => BsdfLobe::Lafortune(l),
            MixComponent::Coated(l) => BsdfLobe::Coated(l),
            MixComponent::ThinDielectric(l) => BsdfLobe::ThinDielectric(l),
            MixComponent::Measured(l) => BsdfLobe::Measured(l),
        }
    }

    /// A stand-alone lobe as a mix component (`None` for a mix: flatten it instead).
    pub fn from_lobe(lobe: BsdfLobe<'a>) -> Option<Self> {
        Some(match lobe {
            BsdfLobe::Lambert(l) => MixComponent::Lambert(l),
            BsdfLobe::Conductor(l) => MixComponent::Conductor(l),
            BsdfLobe::Dielectric(l) => MixComponent::Dielectric(l),
            BsdfLobe::OrenNayar(l) => MixComponent::OrenNayar(l),
            BsdfLobe::Phong(l) => MixComponent::Phong(l),
            BsdfLobe::BlinnPhong(l) => MixComponent::BlinnPhong(l),
            BsdfLobe::Ward(l) => MixComponent::Ward(l),
            BsdfLobe::Lafortune(l) => MixComponent::Lafortune(l),
            BsdfLobe::Coated(l) => MixComponent::Coated(l),
            BsdfLobe::ThinDielectric(l) => MixComponent::ThinDielectric(l),
            BsdfLobe::Measured(l) => MixComponent::Measured(l),
            BsdfLobe::Mix(_) => return None,
        })
    }

    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> SampledSpectrum {
        dispatch_lobe!(MixComponent, self, l => l.eval(wo, wi, mode))
    }
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> f32 {
        dispatch_lobe!(MixComponent, self, l => l.pdf(wo, wi, mode))
    }
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3A,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        dispatch_lobe!(MixComponent, self, l => l.sample(wo, u_lobe, u, mode))
    }
    #[inline]
    pub fn is_specular(&self) -> bool {
        dispatch_lobe!(MixComponent, self, l => LobeKind::is_specular(l))
    }
    #[inline]
    pub fn has_specular(&self) -> bool {
        dispatch_lobe!(MixComponent, self, l => l.has_specular())
    }
    #[inline]
    pub fn is_reflection_only(&self) -> bool {
        dispatch_lobe!(MixComponent, self, l => l.is_reflection_only())
    }
}

/// The blend: `components[..count]` with `weights[..count]` (each ≥ 0, summing to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mix<'a> {
    pub components: [MixComponent<'a>; MIX_MAX_COMPONENTS],
    pub weights: [f32; MIX_MAX_COMPONENTS],
    pub count: usize,
}

impl<'a> Mix<'a> {
    /// A blend of `parts` (weights normalised to sum 1); `None` for no part, more than
    /// `MIX_MAX_COMPONENTS`, or weights that are negative, non-finite or all zero.
    pub fn new(parts: &[(MixComponent<'a>, f32)]) -> Option<Self> {
        if parts.is_empty() || parts.len() > MIX_MAX_COMPONENTS {
            return None;
        }
        let total: f32 = parts.iter().map(|p| p.1).sum();
        if !(total > 0.0 && total.is_finite()) || parts.iter().any(|p| p.1.is_nan() || p.1 < 0.0) {
            return None;
        }
        let filler = MixComponent::Lambert(Lambert {
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
    fn parts(&self) -> impl Iterator<Item = (&MixComponent<'a>, f32)> {
        self.components[..self.count]
            .iter()
            .zip(self.weights[..self.count].iter().copied())
    }

    pub fn is_specular(&self) -> bool {
        self.parts().all(|(c, w)| w == 0.0 || c.is_specular())
    }

    pub fn has_specular(&self) -> bool {
        self.parts().any(|(c, w)| w > 0.0 && c.has_specular())
    }

    pub fn is_reflection_only(&self) -> bool {
        self.parts().all(|(c, _)| c.is_reflection_only())
    }

    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> SampledSpectrum {
        let mut f = SampledSpectrum::zero();
        for (c, w) in self.parts() {
            if w > 0.0 {
                f += c.eval(wo, wi, mode) * w;
            }
        }
        f
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> f32 {
        let mut p = 0.0;
        for (c, w) in self.parts() {
            if w > 0.0 {
                p += c.pdf(wo, wi, mode) * w;
            }
        }
        p
    }

    #[inline]
    pub fn sample(
        &self,
        wo: Vec3A,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
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
