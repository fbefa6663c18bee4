//! `prism converge SCENE.json [--reference REF.exr] [--method M]… [--budget-s S]
//! [--max-spp N] [--checkpoints N] -o CHART.png|svg… [--json DATA.json]`: error against
//! time for each method (issue 6). Each method renders progressively (`progressive`); at
//! every checkpoint the RMSE, relMSE and mean ΔE2000 against the reference are recorded
//! (the metrics of `prism compare`, computed off the render threads); the chart (`chart`)
//! and JSON carry the log–log slopes (`fit`). Methods: `method`. Reference: `reference`.
//! See docs/converge.md.

mod chart;
mod fit;
mod method;
mod pass_planner;
mod progressive;
mod ratios;
mod reference;
mod report;

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use glam::UVec2;
use prism_cpu::memory::MemoryBudget;
use prism_image::io::write_image;
use prism_image::Image;
use prism_post::metrics::PreparedReference;
use prism_render::bsdf_table_cache::AngularTableCache;
use prism_render::film::{AovSelection, FilmMemory};
use prism_render::integrator::DEFAULT_TILE_SIZE_PX;
use prism_render::{render, RenderScene, RenderSettings, SamplerKind};
use serde_json::{json, Value};

use chart::{Curve, PANELS};

const PANEL_COUNT: usize = PANELS.len();
use fit::{first_crossing, PowerFit};
use method::Method;
use progressive::{film_to_image, run_method, run_plain, Budget, MethodRun};
use reference::{load_reference, ReferenceKey};

/// relMSE that the time-to-error column of docs/methods.md refers to.
pub const TARGET_RELMSE: f64 = 1e-2;
/// Default spp of a reference rendered by `prism converge`.
pub const DEFAULT_REFERENCE_SPP: u32 = 1024;
/// Default time budget per method when neither --budget-s nor --max-spp is given, s.
pub const DEFAULT_BUDGET_S: f64 = 10.0;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// The scene file (JSON, docs/scene-format.md).
    pub scene: PathBuf,
    /// The converged image to measure against (EXR, HDR or PNG, the render's size, linear
    /// like `prism render`'s EXR). Left out: one is rendered with Owen-scrambled Sobol at
    /// --reference-spp and cached in --cache-dir (`<stem>.reference-WxH-Nspp-HASH.exr`).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Where rendered references and the predictor's BSDF angular tables are cached
    /// (created if missing; default $XDG_CACHE_HOME/prism, else ~/.cache/prism).
    #[arg(long = "cache-dir", value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Samples per pixel of a reference rendered because --reference was left out.
    #[arg(long = "reference-spp", default_value_t = DEFAULT_REFERENCE_SPP, value_parser = prism_args::numbers::parse_spp)]
    pub reference_spp: u32,
    /// A method, INTEGRATOR[+PLAN][:SAMPLER] (repeat for several; default `path`, the path
    /// tracer with the uniform plan and the independent sampler). Integrators: path, light,
    /// bdpt, photon, photon_progressive, radiosity, ambient_occlusion, depth, normal,
    /// albedo; plans: uniform, predicted, predicted-hier, adaptive, oracle (path only);
    /// samplers: independent, sobol.
    #[arg(long = "method", value_name = "METHOD")]
    pub methods: Vec<String>,
    /// Time budget per method, seconds, on the --clock (wall or render CPU time; default 10
    /// unless --max-spp is given).
    #[arg(long = "budget-s", value_name = "S")]
    pub budget_s: Option<f64>,
    /// Samples per pixel per method at most; alone, it makes the checkpoint schedule
    /// deterministic (1 spp to N spp, geometric).
    #[arg(long = "max-spp", value_name = "N", value_parser = prism_args::numbers::parse_spp)]
    pub max_spp: Option<u32>,
    /// Checkpoints per method (geometrically spaced, ≥ 3).
    #[arg(long, default_value_t = 12, value_parser = prism_args::numbers::parse_u32)]
    pub checkpoints: u32,
    /// Chart file (.png or .svg); repeat for both.
    #[arg(short = 'o', long = "output", value_name = "CHART")]
    pub outputs: Vec<PathBuf>,
    /// Write the checkpoints, fits and timings as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Film resolution override, WIDTHxHEIGHT (the reference must match).
    #[arg(long, value_parser = prism_args::resolution::parse_resolution)]
    pub resolution: Option<UVec2>,
    /// Worker threads (default: one per core; at most 4 per logical CPU).
    #[arg(long, value_parser = prism_cpu::threads::parse_thread_count)]
    pub threads: Option<usize>,
    /// Sampler seed of the methods (default: the scene's `film.seed`).
    #[arg(long, value_parser = prism_args::numbers::parse_u64)]
    pub seed: Option<u64>,
    /// Also render each method's final sample count in one pass without checkpoints and
    /// report the time converge added (wall and CPU), in the JSON and on stderr.
    #[arg(long)]
    pub overhead: bool,
    /// Write each method's last checkpoint image as EXR into this directory
    /// (`<n>-<method>.exr`), e.g. to check the numbers with `prism compare`.
    /// Write the study as one self-contained HTML page (images embedded): the chart, the
    /// methods' last checkpoints in a table, and each method's last image against the
    /// reference in a viewer with its FLIP and ΔE2000 maps.
    #[arg(long, value_name = "OUT.html")]
    pub report: Option<PathBuf>,
    #[arg(long = "save-final", value_name = "DIR")]
    pub save_final: Option<PathBuf>,
    /// For `path+oracle`: an EXR with a `variance.Y` layer (what `prism render -o X.exr`
    /// writes, best from many samples) whose measured variance sets the oracle's plan.
    #[arg(long = "oracle-variance", value_name = "FILE.exr")]
    pub oracle_variance: Option<PathBuf>,
    /// The time axis of the chart and fits: `wall` (elapsed time, the default) or `cpu`
    /// (CPU time of the render threads, which other processes on a shared machine do not
    /// stretch). Both are in the JSON either way.
    #[arg(long, value_enum, default_value_t = Clock::Wall)]
    pub clock: Clock,
    /// Chart title (default: the scene file's name and the resolution).
    #[arg(long)]
    pub title: Option<String>,
    #[command(flatten)]
    pub simd: crate::simd::SimdArgs,
}

