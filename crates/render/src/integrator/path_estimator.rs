//! The `path` method as an `Estimator`: each camera sample of a tile through the scalar
//! path tracer (`path`), or the whole tile through the packet tracer (`packet`) where the
//! scene is one the packet tracer serves (`RenderScene::packet`, its allow-list) and each
//! hit takes one light sample (`RenderScene::light_samples_per_hit`).

use glam::UVec2;

use super::camera_sample::CameraSample;
use super::driver::RenderStats;
use super::estimator::{Estimator, Pass, TileWork};
use super::lane_wavelengths::LaneWavelengths;
use super::packet::{render_tile as render_packet_tile, TileJob};
use super::{PathCounters, PathResult, PathTracer};
use crate::film::{FilmTile, LightSplats};
use crate::scene_build::RenderScene;
use prism_spectrum::XyzWeights;

impl Estimator for PathTracer {
    fn name(&self) -> &'static str {
        "path"
    }

    fn prepare(&mut self, _scene: &RenderScene, _pass: &Pass) -> Result<(), String> {
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
        let pass = work.pass;
        let settings = pass.settings;
        let mut counters = PathCounters::default();
        let mut stats = RenderStats::default();
        // Flat diffuse scenes: many paths at once (`integrator::packet`), for plans of one
        // light sample per hit.
        let packet = scene.packet.as_ref().filter(|_| {
            tile.bounds()
                .pixels()
                .all(|p| scene.light_samples_per_hit(work.light_samples(p)) <= 1)
        });
        if let Some(packet) = packet {
            debug_assert!(tile.bounds().pixels().all(|p| {
                let first = pass.first_sample + pass.plan.first_sample(p);
                let own = first..first + pass.plan.camera_samples(p);
                work.samples_of(p) == own
            }));
            let job = TileJob {
                scene,
                packet,
                tracer: self,
                sampler: work.sampler,
                camera_samples: &|p| pass.plan.camera_samples(p),
                first_sample: &|p| pass.first_sample + pass.plan.first_sample(p),
                uses_lens: work.uses_lens,
                want_illumination: settings.illumination_aov,
                wavelength_density: tile.wavelength_density(),
            };
            let c = render_packet_tile(&job, tile, &mut counters);
            stats.rays_traced += c.camera_rays;
            stats.samples += c.samples;
            stats.non_finite_samples += c.non_finite_samples;
        } else {
            scalar_tile(scene, work, tile, &mut stats, |cs, pixel, wavelengths| {
                let light_samples = scene.light_samples_per_hit(work.light_samples(pixel));
                if scene.texture_footprint.is_none() {
                    scene
                        .camera
                        .generate_ray_only(cs.film_point, cs.lens)
                        .map(|ray| {
                            self.radiance(
                                scene,
                                &ray,
                                wavelengths,
                                &mut cs.stream,
                                light_samples,
                                settings.illumination_aov,
                                &mut counters,
                            )
                        })
                } else {
                    let differential_scale = pass.differential_scale(pixel);
                    scene
                        .camera
                        .generate_ray(cs.film_point, cs.lens)
                        .map(|mut camera_ray| {
                            camera_ray.scale_differentials(differential_scale);
                            self.radiance_with_differentials(
                                scene,
                                &camera_ray.ray,
                                Some(&camera_ray),
                                differential_scale,
                                wavelengths,
                                &mut cs.stream,
                                light_samples,
                                settings.illumination_aov,
                                &mut counters,
                            )
                        })
                }
            });
        }
        stats.add_path_counters(&counters);
        stats
    }
}

/// The scalar per-sample loop of a tile: each pixel's samples of the work item, a camera
/// sample and hero wavelengths each, `radiance` for them (`None`: no camera ray), the
/// illumination AOV and the sample added to the tile.
pub(super) fn scalar_tile(
    scene: &RenderScene,
    work: &TileWork,
    tile: &mut FilmTile,
    stats: &mut RenderStats,
    mut radiance: impl FnMut(&mut CameraSample, UVec2, &mut LaneWavelengths) -> Option<PathResult>,
) {
    for pixel in tile.bounds().pixels() {
        for s in work.samples_of(pixel) {
            let mut cs = CameraSample::start(tile, work, pixel, s);
            let mut wavelengths = cs.draw_wavelengths();
            let result = radiance(&mut cs, pixel, &mut wavelengths);
            let sensor = wavelengths.sensor();
            let xyz_weights = XyzWeights::new(sensor);
            let estimate = result.map(|r| {
                if let Some(white) = r.illumination {
                    tile.add_illumination_with(pixel, white, &xyz_weights);
                }
                (r.radiance, r.first_hit)
            });
            cs.add_to_tile(tile, scene, pixel, sensor, &xyz_weights, estimate, stats);
        }
    }
}
