//! The point where a path scatters: a surface (a BSDF in its shading frame) or a point in
//! a medium (a phase function). Estimators walk paths through `ScatterVertex` only, so the
//! path loop is written once for both kinds (pbrt-v4's `SurfaceInteraction` /
//! `MediumInteraction` pair behind one `Interaction`, §4.5; Veach 1997 §8.2 treats both
//! as the vertex's scattering function f_s).
//!
//! Directions are world-space and point away from the vertex: `wo` back along the arriving
//! ray, `wi` onwards. Scattering values include the cosine at surfaces (f·|cos θi|) and are
//! the phase function p in media (no cosine).

use glam::{Vec2, Vec3A};
use prism_geometry::{Frame, SurfaceInteraction};
use prism_spectrum::SampledSpectrum;

use crate::bsdf::{Bsdf, TransportMode};
use crate::light::{LightSample, LightSampleContext};
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

use super::lane_wavelengths::LaneWavelengths;
use crate::medium::PhaseFunction;

/// A surface vertex: the hit, its BSDF and shading frame.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceVertex<'a> {
    pub si: &'a SurfaceInteraction,
    /// Borrowed: a `Bsdf` is a few hundred bytes (a mix holds its lobes by value), and
    /// bidirectional methods view one vertex from several directions.
    pub bsdf: &'a Bsdf<'a>,
    pub frame: Frame,
    pub wo_local: Vec3A,
    /// The shading normal comes from a normal or bump map: directions whose side of the
    /// geometric surface disagrees with the BSDF's reflection/transmission are refused
    /// (see `texture::shading_normal`).
    pub check_sides: bool,
    /// ωo · n_geometric.
    pub wo_dot_ng: f32,
}

/// A medium vertex: a point and the medium's phase function there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumVertex<'a> {
    /// Position, metres (world).
    pub p: Vec3A,
    /// Unit direction back along the arriving ray.
    pub wo: Vec3A,
    /// The medium's (a table is shared, not copied).
    pub phase: &'a PhaseFunction,
}

/// Where a path scatters.
#[derive(Clone, Copy, Debug)]
pub enum ScatterVertex<'a> {
    Surface(SurfaceVertex<'a>),
    Medium(MediumVertex<'a>),
}

/// The scattering function towards a direction: f·|cos θi| (surface) or p (medium), with
/// what the pdf and the illumination AOV need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterEval {
    pub f_cos: SampledSpectrum,
    /// `wi` in the shading frame (the world direction at medium vertices).
    pub wi_local: Vec3A,
}

/// A sampled continuation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterSample {
    /// Unit direction (world).
    pub wi: Vec3A,
    /// f·|cos θi|/pdf (phase samples: p/pdf).
    pub weight: SampledSpectrum,
    /// Solid-angle pdf, or the chosen Dirac lobe's probability when `specular`.
    pub pdf: f32,
    pub specular: bool,
    pub transmission: bool,
    /// η_transmitted/η_incident along the sample (1 for reflection and in media).
    pub eta: f32,
    /// `wi` in the shading frame (world at medium vertices): the white Lambertian weight
    /// of the illumination AOV reads its z.
    pub wi_local: Vec3A,
}

impl<'a> SurfaceVertex<'a> {
    /// The vertex of `si` seen from the ray direction `ray_direction`.
    #[inline(always)]
    pub fn new(
        si: &'a SurfaceInteraction,
        bsdf: &'a Bsdf<'a>,
        ray_direction: Vec3A,
        check_sides: bool,
    ) -> Self {
        let frame = Frame::from_zx(si.n_shading, si.dpdu);
        Self {
            si,
            bsdf,
            frame,
            wo_local: frame.to_local(-ray_direction),
            check_sides,
            wo_dot_ng: -ray_direction.dot(si.n_geometric),
        }
    }

    /// True when world direction `wi` lies on the side of the geometric surface that the
    /// shading frame's reflection (`wi_local.z · wo_local.z > 0`) or transmission implies.
    #[inline(always)]
    pub fn sides_agree(&self, wi: Vec3A, wi_local: Vec3A) -> bool {
        if !self.check_sides {
            return true;
        }
        let geometric_reflection = wi.dot(self.si.n_geometric) * self.wo_dot_ng > 0.0;
        let shading_reflection = wi_local.z * self.wo_local.z > 0.0;
        geometric_reflection == shading_reflection
    }
}

/// A light sample seen from a vertex, before its shadow ray: what next-event estimation
/// (`medium_transport`, the photon camera path) weights and traces.
pub(crate) struct VertexLightSample {
    pub sample: LightSample,
    /// Probability of having chosen the light.
    pub pmf: f32,
    /// The vertex's f · cos towards the light.
    pub eval: ScatterEval,
    /// The vertex's geometric normal (zero in a medium), for the shadow ray's start.
    pub normal: Vec3A,
}

