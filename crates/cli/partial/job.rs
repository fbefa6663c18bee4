//! One `prism render` pass with a sample range, checkpoints, a resumed film and Ctrl-C:
//! the plan of the range, the film (fresh or restored bit for bit from `--resume`), the
//! driver's controlled pass, and the partial files it writes on the way.

use std::path::{Path, PathBuf};
use std::time::Instant;

use prism_bandwidth::SamplePlan;
use prism_render::integrator::Pass;
use prism_render::{
    film_for, render_pass_controlled, AovPlane, Film, FilmImage, PassControl, RenderScene,
    RenderSettings, RenderStats,
};
use prism_scene::SceneDescription;

use super::file::{checkpoint_path, read_partial, write_partial, PartialHeader};
use super::identity::{scene_content_hash, RenderIdentity};
use super::range::SampleRange;
use crate::plan_args::PlanArg;
use crate::progress::Progress;
use crate::render::RenderArgs;

/// What a pass left.
pub struct Rendered {
    pub image: FilmImage,
    /// The film itself: its sums (`Film::sums`, as large as the film) are made only when a
    /// partial file is written.
    pub film: Film,
    pub stats: RenderStats,
    pub complete: bool,
    pub items_done: usize,
    pub range: SampleRange,
    pub plan: Option<Vec<u32>>,
    pub identity: RenderIdentity,
    /// Seconds spent by earlier runs (a resumed checkpoint's).
    pub earlier_wall_time_s: f64,
    pub wall_time_s: f64,
    pub checkpoint: PathBuf,
}

impl Rendered {
    /// The header of a partial file of this state.
    pub fn header(&self) -> PartialHeader {
        PartialHeader {
            identity_hash: self.identity.hash(),
            identity: self
                .identity
                .fields
                .iter()
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
            range: self.range,
            ranges_done: if self.complete {
                vec![self.range]
            } else {
                Vec::new()
            },
            complete: self.complete,
            items_done: self.items_done,
            wall_time_s: self.earlier_wall_time_s + self.wall_time_s,
        }
    }

    /// Writes the partial file of this state to `path`.
    pub fn write_partial(&self, path: &Path) -> Result<(), String> {
        write_partial(
            path,
            &self.image,
            &self.header(),
            &self.film.sums(),
            self.plan.as_deref(),
        )
    }
}

/// The identity of the render `args` ask for (docs: `identity.rs`).
pub fn identity(
    args: &RenderArgs,
    description: &SceneDescription,
    scene: &RenderScene,
    settings: &RenderSettings,
    film: &Film,
) -> RenderIdentity {
    let sel = film.aov_selection();
    let plan = match args.plan.plan {
        PlanArg::Uniform => "uniform".to_string(),
        PlanArg::Predicted | PlanArg::PredictedHier | PlanArg::Adaptive => format!(
            "{} nb={} floor={} allocation={:?} visibility={:?} variance={:?} colour={:?} pool={} \
             indirect={} probe_stride={} max_level={}",
            args.plan.plan.name(),
            args.plan.nb(),
            args.plan.floor(),
            args.plan.allocation_arg(),
            args.plan.visibility(),
            args.plan.variance(),
            args.plan.colour(),
            args.plan.pool_radius(),
            args.plan.indirect(),
            args.plan.probe_stride(),
            args.plan.max_level()
        ),
    };
    RenderIdentity {
        fields: vec![
            ("scene", format!("{:016x}", scene_content_hash(description))),
            ("spp", settings.spp.to_string()),
            ("seed", settings.seed.to_string()),
            (
                "resolution",
                format!("{}x{}", scene.resolution.x, scene.resolution.y),
            ),
            (
                "integrator",
                match args.bdpt_strategy {
                    Some(s) => format!("{} strategy {:?}", scene.integrator.name(), s),
                    None => scene.integrator.name().to_string(),
                },
            ),
            ("sampler", format!("{:?}", settings.sampler).to_lowercase()),
            ("plan", plan),
            (
                "spectral_bins",
                settings.spectral_bins.map_or(0, |b| b.count()).to_string(),
            ),
            (
                "aovs",
                format!(
                    "depth={} normal={} albedo={} illumination={} variance={}",
                    sel.depth, sel.normal, sel.albedo, sel.illumination, sel.variance
                ),
            ),
        ],
    }
}