/// The time axis of a convergence run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Clock {
    Wall,
    Cpu,
}

impl Clock {
    fn name(self) -> &'static str {
        match self {
            Clock::Wall => "wall",
            Clock::Cpu => "cpu",
        }
    }

    /// The axis label of the chart.
    fn axis(self) -> &'static str {
        match self {
            Clock::Wall => "wall time (s)",
            Clock::Cpu => "render CPU time, all threads (s)",
        }
    }

    fn of(self, c: &progressive::Checkpoint) -> f64 {
        match self {
            Clock::Wall => c.time_s,
            Clock::Cpu => c.cpu_time_s.unwrap_or(c.time_s),
        }
    }
}

fn check_arguments(args: &ConvergeArgs) -> Result<Budget, String> {
    if args.outputs.is_empty() && args.json.is_none() && args.report.is_none() {
        return Err(
            "nothing to write: give a chart with -o CHART.png|svg, --json and/or --report".into(),
        );
    }
    if let Some(r) = &args.report {
        crate::compare::check_report_path(r)?;
    }
    for o in &args.outputs {
        let ext = o
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "svg")) {
            return Err(format!(
                "chart {}: expected a .png or .svg file name",
                o.display()
            ));
        }
        crate::atomic_write::check_parent("chart", o)?;
    }
    if let Some(j) = &args.json {
        crate::atomic_write::check_parent("--json", j)?;
    }
    if let Some(d) = &args.save_final {
        if !d.is_dir() {
            return Err(format!(
                "--save-final {}: not an existing directory",
                d.display()
            ));
        }
    }
    if args.checkpoints < 3 {
        return Err(format!(
            "--checkpoints {}: at least 3 are needed to fit a slope and see its spread",
            args.checkpoints
        ));
    }
    if let Some(b) = args.budget_s {
        if !(b.is_finite() && b > 0.0) {
            return Err(format!(
                "--budget-s {b}: expected a positive number of seconds"
            ));
        }
    }
    if args.max_spp == Some(0) {
        return Err("--max-spp must be at least 1".into());
    }
    if args.reference_spp == 0 {
        return Err("--reference-spp must be at least 1".into());
    }
    Ok(Budget {
        time_s: match (args.budget_s, args.max_spp) {
            (Some(b), _) => b,
            (None, Some(_)) => f64::INFINITY,
            (None, None) => DEFAULT_BUDGET_S,
        },
        cpu_clock: args.clock == Clock::Cpu,
        max_spp: args.max_spp,
        checkpoints: args.checkpoints,
    })
}

