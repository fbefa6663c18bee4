//! `photon` and `photon_progressive` as an `Estimator`. A pass of the photon integrators
//! is one camera sample index: the driver renders them one index at a time
//! (`Estimator::sample_indices_per_prepare`), and `prepare` shoots that pass's photons at
//! that pass's wavelengths (one `SampledWavelengths` for every photon and camera path of
//! the pass, as pbrt-v4's SPPM) with that pass's radius, dropping the previous pass's.
//! The film averages the passes' images. `photon_progressive` shrinks its radii as passes
//! add up, so that bias and variance both vanish: in media the beam estimate's radius of
//! pass i follows r²ᵢ₊₁ = r²ᵢ(i + α)/(i + 1) for the whole pass (Knaus & Zwicker 2011,
//! §4); on surfaces each pixel keeps its own radius and photon count (stochastic
//! progressive photon mapping, Hachisuka & Jensen 2009, `sppm`), which `prepare` updates
//! from what the pixel's visible point found in the pass before. Those statistics make
//! pass i depend on passes 0 … i − 1: passes come in order in one estimator, and a range
//! that starts later replays the statistics of the passes before it (`replay`).
//! `prism render --spp N` is N photon passes.

use super::camera::{camera_ray, pass_wavelengths, CameraPaths, CausticGather, PhotonMaps};
use super::medium_sources::PhotonSources;
use super::photon_map::PhotonTree;
use super::replay::replay_pass;
use super::settings::{PhotonMapper, PhotonPlan};
use super::shoot::shoot;
use super::sppm::SppmStatistics;
use crate::film::{FilmTile, LightSplats};
use crate::integrator::camera_sample::CameraSample;
use crate::integrator::driver::RenderStats;
use crate::integrator::estimator::{Estimator, Pass, TileWork};
use crate::integrator::lane_wavelengths::LaneWavelengths;
use crate::integrator::{PathCounters, PathTracer};
use crate::scene_build::{RenderScene, SceneBuildError};
use prism_spectrum::XyzWeights;

/// A photon integrator with the state its passes keep: the resolved settings and the
/// current pass's photons.
pub struct PhotonEstimator {
    pub mapper: PhotonMapper,
    plan: Option<PhotonPlan>,
    /// The lights and emissive media photons start from.
    sources: Option<PhotonSources>,
    maps: PhotonMaps,
    /// The pass (sample index) the maps are for.
    iteration: Option<u32>,
    /// The pass's wavelengths.
    wavelengths: prism_spectrum::SampledWavelengths,
    /// The last pass's (index, r²), from which the next radius continues.
    radius: Option<(u32, f64)>,
    /// Rays the photon pass traced, reported with the first tile's statistics.
    photon_rays: std::sync::atomic::AtomicU64,
    /// `photon_progressive`: every pixel's surface-gather radius and photon count.
    sppm: Option<SppmStatistics>,
}

impl PhotonEstimator {
    pub fn new(mapper: PhotonMapper) -> Self {
        Self {
            mapper,
            plan: None,
            sources: None,
            maps: PhotonMaps::default(),
            iteration: None,
            wavelengths: prism_spectrum::SampledWavelengths::sample_visible(0.5),
            radius: None,
            photon_rays: std::sync::atomic::AtomicU64::new(0),
            sppm: None,
        }
    }

    fn tracer(&self) -> PathTracer {
        PathTracer {
            max_depth: self.mapper.max_depth,
            rr_depth: self.mapper.rr_depth,
            ..PathTracer::default()
        }
    }

    /// Stored photons of the current pass (caustic, volume).
    pub fn photon_counts(&self) -> (usize, usize) {
        (self.maps.caustic.len(), self.maps.volume.len())
    }

    /// `photon_progressive`: `pixel`'s surface-gather statistics for the current pass
    /// (`None` for `photon`, or before the first pass).
    pub fn pixel_statistics(&self, pixel: glam::UVec2) -> Option<super::PixelStatistics> {
        self.sppm.as_ref().map(|s| s.pixel(pixel))
    }

    /// The per-pixel statistics ready for pass `iteration`: fresh at pass 0, else the
    /// last pass's counts folded in. Pass i's radii are the result of passes 0 … i − 1:
    /// passes this estimator did not render (a range that starts after 0, a resumed
    /// render, a pass out of order) are replayed first (`replay`), so that the pass is
    /// the one an uninterrupted render from sample 0 gives, bit for bit.
    fn advance_statistics(
        &mut self,
        scene: &RenderScene,
        pass: &Pass,
        plan: &PhotonPlan,
        sources: &PhotonSources,
        iteration: u32,
    ) {
        let Some(alpha) = plan.alpha else {
            return;
        };
        let resolution = pass.plan.resolution();
        let continues = self
            .sppm
            .as_ref()
            .is_some_and(|s| s.resolution() == resolution && s.pass() < iteration);
        if continues {
            if let Some(stats) = &mut self.sppm {
                stats.advance();
            }
        } else {
            self.sppm = Some(SppmStatistics::new(resolution, plan.radius_m, alpha));
        }
        let tracer = self.tracer();
        if let Some(stats) = &mut self.sppm {
            while stats.pass() < iteration {
                replay_pass(scene, pass, plan, sources, tracer, stats, stats.pass());
                stats.advance();
            }
        }
    }
}

