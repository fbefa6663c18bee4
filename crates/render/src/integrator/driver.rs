//! The driver: runs any `Estimator` over the film — tiles (or tile × sample-range work
//! items for estimators that splat light paths) in parallel on the current rayon pool,
//! every camera sample seeded by (seed, pixel, sample index) through `PixelSampler`, never
//! by thread, and results merged in a fixed order, so the image is bit-identical for any
//! thread count. It has no case per method: `Integrator` dispatches to the estimators.
//!
//! The stream's dimensions: `integrator::dimensions`.

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use glam::UVec2;
use rayon::prelude::*;

use super::estimator::{Estimator, Pass, TileWork};
use super::PathCounters;
use crate::film::{AovSelection, Film, FilmImage, FilmTile, LightSplats, SpectralBins, TileBounds};
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
    /// Record the `variance.Y` AOV (`AovSelection::variance`).
    pub variance_aov: bool,
}

impl RenderSettings {
    /// The density the film these settings ask for draws wavelengths from
    /// (`film_wavelength_density`).
    pub fn wavelength_density(&self) -> prism_spectrum::WavelengthDensity {
        crate::film::film_wavelength_density(self.spectral_bins.is_some())
    }
}

impl Default for RenderSettings {
    /// 16 spp, seed 0, 16-pixel tiles, Sobol, no spectral bins, no illumination or variance AOV.
    fn default() -> Self {
        Self {
            spp: 16,
            seed: 0,
            tile_size_px: DEFAULT_TILE_SIZE_PX,
            sampler: SamplerKind::Sobol,
            spectral_bins: None,
            illumination_aov: false,
            variance_aov: false,
        }
    }
}