impl ScatterVertex<'_> {
    /// Chooses a light with `u_choice`, samples it with `u` (radiance from `le_cache` where
    /// uniform) and evaluates this vertex towards it; `None` where a step yields nothing (no
    /// light, a zero pdf or radiance, a zero f · cos).
    pub(crate) fn sample_light(
        &self,
        scene: &RenderScene,
        u_choice: f32,
        u: Vec2,
        wavelengths: &LaneWavelengths,
        le_cache: &mut SpectrumCache,
    ) -> Option<VertexLightSample> {
        let lights = &scene.lights;
        let ctx = self.light_context();
        let (l, pmf) = lights.sample_at(&ctx, u_choice)?;
        let sample = lights.light(l).sample_li_cached(
            lights.emission_key(l),
            &ctx,
            u,
            wavelengths,
            le_cache,
        )?;
        if sample.pdf <= 0.0 || sample.radiance.is_black() {
            return None;
        }
        let eval = self.eval(sample.wi, TransportMode::Radiance)?;
        if eval.f_cos.is_black() {
            return None;
        }
        Some(VertexLightSample {
            sample,
            pmf,
            eval,
            normal: ctx.n,
        })
    }

    /// Position, metres (world).
    #[inline(always)]
    pub fn p(&self) -> Vec3A {
        match self {
            ScatterVertex::Surface(s) => s.si.p,
            ScatterVertex::Medium(m) => m.p,
        }
    }

    /// The reference point for light sampling (a zero normal in media).
    #[inline(always)]
    pub fn light_context(&self) -> LightSampleContext {
        match self {
            ScatterVertex::Surface(s) => LightSampleContext {
                p: s.si.p,
                n: s.si.n_geometric,
            },
            ScatterVertex::Medium(m) => LightSampleContext {
                p: m.p,
                n: Vec3A::ZERO,
            },
        }
    }

    /// Only Dirac components: light sampling cannot reach it.
    #[inline(always)]
    pub fn is_specular(&self) -> bool {
        match self {
            ScatterVertex::Surface(s) => s.bsdf.is_specular(),
            ScatterVertex::Medium(_) => false,
        }
    }

    /// A surface vertex with a single Lambertian lobe (`Bsdf::is_lambertian`).
    #[inline(always)]
    pub fn is_lambertian(&self) -> bool {
        match self {
            ScatterVertex::Surface(s) => s.bsdf.is_lambertian(),
            ScatterVertex::Medium(_) => false,
        }
    }

    /// The scattering function towards world direction `wi`; `None` where a shading-normal
    /// vertex refuses the direction's side.
    #[inline(always)]
    pub fn eval(&self, wi: Vec3A, mode: TransportMode) -> Option<ScatterEval> {
        match self {
            ScatterVertex::Surface(s) => {
                let wi_local = s.frame.to_local(wi);
                if !s.sides_agree(wi, wi_local) {
                    return None;
                }
                let f_cos = s.bsdf.eval(s.wo_local, wi_local, mode) * wi_local.z.abs();
                Some(ScatterEval { f_cos, wi_local })
            }
            ScatterVertex::Medium(m) => Some(ScatterEval {
                f_cos: SampledSpectrum::splat(m.phase.eval(m.wo, wi)),
                wi_local: wi,
            }),
        }
    }

    /// Solid-angle pdf with which `sample` produces the direction of `eval`.
    #[inline(always)]
    pub fn pdf(&self, eval: &ScatterEval, mode: TransportMode) -> f32 {
        match self {
            ScatterVertex::Surface(s) => s.bsdf.pdf(s.wo_local, eval.wi_local, mode),
            ScatterVertex::Medium(m) => m.phase.pdf(m.wo, eval.wi_local),
        }
    }

    /// Solid-angle pdf with which `sample` produces world direction `wi` (0 where a
    /// shading-normal vertex refuses the direction's side): `pdf` without evaluating f.
    #[inline(always)]
    pub fn pdf_toward(&self, wi: Vec3A, mode: TransportMode) -> f32 {
        match self {
            ScatterVertex::Surface(s) => {
                let wi_local = s.frame.to_local(wi);
                if !s.sides_agree(wi, wi_local) {
                    return 0.0;
                }
                s.bsdf.pdf(s.wo_local, wi_local, mode)
            }
            ScatterVertex::Medium(m) => m.phase.pdf(m.wo, wi),
        }
    }

    /// Samples a continuation from `u_lobe` and `u`; `None` where sampling fails or a
    /// shading-normal vertex refuses the sampled side.
    #[inline(always)]
    pub fn sample(&self, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<ScatterSample> {
        match self {
            ScatterVertex::Surface(s) => {
                let bs = s.bsdf.sample(s.wo_local, u_lobe, u, mode)?;
                let wi = s.frame.from_local(bs.wi);
                if !s.sides_agree(wi, bs.wi) {
                    return None;
                }
                Some(ScatterSample {
                    wi,
                    weight: bs.weight(),
                    pdf: bs.pdf,
                    specular: bs.specular,
                    transmission: bs.transmission,
                    eta: bs.eta,
                    wi_local: bs.wi,
                })
            }
            ScatterVertex::Medium(m) => {
                let ps = m.phase.sample(m.wo, u)?;
                Some(ScatterSample {
                    wi: ps.wi,
                    weight: SampledSpectrum::splat(ps.p / ps.pdf),
                    pdf: ps.pdf,
                    specular: false,
                    transmission: false,
                    eta: 1.0,
                    wi_local: ps.wi,
                })
            }
        }
    }
}