/// The plan of the samples of `range` when the whole render's plan is `plan` (N =
/// `total` samples per pixel on average): pixel p gets [⌊a·N_p/N⌋, ⌊b·N_p/N⌋) of its own
/// sequence. Returns the plan and the pass's first sample.
fn range_plan(
    plan: &SamplePlan,
    uniform: bool,
    range: SampleRange,
    total: u32,
) -> Result<(SamplePlan, u32), String> {
    let resolution = plan.resolution();
    if uniform {
        let p = SamplePlan::uniform(resolution, range.len()).map_err(|e| e.to_string())?;
        return Ok((p, range.start));
    }
    let pixels =
        (0..resolution.y).flat_map(|y| (0..resolution.x).map(move |x| glam::UVec2::new(x, y)));
    let mut counts = Vec::new();
    let mut lights = Vec::new();
    let mut firsts = Vec::new();
    for p in pixels {
        let own = range.of_pixel(plan.camera_samples(p), total);
        counts.push(own.len());
        lights.push(plan.light_samples(p));
        firsts.push(plan.first_sample(p) + own.start);
    }
    let mut out = SamplePlan::from_counts(resolution, counts, lights).map_err(|e| e.to_string())?;
    if range.start > 0 || plan.has_per_pixel_first_samples() {
        out = out.with_first_samples(firsts).map_err(|e| e.to_string())?;
    }
    Ok((out, 0))
}

/// What a range of a render whose passes depend on the passes before replays first, and
/// what that costs (`photon_progressive`'s per-pixel statistics); `None` when nothing is
/// replayed.
fn replay_note(scene: &RenderScene, range: SampleRange) -> Option<String> {
    let prism_render::Integrator::Photon(mapper) = &scene.integrator else {
        return None;
    };
    if !mapper.is_progressive() || range.start == 0 {
        return None;
    }
    let photons = mapper
        .plan(scene)
        .map(|p| {
            format!(
                "{} photons",
                u64::from(p.photons_per_pass) * u64::from(range.start)
            )
        })
        .unwrap_or_else(|_| "their photons".to_string());
    Some(format!(
        "{} replays the per-pixel statistics of passes 0..{} before it renders {range}: the \
         photon tracing of {} passes ({photons}) and each pixel's camera path of every one of \
         them up to its first diffuse vertex, none of it added to the image (a part saves no \
         photon work of the passes before it; docs/scale-out.md)",
        mapper.name(),
        range.start,
        range.start
    ))
}

