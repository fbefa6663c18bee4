//! Integrators: the rendering methods, each an `Estimator` (`estimator`) that the driver
//! (`driver`) runs over the film with no case per method. `Integrator` is the closed set
//! of methods a scene or `--method` can name, dispatched by exhaustive `match`:
//!
//! - `path`: unidirectional path tracing with NEE and MIS (`path`, `path_estimator`, and
//!   the packet tracer `packet` for the scenes its allow-list serves);
//! - `light`: light tracing, every light-path vertex connected to the camera
//!   (`light_tracer`);
//! - `bdpt`: bidirectional path tracing with MIS over all strategies (`bdpt`);
//! - the diagnostic ones — `depth`, `normal`, `albedo`, `ambient_occlusion` — each in its
//!   own file, sharing one tile loop (`diagnostic`).
//!
//! The transport core they share: `PathState` (throughput, MIS state, depth, the
//! sample-dimension cursor), `ScatterVertex` (a surface or a medium point),
//! `LaneWavelengths` (sensor vs transport wavelengths), the dimension layout
//! (`dimensions`) and the camera sample's start (`camera_sample`).
//!
//! Diagnostic outputs are known exactly per sample (a flat spectrum or an RGB value), so
//! they are written to the film as XYZ (`FilmTile::add_sample_xyz`) without sampling
//! wavelengths: a flat spectrum of value v is v · `flat_spectrum_xyz()` (Y = v exactly),
//! an RGB colour goes through `rec709_to_xyz` and comes back out of the film unchanged.

#![deny(clippy::wildcard_enum_match_arm)]

mod albedo;
mod ambient_occlusion;
pub mod bdpt;
mod camera_sample;
mod depth;
mod diagnostic;
pub mod dimensions;
mod driver;
mod estimator;
mod fluorescent_vertex;
mod lane_wavelengths;
mod light_tracer;
mod medium_transport;
mod normal;
pub mod packet;
mod path;
mod path_estimator;
mod path_state;
mod scatter_vertex;

pub use ambient_occlusion::AmbientOcclusion;
pub use bdpt::{Bdpt, BdptStrategy};
pub use driver::{
    film_for, render, render_pass, render_pass_controlled, render_pass_with, render_plan,
    total_samples, PassControl, PassOutcome, RenderError, RenderSettings, RenderStats,
    DEFAULT_TILE_SIZE_PX,
};
pub use estimator::{Estimator, Pass, TileWork};
pub use lane_wavelengths::LaneWavelengths;
pub use light_tracer::LightTracer;
pub use path::{mis_weight, FirstHit, PathCounters, PathResult, PathTracer};
pub use path_state::{PathOrigin, PathState, MAX_NULL_EVENTS};
pub use scatter_vertex::{MediumVertex, ScatterEval, ScatterSample, ScatterVertex, SurfaceVertex};

use glam::DVec3;
use prism_geometry::{Ray, SurfaceInteraction};

use crate::film::{FilmTile, LightSplats};
use crate::sampler::SampleStream;
use crate::scene_build::RenderScene;

/// A per-pixel estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Distance from the camera ray's origin to the first hit, metres, as a flat spectrum.
    Depth,
    /// World-space shading normal n as RGB n·½ + ½.
    Normal,
    /// First-hit material albedo (linear Rec.709).
    Albedo,
    AmbientOcclusion(AmbientOcclusion),
    /// The spectral path tracer (NEE + MIS).
    Path(PathTracer),
    /// Light tracing.
    Light(LightTracer),
    /// Bidirectional path tracing.
    Bdpt(Bdpt),
}

impl Integrator {
    /// The runtime integrator of a scene's `integrator` section; an error for integrators
    /// that this build does not have yet.
    pub fn from_description(description: &prism_scene::Integrator) -> Result<Self, String> {
        Ok(match *description {
            prism_scene::Integrator::Depth => Integrator::Depth,
            prism_scene::Integrator::Normal => Integrator::Normal,
            prism_scene::Integrator::Albedo => Integrator::Albedo,
            prism_scene::Integrator::AmbientOcclusion {
                max_distance_m,
                samples,
            } => Integrator::AmbientOcclusion(AmbientOcclusion::new(
                max_distance_m.map_or(f32::INFINITY, |d| d as f32),
                samples,
            )?),
            prism_scene::Integrator::Path {
                max_depth,
                mis,
                rr_depth,
                fluorescence_lanes,
                spectral_mis,
                ..
            } => Integrator::Path(PathTracer {
                max_depth: max_depth.max(1),
                rr_depth,
                mis,
                fluorescence_lanes,
                spectral_mis,
            }),
            prism_scene::Integrator::Light {
                max_depth,
                rr_depth,
                ..
            } => Integrator::Light(LightTracer {
                max_depth: max_depth.max(1),
                rr_depth,
            }),
            prism_scene::Integrator::Bdpt {
                max_depth,
                mis,
                rr_depth,
                ..
            } => Integrator::Bdpt(Bdpt {
                max_depth: max_depth.max(1),
                rr_depth,
                mis,
                strategy: None,
            }),
        })
    }

