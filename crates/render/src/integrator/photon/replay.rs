//! Replaying `photon_progressive`'s per-pixel statistics (`sppm`) of passes that another
//! process or an earlier run rendered: a render of the samples A..B (`prism render
//! --samples A..B`, a resumed checkpoint, a progressive pass handed to a fresh estimator)
//! needs the radii and counts that passes 0 … A − 1 left, and those depend on what each
//! pass's visible points found. A replayed pass shoots its photons as the rendered pass
//! did (same seed, pass, wavelengths and radius) and traces every pixel's camera sample
//! of that pass up to its gather (`CausticGather::count_only`), adding nothing to the
//! film; its counts then update R and N exactly as the rendered pass's would. The cost is
//! the pass's photon tracing and one camera path per pixel to its first non-specular
//! vertex: splitting a render into ranges saves none of the earlier passes' photon work.

use glam::UVec2;
use rayon::prelude::*;

use super::camera::{camera_ray, pass_wavelengths, CameraPaths, CausticGather, PhotonMaps};
use super::medium_sources::PhotonSources;
use super::photon_map::PhotonTree;
use super::settings::PhotonPlan;
use super::shoot::shoot;
use super::sppm::SppmStatistics;
use crate::integrator::camera_sample::CameraSample;
use crate::integrator::driver::film_for;
use crate::integrator::estimator::{Pass, TileWork};
use crate::integrator::lane_wavelengths::LaneWavelengths;
use crate::integrator::{PathCounters, PathTracer};
use crate::sampler::PixelSampler;
use crate::scene_build::RenderScene;

/// Records into `stats` what pass `iteration`'s visible points find, without rendering
/// it: `stats` must be ready for pass `iteration` (its `pass()`), and is left with the
/// counts recorded, to be folded in by `advance`. `pass` is the pass being prepared: its
/// settings (seed, sampler, tiles) are the render's, and its `footprint_plan`, when set,
/// is the whole render's plan, which says which pixels took a sample in pass `iteration`
/// (all of them without one).
pub fn replay_pass(
    scene: &RenderScene,
    pass: &Pass,
    plan: &PhotonPlan,
    sources: &PhotonSources,
    tracer: PathTracer,
    stats: &SppmStatistics,
    iteration: u32,
) {
    debug_assert_eq!(stats.pass(), iteration);
    let seed = pass.settings.seed;
    let wavelengths = pass_wavelengths(seed, iteration, pass.settings.wavelength_density());
    let (_, r2) = plan.radius_from(iteration, None);
    let radius_m = r2.sqrt() as f32;
    let shot = shoot(
        scene,
        sources,
        &wavelengths,
        plan.photons_per_pass,
        seed,
        iteration,
        tracer.max_depth,
        if plan.nearest.is_some() {
            0.0
        } else {
            radius_m
        },
    );
    // Only the caustic map is gathered at the visible point; the volume photons add to
    // the image only.
    let mut caustic = PhotonTree::build(shot.caustic);
    if let Some(k) = plan.nearest {
        caustic.set_nearest_neighbour_radii(k as usize, 25.0 * plan.radius_m);
    }
    let maps = PhotonMaps {
        caustic,
        volume: PhotonTree::default(),
    };
    let paths = CameraPaths {
        tracer,
        maps: &maps,
    };
    let takes_part = |pixel: UVec2| match pass.footprint_plan {
        Some(whole) => {
            let first = whole.first_sample(pixel);
            (first..first.saturating_add(whole.camera_samples(pixel))).contains(&iteration)
        }
        None => true,
    };
    let film = film_for(scene, pass.settings);
    let maker = film.tile_maker();
    let sampler = PixelSampler::with_kind(pass.settings.sampler, seed);
    let work = TileWork {
        pass,
        sampler: &sampler,
        sample_indices: iteration..iteration + 1,
        uses_lens: scene.camera.uses_lens_sample(),
    };
    film.tiles(pass.settings.tile_size_px)
        .par_iter()
        .for_each(|bounds| {
            // The tile only places the sample in its pixel (the film's filter); nothing
            // is added to it.
            let tile = maker.new_tile(*bounds);
            let mut counters = PathCounters::default();
            for pixel in bounds.pixels().filter(|p| takes_part(*p)) {
                let mut cs = CameraSample::start(&tile, &work, pixel, iteration);
                // As in a rendered pass: the wavelength dimension is not read.
                let _ = cs.stream.get_1d();
                let mut lanes = LaneWavelengths::new(wavelengths);
                let mut gather = CausticGather {
                    radius_m: Some(stats.pixel(pixel).radius_m() as f32),
                    found: 0,
                    count_only: true,
                };
                let scale = pass.differential_scale(pixel);
                if let Some(ray) = camera_ray(scene, &cs, scale) {
                    let _ = paths.radiance(
                        scene,
                        &ray,
                        scale,
                        &mut lanes,
                        &mut cs.stream,
                        &mut gather,
                        &mut counters,
                    );
                }
                stats.record(pixel, gather.found);
            }
        });
}
