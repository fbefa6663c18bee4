//! Emitters. Every light implements [`LightSource`] (no default methods, so a new light
//! that misses one does not compile), and [`Light`] forwards each method by an exhaustive
//! `match`. The contract, in pbrt-v4's terms (§12 `Light`, Veach 1997 ch. 10):
//! - towards a reference point: `sample_li` (a direction towards the light with the
//!   radiance arriving and its solid-angle pdf) and `pdf_li` (that pdf for a given
//!   direction, for MIS against BSDF sampling);
//! - from the light: `sample_le` (an emitted ray: a point with its area density `pdf_pos`
//!   and a direction with its solid-angle density `pdf_dir`, for light tracing and BDPT) and
//!   `pdf_le` (both densities for a given emission). Each pdf is the density the sampler
//!   really uses; a Dirac (the position of point, spot and goniometric lights, the
//!   direction of ideal parallel light) has density 1. Infinite lights start their rays on
//!   the disk of the scene's bounding sphere facing the sampled direction (pdf_pos
//!   1/(π r²));
//! - what paths see: `emitted_radiance` at a point of an emitting surface and
//!   `infinite_radiance` along an escaping direction (zero, explicitly, for lights
//!   without a surface or without a part at infinity);
//! - `power_w` in W over 360–830 nm, for light selection: the mean of `sample_le`'s
//!   estimator L |cos θ| / (pdf_pos pdf_dir) integrated over λ; infinite lights count the
//!   flux into the scene's bounding sphere, π r² ∫∫ L dω dλ (π r² ∫ E⊥ dλ for ideal
//!   parallel light), approximately where a light's docs say so (environment map, daylight
//!   skies, a directional light's disk); then `bandwidth` (for the sample planner),
//!   `is_delta` and `is_infinite`.
//!
//! `LightSet` holds them all, picks one per light sample in proportion to its power, and
//! maps hit instances to area lights.
//!
//! Units: radiance W·m⁻²·sr⁻¹·nm⁻¹ at each sampled wavelength. For a delta light
//! (point, spot, ideal directional) `LightSample::radiance` is the incident irradiance per
//! unit projected solid angle in the same sense pbrt-v4 uses: the contribution of a light
//! sample is f · |cos θ| · radiance / pdf, with pdf = 1 for a delta light.
//!
//! One file per emitter: `point`, `spot`, `goniometric` (IES/EULUMDAT), `directional`
//! (ideal or with an angular diameter), `area` (sphere, disk, rectangle, triangle meshes),
//! `environment` (equirectangular map), `sky` (uniform), `daylight` (CIE, Perez, Preetham).
//! `build` turns the scene's light descriptions into them (photometric strengths through
//! `photometry`); docs/lights.md has every formula.

#![deny(clippy::wildcard_enum_match_arm)]

pub mod area;
pub mod area_bandwidth;
mod bandwidth;
mod build;
pub mod daylight;
pub mod directional;
pub mod environment;
pub mod environment_bandwidth;
pub mod goniometric;
mod goniometric_build;
mod light_bounds;
pub mod light_bvh;
mod light_set;
pub mod photometry;
pub mod piecewise_constant;
mod point;
pub mod scene_sphere;
pub mod selection_table;
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
pub use light_set::{LightSet, ShadingSelection, LIGHT_BVH_MIN_BOUNDED, NO_LIGHT};
pub use point::PointLight;
pub use scene_sphere::SceneSphere;
pub use sky::UniformSky;
pub use spot::SpotLight;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::Ray;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

pub use crate::spectrum_cache::{SpectrumCache, TransportWavelengths};

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
    /// Unit normal of the emitting surface at `p_light` (area lights), zero for lights
    /// without a surface: bidirectional methods convert densities at the light point.
    pub n_light: Vec3A,
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

