//! `bdpt`: bidirectional path tracing (Veach 1997 ch. 10; Lafortune & Willems 1993), with
//! pbrt-v3 §16.3's structure: per camera sample one camera subpath and one light subpath
//! (`walk`), every strategy (s, t) that makes a path of at most `max_depth` scattering
//! events (`connect`), each weighted by multiple importance sampling over all strategies
//! of its length. Strategies with t = 1 (a light-path vertex connected to the lens) land
//! anywhere on the film: they are splatted (`LightSplats`); the others belong to the camera
//! sample's pixel.
//!
//! Spectral: the four hero wavelengths travel through both subpaths; a dispersive vertex on
//! either keeps only the hero for the whole sample (pbrt-v4 does the same).
//!
//! Sample dimensions (`dimensions`): the camera sample's 5, one vertex block per camera
//! vertex (its light-choice and light-position variates serve the s = 1 connection there),
//! then from `bdpt_light_subpath_first_dimension` the light subpath's start block and one
//! vertex block per light vertex (its light-position pair is the lens point of the t = 1
//! connection there).

mod connect;
pub mod vertex;
pub(crate) mod walk;

pub(crate) use connect::connect as connect_strategy;
pub use connect::{Connection, ConnectionVariates};

use glam::{UVec2, Vec3A};
use prism_scene::MisHeuristic;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::camera_sample::CameraSample;
use super::dimensions::{
    bdpt_light_subpath_first_dimension, LightStartDimensions, VertexDimensions,
    CAMERA_SAMPLE_DIMENSIONS,
};
use super::driver::RenderStats;
use super::estimator::{Estimator, Pass, TileWork};
use super::path_state::PathState;
use super::{PathCounters, PathTracer};
use crate::film::{FilmTile, LightSplats, SurfaceAov};
use crate::scene_build::RenderScene;
use vertex::{Subpath, VertexKind};

/// One strategy's image, for debugging (`--bdpt-strategy s,t[,unweighted]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BdptStrategy {
    /// Light subpath vertices.
    pub s: u32,
    /// Camera subpath vertices (≥ 1).
    pub t: u32,
    /// Write the contribution without its MIS weight (weight 1).
    pub unweighted: bool,
}

impl BdptStrategy {
    /// Parses `s,t` or `s,t,unweighted`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "--bdpt-strategy `{text}`: expected `s,t` or `s,t,unweighted` with s ≥ 0 \
                 light-subpath vertices and t ≥ 1 camera-subpath vertices (e.g. `0,2`: \
                 camera paths that hit a light; `2,1`: light paths connected to the camera)"
            )
        };
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let (s, t, unweighted) = match parts.as_slice() {
            [s, t] => (s, t, false),
            [s, t, "unweighted"] => (s, t, true),
            _ => return Err(bad()),
        };
        let s: u32 = s.parse().map_err(|_| bad())?;
        let t: u32 = t.parse().map_err(|_| bad())?;
        if t == 0 || s + t < 2 {
            return Err(bad());
        }
        if s == 1 && t == 1 {
            return Err(format!(
                "--bdpt-strategy `{text}`: (1, 1), a light seen directly through light \
                 tracing, is not one of bdpt's strategies (that path is counted by (0, 2))"
            ));
        }
        Ok(Self { s, t, unweighted })
    }

    /// Scattering events of the paths this strategy makes: s + t − 2.
    pub fn depth(&self) -> u32 {
        self.s + self.t - 2
    }
}

/// Parameters of bidirectional path tracing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bdpt {
    /// Most scattering events of a full path (≥ 1; `path`'s meaning).
    pub max_depth: u32,
    /// Russian roulette on each subpath after this many of its vertices.
    pub rr_depth: u32,
    /// Heuristic of the weights over strategies.
    pub mis: MisHeuristic,
    /// Only this strategy's contribution (debugging), or all.
    pub strategy: Option<BdptStrategy>,
}

impl Bdpt {
    /// The path tracer sharing these parameters (segment transmittance, sensors).
    pub(crate) fn path_tracer(&self) -> PathTracer {
        PathTracer {
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            mis: self.mis,
            // Light paths refuse re-radiation (`prepare`); sensors path-trace with all lanes.
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        }
    }

