//! `light`: light tracing (particle tracing; Arvo 1986, Dutré et al. 1993; Veach 1997
//! §10.2's strategies with t = 1 alone; Mitsuba 3's `ptracer`). Each camera sample traces
//! one light path — a light chosen by power, an emission from `Light::sample_le`, a random
//! walk carrying importance — and connects every vertex to a point on the lens
//! (`Camera::sample_wi`), splatting the contribution where it lands on the film. So
//! `--spp N` traces N·W·H light paths.
//!
//! What a pinhole light tracer cannot reach, it leaves out: pixels that see a specular
//! surface first (no light-path vertex connects through a Dirac lobe), and point-like
//! lights seen directly (a Dirac on the film; `path` does not show them either). The camera
//! side of each sample adds the infinite lights seen directly along the camera ray (a ray
//! that leaves the scene), which light paths cannot connect to, and records the AOVs.

use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::bdpt::vertex::{Subpath, VertexKind};
use super::bdpt::walk;
use super::bdpt::{add_camera_sample, ConnectionVariates};
use super::camera_sample::CameraSample;
use super::dimensions::{LightStartDimensions, VertexDimensions};
use super::driver::RenderStats;
use super::estimator::{Estimator, Pass, TileWork};
use super::lane_wavelengths::LaneWavelengths;
use super::path_state::PathState;
use super::{PathCounters, PathTracer};
use crate::film::{FilmTile, LightSplats, SurfaceAov};
use crate::light::LightHit;
use crate::scene_build::RenderScene;

/// Parameters of the light tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTracer {
    /// Most scattering events of a light path before it reaches the camera (`path`'s
    /// meaning: 1 = direct lighting).
    pub max_depth: u32,
    /// Russian roulette after this many scattering events.
    pub rr_depth: u32,
}

impl LightTracer {
    fn path_tracer(&self) -> PathTracer {
        PathTracer {
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            mis: prism_scene::MisHeuristic::Power,
            // Light paths refuse re-radiation (`prepare`); sensors path-trace with all lanes.
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        }
    }

    /// The light path of one camera sample with every connection to the camera splatted;
    /// returns the final wavelengths (a dispersive vertex may have kept only the hero).
    fn trace_light_path<'s>(
        &self,
        scene: &'s RenderScene,
        stream: crate::sampler::SampleStream,
        wavelengths: LaneWavelengths,
        light_path: &mut Subpath<'s>,
        splats: &mut LightSplats,
        counters: &mut PathCounters,
    ) {
        let mut stream = stream;
        let start = LightStartDimensions::reserve(&mut stream);
        let mut state = PathState::new(glam::Vec3A::ZERO, None, stream, wavelengths);
        walk::light_subpath(
            scene,
            start,
            self.max_depth,
            self.rr_depth,
            &mut state,
            light_path,
            counters,
        );
        if light_path.is_empty() {
            return;
        }
        let sensor = *state.wavelengths.sensor();
        let transport = *state.wavelengths.transport();
        let importance_area = scene.camera.importance_area_px2();
        let xyz_weights = prism_spectrum::XyzWeights::new(&sensor);
        let tracer = self.path_tracer();
        // The light's own point, seen by the camera.
        if let Some(c) = self.connect_light_point(
            scene,
            &tracer,
            light_path,
            state.stream,
            start,
            &transport,
            counters,
        ) {
            let (film_point, value) = c;
            if !splats.splat_with(film_point, value * importance_area, &sensor, &xyz_weights) {
                counters.non_finite_contributions += 1;
            }
        }
        let first_block = start.first() + LightStartDimensions::COUNT;
        let uses_lens = scene.camera.uses_lens_sample();
        // Not read: t = 1 connections sample no light.
        let mut le_cache = crate::spectrum_cache::SpectrumCache::new();
        // t = 1 connections sample their camera vertex; the camera subpath is never read.
        let mut no_camera = Subpath::default();
        for s in 2..=light_path.len() {
            let block = VertexDimensions::starting_at(
                first_block + VertexDimensions::COUNT * (s as u32 - 2),
            );
            let variates = ConnectionVariates {
                u_light_choice: 0.0,
                u_light: glam::Vec2::ZERO,
                u_lens: if uses_lens {
                    state.stream.get_2d_at(block.light())
                } else {
                    glam::Vec2::ZERO
                },
            };
            let Some(c) = super::bdpt::connect_strategy(
                scene,
                &tracer,
                None,
                light_path,
                &mut no_camera,
                s,
                1,
                &variates,
                &transport,
                &mut le_cache,
                counters,
            ) else {
                continue;
            };
            if let Some(film_point) = c.film_point_px {
                if !splats.splat_with(
                    film_point,
                    c.unweighted * importance_area,
                    &sensor,
                    &xyz_weights,
                ) {
                    counters.non_finite_contributions += 1;
                }
            }
        }
    }

    /// Light vertex 0 (a point on an area light) connected to the lens: the emitter as
    /// the camera sees it, L_e |cos θ_l| W_e |cos θ_c| A_lens / (d² · pmf · p_A).
    #[allow(clippy::too_many_arguments)]
    fn connect_light_point(
        &self,
        scene: &RenderScene,
        tracer: &PathTracer,
        light_path: &Subpath,
        stream: crate::sampler::SampleStream,
        start: LightStartDimensions,
        wavelengths: &SampledWavelengths,
        counters: &mut PathCounters,
    ) -> Option<(glam::Vec2, SampledSpectrum)> {
        let v0 = light_path.vertices[0];
        let VertexKind::Light { index } = v0.kind else {
            return None;
        };
        let light = scene.lights.light(index);
        if light.is_delta_position() || light.is_delta_direction() {
            return None;
        }
        let cs = scene
            .camera
            .sample_wi(v0.p, stream.get_2d_at(start.lens()))?;
        if cs.pdf_per_sr <= 0.0 || cs.importance <= 0.0 {
            return None;
        }
        // `sample_wi`'s direction points from the light point to the lens.
        let to_camera = cs.wi;
        // Area lights emit uniformly over their surface (no texture reads the uv).
        let hit = LightHit {
            p: v0.p,
            n: v0.n_geometric,
            uv: glam::Vec2::ZERO,
            distance_m: cs.distance_m,
        };
        let le = light.emitted_radiance(&hit, to_camera, wavelengths);
        if le.is_black() {
            return None;
        }
        let cos_light = v0.n_geometric.dot(to_camera).abs();
        let value = le * (cos_light / v0.pdf_fwd) * (cs.importance / cs.pdf_per_sr);
        counters.rays += 1;
        let shadow = prism_geometry::Ray::spawn_to(v0.p, cs.p_lens_m);
        let visible = tracer.segment_transmittance(scene, shadow, to_camera, wavelengths, counters);
        let value = value * visible;
        (!value.is_black()).then_some((cs.film_point_px, value))
    }
}