/// The run's estimated memory checked against `memory` before the scene is built: the
/// reference's film and image, one method's film at a time, and the prepared reference
/// with a checkpoint's comparison.
fn check_memory(
    args: &ConvergeArgs,
    description: &prism_scene::SceneDescription,
    memory: &MemoryBudget,
) -> Result<(), String> {
    let [w, h] = description.film.resolution;
    let resolution = args.resolution.unwrap_or(UVec2::new(w, h));
    let film = FilmMemory {
        resolution,
        aovs: AovSelection::ALL,
        spectral_bins: 0,
        light_plane: true,
    };
    let pixels = u64::from(resolution.x) * u64::from(resolution.y);
    let estimate = film
        .total_bytes()
        .saturating_mul(2)
        .saturating_add(pixels.saturating_mul(prism_post::metrics::COMPARE_BYTES_PER_PIXEL));
    memory
        .check(
            &format!(
                "{}: converging {}×{} px",
                args.scene.display(),
                resolution.x,
                resolution.y
            ),
            estimate,
        )
        .map_err(|e| e.to_string())
}

/// The 1-minute load average and the logical CPU count (for the JSON: timings on a busy
/// machine read differently).
fn machine_load() -> Value {
    json!({
        "logical_cpus": std::thread::available_parallelism().map(|n| n.get()).ok(),
        "load_average_1m": prism_cpu::clock::load_average_1m(),
    })
}

fn integrator_description(integrator: &prism_render::Integrator) -> String {
    format!("{integrator:?}")
}

fn checkpoint_json(c: &progressive::Checkpoint) -> Value {
    json!({
        "time_s": c.time_s,
        "cpu_time_s": c.cpu_time_s,
        "spp": c.spp,
        "samples": c.samples,
        "rmse": c.comparison.rmse,
        "relmse": c.comparison.relmse,
        "mse": c.comparison.mse,
        "psnr_db": if c.comparison.psnr_db.is_finite() { json!(c.comparison.psnr_db) } else { Value::Null },
        "delta_e2000_mean": c.comparison.delta_e2000_mean,
        "delta_e2000_p95": c.comparison.delta_e2000_p95,
        "non_finite_pixels": c.comparison.non_finite_pixels,
    })
}

fn metric_of(c: &progressive::Checkpoint, m: usize) -> f64 {
    match m {
        0 => c.comparison.rmse,
        1 => c.comparison.relmse,
        _ => c.comparison.delta_e2000_mean,
    }
}