    /// All strategies of one camera sample: the camera-side radiance (strategies t ≥ 2)
    /// and the t = 1 splats (scaled by the camera's importance area, see `LightSplats`).
    #[allow(clippy::too_many_arguments)]
    fn sample<'s>(
        &self,
        scene: &'s RenderScene,
        cs: &mut CameraSample,
        camera_path: &mut Subpath<'s>,
        light_path: &mut Subpath<'s>,
        splats: &mut LightSplats,
        counters: &mut PathCounters,
    ) -> (
        SampledSpectrum,
        SampledWavelengths,
        Option<SurfaceAov>,
        bool,
    ) {
        let zero = SampledSpectrum::splat(0.0);
        let wavelengths = cs.draw_wavelengths();
        debug_assert_eq!(cs.stream.dimension(), CAMERA_SAMPLE_DIMENSIONS);
        let camera_ray = scene.camera.generate_ray_only(cs.film_point, cs.lens);
        let mut camera_state = PathState::new(Vec3A::ZERO, None, cs.stream, wavelengths);
        match &camera_ray {
            Some(ray) => {
                let pdf_dir = scene.camera.pdf_we(ray).map_or(0.0, |(_, pdf_dir)| pdf_dir);
                walk::camera_subpath(
                    scene,
                    ray,
                    pdf_dir,
                    self.max_depth,
                    self.rr_depth,
                    &mut camera_state,
                    camera_path,
                    counters,
                );
            }
            None => {
                // A film point without a ray (outside a circular fisheye's image circle):
                // no camera subpath, but the light subpath is traced all the same — its
                // t = 1 connections land anywhere on the film, and the film divides the
                // splats by every camera sample's light path.
                camera_path.clear();
                camera_path.vertices.push(vertex::BdptVertex::camera(
                    scene.camera.frame().camera_to_world.point(Vec3A::ZERO),
                    scene.camera.forward(),
                    SampledSpectrum::splat(1.0),
                ));
            }
        }
        let ray_origin = camera_path.vertices[0].p;
        // The light subpath's dimensions start at a fixed place (module docs).
        let mut light_stream = cs.stream;
        let first = bdpt_light_subpath_first_dimension(self.max_depth);
        light_stream.reserve(first - light_stream.dimension());
        let start = LightStartDimensions::reserve(&mut light_stream);
        let mut light_state =
            PathState::new(ray_origin, None, light_stream, camera_state.wavelengths);
        walk::light_subpath(
            scene,
            start,
            self.max_depth,
            self.rr_depth,
            &mut light_state,
            light_path,
            counters,
        );
        let final_wavelengths = light_state.wavelengths;
        let transport = *final_wavelengths.transport();
        let sensor = *final_wavelengths.sensor();
        let aov = camera_path.vertices.get(1).and_then(|v| match v.kind {
            VertexKind::Surface { scatter, .. } => {
                let si = &camera_path.surfaces[scatter as usize].si;
                Some(SurfaceAov {
                    depth_m: (si.p - ray_origin).length(),
                    normal: si.n_shading,
                    albedo_rgb: scene.albedo(si.material_id),
                })
            }
            VertexKind::Camera
            | VertexKind::Light { .. }
            | VertexKind::InfiniteLight { .. }
            | VertexKind::Medium(_) => None,
        });
        let tracer = self.path_tracer();
        let importance_area = scene.camera.importance_area_px2();
        let xyz_weights = prism_spectrum::XyzWeights::new(&sensor);
        let mut radiance = zero;
        let (n_camera, n_light) = (camera_path.len(), light_path.len());
        let light_first = start_of_light_vertex_blocks(start);
        let uses_lens = scene.camera.uses_lens_sample();
        // The lights' spectra at this sample's transport wavelengths (s = 1 connections).
        let mut le_cache = crate::spectrum_cache::SpectrumCache::new();
        for t in 1..=n_camera {
            for s in 0..=n_light {
                let depth = s as i64 + t as i64 - 2;
                if (s == 1 && t == 1) || depth < 0 || depth > i64::from(self.max_depth) {
                    continue;
                }
                if let Some(only) = self.strategy {
                    if (only.s as usize, only.t as usize) != (s, t) {
                        continue;
                    }
                }
                // s = 1 at camera vertex t − 1 (≥ 1) uses that vertex's block; t = 1 at light
                // vertex s − 1 (≥ 1) its block (module docs).
                let camera_block = VertexDimensions::starting_at(
                    CAMERA_SAMPLE_DIMENSIONS + VertexDimensions::COUNT * (t.max(2) as u32 - 2),
                );
                let light_block = VertexDimensions::starting_at(
                    light_first + VertexDimensions::COUNT * (s.max(2) as u32 - 2),
                );
                // Only the variates the strategy reads (each is a hash or a Sobol point).
                let (u_light_choice, u_light) = if s == 1 {
                    (
                        cs.stream.get_1d_at(camera_block.light_choice()),
                        cs.stream.get_2d_at(camera_block.light()),
                    )
                } else {
                    (0.0, glam::Vec2::ZERO)
                };
                let u_lens = if t == 1 && uses_lens {
                    cs.stream.get_2d_at(light_block.light())
                } else {
                    glam::Vec2::ZERO
                };
                let variates = ConnectionVariates {
                    u_light_choice,
                    u_light,
                    u_lens,
                };
                let Some(c) = connect::connect(
                    scene,
                    &tracer,
                    Some(self.mis),
                    light_path,
                    camera_path,
                    s,
                    t,
                    &variates,
                    &transport,
                    &mut le_cache,
                    counters,
                ) else {
                    continue;
                };
                let weight = match self.strategy {
                    Some(BdptStrategy {
                        unweighted: true, ..
                    }) => 1.0,
                    Some(BdptStrategy {
                        unweighted: false, ..
                    })
                    | None => c.weight,
                };
                let value = c.unweighted * weight;
                match c.film_point_px {
                    Some(film_point) => {
                        if !splats.splat_with(
                            film_point,
                            value * importance_area,
                            &sensor,
                            &xyz_weights,
                        ) {
                            counters.non_finite_contributions += 1;
                        }
                    }
                    None => radiance += value,
                }
            }
        }
        (radiance, sensor, aov, camera_ray.is_some())
    }
}

