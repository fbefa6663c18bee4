//! The `radiosity` method: a hierarchical radiosity solution with clustering
//! (prism-radiosity), computed once in `prepare`, then a final gather per camera sample
//! (Mostefaoui et al. §5 without the interpolation tree yet): emission and direct light as
//! `path` computes them at the first hit (light sampling and BSDF sampling with MIS), and
//! the light reflected more than once from the solution at the BSDF-sampled ray's hit.

mod direct;
pub mod gather;
pub mod meshed;
pub mod patches;
pub mod solution_io;
pub mod tiled;

pub use self::gather::SolvedScene;

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3A;
use prism_geometry::Ray;
use prism_radiosity::{Radiosity, RadiositySettings, Visibility};

pub use self::direct::PointLikeAndSkyLights;
use self::patches::{scene_patches, PatchMap, SolutionBands};
use super::driver::RenderStats;
use super::estimator::{Estimator, Pass, TileWork};
use super::path_estimator::scalar_tile;
use super::{PathCounters, PathTracer};
use crate::film::{FilmTile, LightSplats};
use crate::scene_build::RenderScene;

/// The interpolated gather's bound when the scene gives none (the default).
pub const DEFAULT_GATHER_EPSILON: f32 = 0.1;

/// The `radiosity` integrator's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiosityMethod {
    pub error_bound_rel: f32,
    pub iterations: u32,
    /// The interpolated gather's bound ε (paper §5); 0 traces every gather ray.
    pub gather_epsilon: f32,
    /// `--max-memory` for the hierarchy.
    pub memory_limit_bytes: Option<u64>,
    /// The wavelength bands of the solution: the default 16, or the render's spectral
    /// bins.
    pub bands: SolutionBands,
}

/// The estimator: the solution, built by the first `prepare`.
pub struct RadiosityEstimator {
    method: RadiosityMethod,
    solved: Option<Arc<SolvedScene>>,
}

impl RadiosityEstimator {
    pub fn new(method: RadiosityMethod) -> Self {
        Self {
            method,
            solved: None,
        }
    }
}

/// The scene's own ray tracer as the solution's visibility oracle.
pub(crate) struct SceneVisibility<'a>(pub &'a RenderScene, pub &'a PatchMap);

impl Visibility for SceneVisibility<'_> {
    /// Points of tiled carriers take their rays from above their tile's slab, points of
    /// meshed spheres from the sphere (`PatchMap::lift`).
    fn visible(&self, from: Vec3A, n_from: Vec3A, to: Vec3A, n_to: Vec3A) -> bool {
        let scale = |p: Vec3A| 1e-4 * (1.0 + p.abs().max_element());
        let a = self
            .1
            .lift(from, n_from)
            .unwrap_or(from + n_from * scale(from));
        let b = self.1.lift(to, n_to).unwrap_or(to + n_to * scale(to));
        !self.0.geometry.occluded(&Ray::spawn_to(a, b))
    }

    /// Covered when the ray along the normal meets a surface from behind first (the point
    /// is inside a closed mesh, e.g. under a box standing on it). A tiled carrier's point
    /// stands for the macro-surface and is never covered by its own tile.
    fn covered(&self, p: Vec3A, n: Vec3A) -> bool {
        if self.1.carriers.lift(p, n).is_some() {
            return false;
        }
        let p = self
            .1
            .spheres
            .iter()
            .find_map(|s| s.lift(p, n))
            .unwrap_or(p);
        let scale = 1e-4 * (1.0 + p.abs().max_element());
        let ray = Ray::spawn(p + n * scale, n);
        self.0.geometry.intersect(&ray).is_some_and(|hit| {
            let si = self.0.geometry.interaction(&ray, &hit);
            si.n_geometric.dot(n) > 0.0
        })
    }

    /// A tiled carrier's patches (one per side) are seen through by its tile's τ.
    fn transparency(&self, patch: u32, towards: Vec3A) -> f32 {
        self.1
            .carrier_of_patch(patch)
            .map_or(0.0, |c| self.1.carriers.transparency_towards(c, towards))
    }

    fn any_see_through(&self) -> bool {
        !self.1.carriers.0.is_empty()
    }
}