fn file_label(method: &Method) -> String {
    method
        .label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

pub fn run(args: &ConvergeArgs, memory: &MemoryBudget) -> Result<(), String> {
    args.simd.apply()?;
    let budget = check_arguments(args)?;
    // The cache must take the reference before one is rendered for it.
    let cache_dir = match &args.reference {
        Some(_) => None,
        None => Some(crate::cache_dir::prepare_cache_dir(
            args.cache_dir.as_deref(),
            "the reference cache",
            " or a --reference",
        )?),
    };
    let methods: Vec<Method> = if args.methods.is_empty() {
        vec![Method::parse("path")?]
    } else {
        args.methods
            .iter()
            .map(|m| Method::parse(m))
            .collect::<Result<_, _>>()?
    };
    if let Some(other) = methods
        .iter()
        .find(|m| m.quantity() != methods[0].quantity())
    {
        return Err(format!(
            "--method {} estimates {} but --method {} estimates {}: one run compares methods \
             for the same quantity against one reference",
            methods[0].label,
            methods[0].quantity(),
            other.label,
            other.quantity()
        ));
    }
    let scene_bytes = std::fs::read(&args.scene)
        .map_err(|e| format!("{}: cannot read the scene: {e}", args.scene.display()))?;
    let description = prism_scene::load_scene(&args.scene).map_err(|e| e.to_string())?;
    check_memory(args, &description, memory)?;
    let mut scene = RenderScene::build(&description, args.resolution).map_err(|e| e.to_string())?;
    let resolution = scene.resolution;
    // A user's reference is checked before anything renders or is written.
    let given_reference = match &args.reference {
        Some(path) => Some(load_reference(path, resolution)?),
        None => None,
    };
    let integrators: Vec<prism_render::Integrator> = methods
        .iter()
        .map(|m| m.integrator(&description.integrator))
        .collect::<Result<_, _>>()?;
    if integrators.iter().any(|i| i.is_spectral()) && scene.lights.is_empty() {
        return Err(format!(
            "{}: the scene has no lights: every path-traced image is black and there is no \
             error to chart",
            args.scene.display()
        ));
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool
        .build()
        .map_err(|e| format!("cannot start the thread pool: {e}"))?;
    let seed = args.seed.unwrap_or(scene.seed);
    let load_start = machine_load();

    // The reference: given, cached, or rendered now with Owen-scrambled Sobol and a seed
    // unrelated to the methods' (correlated noise would hide error).
    let (reference, reference_json) = match (given_reference, &args.reference) {
        (Some(image), Some(path)) => (image, json!({"path": path, "source": "given"})),
        _ => {
            let reference_seed = seed ^ 0x9e37_79b9_7f4a_7c15;
            let integrator = integrators[0];
            let key = ReferenceKey {
                scene_file: &args.scene,
                scene_bytes: &scene_bytes,
                resolution,
                spp: args.reference_spp,
                seed: reference_seed,
                integrator: integrator_description(&integrator),
                asset_files: &description.asset_files,
            };
            let path = key.cache_path(cache_dir.as_deref().unwrap_or(Path::new(".")));
            let cached = path
                .is_file()
                .then(|| load_reference(&path, resolution).ok());
            match cached.flatten() {
                Some(image) => {
                    eprintln!(
                        "reference: using the cached {} ({} spp, Owen-scrambled Sobol)",
                        path.display(),
                        args.reference_spp
                    );
                    (
                        image,
                        json!({"path": path, "source": "cached", "spp": args.reference_spp,
                               "sampler": "sobol", "seed": reference_seed}),
                    )
                }
                None => {
                    eprintln!(
                        "reference: none given, rendering one at {} spp (Owen-scrambled Sobol, \
                         {}×{} px) and caching it as {}",
                        args.reference_spp,
                        resolution.x,
                        resolution.y,
                        path.display()
                    );
                    scene.integrator = integrator;
                    let settings = RenderSettings {
                        spp: args.reference_spp,
                        seed: reference_seed,
                        tile_size_px: DEFAULT_TILE_SIZE_PX,
                        sampler: SamplerKind::Sobol,
                        spectral_bins: None,
                        illumination_aov: false,
                        variance_aov: false,
                    };
                    let start = Instant::now();
                    let (film, _) = pool.install(|| render(&scene, &settings, &|_| {}));
                    let seconds = start.elapsed().as_secs_f64();
                    let image = Image::new(
                        film.width as usize,
                        film.height as usize,
                        film.rgb,
                        prism_spectrum::rgb_space::RgbColorSpace::srgb(),
                    )
                    .map_err(|e| e.to_string())?;
                    write_image(&path, &image).map_err(|e| {
                        format!("cannot cache the reference {}: {e}", path.display())
                    })?;
                    eprintln!("reference: rendered in {seconds:.1} s");
                    (
                        image,
                        json!({"path": path, "source": "rendered", "spp": args.reference_spp,
                               "sampler": "sobol", "seed": reference_seed,
                               "render_time_s": seconds}),
                    )
                }
            }
        }
    };

    // What every checkpoint compares against, computed once: clean pixels, CIELAB, peaks.
    let prepare_start = Instant::now();
    let prepared = PreparedReference::new(&reference);
    let reference_prepare_s = prepare_start.elapsed().as_secs_f64();

    let wants_oracle = methods.iter().any(|m| m.plan == method::PlanKind::Oracle);
    let oracle = match (&args.oracle_variance, wants_oracle) {
        (Some(path), true) => Some(pass_planner::oracle_allocation(
            path,
            scene.resolution,
            seed,
        )?),
        (None, true) => return Err("--method path+oracle needs --oracle-variance FILE.exr".into()),
        (Some(_), false) => {
            return Err("--oracle-variance is for a `path+oracle` method; none was given".into())
        }
        (None, false) => None,
    };
    let wants_tables = methods.iter().any(|m| {
        matches!(
            m.plan,
            method::PlanKind::Predicted | method::PlanKind::PredictedHier
        )
    });
    let table_cache = if wants_tables {
        crate::cache_dir::optional_cache_dir(args.cache_dir.as_deref(), cache_dir.as_deref())?
            .map(AngularTableCache::new)
    } else {
        None
    };
    let plan_inputs = pass_planner::PlanInputs {
        oracle: oracle.as_ref(),
        table_cache: table_cache.as_ref(),
    };
    let mut curves = Vec::new();
    let mut methods_json = Vec::new();
    let mut report_entries = Vec::new();
    for (index, (method, integrator)) in methods.iter().zip(&integrators).enumerate() {
        scene.integrator = *integrator;
        scene
            .integrator
            .set_memory_limit_bytes(Some(memory.limit_bytes));
        let settings = RenderSettings {
            spp: 1,
            seed,
            tile_size_px: DEFAULT_TILE_SIZE_PX,
            sampler: method.sampler,
            spectral_bins: None,
            illumination_aov: false,
            variance_aov: false,
        };
        let run: MethodRun = run_method(
            &scene,
            &settings,
            method.plan,
            &prepared,
            &budget,
            &pool,
            plan_inputs,
        )?;
        let last = run
            .checkpoints
            .last()
            .ok_or_else(|| format!("--method {}: no checkpoint was rendered", method.label))?;
        let series = |m: usize| -> Vec<(f64, f64)> {
            run.checkpoints
                .iter()
                .map(|c| (args.clock.of(c), metric_of(c, m)))
                .collect()
        };
        let fits: [Option<PowerFit>; 3] = [0, 1, 2].map(|m| PowerFit::new(series(m)));
        let rmse_vs_spp = PowerFit::new(
            run.checkpoints
                .iter()
                .map(|c| (f64::from(c.spp), c.comparison.rmse)),
        );
        let time_to_target = first_crossing(&series(1), TARGET_RELMSE);
        let overhead = if args.overhead {
            let (plain_wall, plain_cpu) =
                run_plain(&scene, &settings, method.plan, last.spp, &pool, plan_inputs)?;
            let wall_fraction = run.render_wall_s / plain_wall - 1.0;
            let cpu_fraction = match (run.cpu_s, plain_cpu) {
                (Some(a), Some(b)) => Some(a / b - 1.0),
                _ => None,
            };
            eprintln!(
                "{}: overhead of converge: wall {:+.1} % ({:.3} s vs {:.3} s in one pass), CPU {}; \
                 metric thread {:.3} s CPU, film copies {:.4} s",
                method.label,
                100.0 * wall_fraction,
                run.render_wall_s,
                plain_wall,
                cpu_fraction.map_or("n/a".into(), |f| format!("{:+.1} %", 100.0 * f)),
                run.metric_cpu_s,
                run.snapshot_wall_s,
            );
            json!({
                "spp": last.spp,
                "converge_wall_s": run.render_wall_s,
                "single_pass_wall_s": plain_wall,
                "wall_fraction": wall_fraction,
                "converge_cpu_s": run.cpu_s,
                "single_pass_cpu_s": plain_cpu,
                "cpu_fraction": cpu_fraction,
            })
        } else {
            Value::Null
        };
        if let Some(dir) = &args.save_final {
            let path = dir.join(format!("{index}-{}.exr", file_label(method)));
            write_image(&path, &film_to_image(&run.film, run.upsampling.as_deref())?)
                .map_err(|e| e.to_string())?;
        }
        if args.report.is_some() {
            report_entries.push(report::MethodEntry::new(
                &method.label,
                last.spp,
                args.clock.of(last),
                fits[1].map(|f| f.slope),
                time_to_target,
                &film_to_image(&run.film, run.upsampling.as_deref())?,
                &prepared,
            )?);
        }
        let slope_text = |f: &Option<PowerFit>| {
            f.as_ref()
                .map_or("n/a".into(), |f| chart::format_slope(f.slope))
        };
        eprintln!(
            "{}: {} checkpoints, {} spp in {:.2} s; final RMSE {:.3e}, relMSE {:.3e}, ΔE2000 \
             {:.3}; slopes RMSE {}, relMSE {}, ΔE2000 {}",
            method.label,
            run.checkpoints.len(),
            last.spp,
            last.time_s,
            last.comparison.rmse,
            last.comparison.relmse,
            last.comparison.delta_e2000_mean,
            slope_text(&fits[0]),
            slope_text(&fits[1]),
            slope_text(&fits[2]),
        );
        let legend_curve = Curve {
            label: method.label.clone(),
            points: Vec::new(),
            fits,
        };
        let legend: Vec<String> = (0..PANEL_COUNT)
            .map(|m| chart::legend_label(&legend_curve, m))
            .collect();
        methods_json.push(json!({
            "method": method.label,
            "canonical": method.canonical(),
            "integrator": integrator.name(),
            "plan": method.plan.name(),
            "sampler": match method.sampler { SamplerKind::Sobol => "sobol", SamplerKind::Independent => "independent" },
            "rmse_slope": fits[0].map(|f| f.slope),
            "relmse_slope": fits[1].map(|f| f.slope),
            "delta_e2000_slope": fits[2].map(|f| f.slope),
            "rmse_slope_vs_spp": rmse_vs_spp.map(|f| f.slope),
            "fits": {
                "rmse": PowerFit::to_json(fits[0].as_ref()),
                "relmse": PowerFit::to_json(fits[1].as_ref()),
                "delta_e2000_mean": PowerFit::to_json(fits[2].as_ref()),
            },
            "legend": legend,
            "time_to_relmse_target_s": time_to_target,
            "tables_cpu_s": run.predictor_cpu.map(|p| p.tables_cpu_s),
            "predict_cpu_s": run.predictor_cpu.map(|p| p.predict_cpu_s),
            // The budget for the predictor: its CPU time (tables apart) as a share
            // of the method's time to the relMSE target, on the CPU clock only.
            "predict_cpu_fraction_of_time_to_target": match (run.predictor_cpu, time_to_target, args.clock) {
                (Some(p), Some(t), Clock::Cpu) if t > 0.0 => Some(p.predict_cpu_s / t),
                _ => None,
            },
            "final": checkpoint_json(last),
            "render_wall_s": run.render_wall_s,
            "cpu_s": run.cpu_s,
            "converge_cost": {
                "metric_thread_cpu_s": run.metric_cpu_s,
                "film_copies_wall_s": run.snapshot_wall_s,
                "metric_cpu_fraction_of_render_cpu": last.cpu_time_s.map(|c| run.metric_cpu_s / c),
                "film_copies_fraction_of_render_wall": run.snapshot_wall_s / run.render_wall_s,
                "metric_cpu_per_checkpoint_s": run.metric_cpu_s / run.checkpoints.len() as f64,
                // Once per run, before the first method (shared by all methods).
                "reference_prepare_wall_s": reference_prepare_s,
            },
            "stats": {
                "samples": run.stats.samples,
                "rays_traced": run.stats.rays_traced,
                "non_finite_samples": run.stats.non_finite_samples,
                "non_finite_contributions": run.stats.non_finite_contributions,
            },
            "overhead": overhead,
            "checkpoints": run.checkpoints.iter().map(checkpoint_json).collect::<Vec<_>>(),
        }));
        curves.push(Curve {
            label: method.label.clone(),
            points: run
                .checkpoints
                .iter()
                .map(|c| (args.clock.of(c), [0, 1, 2].map(|m| metric_of(c, m))))
                .collect(),
            fits,
        });
        // Reference noise: at N_ref spp the reference's own error adds σ²/N_ref to the
        // measured MSE, which flattens the curve once the method's spp nears it.
        if reference_json["source"] != "given" && last.spp.saturating_mul(4) > args.reference_spp {
            eprintln!(
                "warning: --method {} reached {} spp, more than a quarter of the reference's {} \
                 spp: the reference's own noise flattens the last checkpoints (raise \
                 --reference-spp)",
                method.label, last.spp, args.reference_spp
            );
        }
    }
    // Each method against the first, on the run's clock (relMSE).
    let relmse_series =
        |c: &Curve| -> Vec<(f64, f64)> { c.points.iter().map(|p| (p.0, p.1[1])).collect() };
    if let Some((first, rest)) = curves.split_first() {
        let against = relmse_series(first);
        for (json, curve) in methods_json.iter_mut().skip(1).zip(rest) {
            json["ratios"] = ratios::ratios(&first.label, &against, &relmse_series(curve));
        }
    }
    let title = args.title.clone().unwrap_or_else(|| {
        format!(
            "{} — {}×{} px — error against {}",
            args.scene
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            resolution.x,
            resolution.y,
            match args.clock {
                Clock::Wall => "wall time",
                Clock::Cpu => "render CPU time",
            }
        )
    });
    for o in &args.outputs {
        chart::write_chart(o, &title, args.clock.axis(), &curves)?;
        eprintln!("wrote {}", o.display());
    }
    if let Some(path) = &args.report {
        let intro = format!(
            "{} at {}×{} px against a {} reference. Budget per method: {} ({}). The \
             table and the images are each method's last checkpoint; the viewer shows it \
             (A, left) against the reference (B, right).",
            args.scene.display(),
            resolution.x,
            resolution.y,
            reference_json["source"].as_str().unwrap_or("given"),
            match (budget.time_s.is_finite(), budget.max_spp) {
                (true, Some(spp)) => format!("{} s or {spp} spp", budget.time_s),
                (true, None) => format!("{} s", budget.time_s),
                (false, Some(spp)) => format!("{spp} spp"),
                (false, None) => "none".into(),
            },
            args.clock.axis(),
        );
        let page = report::converge_page(
            &title,
            intro,
            chart::chart_svg(&title, args.clock.axis(), &curves)?,
            &reference,
            prism_post::auto_exposure::auto_exposure_ev(&reference).unwrap_or(0.0),
            std::mem::take(&mut report_entries),
        )?;
        prism_post::report::write_report(path, &page).map_err(|e| e.to_string())?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.json {
        let value = json!({
            "scene": args.scene,
            "resolution": [resolution.x, resolution.y],
            "reference": reference_json,
            "budget": {
                "time_s_per_method": budget.time_s.is_finite().then_some(budget.time_s),
                "clock": args.clock.name(),
                "max_spp": budget.max_spp,
                "checkpoints": budget.checkpoints,
            },
            "seed": seed,
            "threads": pool.current_num_threads(),
            "clock": args.clock.name(),
            "relmse_target": TARGET_RELMSE,
            "machine_at_start": load_start,
            "machine_at_end": machine_load(),
            "methods": methods_json,
        });
        let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())? + "\n";
        crate::atomic_write::write_atomic(path, text.as_bytes(), "convergence data")?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
