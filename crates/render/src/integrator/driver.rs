//! Runs an integrator over the film: tiles in parallel on the current rayon pool, every
//! camera sample seeded by (seed, pixel, sample index) through `PixelSampler`, never by
//! thread, so the image is bit-identical for any thread count (DESIGN.md "Deterministic").
//!
//! Per camera sample the stream's dimensions are: 2 for the filter offset, 2 for the lens,
//! then whatever the integrator draws.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, UVec2, Vec2};

use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::packet::{render_tile as render_packet_tile, TileJob};
use super::{Integrator, PathCounters};
use crate::film::xyz::XyzWeights;
use crate::film::{AovSelection, Film, FilmImage, SpectralBins, SurfaceAov};
use crate::sampler::{PixelSampler, SamplerKind};
use crate::scene_build::RenderScene;
use prism_bandwidth::{BandwidthError, SamplePlan};

/// Tile edge in pixels: 16 × 16 tiles give a 640 × 480 film 1200 work items, plenty for
/// load balancing, while a tile's accumulators (≈ 20 KiB) stay in L1/L2.
pub const DEFAULT_TILE_SIZE_PX: u32 = 16;

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Camera samples per pixel (≥ 1).
    pub spp: u32,
    pub seed: u64,
    pub tile_size_px: u32,
    /// Sampler of every camera sample's stream (default Sobol).
    pub sampler: SamplerKind,
    /// Spectral bins of the film (`None`: XYZ only). Validated by `SpectralBins::new`.
    pub spectral_bins: Option<SpectralBins>,
    /// Record the `illumination.X/Y/Z` AOV (filled by `FilmTile::add_illumination`).
    pub illumination_aov: bool,
}

impl Default for RenderSettings {
    /// 16 spp, seed 0, 16-pixel tiles, Sobol, no spectral bins, no illumination AOV.
    fn default() -> Self {
        Self {
            spp: 16,
            seed: 0,
            tile_size_px: DEFAULT_TILE_SIZE_PX,
            sampler: SamplerKind::Sobol,
            spectral_bins: None,
            illumination_aov: false,
        }
    }
}