/// An emitted ray (`sample_le`), in the conventions of pbrt-v4's `LightLeSample`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLeSample {
    /// Origin on the light (world, m) and unit direction of emission.
    pub ray: Ray,
    /// Unit normal of the emitting surface at the origin (area lights), zero for point-like
    /// lights; for infinite lights the disk normal (= ray direction).
    pub n: Vec3A,
    /// pbrt-v4 conventions: area lights L_e(p, ω); point/spot/goniometric the intensity
    /// I(ω) (W·sr⁻¹·nm⁻¹); infinite lights (environment, skies, sun with a disk) the
    /// radiance arriving along −ray.direction; ideal directional light the irradiance (as
    /// its sample_li radiance).
    pub radiance: SampledSpectrum,
    /// Area density of the origin, m⁻² (1 for a delta position; 1/(π r²) on the scene disk
    /// for infinite lights).
    pub pdf_pos: f32,
    /// Solid-angle density of the direction, sr⁻¹ (1 for a delta direction: ideal
    /// directional light).
    pub pdf_dir: f32,
}

/// What every emitter answers (see the module docs). No default methods: a new light must
/// state each answer, zero included.
pub trait LightSource {
    /// A direction from `ctx` towards the light, or `None` where the light cannot be
    /// sampled from there.
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample>;