/// The scene's film with the spectral bins and illumination AOV `settings` ask for: what
/// `render_plan` renders into, and what `render_pass` accumulates pass after pass.
pub fn film_for(scene: &RenderScene, settings: &RenderSettings) -> Film {
    let mut film = scene.new_film();
    if settings.illumination_aov || settings.variance_aov {
        let selection = film.aov_selection();
        let aovs = AovSelection {
            illumination: selection.illumination || settings.illumination_aov,
            variance: selection.variance || settings.variance_aov,
            ..selection
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
    /// Light paths traced (light tracing, BDPT).
    pub light_paths: u64,
    /// Medium boundaries a path met from a medium other than the one declared on that side
    /// (`PathCounters::medium_mismatches`).
    pub medium_mismatches: u64,
}

impl RenderStats {
    /// Adds another item's counts.
    pub fn add(&mut self, other: &RenderStats) {
        self.rays_traced += other.rays_traced;
        self.samples += other.samples;
        self.non_finite_samples += other.non_finite_samples;
        self.bounces += other.bounces;
        self.roulette_terminations += other.roulette_terminations;
        self.non_finite_contributions += other.non_finite_contributions;
        self.light_paths += other.light_paths;
        self.medium_mismatches += other.medium_mismatches;
    }

    /// Adds a path tracer's counters.
    pub fn add_path_counters(&mut self, c: &PathCounters) {
        self.rays_traced += c.rays;
        self.bounces += c.bounces;
        self.roulette_terminations += c.roulette_terminations;
        self.non_finite_contributions += c.non_finite_contributions;
        self.medium_mismatches += c.medium_mismatches;
    }
}

/// Why a render pass could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderError {
    /// The sample plan does not fit the film.
    Plan(BandwidthError),
    /// The estimator refused the scene (its `prepare` said why).
    Estimator(String),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Plan(e) => write!(f, "{e}"),
            RenderError::Estimator(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for RenderError {}

impl From<BandwidthError> for RenderError {
    fn from(e: BandwidthError) -> Self {
        RenderError::Plan(e)
    }
}

/// Renders `scene` with its integrator and the uniform plan (`settings.spp` camera samples
/// and one light sample per hit everywhere) and returns the finished film with statistics.
/// `progress` is called after each work item with the number of camera samples it took.
/// Panics when the scene's estimator refuses the scene, which `RenderScene::build` checks
/// for every scene it builds (a scene whose integrator was replaced afterwards goes through
/// `render_plan` or `render_pass`, which return the error).
pub fn render(
    scene: &RenderScene,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> (FilmImage, RenderStats) {
    let plan = SamplePlan::uniform(scene.resolution, settings.spp.max(1))
        .expect("the resolution was checked when the camera frame was built");
    match render_plan(scene, settings, &plan, progress) {
        Ok(result) => result,
        Err(e) => panic!("render: {e}"),
    }
}

/// Renders `scene` executing `plan` (prism-bandwidth): per pixel its camera samples (0 is
/// allowed: the pixel stays empty, `spp.Y` = 0) and per hit its light samples. Errors when
/// the plan's resolution is not the film's or the estimator refuses the scene.
/// `settings.spp` is ignored.
pub fn render_plan(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: &SamplePlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(FilmImage, RenderStats), RenderError> {
    plan.check_resolution(scene.resolution)?;
    let mut film = film_for(scene, settings);
    let stats = render_pass(scene, settings, plan, &mut film, 0, progress)?;
    Ok((film.finish(), stats))
}

/// One pass of a progressive render with the scene's own integrator: adds to `film` (from
/// `film_for`) the camera samples `first_sample .. first_sample + plan.camera_samples(pixel)`
/// of every pixel. Sample indices continue the same per-pixel sequence (Sobol points,
/// independent hashes), so passes over [0, a), [a, b), … give the film of one render of b
/// samples, up to the order of the f64 additions (`prism converge`, tested). Errors when
/// the plan's or the film's resolution is not the scene's. `settings.spp` is ignored.
pub fn render_pass(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: &SamplePlan,
    film: &mut Film,
    first_sample: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderStats, RenderError> {
    let mut estimator = scene.integrator.estimator();
    let pass_index = u32::from(first_sample > 0);
    render_pass_with(
        estimator.as_mut(),
        scene,
        &Pass {
            index: pass_index,
            settings,
            plan,
            first_sample,
            footprint_plan: None,
        },
        film,
        progress,
    )
}

/// Work items of estimators that splat are cut to about this many light paths, so that an
/// item's splat list stays well under a megabyte.
const LIGHT_PATHS_PER_ITEM: u32 = 4096;
/// Work items rendered in parallel before their splats are merged in order: bounds the
/// memory held by finished items.
const ITEMS_PER_BATCH: usize = 32;

/// One pass of `estimator` over `film` (the driver of every method): `prepare`, then every
/// work item in parallel on the current rayon pool, merged in a fixed order so the film is
/// bit-identical for any number of threads.
pub fn render_pass_with(
    estimator: &mut (impl Estimator + ?Sized),
    scene: &RenderScene,
    pass: &Pass,
    film: &mut Film,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderStats, RenderError> {
    let never = AtomicBool::new(false);
    let control = PassControl {
        stop: &never,
        resumed: false,
        items_done: 0,
        checkpoint: None,
    };
    render_pass_controlled(estimator, scene, pass, film, progress, &control).map(|o| o.stats)
}

/// What may interrupt a pass and what it saves on the way (`prism render --checkpoint-every`,
/// `--resume`, Ctrl-C).
pub struct PassControl<'a> {
    /// Once set, no further work item starts; the items in flight finish and are merged.
    pub stop: &'a AtomicBool,
    /// The film is a checkpoint of this same pass (not the sum of earlier passes): tiles
    /// whose pixels hold all the pass's samples already are skipped. False for a pass that
    /// adds to a film of earlier passes (progressive renders, photon passes).
    pub resumed: bool,
    /// Work items already in the film (`PassOutcome::items_done` of the checkpoint being
    /// resumed; 0 for a fresh film). Only estimators whose items must be merged in order
    /// use it; the others skip the tiles whose pixels already hold all their samples.
    pub items_done: usize,
    /// At most every `Duration`, between work items, the film so far and the items done:
    /// a consistent state to resume from (the callback writes the checkpoint).
    pub checkpoint: Option<(Duration, &'a CheckpointFn<'a>)>,
}

/// Receives the film so far and the work items done (see `PassControl::checkpoint`).
pub type CheckpointFn<'a> = dyn Fn(&Film, usize) + Sync + 'a;

/// How far a controlled pass got.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassOutcome {
    pub stats: RenderStats,
    /// Work items in the film (for resuming the ordered kind: see `PassControl`).
    pub items_done: usize,
    /// Every work item of the pass is in the film.
    pub complete: bool,
}

/// A checkpoint is due when `every` has passed since the last one.
struct CheckpointClock<'a> {
    last: Mutex<Instant>,
    every: Duration,
    write: &'a CheckpointFn<'a>,
}

impl CheckpointClock<'_> {
    fn due(&self) -> bool {
        self.last
            .lock()
            .map(|mut last| {
                if last.elapsed() >= self.every {
                    *last = Instant::now();
                    true
                } else {
                    false
                }
            })
            .unwrap_or(false)
    }
}

/// [`render_pass_with`] that stops when `control.stop` is set, continues a film restored
/// from a checkpoint, and hands out checkpoints. The film it leaves is the film of an
/// uninterrupted pass restricted to the items done, and continuing it (a second call with
/// `items_done` from the outcome) gives the uninterrupted film bit for bit: items are
/// merged either into pixels that nothing else touches (tiles of an estimator that writes
/// its own pixels only, on a film that does not splat) or in item order.
pub fn render_pass_controlled(
    estimator: &mut (impl Estimator + ?Sized),
    scene: &RenderScene,
    pass: &Pass,
    film: &mut Film,
    progress: &(dyn Fn(u64) + Sync),
    control: &PassControl,
) -> Result<PassOutcome, RenderError> {
    pass.plan.check_resolution(scene.resolution)?;
    pass.plan.check_resolution(film.resolution())?;
    if estimator.splats_light_paths() && pass.plan.has_per_pixel_first_samples() {
        // Their work items are sample ranges shared by a whole tile: a plan whose pixels
        // all start at one index (`prism converge`'s uniform passes) is the uniform plan
        // moved by that index; any other is refused.
        let Some(first) = uniform_first_sample(pass.plan) else {
            return Err(RenderError::Estimator(format!(
                "{} takes the same samples in every pixel: a plan whose pixels start their \
                 samples at different indices (a predicted or adaptive plan) is for `path`",
                estimator.name()
            )));
        };
        let plan = plan_counts(pass.plan)?;
        let moved = Pass {
            first_sample: pass.first_sample + first,
            plan: &plan,
            ..*pass
        };
        return render_pass_controlled(estimator, scene, &moved, film, progress, control);
    }
    if let Some(per_prepare) = estimator.sample_indices_per_prepare() {
        return render_in_sample_steps(
            estimator,
            scene,
            pass,
            film,
            progress,
            per_prepare,
            control,
        );
    }
    estimator
        .prepare(scene, pass)
        .map_err(RenderError::Estimator)?;
    run_prepared(&*estimator, scene, pass, film, progress, control)
}

/// `render_pass_with` for an estimator that prepares every `per_prepare` sample indices:
/// the pass cut into passes of at most that many indices, `prepare` before each. The
/// pixels' sample ranges must start at the same index. The steps are the pass's work items:
/// a stop request ends the pass between steps, checkpoints are handed out between steps
/// with the steps done, and a resumed pass starts at the next step.
fn render_in_sample_steps(
    estimator: &mut (impl Estimator + ?Sized),
    scene: &RenderScene,
    pass: &Pass,
    film: &mut Film,
    progress: &(dyn Fn(u64) + Sync),
    per_prepare: u32,
    control: &PassControl,
) -> Result<PassOutcome, RenderError> {
    let resolution = pass.plan.resolution();
    let Some(first) = uniform_first_sample(pass.plan) else {
        return Err(RenderError::Estimator(format!(
            "{} renders one pass per sample index, the same in every pixel: a plan whose \
             pixels start their samples at different indices (a predicted or adaptive plan) \
             is for `path`",
            estimator.name()
        )));
    };
    let counts: Vec<u32> = pixels_of(resolution)
        .map(|p| pass.plan.camera_samples(p))
        .collect();
    let light: Vec<u32> = pixels_of(resolution)
        .map(|p| pass.plan.light_samples(p))
        .collect();
    let most = counts.iter().copied().max().unwrap_or(0);
    let n = counts.len();
    let step = per_prepare.max(1);
    let mut total = RenderStats::default();
    // The work items of such a pass are its steps: a checkpoint holds the film of the steps
    // done, and resuming it continues with the next step (an estimator that keeps state
    // across steps, photon_progressive's per-pixel radii, replays the steps before it).
    let mut steps_done = if control.resumed {
        control.items_done
    } else {
        0
    };
    let mut k = u32::try_from(steps_done)
        .ok()
        .and_then(|s| s.checked_mul(step))
        .unwrap_or(u32::MAX);
    let clock = control.checkpoint.map(|(every, write)| CheckpointClock {
        last: Mutex::new(Instant::now()),
        every,
        write,
    });
    let never = AtomicBool::new(false);
    let step_control = PassControl {
        stop: &never,
        resumed: false,
        items_done: 0,
        checkpoint: None,
    };
    while k < most {
        if control.stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Ok(PassOutcome {
                stats: total,
                items_done: steps_done,
                complete: false,
            });
        }
        let sub_counts: Vec<u32> = counts
            .iter()
            .map(|c| c.saturating_sub(k).min(step))
            .collect();
        let plan = SamplePlan::from_counts(resolution, sub_counts, light.clone())?
            .with_first_samples(vec![first + k; n])?;
        let sub = Pass {
            index: pass.index + k,
            plan: &plan,
            ..*pass
        };
        estimator
            .prepare(scene, &sub)
            .map_err(RenderError::Estimator)?;
        let outcome = run_prepared(&*estimator, scene, &sub, film, progress, &step_control)?;
        total.add(&outcome.stats);
        k = k.saturating_add(step);
        steps_done += 1;
        if let Some(clock) = &clock {
            if k < most && clock.due() {
                (clock.write)(film, steps_done);
            }
        }
    }
    Ok(PassOutcome {
        stats: total,
        items_done: steps_done,
        complete: true,
    })
}

/// The pixels of a `resolution` film, row-major (the plans' order).
fn pixels_of(resolution: UVec2) -> impl Iterator<Item = UVec2> {
    (0..resolution.y).flat_map(move |y| (0..resolution.x).map(move |x| UVec2::new(x, y)))
}

/// The index every pixel of `plan` starts at, if they all start at one.
fn uniform_first_sample(plan: &SamplePlan) -> Option<u32> {
    let first = plan.first_sample(UVec2::ZERO);
    pixels_of(plan.resolution())
        .all(|p| plan.first_sample(p) == first)
        .then_some(first)
}

/// `plan`'s counts without its per-pixel first samples.
fn plan_counts(plan: &SamplePlan) -> Result<SamplePlan, RenderError> {
    let resolution = plan.resolution();
    let counts = pixels_of(resolution)
        .map(|p| plan.camera_samples(p))
        .collect();
    let light = pixels_of(resolution)
        .map(|p| plan.light_samples(p))
        .collect();
    Ok(SamplePlan::from_counts(resolution, counts, light)?)
}

/// Every work item of a prepared pass, in parallel, merged in a fixed order, under
/// `control` (see [`render_pass_controlled`]).
fn run_prepared(
    estimator: &(impl Estimator + ?Sized),
    scene: &RenderScene,
    pass: &Pass,
    film: &mut Film,
    progress: &(dyn Fn(u64) + Sync),
    control: &PassControl,
) -> Result<PassOutcome, RenderError> {
    let sampler = PixelSampler::with_kind(pass.settings.sampler, pass.settings.seed);
    let uses_lens = scene.camera.uses_lens_sample();
    let tile_size_px = pass.settings.tile_size_px;
    let all_samples = pass.first_sample..u32::MAX;
    let clock = control.checkpoint.map(|(every, write)| CheckpointClock {
        last: Mutex::new(Instant::now()),
        every,
        write,
    });
    let stop = control.stop;
    if !estimator.splats_light_paths() && !film.splats() {
        // Tiles write their own pixels only: each is added once into pixels at zero, in
        // whatever order they finish (same bits as any order), under a lock so that a
        // checkpoint sees whole tiles. Tiles whose pixels hold all their samples already
        // (a resumed checkpoint) are skipped.
        let all_tiles = film.tiles(tile_size_px);
        let tiles: Vec<TileBounds> = all_tiles
            .iter()
            .copied()
            .filter(|b| {
                !(control.resumed
                    && b.pixels()
                        .all(|p| film.sample_count(p) == pass.plan.camera_samples(p)))
            })
            .collect();
        let skipped = all_tiles.len() - tiles.len();
        let maker = film.tile_maker();
        let no_splats = film.unused_light_splats();
        let shared = Mutex::new((&mut *film, RenderStats::default(), skipped));
        tiles.par_iter().for_each(|bounds| {
            if stop.load(Ordering::Relaxed) {
                return;
            }
            let work = TileWork {
                pass,
                sampler: &sampler,
                sample_indices: all_samples.clone(),
                uses_lens,
            };
            let mut tile = maker.new_tile(*bounds);
            let mut splats = no_splats.clone();
            let stats = estimator.render_tile(scene, &work, &mut tile, &mut splats);
            debug_assert_eq!(splats.splat_count(), 0, "{} splats", estimator.name());
            progress(stats.samples);
            if let Ok(mut guard) = shared.lock() {
                let (film, total, done) = &mut *guard;
                film.merge_tile(&tile);
                total.add(&stats);
                *done += 1;
                if let Some(clock) = &clock {
                    if clock.due() {
                        (clock.write)(film, *done);
                    }
                }
            }
        });
        let (_, stats, done) = shared
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        return Ok(PassOutcome {
            stats,
            items_done: done,
            complete: done == all_tiles.len(),
        });
    }
    // Estimators that splat light paths (and films that splat): tiles cut into sample
    // ranges of about LIGHT_PATHS_PER_ITEM camera samples (one light path each), merged
    // in item order.
    let mut items = Vec::new();
    for bounds in film.tiles(tile_size_px) {
        if !estimator.splats_light_paths() {
            items.push((bounds, all_samples.clone()));
            continue;
        }
        let most = bounds
            .pixels()
            .map(|p| pass.plan.camera_samples(p))
            .max()
            .unwrap_or(0);
        let chunk = (LIGHT_PATHS_PER_ITEM / bounds.pixel_count().max(1) as u32).max(1);
        let mut k = 0u32;
        while k < most {
            let end = k.saturating_add(chunk).min(most);
            let start = pass.first_sample.saturating_add(k);
            items.push((bounds, start..pass.first_sample.saturating_add(end)));
            k = end;
        }
    }
    let template = if estimator.splats_light_paths() {
        film.light_splats()
    } else {
        film.unused_light_splats()
    };
    let mut total = RenderStats::default();
    let mut done = control.items_done.min(items.len());
    while done < items.len() && !stop.load(Ordering::Relaxed) {
        let batch = &items[done..(done + ITEMS_PER_BATCH).min(items.len())];
        let film_ref = &*film;
        let template = &template;
        let results: Vec<Option<(FilmTile, LightSplats, RenderStats)>> = batch
            .par_iter()
            .map(|(bounds, range)| {
                if stop.load(Ordering::Relaxed) {
                    return None;
                }
                let work = TileWork {
                    pass,
                    sampler: &sampler,
                    sample_indices: range.clone(),
                    uses_lens,
                };
                let mut tile = film_ref.new_tile(*bounds);
                tile.set_sample_weights(pass.plan);
                let mut splats = template.clone();
                let stats = estimator.render_tile(scene, &work, &mut tile, &mut splats);
                progress(stats.samples);
                Some((tile, splats, stats))
            })
            .collect();
        // The longest finished prefix: later items wait for a resume, in order.
        for (tile, splats, stats) in results.iter().map_while(Option::as_ref) {
            film.merge_tile(tile);
            if estimator.splats_light_paths() {
                film.merge_light_splats(splats);
            }
            total.add(stats);
            done += 1;
        }
        if let Some(clock) = &clock {
            if done < items.len() && clock.due() {
                (clock.write)(film, done);
            }
        }
    }
    Ok(PassOutcome {
        stats: total,
        items_done: done,
        complete: done == items.len(),
    })
}

/// Total camera samples of a render: pixels × spp (for progress bars).
pub fn total_samples(resolution: UVec2, spp: u32) -> u64 {
    u64::from(resolution.x) * u64::from(resolution.y) * u64::from(spp.max(1))
}