/// The first dimension of the light subpath's vertex blocks.
fn start_of_light_vertex_blocks(start: LightStartDimensions) -> u32 {
    start.first() + LightStartDimensions::COUNT
}

impl Estimator for Bdpt {
    fn name(&self) -> &'static str {
        "bdpt"
    }

    fn prepare(&mut self, scene: &RenderScene, _pass: &Pass) -> Result<(), String> {
        scene.refuse_reradiation("bdpt")?;
        if let Some(media) = &scene.media {
            return Err(crate::integrator::media_refusal("bdpt", &media.names));
        }
        scene
            .camera
            .importance_support()
            .map_err(|why| format!("bdpt: {why}"))
    }

    fn splats_light_paths(&self) -> bool {
        true
    }

    fn sample_indices_per_prepare(&self) -> Option<u32> {
        None
    }

    fn render_tile(
        &self,
        scene: &RenderScene,
        work: &TileWork,
        tile: &mut FilmTile,
        splats: &mut LightSplats,
    ) -> RenderStats {
        let mut counters = PathCounters::default();
        let mut stats = RenderStats::default();
        let mut camera_path = Subpath::default();
        let mut light_path = Subpath::default();
        for pixel in tile.bounds().pixels() {
            for s in work.samples_of(pixel) {
                let mut cs = CameraSample::start(tile, work, pixel, s);
                let (radiance, sensor, aov, traced) = self.sample(
                    scene,
                    &mut cs,
                    &mut camera_path,
                    &mut light_path,
                    splats,
                    &mut counters,
                );
                if traced {
                    stats.rays_traced += 1;
                }
                if radiance.has_non_finite() {
                    stats.non_finite_samples += 1;
                }
                add_camera_sample(tile, pixel, &cs, radiance, &sensor, aov.as_ref());
                splats.count_paths(1);
                stats.light_paths += 1;
                stats.samples += 1;
            }
        }
        stats.add_path_counters(&counters);
        stats
    }
}

/// Adds a camera sample's camera-side radiance to its pixel.
pub(crate) fn add_camera_sample(
    tile: &mut FilmTile,
    pixel: UVec2,
    cs: &CameraSample,
    radiance: SampledSpectrum,
    sensor: &SampledWavelengths,
    aov: Option<&SurfaceAov>,
) {
    tile.add_sample_at(
        pixel,
        cs.film_point,
        radiance,
        sensor,
        cs.filter_weight,
        aov,
    );
}
