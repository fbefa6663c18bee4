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
//!
//! One file per emitter: `point`, `spot`, `directional` (ideal or with an angular
//! diameter), `area` (sphere, disk, rectangle, triangle meshes), `environment`
//! (equirectangular map), `sky` (uniform). `build` turns the scene's light descriptions
//! into them (photometric strengths through `photometry`); docs/lights.md has every
//! formula.

pub mod area;
mod build;
pub mod daylight;
pub mod directional;
pub mod environment;
pub mod goniometric;
mod goniometric_build;
mod light_set;
pub mod photometry;
pub mod piecewise_constant;
mod point;
pub mod scene_sphere;
pub mod sky;
pub mod spot;
#[cfg(test)]
mod test_support;
pub mod warp;

pub use area::{AreaLight, AreaShape};
pub use daylight::sky_light::DaylightSkyLight;
pub use directional::DirectionalLight;
pub use environment::EnvironmentLight;
pub use goniometric::GoniometricLight;
pub use light_set::{LightSet, NO_LIGHT};
pub use point::PointLight;
pub use scene_sphere::SceneSphere;
pub use sky::UniformSky;
pub use spot::SpotLight;

use glam::{Vec2, Vec3A};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

pub use crate::spectrum_cache::SpectrumCache;

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
    Spot(SpotLight),
    Directional(DirectionalLight),
    Area(AreaLight),
    Environment(Box<EnvironmentLight>),
    Sky(UniformSky),
    /// CIE, Perez or Preetham sky (its sun is a separate `Directional`).
    Daylight(Box<DaylightSkyLight>),
    /// A point luminaire with an IES/EULUMDAT intensity distribution.
    Goniometric(Box<GoniometricLight>),
}

impl Light {
    /// `sample_li` for light number `index` of the scene's `LightSet`, with its spectrum
    /// from the path's `cache` (keyed by light index) where the radiance is uniform (area
    /// lights).
    #[inline]
    pub fn sample_li_cached(
        &self,
        index: u32,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
        cache: &mut SpectrumCache,
    ) -> Option<LightSample> {
        match self {
            Light::Area(l) => {
                l.sample_li_with(ctx, u, || cache.get(index, &l.radiance, wavelengths))
            }
            _ => self.sample_li(ctx, u, wavelengths),
        }
    }

    /// `emitted_radiance` for light number `index`, with its spectrum from `cache` (see
    /// `sample_li_cached`).
    #[inline]
    pub fn emitted_radiance_cached(
        &self,
        index: u32,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
        cache: &mut SpectrumCache,
    ) -> SampledSpectrum {
        match self {
            Light::Area(l) => {
                l.emitted_radiance_with(hit, wo, || cache.get(index, &l.radiance, wavelengths))
            }
            _ => SampledSpectrum::splat(0.0),
        }
    }

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
            Light::Spot(l) => l.sample_li(ctx, u, wavelengths),
            Light::Directional(l) => l.sample_li(ctx, u, wavelengths),
            Light::Area(l) => l.sample_li(ctx, u, wavelengths),
            Light::Environment(l) => l.sample_li(ctx, u, wavelengths),
            Light::Sky(l) => l.sample_li(ctx, u, wavelengths),
            Light::Daylight(l) => l.sample_li(ctx, u, wavelengths),
            Light::Goniometric(l) => l.sample_li(ctx, u, wavelengths),
        }
    }

    /// Solid-angle pdf with which `sample_li` from `ctx` produces `wi`; `hit` is where a
    /// ray along `wi` met the light's surface (`None` for infinite lights). 0 for delta
    /// lights, for an area light without `hit`, and for directions `sample_li` never
    /// returns (the back of a one-sided area light, outside the sun's disk).
    #[inline]
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3A, hit: Option<&LightHit>) -> f32 {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Goniometric(_) => 0.0,
            Light::Directional(l) => l.pdf_li(wi),
            Light::Area(l) => l.pdf_li(ctx, wi, hit),
            Light::Environment(l) => l.pdf_li(wi),
            Light::Sky(l) => l.pdf_li(ctx, wi),
            Light::Daylight(l) => l.pdf_li(wi),
        }
    }

    /// Radiance leaving an emitting surface at `hit` in direction `wo` (unit, away from
    /// the surface, towards the previous path vertex). Zero for lights without a surface
    /// and on the back of a one-sided area light.
    #[inline]
    pub fn emitted_radiance(
        &self,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            Light::Area(l) => l.emitted_radiance(hit, wo, wavelengths),
            _ => SampledSpectrum::splat(0.0),
        }
    }

    /// Radiance arriving from an infinitely distant light along the ray direction
    /// `direction` (unit, pointing away from the scene, towards the light). Zero for
    /// lights at finite distance and for ideal directional light.
    #[inline]
    pub fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            Light::Directional(l) => l.infinite_radiance(direction, wavelengths),
            Light::Environment(l) => l.infinite_radiance(direction, wavelengths),
            Light::Sky(l) => l.infinite_radiance(wavelengths),
            Light::Daylight(l) => l.radiance(direction, wavelengths),
            _ => SampledSpectrum::splat(0.0),
        }
    }

    /// Dirac in position or direction: BSDF-sampled rays never hit it (point, spot,
    /// directional with angular diameter 0).
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Goniometric(_) => true,
            Light::Directional(l) => l.is_delta(),
            Light::Area(_) | Light::Environment(_) | Light::Sky(_) | Light::Daylight(_) => false,
        }
    }

    /// At infinity (environment, sky, directional — ideal or not): shadow rays go to
    /// infinity and the power uses the scene's bounding sphere. Rays that leave the scene
    /// see the non-delta ones (`LightSet::infinite_lights`).
    #[inline]
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Directional(_) | Light::Environment(_) | Light::Sky(_) | Light::Daylight(_)
        )
    }

    /// Radiant power in W (the integral of its spectrum over 360–830 nm), for choosing
    /// lights in proportion to power. Infinite lights use the scene's bounding sphere.
    pub fn power_w(&self, scene_radius_m: f32) -> f64 {
        match self {
            Light::Point(l) => l.power_w(),
            Light::Spot(l) => l.power_w(),
            Light::Directional(l) => l.power_w(scene_radius_m),
            Light::Area(l) => l.power_w(),
            Light::Environment(l) => l.power_w(scene_radius_m),
            Light::Sky(l) => l.power_w(scene_radius_m),
            Light::Daylight(l) => l.power_w(scene_radius_m),
            Light::Goniometric(l) => l.power_w(),
        }
    }
}
