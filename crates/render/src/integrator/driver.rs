//! Runs an integrator over the film: tiles in parallel on the current rayon pool, every
//! camera sample seeded by (seed, pixel, sample index) through `PixelSampler`, never by
//! thread, so the image is bit-identical for any thread count (DESIGN.md "Deterministic").
//!
//! Per camera sample the stream's dimensions are: 2 for the filter offset, 2 for the lens,
//! then whatever the integrator draws.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, UVec2};

use crate::film::{AovSelection, Film, FilmImage, SpectralBins, SurfaceAov};
use crate::sampler::{PixelSampler, SamplerKind};
use crate::scene_build::RenderScene;

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

/// The scene's film with the spectral bins and illumination AOV `settings` ask for.
fn film_for(scene: &RenderScene, settings: &RenderSettings) -> Film {
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
}

/// Renders `scene` and returns the finished film with statistics. `progress` is called
/// after each tile with the number of camera samples that tile took (from worker threads).
pub fn render(
    scene: &RenderScene,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> (FilmImage, RenderStats) {
    let mut film = film_for(scene, settings);
    let sampler = PixelSampler::with_kind(settings.sampler, settings.seed);
    let spp = settings.spp.max(1);
    let rays_total = AtomicU64::new(0);
    let samples_total = AtomicU64::new(0);
    let non_finite_total = AtomicU64::new(0);
    film.render_tiles(settings.tile_size_px, |tile| {
        let (mut rays, mut samples, mut non_finite) = (0u64, 0u64, 0u64);
        for pixel in tile.bounds().pixels() {
            for s in 0..spp {
                let mut stream = sampler.stream(pixel, s);
                let (film_point, weight) = tile.sample_film_point(pixel, stream.get_2d());
                let lens = stream.get_2d();
                let (xyz, aov) = match scene.camera.generate_ray(film_point, lens) {
                    None => (DVec3::ZERO, None),
                    Some(ray) => {
                        rays += 1;
                        match scene.geometry.intersect(&ray.ray) {
                            None => (DVec3::ZERO, None),
                            Some(h) => {
                                let si = scene.geometry.interaction(&ray.ray, &h);
                                let xyz = scene.integrator.shade(
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
                tile.add_sample_xyz(pixel, xyz, weight, aov.as_ref());
                samples += 1;
            }
        }
        rays_total.fetch_add(rays, Ordering::Relaxed);
        samples_total.fetch_add(samples, Ordering::Relaxed);
        non_finite_total.fetch_add(non_finite, Ordering::Relaxed);
        progress(samples);
    });
    let stats = RenderStats {
        rays_traced: rays_total.into_inner(),
        samples: samples_total.into_inner(),
        non_finite_samples: non_finite_total.into_inner(),
    };
    (film.finish(), stats)
}

/// Total camera samples of a render: pixels × spp (for progress bars).
pub fn total_samples(resolution: UVec2, spp: u32) -> u64 {
    u64::from(resolution.x) * u64::from(resolution.y) * u64::from(spp.max(1))
}
