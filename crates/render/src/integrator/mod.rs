//! Integrators: what a camera sample computes. This slice has the diagnostic ones —
//! `depth`, `normal`, `albedo` and `ambient_occlusion` — each in its own file; the path
//! tracer follows. `render` (in `driver`) runs any of them over the film tile by tile.
//!
//! Diagnostic outputs are known exactly per sample (a flat spectrum or an RGB value), so
//! they are written to the film as XYZ (`FilmTile::add_sample_xyz`) without sampling
//! wavelengths: a flat spectrum of value v is v · `flat_spectrum_xyz()` (Y = v exactly),
//! an RGB colour goes through `rec709_to_xyz` and comes back out of the film unchanged.

mod albedo;
mod ambient_occlusion;
mod depth;
mod driver;
mod normal;
pub mod packet;
mod path;

pub use ambient_occlusion::AmbientOcclusion;
pub use driver::{
    film_for, render, render_pass, render_plan, total_samples, RenderSettings, RenderStats,
    DEFAULT_TILE_SIZE_PX,
};
pub use path::{mis_weight, FirstHit, PathCounters, PathOrigin, PathResult, PathTracer};

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
                ..
            } => Integrator::Path(PathTracer {
                max_depth: max_depth.max(1),
                rr_depth,
                mis,
            }),
        })
    }

    /// The name used in scene files and statistics.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Depth => "depth",
            Integrator::Normal => "normal",
            Integrator::Albedo => "albedo",
            Integrator::AmbientOcclusion(_) => "ambient_occlusion",
            Integrator::Path(_) => "path",
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
            // Spectral: the driver calls `PathTracer::radiance` directly.
            Integrator::Path(_) => DVec3::ZERO,
        }
    }
}
