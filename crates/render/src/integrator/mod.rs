//! Integrators: the rendering methods, each an `Estimator` (`estimator`) that the driver
//! (`driver`) runs over the film with no case per method. `Integrator` is the closed set
//! of methods a scene or `--method` can name, dispatched by exhaustive `match`:
//!
//! - `path`: unidirectional path tracing with NEE and MIS (`path`, `path_estimator`, and
//!   the packet tracer `packet` for the scenes its allow-list serves);
//! - `light`: light tracing, every light-path vertex connected to the camera
//!   (`light_tracer`);
//! - `bdpt`: bidirectional path tracing with MIS over all strategies (`bdpt`);
//! - `photon`, `photon_progressive`: caustic and volume photon maps next to `path`'s
//!   estimators (`photon`), the only methods whose passes keep state (their photons), so
//!   the driver runs each method through `Integrator::estimator`;
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
pub mod photon;
pub mod radiosity;
pub(crate) mod scatter_vertex;

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
pub use path::{mis_weight, FirstHit, PathCounters, PathResult, PathTracer, SolutionGather};
pub use path_state::{PathOrigin, PathState, MAX_NULL_EVENTS};
pub use photon::{PhotonEstimator, PhotonMapper, RadiusRule};
pub use radiosity::{RadiosityEstimator, RadiosityMethod};
pub use scatter_vertex::{MediumVertex, ScatterEval, ScatterSample, ScatterVertex, SurfaceVertex};

use glam::DVec3;
use prism_geometry::{Ray, SurfaceInteraction};

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
    /// `photon` or `photon_progressive` (`PhotonMapper::is_progressive`).
    Photon(PhotonMapper),
    /// Hierarchical radiosity with a final gather.
    Radiosity(RadiosityMethod),
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
            prism_scene::Integrator::Photon {
                max_depth,
                rr_depth,
                photons_per_pass,
                radius,
                ..
            } => Integrator::Photon(PhotonMapper {
                max_depth: max_depth.max(1),
                rr_depth,
                photons_per_pass,
                radius: match radius {
                    prism_scene::PhotonRadius::Fixed(r) => RadiusRule::Fixed(r.map(|r| r as f32)),
                    prism_scene::PhotonRadius::Nearest(k) => RadiusRule::Nearest(k),
                },
                memory_limit_bytes: None,
            }),
            prism_scene::Integrator::PhotonProgressive {
                max_depth,
                rr_depth,
                photons_per_pass,
                initial_radius_m,
                alpha,
                ..
            } => Integrator::Photon(PhotonMapper {
                max_depth: max_depth.max(1),
                rr_depth,
                photons_per_pass,
                radius: RadiusRule::Progressive {
                    initial_m: initial_radius_m.map(|r| r as f32),
                    alpha: alpha as f32,
                },
                memory_limit_bytes: None,
            }),
            prism_scene::Integrator::Radiosity {
                error_bound_rel,
                iterations,
                gather_epsilon,
                ..
            } => Integrator::Radiosity(RadiosityMethod {
                error_bound_rel: error_bound_rel as f32,
                iterations,
                gather_epsilon: gather_epsilon as f32,
                memory_limit_bytes: None,
                bands: radiosity::patches::SolutionBands::DEFAULT,
            }),
        })
    }

    /// The estimator that renders this method's passes, with the state they keep (a photon
    /// integrator's photons): what the driver runs.
    pub fn estimator(&self) -> Box<dyn Estimator> {
        match self {
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => Box::new(diagnostic::Diagnostic(*self)),
            Integrator::Path(p) => Box::new(*p),
            Integrator::Light(l) => Box::new(*l),
            Integrator::Bdpt(b) => Box::new(*b),
            Integrator::Photon(m) => Box::new(PhotonEstimator::new(*m)),
            Integrator::Radiosity(r) => Box::new(RadiosityEstimator::new(*r)),
        }
    }

    /// Sets the most bytes a method's per-pass storage may take (the photon integrators'
    /// photons; `None`: their default, 75 % of the machine's memory). Other methods keep
    /// no per-pass storage worth a limit.
    pub fn set_memory_limit_bytes(&mut self, limit: Option<u64>) {
        match self {
            Integrator::Photon(m) => m.memory_limit_bytes = limit,
            Integrator::Radiosity(r) => r.memory_limit_bytes = limit,
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_)
            | Integrator::Path(_)
            | Integrator::Light(_)
            | Integrator::Bdpt(_) => {}
        }
    }

    /// Carries `radiosity`'s solution in the render's spectral bins (`--spectral-bins`)
    /// instead of its default bands; other methods have no bands.
    pub fn set_spectral_bins(&mut self, bins: Option<crate::film::spectral_bins::SpectralBins>) {
        match self {
            Integrator::Radiosity(r) => {
                r.bands = bins.map_or(
                    radiosity::patches::SolutionBands::DEFAULT,
                    radiosity::patches::SolutionBands::of_spectral_bins,
                )
            }
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_)
            | Integrator::Path(_)
            | Integrator::Light(_)
            | Integrator::Bdpt(_)
            | Integrator::Photon(_) => {}
        }
    }

    /// Err with the reason when this method cannot render `scene` at all (checked when a
    /// scene is built and again by `prepare`): the photon integrators' refusals (no lights,
    /// re-radiation, emissive media) and their memory estimate.
    pub fn refuse_scene(
        &self,
        scene: &RenderScene,
    ) -> Result<(), crate::scene_build::SceneBuildError> {
        match self {
            Integrator::Photon(m) => match photon::refusal(m, scene) {
                Some(reason) => Err(reason),
                None => m.plan(scene).map(|_| ()),
            },
            Integrator::Radiosity(r) => radiosity::patches::scene_patches(scene, r.bands)
                .map(|_| ())
                .map_err(|m| {
                    crate::scene_build::SceneBuildError::new(&scene.file, "integrator", m)
                }),
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_)
            | Integrator::Path(_)
            | Integrator::Light(_)
            | Integrator::Bdpt(_) => Ok(()),
        }
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
            Integrator::Photon(m) => PathTracer {
                max_depth: m.max_depth,
                rr_depth: m.rr_depth,
                ..PathTracer::default()
            },
            Integrator::Radiosity(_) => PathTracer::default(),
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => PathTracer::default(),
        }
    }

    /// True for the methods that estimate radiance (the others are diagnostics).
    pub fn is_spectral(&self) -> bool {
        match self {
            Integrator::Path(_)
            | Integrator::Light(_)
            | Integrator::Bdpt(_)
            | Integrator::Photon(_)
            | Integrator::Radiosity(_) => true,
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
            Integrator::Light(_) | Integrator::Bdpt(_) | Integrator::Radiosity(_) => {
                Err(media_refusal(self.name(), names))
            }
            Integrator::Path(_)
            | Integrator::Photon(_)
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
            Integrator::Photon(m) => m.name(),
            Integrator::Radiosity(_) => "radiosity",
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
            Integrator::Path(_)
            | Integrator::Light(_)
            | Integrator::Bdpt(_)
            | Integrator::Photon(_)
            | Integrator::Radiosity(_) => DVec3::ZERO,
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