/// The solution for `scene`, with one line of statistics per iteration.
pub fn solve(
    scene: &RenderScene,
    method: &RadiosityMethod,
) -> Result<(SolvedScene, Vec<String>), String> {
    let (patches, map) = scene_patches(scene, method.bands)?;
    let settings = RadiositySettings {
        error_bound_rel: method.error_bound_rel,
        memory_limit_bytes: method.memory_limit_bytes,
        ..RadiositySettings::default()
    };
    let mut solution =
        Radiosity::new(&patches, method.bands.count, settings).map_err(|e| e.to_string())?;
    let visibility = SceneVisibility(scene, &map);
    let direct_lights = PointLikeAndSkyLights::new(scene, &map);
    let pyramids = tiled::TilePyramids::new(scene, &map, method.memory_limit_bytes);
    let mut lines = Vec::new();
    for i in 1..=method.iterations {
        let s = solution
            .iterate_with(&visibility, &direct_lights, &pyramids)
            .map_err(|e| e.to_string())?;
        lines.extend(pyramids.take_lines());
        lines.push(format!(
            "radiosity: iteration {i}: {} patches, {} elements, {} links ({} from clusters, {} \
             through their Z-buffers), {:.1} MiB, refine {:.2} s, solve {:.2} s ({} sweeps)",
            s.patches,
            s.elements,
            s.links,
            s.cluster_links,
            s.z_buffer_links,
            s.memory_bytes as f64 / 1048576.0,
            s.refine_s,
            s.solve_s,
            s.sweeps
        ));
    }
    Ok((
        SolvedScene::new(solution, map, method.gather_epsilon),
        lines,
    ))
}

/// `solve` with its statistics and time on stderr (what `prism render` prints).
pub fn solve_and_report(
    scene: &RenderScene,
    method: &RadiosityMethod,
) -> Result<SolvedScene, String> {
    let start = Instant::now();
    let (solved, lines) = solve(scene, method)?;
    for line in lines {
        eprintln!("{line}");
    }
    let bands = method.bands;
    eprintln!(
        "radiosity: solution in {:.2} s ({} bands of {:.3} nm from {} nm)",
        start.elapsed().as_secs_f64(),
        bands.count,
        bands.width_nm,
        bands.first_nm
    );
    Ok(solved)
}

impl Estimator for RadiosityEstimator {
    fn name(&self) -> &'static str {
        "radiosity"
    }

    fn prepare(&mut self, scene: &RenderScene, _pass: &Pass) -> Result<(), String> {
        if self.solved.is_some() {
            return Ok(());
        }
        // The scene's own solution when this is the scene's method (shared with its
        // sensors), else one of its own (`prism converge` with another scene method).
        self.solved = Some(match scene.radiosity_solution() {
            Some(solution) if scene.integrator == super::Integrator::Radiosity(self.method) => {
                solution?
            }
            Some(_) | None => Arc::new(solve_and_report(scene, &self.method)?),
        });
        Ok(())
    }

    fn splats_light_paths(&self) -> bool {
        false
    }

    fn sample_indices_per_prepare(&self) -> Option<u32> {
        None
    }

    fn render_tile(
        &self,
        scene: &RenderScene,
        work: &TileWork,
        tile: &mut FilmTile,
        _splats: &mut LightSplats,
    ) -> RenderStats {
        let mut counters = PathCounters::default();
        let mut stats = RenderStats::default();
        let Some(solved) = self.solved.as_deref() else {
            return stats;
        };
        // One bounce (direct light with MIS), then the solution.
        let tracer = PathTracer {
            max_depth: 1,
            rr_depth: u32::MAX,
            ..PathTracer::default()
        };
        let settings = work.pass.settings;
        scalar_tile(scene, work, tile, &mut stats, |cs, pixel, wavelengths| {
            scene
                .camera
                .generate_ray_only(cs.film_point, cs.lens)
                .map(|ray| {
                    tracer.radiance_gathered(
                        scene,
                        &ray,
                        wavelengths,
                        &mut cs.stream,
                        scene.light_samples_per_hit(work.light_samples(pixel)),
                        settings.illumination_aov,
                        &mut counters,
                        solved,
                    )
                })
        });
        stats.add_path_counters(&counters);
        stats
    }
}
