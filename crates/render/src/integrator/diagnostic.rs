//! The diagnostic estimators' shared tile loop: one camera ray per sample, the first hit
//! shaded by `Integrator::shade` into a known XYZ (no wavelength sampling), AOVs recorded.

use glam::DVec3;

use super::camera_sample::CameraSample;
use super::driver::RenderStats;
use super::estimator::{Estimator, Pass, TileWork};
use super::Integrator;
use crate::film::{FilmTile, LightSplats, SurfaceAov};
use crate::scene_build::RenderScene;

/// A diagnostic integrator (depth, normal, albedo, ambient occlusion) as an `Estimator`.
pub(crate) struct Diagnostic(pub Integrator);

impl Estimator for Diagnostic {
    fn name(&self) -> &'static str {
        self.0.name()
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
        render_tile(&self.0, scene, work, tile)
    }
}

/// Renders the work item with the diagnostic `integrator` (not `Path`, `Light`, `Bdpt`).
pub(crate) fn render_tile(
    integrator: &Integrator,
    scene: &RenderScene,
    work: &TileWork,
    tile: &mut FilmTile,
) -> RenderStats {
    let mut stats = RenderStats::default();
    for pixel in tile.bounds().pixels() {
        for s in work.samples_of(pixel) {
            let mut cs = CameraSample::start(tile, work, pixel, s);
            let (xyz, aov) = match scene.camera.generate_ray(cs.film_point, cs.lens) {
                None => (DVec3::ZERO, None),
                Some(ray) => {
                    stats.rays_traced += 1;
                    match scene.geometry.intersect(&ray.ray) {
                        None => (DVec3::ZERO, None),
                        Some(h) => {
                            let si = scene.geometry.interaction(&ray.ray, &h);
                            let xyz = integrator.shade(
                                scene,
                                &ray.ray,
                                &si,
                                &mut cs.stream,
                                &mut stats.rays_traced,
                            );
                            let aov = SurfaceAov {
                                depth_m: h.t,
                                normal: si.n_shading,
                                albedo_rgb: scene.albedo(si.material_id),
                            };
                            (xyz, Some(aov))
                        }
                    }
                }
            };
            if !xyz.is_finite() {
                stats.non_finite_samples += 1;
            }
            tile.add_sample_xyz_at(pixel, cs.film_point, xyz, cs.filter_weight, aov.as_ref());
            stats.samples += 1;
        }
    }
    stats
}