impl Estimator for LightTracer {
    fn name(&self) -> &'static str {
        "light"
    }

    fn prepare(&mut self, scene: &RenderScene, _pass: &Pass) -> Result<(), String> {
        scene.refuse_reradiation("light")?;
        if let Some(media) = &scene.media {
            return Err(crate::integrator::media_refusal("light", &media.names));
        }
        scene
            .camera
            .importance_support()
            .map_err(|why| format!("light: {why}"))
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
        let mut light_path = Subpath::default();
        let tracer = self.path_tracer();
        for pixel in tile.bounds().pixels() {
            for s in work.samples_of(pixel) {
                let mut cs = CameraSample::start(tile, work, pixel, s);
                let wavelengths = cs.draw_wavelengths();
                // Camera side: the infinite lights seen directly, and the AOVs.
                let mut radiance = SampledSpectrum::splat(0.0);
                let mut aov = None;
                if let Some(ray) = scene.camera.generate_ray_only(cs.film_point, cs.lens) {
                    stats.rays_traced += 1;
                    match scene.geometry.intersect(&ray) {
                        None => {
                            let origin = crate::light::LightSampleContext {
                                p: ray.origin,
                                n: glam::Vec3A::ZERO,
                            };
                            tracer.escape_terms(
                                scene,
                                true,
                                &origin,
                                0.0,
                                ray.direction,
                                wavelengths.transport(),
                                |x| radiance += x,
                            );
                        }
                        Some(hit) => {
                            let si = scene.geometry.interaction(&ray, &hit);
                            aov = Some(SurfaceAov {
                                depth_m: hit.t,
                                normal: si.n_shading,
                                albedo_rgb: scene.albedo(si.material_id),
                            });
                        }
                    }
                }
                self.trace_light_path(
                    scene,
                    cs.stream,
                    wavelengths,
                    &mut light_path,
                    splats,
                    &mut counters,
                );
                if radiance.has_non_finite() {
                    stats.non_finite_samples += 1;
                }
                add_camera_sample(
                    tile,
                    pixel,
                    &cs,
                    radiance,
                    wavelengths.sensor(),
                    aov.as_ref(),
                );
                splats.count_paths(1);
                stats.light_paths += 1;
                stats.samples += 1;
            }
        }
        stats.add_path_counters(&counters);
        stats
    }
}