/// Why a photon integrator cannot render `scene`, if it cannot.
pub fn refusal(mapper: &PhotonMapper, scene: &RenderScene) -> Option<SceneBuildError> {
    let file = &scene.file;
    let name = mapper.name();
    let sources = match PhotonSources::build(scene) {
        Ok(s) => s,
        Err(e) => return Some(e),
    };
    if sources.is_empty(scene) {
        return Some(SceneBuildError::new(
            file,
            "integrator",
            format!(
                "`{name}` shoots photons from the lights and emissive media, and the scene \
                 has neither (add a `lights` entry)"
            ),
        ));
    }
    if let Some(material) = scene.reradiating_material() {
        return Some(SceneBuildError::new(
            file,
            format!("materials.{material}"),
            format!(
                "material '{material}' re-radiates (fluorescence): `{name}` carries one \
                 wavelength set per pass and does not shift it; use path"
            ),
        ));
    }
    if let Some(media) = &scene.media {
        for (m, medium) in media.media.iter().enumerate() {
            let optics = medium.optics();
            if optics.fluorescence.is_none() {
                continue;
            }
            let medium_name = &media.names[m];
            return Some(SceneBuildError::new(
                file,
                format!("media.{medium_name}"),
                format!(
                    "medium '{medium_name}' re-radiates (a fluorophore): `{name}` carries one \
                     wavelength set per pass and does not shift it; use path"
                ),
            ));
        }
    }
    None
}

impl Estimator for PhotonEstimator {
    fn name(&self) -> &'static str {
        self.mapper.name()
    }

    fn prepare(&mut self, scene: &RenderScene, pass: &Pass) -> Result<(), String> {
        if self.sources.is_none() {
            if let Some(reason) = refusal(&self.mapper, scene) {
                return Err(reason.to_string());
            }
            self.sources = Some(PhotonSources::build(scene).map_err(|e| e.to_string())?);
        }
        let sources = self.sources.clone().unwrap_or_default();
        let plan = match self.plan {
            Some(p) => p,
            None => {
                let p = self.mapper.plan(scene).map_err(|e| e.to_string())?;
                self.plan = Some(p);
                p
            }
        };
        // The driver gives a photon integrator passes of one sample index, the same in
        // every pixel.
        let iteration = pass.first_sample + pass.plan.first_sample(glam::UVec2::ZERO);
        if self.iteration == Some(iteration) {
            return Ok(());
        }
        self.advance_statistics(scene, pass, &plan, &sources, iteration);
        // Drop the last pass's photons before the next are shot.
        self.maps = PhotonMaps::default();
        self.wavelengths = pass_wavelengths(
            pass.settings.seed,
            iteration,
            pass.settings.wavelength_density(),
        );
        let radius = plan.radius_from(iteration, self.radius);
        self.radius = Some(radius);
        let radius_m = radius.1.sqrt() as f32;
        let shot = shoot(
            scene,
            &sources,
            &self.wavelengths,
            plan.photons_per_pass,
            pass.settings.seed,
            iteration,
            self.mapper.max_depth,
            if plan.nearest.is_some() {
                0.0
            } else {
                radius_m
            },
        );
        let mut caustic = PhotonTree::build(shot.caustic);
        let mut volume = PhotonTree::build(shot.volume);
        if let Some(k) = plan.nearest {
            // A lone photon's radius is bounded by 25 times the default radius.
            let most = 25.0 * plan.radius_m;
            caustic.set_nearest_neighbour_radii(k as usize, most);
            volume.set_nearest_neighbour_radii(k as usize, most);
        }
        self.maps = PhotonMaps { caustic, volume };
        self.photon_rays
            .store(shot.rays, std::sync::atomic::Ordering::Relaxed);
        self.iteration = Some(iteration);
        Ok(())
    }

    fn splats_light_paths(&self) -> bool {
        false
    }

    fn sample_indices_per_prepare(&self) -> Option<u32> {
        Some(1)
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
        stats.rays_traced += self
            .photon_rays
            .swap(0, std::sync::atomic::Ordering::Relaxed);
        let paths = CameraPaths {
            tracer: self.tracer(),
            maps: &self.maps,
        };
        for pixel in tile.bounds().pixels() {
            for s in work.samples_of(pixel) {
                debug_assert_eq!(Some(s), self.iteration, "one photon pass per sample index");
                let mut cs = CameraSample::start(tile, work, pixel, s);
                // The stream's wavelength dimension is not read: the pass's set is used.
                let _ = cs.stream.get_1d();
                let mut wavelengths = LaneWavelengths::new(self.wavelengths);
                let mut gather = CausticGather {
                    radius_m: self.sppm.as_ref().map(|s| s.pixel(pixel).radius_m() as f32),
                    found: 0,
                    count_only: false,
                };
                let scale = work.pass.differential_scale(pixel);
                let result = camera_ray(scene, &cs, scale).map(|ray| {
                    paths.radiance(
                        scene,
                        &ray,
                        scale,
                        &mut wavelengths,
                        &mut cs.stream,
                        &mut gather,
                        &mut counters,
                    )
                });
                if let Some(stats) = &self.sppm {
                    stats.record(pixel, gather.found);
                }
                let sensor = wavelengths.sensor();
                let xyz_weights = XyzWeights::new(sensor);
                cs.add_to_tile(tile, scene, pixel, sensor, &xyz_weights, result, &mut stats);
            }
        }
        stats.add_path_counters(&counters);
        stats
    }
}