    /// Solid-angle pdf with which `sample_li` from `ctx` produces `wi`; `hit` is where a ray
    /// along `wi` met the light's surface (`None` for lights without one). 0 for delta
    /// lights.
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3A, hit: Option<&LightHit>) -> f32;

    /// Radiance leaving the light's surface at `hit` towards `wo` (zero without a surface).
    fn emitted_radiance(
        &self,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum;

    /// Radiance arriving from infinity along `direction` (unit, towards the light; zero for
    /// lights at finite distance and for ideal parallel light).
    fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum;

    /// An emitted ray from `u_pos` (the origin) and `u_dir` (the direction); `None` only
    /// where a density would be 0 (the radiance may be zero). `scene` is the bounding
    /// sphere whose disk infinite lights start from.
    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample>;

    /// (pdf_pos m⁻², pdf_dir sr⁻¹) with which `sample_le` produces an emission from
    /// `origin` (surface normal `n`, zero if none) along the unit `direction`.
    fn pdf_le(&self, scene: &SceneSphere, origin: Vec3A, n: Vec3A, direction: Vec3A) -> (f32, f32);

    /// Radiant power in W over 360–830 nm; infinite lights through a sphere of radius
    /// `scene_radius_m`.
    fn power_w(&self, scene_radius_m: f32) -> f64;

    /// ν_l for the sample planner (`bandwidth.rs`).
    fn bandwidth(&self) -> Bandwidth;

    /// Dirac in position or direction: BSDF-sampled rays never hit it.
    fn is_delta(&self) -> bool;

    /// At infinity: shadow rays go to infinity and the power uses the scene's bounding
    /// sphere.
    fn is_infinite(&self) -> bool;
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
    /// The spectrum the light emits alike at every point and in every direction, which a
    /// path's `SpectrumCache` can hold: an area light's radiance, a point light's
    /// intensity; `None` for the others (maps and skies vary over directions; spots,
    /// luminaires and distant lights evaluate their own spectra and are not cached).
    pub fn uniform_emission(&self) -> Option<&Spectrum> {
        match self {
            Light::Area(l) => Some(&l.radiance),
            Light::Point(l) => Some(&l.intensity),
            Light::Spot(_)
            | Light::Directional(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Goniometric(_) => None,
        }
    }

    /// `sample_li` with the light's uniform emission (`uniform_emission`) from the path's
    /// `cache` under `cache_key` (`LightSet::emission_key`: lights with equal spectra share
    /// one).
    #[inline]
    pub fn sample_li_cached(
        &self,
        cache_key: u32,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &impl TransportWavelengths,
        cache: &mut SpectrumCache,
    ) -> Option<LightSample> {
        match self {
            Light::Area(l) => {
                l.sample_li_with(ctx, u, || cache.get(cache_key, &l.radiance, wavelengths))
            }
            Light::Point(l) => point::point_emitter_sample(ctx, l.position_m, |_| {
                Some(cache.get(cache_key, &l.intensity, wavelengths))
            }),
            Light::Spot(_)
            | Light::Directional(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Goniometric(_) => self.sample_li(ctx, u, wavelengths.transport()),
        }
    }

    /// `emitted_radiance` with the light's uniform emission from `cache` under `cache_key`
    /// (see `sample_li_cached`).
    #[inline]
    pub fn emitted_radiance_cached(
        &self,
        cache_key: u32,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &impl TransportWavelengths,
        cache: &mut SpectrumCache,
    ) -> SampledSpectrum {
        match self {
            Light::Area(l) => {
                l.emitted_radiance_with(hit, wo, || cache.get(cache_key, &l.radiance, wavelengths))
            }
            Light::Point(_)
            | Light::Spot(_)
            | Light::Directional(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Goniometric(_) => SampledSpectrum::splat(0.0),
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
            Light::Point(l) => l.pdf_li(ctx, wi, hit),
            Light::Spot(l) => l.pdf_li(ctx, wi, hit),
            Light::Directional(l) => l.pdf_li(ctx, wi, hit),
            Light::Area(l) => l.pdf_li(ctx, wi, hit),
            Light::Environment(l) => l.pdf_li(ctx, wi, hit),
            Light::Sky(l) => l.pdf_li(ctx, wi, hit),
            Light::Daylight(l) => l.pdf_li(ctx, wi, hit),
            Light::Goniometric(l) => l.pdf_li(ctx, wi, hit),
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
            Light::Point(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Spot(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Directional(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Area(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Environment(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Sky(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Daylight(l) => l.emitted_radiance(hit, wo, wavelengths),
            Light::Goniometric(l) => l.emitted_radiance(hit, wo, wavelengths),
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
            Light::Point(l) => l.infinite_radiance(direction, wavelengths),
            Light::Spot(l) => l.infinite_radiance(direction, wavelengths),
            Light::Directional(l) => l.infinite_radiance(direction, wavelengths),
            Light::Area(l) => l.infinite_radiance(direction, wavelengths),
            Light::Environment(l) => l.infinite_radiance(direction, wavelengths),
            Light::Sky(l) => l.infinite_radiance(direction, wavelengths),
            Light::Daylight(l) => l.infinite_radiance(direction, wavelengths),
            Light::Goniometric(l) => l.infinite_radiance(direction, wavelengths),
        }
    }

    /// [`Self::infinite_radiance`] along `direction` at each of `wavelength_sets`, added to
    /// the matching entry of `out`: an environment map finds its texels once for all sets
    /// (the predictor's background quadrature).
    pub fn add_infinite_radiance_each(
        &self,
        direction: Vec3A,
        wavelength_sets: &[SampledWavelengths],
        out: &mut [SampledSpectrum],
    ) {
        match self {
            Light::Environment(l) => l.add_radiance_each(direction, wavelength_sets, out),
            Light::Point(_)
            | Light::Spot(_)
            | Light::Directional(_)
            | Light::Area(_)
            | Light::Sky(_)
            | Light::Daylight(_)
            | Light::Goniometric(_) => {
                for (o, wavelengths) in out.iter_mut().zip(wavelength_sets) {
                    *o += self.infinite_radiance(direction, wavelengths);
                }
            }
        }
    }

    /// Samples an emitted ray (light tracing, BDPT): the origin from `u_pos`, the
    /// direction from `u_dir`; `scene` is the bounding sphere infinite lights start from
    /// (`LightSet::scene_sphere`). See `LightLeSample` for what `radiance` means per kind.
    #[inline]
    pub fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        match self {
            Light::Point(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Spot(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Directional(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Area(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Environment(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Sky(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Daylight(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
            Light::Goniometric(l) => l.sample_le(scene, u_pos, u_dir, wavelengths),
        }
    }

    /// Densities with which sample_le would produce an emission from `origin` (normal `n`,
    /// zero if none) along `direction`; for infinite lights `origin` is ignored and pdf_pos
    /// is the scene disk's 1/(π r²). A Dirac component answers 1 without checking that
    /// `origin` (`direction`) is the light's own: callers ask about emissions it made.
    #[inline]
    pub fn pdf_le(
        &self,
        scene: &SceneSphere,
        origin: Vec3A,
        n: Vec3A,
        direction: Vec3A,
    ) -> (f32, f32) {
        match self {
            Light::Point(l) => l.pdf_le(scene, origin, n, direction),
            Light::Spot(l) => l.pdf_le(scene, origin, n, direction),
            Light::Directional(l) => l.pdf_le(scene, origin, n, direction),
            Light::Area(l) => l.pdf_le(scene, origin, n, direction),
            Light::Environment(l) => l.pdf_le(scene, origin, n, direction),
            Light::Sky(l) => l.pdf_le(scene, origin, n, direction),
            Light::Daylight(l) => l.pdf_le(scene, origin, n, direction),
            Light::Goniometric(l) => l.pdf_le(scene, origin, n, direction),
        }
    }

    /// Dirac in position or direction: BSDF-sampled rays never hit it (point, spot,
    /// goniometric, directional with angular diameter 0).
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Point(l) => l.is_delta(),
            Light::Spot(l) => l.is_delta(),
            Light::Directional(l) => l.is_delta(),
            Light::Area(l) => l.is_delta(),
            Light::Environment(l) => l.is_delta(),
            Light::Sky(l) => l.is_delta(),
            Light::Daylight(l) => l.is_delta(),
            Light::Goniometric(l) => l.is_delta(),
        }
    }

    /// Dirac in position: point, spot and goniometric lights (`sample_le`'s pdf_pos is 1).
    #[inline]
    pub fn is_delta_position(&self) -> bool {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Goniometric(_) => true,
            Light::Directional(_)
            | Light::Area(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_) => false,
        }
    }

    /// Dirac in direction: ideal parallel light (`sample_le`'s pdf_dir is 1).
    #[inline]
    pub fn is_delta_direction(&self) -> bool {
        match self {
            Light::Directional(l) => l.is_delta(),
            Light::Point(_)
            | Light::Spot(_)
            | Light::Goniometric(_)
            | Light::Area(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_) => false,
        }
    }

    /// At infinity (environment, sky, directional — ideal or not): shadow rays go to
    /// infinity and the power uses the scene's bounding sphere. Rays that leave the scene
    /// see the non-delta ones (`LightSet::infinite_lights`).
    #[inline]
    pub fn is_infinite(&self) -> bool {
        match self {
            Light::Point(l) => l.is_infinite(),
            Light::Spot(l) => l.is_infinite(),
            Light::Directional(l) => l.is_infinite(),
            Light::Area(l) => l.is_infinite(),
            Light::Environment(l) => l.is_infinite(),
            Light::Sky(l) => l.is_infinite(),
            Light::Daylight(l) => l.is_infinite(),
            Light::Goniometric(l) => l.is_infinite(),
        }
    }

    /// Radiant power in W (the integral of its spectrum over 360–830 nm), for choosing
    /// lights in proportion to power. Infinite lights use the scene's bounding sphere.
    pub fn power_w(&self, scene_radius_m: f32) -> f64 {
        match self {
            Light::Point(l) => l.power_w(scene_radius_m),
            Light::Spot(l) => l.power_w(scene_radius_m),
            Light::Directional(l) => l.power_w(scene_radius_m),
            Light::Area(l) => l.power_w(scene_radius_m),
            Light::Environment(l) => l.power_w(scene_radius_m),
            Light::Sky(l) => l.power_w(scene_radius_m),
            Light::Daylight(l) => l.power_w(scene_radius_m),
            Light::Goniometric(l) => l.power_w(scene_radius_m),
        }
    }

    /// ν_l of the light for the sample planner (Bagher et al. 2013; choices in
    /// `bandwidth.rs`).
    pub fn bandwidth(&self) -> Bandwidth {
        match self {
            Light::Point(l) => l.bandwidth(),
            Light::Spot(l) => l.bandwidth(),
            Light::Directional(l) => l.bandwidth(),
            Light::Area(l) => l.bandwidth(),
            Light::Environment(l) => l.bandwidth(),
            Light::Sky(l) => l.bandwidth(),
            Light::Daylight(l) => l.bandwidth(),
            Light::Goniometric(l) => l.bandwidth(),
        }
    }
}