/// The scene's film with the spectral bins and illumination AOV `settings` ask for: what
/// `render_plan` renders into, and what `render_pass` accumulates pass after pass.
pub fn film_for(scene: &RenderScene, settings: &RenderSettings) -> Film {
    let mut film = scene.new_film();
    if settings.illumination_aov {
        let aovs = AovSelection {
            illumination: true,
            ..film.aov_selection()
        };
        film = film.with_aovs(aovs);
    }
    match settings.spectral_bins {
        Some(bins) => film.with_bins(bins),
        None => film,
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera rays plus every secondary (occlusion) ray.
    pub rays_traced: u64,
    /// Camera samples taken (pixels × spp).
    pub samples: u64,
    /// Samples whose value was NaN or infinite (dropped by the film as zero).
    pub non_finite_samples: u64,
    /// Scattering events of all paths (path tracer).
    pub bounces: u64,
    /// Paths ended by Russian roulette.
    pub roulette_terminations: u64,
    /// Single light or emission contributions that were NaN/∞ and were dropped before they
    /// reached the film (path tracer).
    pub non_finite_contributions: u64,
}

/// Renders `scene` with the uniform plan (`settings.spp` camera samples and one light
/// sample per hit everywhere) and returns the finished film with statistics. `progress` is
/// called after each tile with the number of camera samples that tile took.
pub fn render(
    scene: &RenderScene,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> (FilmImage, RenderStats) {
    let plan = SamplePlan::uniform(scene.resolution, settings.spp.max(1))
        .expect("the resolution was checked when the camera frame was built");
    render_plan(scene, settings, &plan, progress).expect("a uniform plan has the film's resolution")
}

/// Renders `scene` executing `plan` (prism-bandwidth): per pixel its camera samples (0 is
/// allowed: the pixel stays empty, `spp.Y` = 0) and per hit its light samples. Errors when
/// the plan's resolution is not the film's. `settings.spp` is ignored.
pub fn render_plan(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: &SamplePlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(FilmImage, RenderStats), BandwidthError> {
    plan.check_resolution(scene.resolution)?;
    let mut film = film_for(scene, settings);
    let stats = render_pass(scene, settings, plan, &mut film, 0, progress)?;
    Ok((film.finish(), stats))
}

/// One pass of a progressive render: adds to `film` (from `film_for`) the camera samples
/// `first_sample .. first_sample + plan.camera_samples(pixel)` of every pixel. Sample
/// indices continue the same per-pixel sequence (Sobol points, independent hashes), so
/// passes over [0, a), [a, b), … give the film of one render of b samples, up to the
/// order of the f64 additions (`prism converge`, tested). Errors when the plan's or the
/// film's resolution is not the scene's. `settings.spp` is ignored.
pub fn render_pass(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: &SamplePlan,
    film: &mut Film,
    first_sample: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderStats, BandwidthError> {
    plan.check_resolution(scene.resolution)?;
    plan.check_resolution(film.resolution())?;
    let sampler = PixelSampler::with_kind(settings.sampler, settings.seed);
    let rays_total = AtomicU64::new(0);
    let samples_total = AtomicU64::new(0);
    let non_finite_total = AtomicU64::new(0);
    let bounces_total = AtomicU64::new(0);
    let roulette_total = AtomicU64::new(0);
    let non_finite_contributions_total = AtomicU64::new(0);
    let uses_lens = scene.camera.uses_lens_sample();
    film.render_tiles(settings.tile_size_px, |tile| {
        let (mut rays, mut samples, mut non_finite) = (0u64, 0u64, 0u64);
        let mut counters = PathCounters::default();
        // Flat diffuse scenes: many paths at once (`integrator::packet`), for plans of one
        // light sample per hit.
        let packet_tracer = match (&scene.integrator, &scene.packet) {
            (Integrator::Path(tracer), Some(packet))
                if tile.bounds().pixels().all(|p| plan.light_samples(p) <= 1) =>
            {
                Some((tracer, packet))
            }
            _ => None,
        };
        if let Some((tracer, packet)) = packet_tracer {
            let job = TileJob {
                scene,
                packet,
                tracer,
                sampler: &sampler,
                camera_samples: &|p| plan.camera_samples(p),
                first_sample,
                uses_lens,
                want_illumination: settings.illumination_aov,
            };
            let c = render_packet_tile(&job, tile, &mut counters);
            rays += c.camera_rays;
            samples += c.samples;
            non_finite += c.non_finite_samples;
        }
        let scalar_pixels = packet_tracer.is_none().then(|| tile.bounds().pixels());
        for pixel in scalar_pixels.into_iter().flatten() {
            let light_samples = plan.light_samples(pixel);
            let count = plan.camera_samples(pixel);
            // Several samples share the pixel: each one's differential covers a fraction of
            // it (pbrt-v4 `GetCameraSample`/`ScaleDifferentials`: max(1/8, 1/√spp)); a
            // progressive pass scales by its own sample count.
            let differential_scale = (1.0 / (count.max(1) as f32).sqrt()).max(0.125);
            for s in first_sample..first_sample.saturating_add(count) {
                let mut stream = sampler.stream(pixel, s);
                let (film_point, weight) = tile.sample_film_point(pixel, stream.get_2d());
                // The lens dimensions are reserved for every camera, computed for the thin
                // lens only (the others ignore them).
                let lens_dimension = stream.reserve(2);
                let lens = if uses_lens {
                    stream.get_2d_at(lens_dimension)
                } else {
                    Vec2::ZERO
                };
                match &scene.integrator {
                    Integrator::Path(tracer) => {
                        let mut wavelengths = SampledWavelengths::sample_visible(stream.get_1d());
                        // Ray differentials only feed texture filtering: without textures the
                        // camera ray alone (same bits) saves two camera rays per sample.
                        let result = if scene.texture_footprint.is_none() {
                            scene.camera.generate_ray_only(film_point, lens).map(|ray| {
                                tracer.radiance(
                                    scene,
                                    &ray,
                                    &mut wavelengths,
                                    &mut stream,
                                    light_samples,
                                    settings.illumination_aov,
                                    &mut counters,
                                )
                            })
                        } else {
                            scene
                                .camera
                                .generate_ray(film_point, lens)
                                .map(|mut camera_ray| {
                                    camera_ray.scale_differentials(differential_scale);
                                    tracer.radiance_with_differentials(
                                        scene,
                                        &camera_ray.ray,
                                        Some(&camera_ray),
                                        differential_scale,
                                        &mut wavelengths,
                                        &mut stream,
                                        light_samples,
                                        settings.illumination_aov,
                                        &mut counters,
                                    )
                                })
                        };
                        // One colour-matching lookup for the beauty and the illumination AOV.
                        let xyz_weights = XyzWeights::new(&wavelengths);
                        let (radiance, aov) = match result {
                            None => (SampledSpectrum::splat(0.0), None),
                            Some(r) => {
                                rays += 1;
                                if let Some(white) = r.illumination {
                                    tile.add_illumination_with(pixel, white, &xyz_weights);
                                }
                                let aov = r.first_hit.map(|si| SurfaceAov {
                                    depth_m: si.t,
                                    normal: si.n_shading,
                                    albedo_rgb: scene.albedo(si.material_id),
                                });
                                (r.radiance, aov)
                            }
                        };
                        if radiance.has_non_finite() {
                            non_finite += 1;
                        }
                        tile.add_sample_with(
                            pixel,
                            film_point,
                            radiance,
                            &wavelengths,
                            &xyz_weights,
                            weight,
                            aov.as_ref(),
                        );
                    }
                    diagnostic => {
                        let (xyz, aov) = match scene.camera.generate_ray(film_point, lens) {
                            None => (DVec3::ZERO, None),
                            Some(ray) => {
                                rays += 1;
                                match scene.geometry.intersect(&ray.ray) {
                                    None => (DVec3::ZERO, None),
                                    Some(h) => {
                                        let si = scene.geometry.interaction(&ray.ray, &h);
                                        let xyz = diagnostic.shade(
                                            scene,
                                            &ray.ray,
                                            &si,
                                            &mut stream,
                                            &mut rays,
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
                            non_finite += 1;
                        }
                        tile.add_sample_xyz_at(pixel, film_point, xyz, weight, aov.as_ref());
                    }
                }
                samples += 1;
            }
        }
        rays_total.fetch_add(rays + counters.rays, Ordering::Relaxed);
        samples_total.fetch_add(samples, Ordering::Relaxed);
        non_finite_total.fetch_add(non_finite, Ordering::Relaxed);
        bounces_total.fetch_add(counters.bounces, Ordering::Relaxed);
        roulette_total.fetch_add(counters.roulette_terminations, Ordering::Relaxed);
        non_finite_contributions_total
            .fetch_add(counters.non_finite_contributions, Ordering::Relaxed);
        progress(samples);
    });
    let stats = RenderStats {
        rays_traced: rays_total.into_inner(),
        samples: samples_total.into_inner(),
        non_finite_samples: non_finite_total.into_inner(),
        bounces: bounces_total.into_inner(),
        roulette_terminations: roulette_total.into_inner(),
        non_finite_contributions: non_finite_contributions_total.into_inner(),
    };
    Ok(stats)
}

/// Total camera samples of a render: pixels × spp (for progress bars).
pub fn total_samples(resolution: UVec2, spp: u32) -> u64 {
    u64::from(resolution.x) * u64::from(resolution.y) * u64::from(spp.max(1))
}