    /// The path tracer that measures illuminance sensors for this method: the method's
    /// own depth, roulette and MIS settings where it has them (`path`, `light`, `bdpt`
    /// integrate the same radiance; sensors are points, not pixels, so they are measured
    /// by path tracing), the default path tracer for the diagnostic integrators.
    pub fn sensor_tracer(&self) -> PathTracer {
        match self {
            Integrator::Path(p) => *p,
            Integrator::Light(l) => PathTracer {
                max_depth: l.max_depth,
                rr_depth: l.rr_depth,
                mis: prism_scene::MisHeuristic::Power,
                fluorescence_lanes: prism_scene::FluorescenceLanes::All,
                spectral_mis: true,
            },
            Integrator::Bdpt(b) => b.path_tracer(),
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => PathTracer::default(),
        }
    }

    /// True for the methods that estimate radiance (the others are diagnostics).
    pub fn is_spectral(&self) -> bool {
        match self {
            Integrator::Path(_) | Integrator::Light(_) | Integrator::Bdpt(_) => true,
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => false,
        }
    }

    /// Err with the reason when this method cannot render a scene with the media `names`
    /// (the light-path methods sample no media yet: rendering them as vacuum would be
    /// silently wrong). Diagnostic integrators look at surfaces only, so media do not
    /// concern them.
    pub fn refuse_media(&self, names: &[String]) -> Result<(), String> {
        match self {
            Integrator::Light(_) | Integrator::Bdpt(_) => Err(media_refusal(self.name(), names)),
            Integrator::Path(_)
            | Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => Ok(()),
        }
    }

    /// The name used in scene files and statistics.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Depth => "depth",
            Integrator::Normal => "normal",
            Integrator::Albedo => "albedo",
            Integrator::AmbientOcclusion(_) => "ambient_occlusion",
            Integrator::Path(_) => "path",
            Integrator::Light(_) => "light",
            Integrator::Bdpt(_) => "bdpt",
        }
    }

    /// The XYZ (output normalisation) of a camera ray `ray` whose first hit is `hit`.
    /// `rays` counts the extra rays traced.
    #[inline]
    pub fn shade(
        &self,
        scene: &RenderScene,
        ray: &Ray,
        hit: &SurfaceInteraction,
        stream: &mut SampleStream,
        rays: &mut u64,
    ) -> DVec3 {
        match self {
            Integrator::Depth => depth::shade(hit),
            Integrator::Normal => normal::shade(hit),
            Integrator::Albedo => albedo::shade(scene, hit),
            Integrator::AmbientOcclusion(ao) => ao.shade(&scene.geometry, ray, hit, stream, rays),
            // Spectral: their own estimators.
            Integrator::Path(_) | Integrator::Light(_) | Integrator::Bdpt(_) => DVec3::ZERO,
        }
    }
}

impl Estimator for Integrator {
    fn name(&self) -> &'static str {
        Integrator::name(self)
    }

    fn prepare(&mut self, scene: &RenderScene, pass: &Pass) -> Result<(), String> {
        match self {
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => Ok(()),
            Integrator::Path(p) => p.prepare(scene, pass),
            Integrator::Light(l) => l.prepare(scene, pass),
            Integrator::Bdpt(b) => b.prepare(scene, pass),
        }
    }

    fn splats_light_paths(&self) -> bool {
        match self {
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => false,
            Integrator::Path(p) => p.splats_light_paths(),
            Integrator::Light(l) => l.splats_light_paths(),
            Integrator::Bdpt(b) => b.splats_light_paths(),
        }
    }

    fn render_tile(
        &self,
        scene: &RenderScene,
        work: &TileWork,
        tile: &mut FilmTile,
        splats: &mut LightSplats,
    ) -> RenderStats {
        match self {
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => diagnostic::render_tile(self, scene, work, tile),
            Integrator::Path(p) => p.render_tile(scene, work, tile, splats),
            Integrator::Light(l) => l.render_tile(scene, work, tile, splats),
            Integrator::Bdpt(b) => b.render_tile(scene, work, tile, splats),
        }
    }
}

/// Why light-path method `method` refuses a scene with the media `names`.
pub(crate) fn media_refusal(method: &str, names: &[String]) -> String {
    let listed: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    format!(
        "`{method}` samples no participating media yet (the scene has {}): use `path`",
        listed.join(", ")
    )
}