/// Renders the range of `args` (or the resumed checkpoint's) of `plan` into a film and
/// returns it with what it did. `extra_aovs` are added to the image (the predictor's).
#[allow(clippy::too_many_arguments)]
pub fn render(
    args: &RenderArgs,
    description: &SceneDescription,
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: &SamplePlan,
    extra_aovs: Vec<AovPlane>,
    output: &Path,
    pool: &rayon::ThreadPool,
) -> Result<Rendered, String> {
    let mut film = film_for(scene, settings);
    let identity = identity(args, description, scene, settings, &film);
    let per_pixel_plan = args.plan.plan != PlanArg::Uniform;
    let plan_counts: Option<Vec<u32>> = per_pixel_plan.then(|| {
        let r = plan.resolution();
        (0..r.y)
            .flat_map(|y| (0..r.x).map(move |x| glam::UVec2::new(x, y)))
            .map(|p| plan.camera_samples(p))
            .collect()
    });
    let total = settings.spp;
    let mut range = args.samples.unwrap_or(SampleRange {
        start: 0,
        end: total,
    });
    if range.end > total {
        return Err(format!(
            "--samples {range}: the range ends past the render's {total} samples per pixel \
             (--spp {total}); expected A..B with B ≤ spp"
        ));
    }
    let mut items_done = 0;
    let mut earlier_wall_time_s = 0.0;
    if let Some(path) = &args.resume {
        let saved = read_partial(path)?;
        let differences = identity.differences(&saved.header.identity);
        if !differences.is_empty() {
            return Err(format!(
                "cannot resume {}: it is a part of another render; what changed: {}",
                path.display(),
                differences.join("; ")
            ));
        }
        if args.samples.is_some_and(|r| r != saved.header.range) {
            return Err(format!(
                "cannot resume {}: it renders the samples {}, this run asks for --samples {range}",
                path.display(),
                saved.header.range
            ));
        }
        if saved.plan != plan_counts {
            return Err(format!(
                "cannot resume {}: plan: the per-pixel sample plan computed now differs from \
                 the one stored in the file",
                path.display()
            ));
        }
        range = saved.header.range;
        film.set_sums(&saved.sums)
            .map_err(|e| format!("cannot resume {}: {e}", path.display()))?;
        items_done = saved.header.items_done;
        earlier_wall_time_s = saved.header.wall_time_s;
        if saved.header.complete {
            eprintln!(
                "{}: every sample of {range} is already in it; writing the output",
                path.display()
            );
        }
    }
    let (pass_plan, first_sample) = range_plan(plan, !per_pixel_plan, range, total)?;
    if let Some(line) = replay_note(scene, range) {
        eprintln!("{}: {line}", args.scene.display());
    }
    let checkpoint = checkpoint_path(output);
    let start = Instant::now();
    let progress = Progress::start(
        args.progress,
        args.progress_every,
        pass_plan.total_camera_samples(),
        &args.scene.display().to_string(),
    );
    let write_checkpoint = |film: &Film, items: usize| {
        let rendered = Rendered {
            image: film.finish(),
            film: film.clone(),
            stats: RenderStats::default(),
            complete: false,
            items_done: items,
            range,
            plan: plan_counts.clone(),
            identity: identity.clone(),
            earlier_wall_time_s,
            wall_time_s: start.elapsed().as_secs_f64(),
            checkpoint: checkpoint.clone(),
        };
        if let Err(e) = rendered.write_partial(&checkpoint) {
            eprintln!("warning: {e}");
        }
    };
    let control = PassControl {
        stop: super::signals::stop_flag(),
        resumed: args.resume.is_some(),
        items_done,
        checkpoint: args
            .checkpoint_every
            .map(|every| (every, &write_checkpoint as &(dyn Fn(&Film, usize) + Sync))),
    };
    let pass = Pass {
        index: u32::from(first_sample > 0),
        settings,
        plan: &pass_plan,
        first_sample,
        footprint_plan: Some(plan),
    };
    let items = std::sync::atomic::AtomicUsize::new(0);
    let on_item = |n: u64| {
        progress.inc(n);
        let done = items.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if args.stop_after_items.is_some_and(|stop| done >= stop) {
            super::signals::stop_flag().store(true, std::sync::atomic::Ordering::SeqCst);
        }
    };
    let outcome = pool.install(|| {
        let mut estimator = scene.integrator.estimator();
        render_pass_controlled(
            estimator.as_mut(),
            scene,
            &pass,
            &mut film,
            &on_item,
            &control,
        )
    });
    progress.finish();
    let outcome = outcome.map_err(|e| format!("{}: {e}", args.scene.display()))?;
    let wall_time_s = start.elapsed().as_secs_f64();
    let mut image = film.finish();
    image.aovs.extend(extra_aovs);
    Ok(Rendered {
        image,
        film,
        stats: outcome.stats,
        complete: outcome.complete,
        items_done: outcome.items_done,
        range,
        plan: plan_counts,
        identity,
        earlier_wall_time_s,
        wall_time_s,
        checkpoint,
    })
}
