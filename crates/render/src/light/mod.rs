//! Emitters. Every light answers, for a reference point, "sample a direction towards me"
//! (`sample_li`, with the radiance arriving and the solid-angle pdf) and "how likely would
//! you have sampled this direction" (`pdf_li`, for MIS against BSDF sampling); lights that
//! paths can hit (area, environment, sky, a sun of non-zero size) also give the radiance
//! leaving them (`emitted_radiance` for surfaces, `infinite_radiance` for directions).
//! `LightSet` holds them all, picks one per light sample in proportion to its power, and
//! maps hit instances to area lights.
//!
//! Units: radiance W·m⁻²·sr⁻¹·nm⁻¹ at each sampled wavelength. For a delta light
//! (point, spot, ideal directional) `LightSample::radiance` is the incident irradiance per
//! unit projected solid angle in the same sense pbrt-v4 uses: the contribution of a light
//! sample is f · |cos θ| · radiance / pdf, with pdf = 1 for a delta light.

mod light_set;
mod point;

pub use light_set::{LightSet, NO_LIGHT};
pub use point::PointLight;

use glam::{Vec2, Vec3A};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

/// Where light arrives: the reference point of `sample_li` / `pdf_li`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSampleContext {
    /// Position, metres (world).
    pub p: Vec3A,
    /// Geometric normal at `p` (unit), or zero for a point in a medium.
    pub n: Vec3A,
}

/// A sampled direction towards a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the reference point towards the light (world).
    pub wi: Vec3A,
    /// Radiance arriving along `wi` if unoccluded (see the module docs for delta lights).
    pub radiance: SampledSpectrum,
    /// Solid-angle pdf of `wi` (1 for delta lights). Does not include the light selection
    /// probability.
    pub pdf: f32,
    /// The point sampled on the light (world, metres); for infinite lights a point far
    /// along `wi`. Shadow rays go from the reference point to here.
    pub p_light: Vec3A,
    /// Distance to `p_light`, metres (+∞ for infinite lights).
    pub distance_m: f32,
    /// Dirac in direction: BSDF sampling can never hit it (MIS weight 1).
    pub delta: bool,
}

/// A point on an emitting surface that a path hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightHit {
    /// Position, metres (world).
    pub p: Vec3A,
    /// Geometric normal of the emitting surface (unit, world).
    pub n: Vec3A,
    pub uv: Vec2,
    /// Distance from the reference point, metres.
    pub distance_m: f32,
}

/// One emitter.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point(PointLight),
}

impl Light {
    /// Samples a direction from `ctx` towards the light.
    #[inline]
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        match self {
            Light::Point(l) => l.sample_li(ctx, u, wavelengths),
        }
    }

    /// Solid-angle pdf with which `sample_li` from `ctx` produces `wi`; `hit` is where a
    /// ray along `wi` met the light's surface (`None` for infinite lights). 0 for delta
    /// lights.
    #[inline]
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3A, hit: Option<&LightHit>) -> f32 {
        let _ = (ctx, wi, hit);
        match self {
            Light::Point(_) => 0.0,
        }
    }

    /// Radiance leaving an emitting surface at `hit` in direction `wo` (unit, away from
    /// the surface, towards the previous path vertex). Zero for lights without a surface.
    #[inline]
    pub fn emitted_radiance(
        &self,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let _ = (hit, wo, wavelengths);
        match self {
            Light::Point(_) => SampledSpectrum::splat(0.0),
        }
    }

    /// Radiance arriving from an infinitely distant light along the ray direction
    /// `direction` (unit, pointing away from the scene, towards the light). Zero for
    /// lights at finite distance.
    #[inline]
    pub fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let _ = (direction, wavelengths);
        match self {
            Light::Point(_) => SampledSpectrum::splat(0.0),
        }
    }

    /// Dirac in position or direction: BSDF-sampled rays never hit it.
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Point(_) => true,
        }
    }

    /// At infinity (environment, sky, directional): seen by rays that leave the scene.
    #[inline]
    pub fn is_infinite(&self) -> bool {
        match self {
            Light::Point(_) => false,
        }
    }

    /// Radiant power in W (the integral of its spectrum over 360–830 nm), for choosing
    /// lights in proportion to power. Infinite lights use the scene's bounding sphere.
    pub fn power_w(&self, scene_radius_m: f32) -> f64 {
        let _ = scene_radius_m;
        match self {
            Light::Point(l) => l.power_w(),
        }
    }
}
