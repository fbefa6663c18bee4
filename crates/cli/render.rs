//! `prism render SCENE.json`: load a scene (prism-scene), build it (prism-render), render it
//! tile by tile on a rayon pool and write the image (prism-post) atomically.
//!
//! Output: `-o`, else the scene's `film.output` (relative to the scene file), else
//! `<scene stem>.exr` in the current directory. EXR: unprefixed R, G, B linear Rec.709,
//! header `prism:cd_m2_per_unit`, layers `luminance.Y` (cd/m²), `depth.Z` (m),
//! `normal.X/Y/Z`, `albedo.R/G/B`, `illumination.X/Y/Z` and `spp.Y`, and with
//! `--spectral-bins N` the bins as `S0.<centre>nm` channels (Fichet et al. 2021 layout,
//! W·m⁻²·sr⁻¹·nm⁻¹). PNG: the RGB sRGB-encoded (16 bit). See docs/rendering.md.
//! A scene with `sensors` also gets `<output stem>.sensors.json` and `.sensors.csv`
//! (illuminance in lx with standard errors, uniformity; docs/lighting.md).
//!
//! Partial renders (crates/cli/partial/, docs/rendering.md): `--samples A..B` renders one
//! range of the sample sequence into a partial EXR for `prism merge`, `--checkpoint-every`
//! saves `<output stem>.partial.exr`, `--resume` continues one bit for bit, and Ctrl-C or
//! SIGTERM stops between work items, saving the work (exit 128 + signal).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::Args;
use glam::UVec2;
use prism_cpu::memory::MemoryBudget;
use prism_image::io::exr::ExrWriteOptions;
use prism_image::io::spectral_exr::write_exr_with_spectral_bands;
use prism_image::io::{write_image, ImageFormat};
use prism_image::Image;
use prism_render::film::spectral_bins::{MAX_SPECTRAL_BINS, MIN_SPECTRAL_BINS};
use prism_render::film::FilmMemory;
use prism_render::integrator::DEFAULT_TILE_SIZE_PX;
use prism_render::{
    total_samples, FilmImage, PlanRequest, RenderPlan, RenderScene, RenderSettings, RenderStats,
    SamplerKind, SpectralBins,
};
use prism_spectrum::rgb_space::RgbColorSpace;
use serde_json::json;

use crate::partial::range::SampleRange;
use crate::plan_args::PlanArg;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file: Prism JSON (docs/scene-format.md), or Mitsuba 3 XML (.xml) or
    /// pbrt-v4 (.pbrt), imported on the fly (docs/import.md).
    pub scene: PathBuf,
    #[command(flatten)]
    pub import: crate::import::ImportFlags,
    /// Output image (.exr or .png; .hdr also works). Default: the scene's `film.output`,
    /// else `<scene stem>.exr` in the current directory.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Samples per pixel (default: the scene's `film.spp`).
    #[arg(long, value_parser = prism_args::numbers::parse_spp)]
    pub spp: Option<u32>,
    /// Worker threads (default: one per core; at most 4 per logical CPU).
    #[arg(long, value_parser = prism_cpu::threads::parse_thread_count)]
    pub threads: Option<usize>,
    /// Sampler seed (default: the scene's `film.seed`).
    #[arg(long, value_parser = prism_args::numbers::parse_u64)]
    pub seed: Option<u64>,
    /// Film resolution override, WIDTHxHEIGHT (e.g. 64x48), for previews and tests.
    #[arg(long, value_parser = prism_args::resolution::parse_resolution)]
    pub resolution: Option<UVec2>,
    /// Print the render plan (what the scene needs and why) and exit without rendering.
    #[arg(long)]
    pub explain: bool,
    /// Write render statistics as JSON to this file.
    #[arg(long = "stats-json")]
    pub stats_json: Option<PathBuf>,
    /// Also write the spectral radiance in N equal bins over 360–830 nm (1–471) as
    /// `S0.<λ>nm` channels of the EXR (Fichet et al. 2021 layout, W·m⁻²·sr⁻¹·nm⁻¹).
    #[arg(long = "spectral-bins", value_name = "N", value_parser = prism_args::numbers::parse_u32)]
    pub spectral_bins: Option<u32>,
    /// Measure the scene's `sensors` only (`<output stem>.sensors.json/.csv`), no image.
    #[arg(long = "sensors-only")]
    pub sensors_only: bool,
    /// `radiosity`: write the solution to FILE once solved, to render more views of it
    /// with --load-solution (docs/radiosity.md).
    #[arg(long = "save-solution", value_name = "FILE")]
    pub save_solution: Option<PathBuf>,
    /// `radiosity`: render from the solution in FILE instead of solving (it must have been
    /// solved for this scene's surfaces, materials and lights).
    #[arg(long = "load-solution", value_name = "FILE")]
    pub load_solution: Option<PathBuf>,
    /// `radiosity`: write the solution as a PLY mesh with per-vertex illuminance (lx) and
    /// luminance (cd/m²).
    #[arg(long = "export-solution", value_name = "FILE.ply")]
    pub export_solution: Option<PathBuf>,
    /// Also write a false-colour PNG with a legend: of the image's luminance (cd/m²) or of
    /// every grid sensor's illuminance (lx), as `<stem>.<what>.falsecolour.png`.
    #[arg(long = "false-colour", value_enum)]
    pub false_colour: Option<crate::falsecolour::FalseColourQuantity>,
    /// Scale of the false-colour ramp.
    #[arg(long = "false-colour-scale", value_enum, default_value = "linear")]
    pub false_colour_scale: crate::falsecolour::ScaleArg,
    /// Value range of the false-colour ramp, MIN:MAX (default: 0 to the maximum, or three
    /// decades below the maximum on a log scale).
    #[arg(long = "false-colour-range", value_parser = prism_args::value_range::parse_range)]
    pub false_colour_range: Option<(f64, f64)>,
    /// `bdpt` only: write one strategy's image, S,T (S light-subpath and T camera-subpath
    /// vertices; MIS-weighted) or S,T,unweighted (weight 1), for debugging.
    #[arg(long = "bdpt-strategy", value_name = "S,T[,unweighted]", value_parser = prism_render::integrator::BdptStrategy::parse)]
    pub bdpt_strategy: Option<prism_render::integrator::BdptStrategy>,
    /// Render only samples [A, B) of each pixel's spp-sample sequence (`--spp` defaults to
    /// B) and write a partial EXR with the film's sums, for `prism merge`
    /// (docs/scale-out.md).
    #[arg(long, value_name = "A..B", value_parser = prism_args::sample_range::parse_range)]
    pub samples: Option<SampleRange>,
    /// Write the film so far to `<output stem>.partial.exr` this often (Ns, Nm or Nh, at
    /// least 1s), atomically; `--resume` continues from it.
    #[arg(long = "checkpoint-every", value_name = "DURATION", value_parser = prism_args::duration::parse_duration)]
    pub checkpoint_every: Option<Duration>,
    /// Continue the render saved in this partial image (a checkpoint, or the partial
    /// output of an interrupted render); the result is the uninterrupted render's, bit for
    /// bit. Refused when the scene or an option that changes the image differs.
    #[arg(long, value_name = "PARTIAL.exr")]
    pub resume: Option<PathBuf>,
    /// Progress on stderr: `auto` a bar with ETA on a terminal (nothing otherwise),
    /// `plain` a line of text every `--progress-every` (for log files), `none`.
    #[arg(long, value_enum, default_value = "auto")]
    pub progress: ProgressArg,
    /// Stops as Ctrl-C would once this many work items are done (tests of resuming).
    #[arg(long = "stop-after-items", hide = true)]
    pub stop_after_items: Option<usize>,
    /// Interval of `--progress plain` (Ns, Nm or Nh).
    #[arg(long = "progress-every", value_name = "DURATION", default_value = "10s", value_parser = prism_args::duration::parse_duration)]
    pub progress_every: Duration,
    /// How light samples at shading points choose a light: `auto` through the light BVH
    /// from 8 lights with bounds on, below it `infinite-apart`; `infinite-apart` each light
    /// at infinity with 1/(their count + 1), the others by power; `power` always by power,
    /// lights at infinity included; `bvh` through the light BVH whenever a light has bounds.
    #[arg(long = "light-selection", value_enum, default_value = "auto")]
    pub light_selection: LightSelectionArg,
    /// Light samples per hit: `auto` one per light at infinity and one for the other lights
    /// where lights at infinity are chosen apart beside lights with power, one per light at
    /// infinity where two or more light the scene alone (the choice between a sky and a lamp
    /// or a sun then adds no noise), else one; `one` a single choice among all lights (times
    /// the plan's light samples either way).
    #[arg(long = "light-samples-per-hit", value_enum, default_value = "auto")]
    pub light_samples_per_hit: LightSamplesPerHitArg,
    #[command(flatten)]
    pub plan: crate::plan_args::PlanArgs,
    #[command(flatten)]
    pub simd: crate::simd::SimdArgs,
}

/// `--light-selection`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LightSelectionArg {
    Auto,
    InfiniteApart,
    Power,
    Bvh,
}

/// `--light-samples-per-hit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LightSamplesPerHitArg {
    Auto,
    One,
}

/// How `prism render` reports progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ProgressArg {
    Auto,
    Plain,
    None,
}

/// The render's estimated memory (film, AOVs, spectral bins, output image) checked against
/// `budget` before the scene is built.
fn check_memory(
    args: &RenderArgs,
    description: &prism_scene::SceneDescription,
    spectral_bins: Option<SpectralBins>,
    budget: &MemoryBudget,
) -> Result<(), String> {
    let [w, h] = description.film.resolution;
    let resolution = args.resolution.unwrap_or(UVec2::new(w, h));
    let film = FilmMemory::for_integrator(
        &description.integrator,
        resolution,
        spectral_bins.map_or(0, |b| b.count()),
    );
    let what = match spectral_bins {
        Some(b) => format!(
            "{}: rendering {}×{} px with {} spectral bins",
            args.scene.display(),
            resolution.x,
            resolution.y,
            b.count()
        ),
        None => format!(
            "{}: rendering {}×{} px",
            args.scene.display(),
            resolution.x,
            resolution.y
        ),
    };
    budget
        .check(&what, film.total_bytes())
        .map_err(|e| e.to_string())
}

/// Where the image goes (see the module docs).
fn output_path(args: &RenderArgs, scene_output: Option<&Path>) -> PathBuf {
    if let Some(o) = &args.output {
        return o.clone();
    }
    if let Some(o) = scene_output {
        return o.to_path_buf();
    }
    let stem = args
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.exr"))
}

/// Fails early (before rendering) when the output cannot be written: unknown extension,
/// missing folder or a folder that is not one.
fn check_output(path: &Path) -> Result<(), String> {
    ImageFormat::from_path(path).map_err(|e| format!("output {}: {e}", path.display()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => Err(format!(
            "output {}: {} is not a directory",
            path.display(),
            dir.display()
        )),
        Err(e) => Err(format!(
            "output {}: cannot use the directory {}: {e}",
            path.display(),
            dir.display()
        )),
    }
}

/// `--spectral-bins N` checked against its range and the output format (before rendering).
fn spectral_bins(args: &RenderArgs, output: &Path) -> Result<Option<SpectralBins>, String> {
    let Some(n) = args.spectral_bins else {
        return Ok(None);
    };
    let bins = SpectralBins::new(n).map_err(|_| {
        format!(
            "--spectral-bins {n}: expected {MIN_SPECTRAL_BINS} to {MAX_SPECTRAL_BINS} equal bins \
             over 360–830 nm"
        )
    })?;
    match ImageFormat::from_path(output) {
        Ok(ImageFormat::Exr) => Ok(Some(bins)),
        _ => Err(format!(
            "--spectral-bins needs an .exr output (spectral channels S0.<λ>nm beside R, G, B); \
             {} cannot hold them",
            output.display()
        )),
    }
}

/// One EXR layer being assembled: name, channel names, one plane per channel.
type LayerPlanes<'a> = (String, Vec<String>, Vec<&'a [f32]>);

/// The film as a prism-post image with every layer.
pub(crate) fn to_image(film: &FilmImage) -> Result<Image, String> {
    let (w, h) = (film.width as usize, film.height as usize);
    let mut image =
        Image::new(w, h, film.rgb.clone(), RgbColorSpace::srgb()).map_err(|e| e.to_string())?;
    image.cd_m2_per_unit = Some(film.cd_m2_per_unit);
    image
        .set_layer("luminance", &["Y"], film.luminance_cd_m2())
        .map_err(|e| e.to_string())?;
    // AOV planes come as `layer.channel`; group them by layer, channels interleaved.
    let mut layers: Vec<LayerPlanes> = Vec::new();
    for plane in &film.aovs {
        let (layer, channel) = plane.name.split_once('.').unwrap_or(("", &plane.name));
        match layers.iter_mut().find(|(l, _, _)| l == layer) {
            Some((_, channels, planes)) => {
                channels.push(channel.to_string());
                planes.push(&plane.values);
            }
            None => layers.push((
                layer.to_string(),
                vec![channel.to_string()],
                vec![&plane.values],
            )),
        }
    }
    for (layer, channels, planes) in layers {
        let n = w * h;
        let mut samples = Vec::with_capacity(n * planes.len());
        for i in 0..n {
            samples.extend(planes.iter().map(|p| p[i]));
        }
        let names: Vec<&str> = channels.iter().map(String::as_str).collect();
        image
            .set_layer(&layer, &names, samples)
            .map_err(|e| e.to_string())?;
    }
    Ok(image)
}

pub fn run(args: &RenderArgs, budget: &MemoryBudget) -> Result<ExitCode, String> {
    args.simd.apply()?;
    args.plan.check()?;
    let (description, _side_files) = crate::import::load_any_scene(&args.scene, &args.import)?;
    let output = output_path(args, description.film.output.as_deref());
    if !args.explain {
        check_output(&output)?;
        if let Some(stats) = &args.stats_json {
            crate::atomic_write::check_parent("--stats-json", stats)?;
        }
        if args.false_colour.is_some() {
            crate::falsecolour::check_options(args.false_colour_scale, args.false_colour_range)?;
        }
    }
    let spectral_bins = spectral_bins(args, &output)?;
    if !args.explain && !args.sensors_only {
        check_memory(args, &description, spectral_bins, budget)?;
    }
    if args.false_colour == Some(crate::falsecolour::FalseColourQuantity::Illuminance)
        && !description
            .sensors
            .iter()
            .any(|s| matches!(s.kind, prism_scene::SensorKind::Grid { .. }))
    {
        return Err(format!(
            "--false-colour illuminance: {} has no `grid` sensor (see docs/lighting.md)",
            args.scene.display()
        ));
    }
    let mut scene = RenderScene::build(&description, args.resolution).map_err(|e| e.to_string())?;
    match args.light_selection {
        LightSelectionArg::Auto => {}
        LightSelectionArg::InfiniteApart => {
            scene.set_light_selection(prism_render::light::ShadingSelection::InfiniteApart);
        }
        LightSelectionArg::Power => {
            scene.set_light_selection(prism_render::light::ShadingSelection::Power);
        }
        LightSelectionArg::Bvh => {
            if !scene.set_light_selection(prism_render::light::ShadingSelection::Bvh) {
                return Err(format!(
                    "--light-selection bvh: {} has no light with bounds (only lights at \
                     infinity, or none) for a light BVH to choose among",
                    args.scene.display()
                ));
            }
        }
    }
    match args.light_samples_per_hit {
        LightSamplesPerHitArg::Auto => {}
        LightSamplesPerHitArg::One => scene.lights.set_sample_each_infinite(false),
    }
    scene
        .integrator
        .set_memory_limit_bytes(Some(budget.limit_bytes));
    // A radiosity solution is carried in the spectral bins asked for.
    scene.integrator.set_spectral_bins(spectral_bins);
    if !args.explain {
        radiosity_solution_files(args, &scene)?;
    }
    if let Some(strategy) = args.bdpt_strategy {
        match &mut scene.integrator {
            prism_render::Integrator::Bdpt(b) => {
                if strategy.depth() > b.max_depth {
                    return Err(format!(
                        "--bdpt-strategy {},{}: paths of {} scattering events, beyond the \
                         scene's max_depth {}",
                        strategy.s,
                        strategy.t,
                        strategy.depth(),
                        b.max_depth
                    ));
                }
                b.strategy = Some(strategy);
            }
            other => {
                return Err(format!(
                    "--bdpt-strategy needs the `bdpt` integrator; {} renders with `{}` (set \
                     \"integrator\": {{\"type\": \"bdpt\"}})",
                    args.scene.display(),
                    other.name()
                ))
            }
        }
    }
    // A resumed render's spp is the checkpoint's unless given (it is checked against the
    // whole identity later).
    let resumed_spp = match &args.resume {
        Some(path) => prism_image::io::raw_exr::read_text_attributes(path)
            .map_err(|e| format!("--resume: {e}"))?
            .get(&format!("{}.spp", crate::partial::identity::HASH_ATTRIBUTE))
            .and_then(|v| v.parse::<u32>().ok()),
        None => None,
    };
    let settings = RenderSettings {
        // A range's end is the default: `--samples 256..512` is half of a 512-spp render.
        spp: args
            .spp
            .or(args.samples.map(|r| r.end))
            .or(resumed_spp)
            .unwrap_or(scene.spp),
        seed: args.seed.unwrap_or(scene.seed),
        tile_size_px: DEFAULT_TILE_SIZE_PX,
        // The scene's sampler for the integrators that take one, Sobol otherwise.
        sampler: description.integrator.render_sampler(),
        spectral_bins,
        // Cheap, and what `prism tonemap --wb scene` reads: always in EXR outputs.
        illumination_aov: matches!(ImageFormat::from_path(&output), Ok(ImageFormat::Exr)),
        // What a sample plan can be judged by (`path+oracle`); EXR only, as cheap.
        variance_aov: matches!(ImageFormat::from_path(&output), Ok(ImageFormat::Exr)),
    };
    if settings.spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    if scene.integrator.is_spectral() && scene.lights.is_empty() {
        eprintln!(
            "{}: warning: the scene has no lights: the {} image is black \
             (add a `lights` entry, or choose a diagnostic `integrator`)",
            args.scene.display(),
            scene.integrator.name()
        );
    }
    // One built light per `lights` entry, in order (prism-render light::build).
    let radius_m = scene.lights.scene_sphere().radius_m;
    for (i, light) in scene.lights.lights().iter().enumerate() {
        let power_w = light.power_w(radius_m);
        if power_w.is_nan() || power_w <= 0.0 {
            eprintln!(
                "{}: warning: lights[{i}] has zero power: it emits nothing (check its \
                 strength and spectrum)",
                args.scene.display()
            );
        }
    }
    // A spectral render of a camera or a light shut inside a closed shape is black; the
    // diagnostic integrators (depth, normals) show the geometry whatever the light.
    if scene.integrator.is_spectral() {
        for warning in prism_render::enclosure::enclosure_warnings(&scene, &description) {
            eprintln!("{}: warning: {warning}", args.scene.display());
        }
    }
    if args.explain {
        let request = PlanRequest {
            spp: settings.spp,
            spectral_bins: settings.spectral_bins.map(|b| b.count()),
            aov_output: ImageFormat::from_path(&output).is_ok_and(|f| f == ImageFormat::Exr),
            sampler: match settings.sampler {
                SamplerKind::Sobol => "Owen-scrambled Sobol",
                SamplerKind::Independent => "independent",
            },
            sample_plan: args.plan.kind(),
        };
        print!("{}", RenderPlan::new(&scene, &request));
        return Ok(ExitCode::SUCCESS);
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool
        .build()
        .map_err(|e| format!("cannot start the thread pool: {e}"))?;
    let threads = pool.current_num_threads();

    if args.sensors_only {
        if args.false_colour == Some(crate::falsecolour::FalseColourQuantity::Luminance) {
            return Err("--false-colour luminance needs the image: drop --sensors-only".into());
        }
        if description.sensors.is_empty() {
            return Err(format!(
                "--sensors-only: {} has no `sensors` (see docs/lighting.md)",
                args.scene.display()
            ));
        }
        return measure_and_write_sensors(
            args,
            &pool,
            &scene,
            &description.sensors,
            &settings,
            &output,
        )
        .map(|()| ExitCode::SUCCESS);
    }
    if args.plan.plan != PlanArg::Uniform
        && !matches!(scene.integrator, prism_render::Integrator::Path(_))
    {
        return Err(format!(
            "--plan {}: per-pixel sample plans are for the `path` integrator; {} renders \
             with `{}`",
            args.plan.plan.name(),
            args.scene.display(),
            scene.integrator.name()
        ));
    }
    if args.plan.plan == PlanArg::PredictedHier && args.samples.is_some() {
        return Err(
            "--plan predicted-hier interpolates the pixels it does not shade once the render \
             is whole, so it cannot render a sample range (--samples); use --plan predicted"
                .into(),
        );
    }
    if args.plan.plan == PlanArg::Adaptive {
        if args.samples.is_some() || args.checkpoint_every.is_some() || args.resume.is_some() {
            return Err(
                "--plan adaptive chooses each pass from the image so far, so it cannot \
                 render a sample range (--samples), checkpoint or resume; use --plan \
                 uniform or predicted"
                    .into(),
            );
        }
        return render_adaptive(
            args,
            &description,
            &pool,
            &scene,
            &settings,
            &output,
            threads,
        )
        .map(|()| ExitCode::SUCCESS);
    }
    if args.samples.is_some() && !matches!(ImageFormat::from_path(&output), Ok(ImageFormat::Exr)) {
        return Err(format!(
            "--samples writes a partial EXR (the film's sums beside the image); {} is not an \
             .exr output",
            output.display()
        ));
    }
    let checkpoint = crate::partial::file::checkpoint_path(&output);
    let mut temp_files = vec![
        prism_image::io::temp_sibling(&output),
        prism_image::io::temp_sibling(&checkpoint),
    ];
    if let Some(stats) = &args.stats_json {
        temp_files.push(prism_image::io::temp_sibling(stats));
    }
    if !description.sensors.is_empty() {
        let (json, csv) = crate::sensors::sensor_paths(&output);
        temp_files.push(prism_image::io::temp_sibling(&json));
        temp_files.push(prism_image::io::temp_sibling(&csv));
        temp_files.push(prism_image::io::temp_sibling(
            &crate::partial::sensor_sums::sidecar_path(&output),
        ));
    }
    crate::partial::signals::install(&temp_files)?;
    let mut predictor_time = None;
    let (plan, extra_aovs, upsampling) = match args.plan.plan {
        PlanArg::Uniform | PlanArg::Adaptive => (
            prism_bandwidth::SamplePlan::uniform(scene.resolution, settings.spp)
                .map_err(|e| e.to_string())?,
            Vec::new(),
            None,
        ),
        PlanArg::Predicted | PlanArg::PredictedHier => {
            // Deterministic in the seed: every process of a split render computes it alike.
            let predictor = args.plan.predictor(settings.spp, settings.seed);
            let table_cache = args.plan.table_cache()?;
            let (prediction, upsampling, time) = pool
                .install(|| {
                    crate::predictor_time::predict_timed(
                        &scene,
                        &predictor,
                        settings.seed,
                        table_cache.as_ref(),
                    )
                })
                .map_err(|e| format!("{}: {e}", args.scene.display()))?;
            predictor_time = Some(time);
            let aovs = prediction.aov_planes();
            (prediction.allocated.plan, aovs, upsampling)
        }
    };
    let mut rendered = crate::partial::job::render(
        args,
        &description,
        &scene,
        &settings,
        &plan,
        extra_aovs,
        &output,
        &pool,
    )?;
    let exr_output = matches!(ImageFormat::from_path(&output), Ok(ImageFormat::Exr));
    if !exr_output {
        // Only EXR holds layers; the plan's are extra.
        rendered
            .image
            .aovs
            .retain(|a| !a.name.starts_with("bandwidth.") && !a.name.starts_with("plan."));
    }
    // A range of the sample sequence (given, or resumed) is written as a partial EXR.
    let range_output = args.samples.is_some()
        || rendered.range
            != (SampleRange {
                start: 0,
                end: settings.spp,
            });
    if let Some(upsampling) = &upsampling {
        rendered
            .image
            .upsample(upsampling)
            .map_err(|e| format!("{}: {e}", args.scene.display()))?;
    }
    if range_output && !exr_output {
        return Err(format!(
            "{} renders the samples {} of {}: a range is written as a partial EXR; {} is \
             not an .exr output",
            args.scene.display(),
            rendered.range,
            settings.spp,
            output.display()
        ));
    }
    if !rendered.complete {
        let signal = crate::partial::signals::received();
        rendered.write_partial(&rendered.checkpoint)?;
        let header = rendered.header();
        let mut marks = vec![(
            crate::partial::file::COMPLETE.to_string(),
            "false".to_string(),
        )];
        let sums = rendered.film.sums();
        marks.extend(crate::partial::file::header_attributes(&header, &sums));
        if range_output {
            rendered.write_partial(&output)?;
        } else {
            write_output(&output, &rendered.image, &marks)?;
        }
        let done: u64 = sums.sample_counts().iter().map(|&c| u64::from(c)).sum();
        eprintln!(
            "{}: stopped by {} after {} of the range's samples ({} work items); wrote the \
             checkpoint {} and the PARTIAL image {}; continue with --resume {}",
            args.scene.display(),
            signal.map_or("--stop-after-items", crate::partial::signals::name),
            done,
            rendered.items_done,
            rendered.checkpoint.display(),
            output.display(),
            rendered.checkpoint.display()
        );
        if let Some(path) = &args.stats_json {
            write_stats(path, &scene, &settings, threads, &rendered, predictor_time)?;
        }
        // The shell's convention for a signal (130 for SIGINT, 143 for SIGTERM).
        return Ok(ExitCode::from(
            signal.map_or(1, |s| (128 + s).clamp(1, 255)) as u8,
        ));
    }
    if range_output {
        rendered.write_partial(&output)?;
    } else {
        write_output(&output, &rendered.image, &[])?;
    }
    // The checkpoint is superseded by the finished output.
    if rendered.checkpoint != output {
        match std::fs::remove_file(&rendered.checkpoint) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => eprintln!(
                "warning: cannot remove the checkpoint {}: {e}",
                rendered.checkpoint.display()
            ),
        }
    }
    let film = &rendered.image;
    if args.false_colour == Some(crate::falsecolour::FalseColourQuantity::Luminance) {
        let path = crate::falsecolour::write_luminance(
            &output,
            &film.luminance_cd_m2(),
            (film.width as usize, film.height as usize),
            args.false_colour_scale,
            args.false_colour_range,
        )?;
        eprintln!("wrote {}", path.display());
    }
    if !description.sensors.is_empty() {
        if range_output {
            measure_sensor_share(
                args,
                &pool,
                &scene,
                &description,
                &settings,
                &rendered,
                &output,
            )?;
        } else {
            measure_and_write_sensors(
                args,
                &pool,
                &scene,
                &description.sensors,
                &settings,
                &output,
            )?;
        }
    }
    if let Some(path) = &args.stats_json {
        write_stats(path, &scene, &settings, threads, &rendered, predictor_time)?;
    }
    report_medium_mismatches(args, &rendered.stats);
    if let Some(Ok(solved)) = scene.radiosity_solution() {
        if let Some(line) = solved.gather_statistics() {
            eprintln!("{line}");
        }
    }
    let wall_time_s = rendered.wall_time_s;
    eprintln!(
        "wrote {} ({}×{}, {} spp{}, {:.2} s, {:.3} M rays/s)",
        output.display(),
        scene.resolution.x,
        scene.resolution.y,
        settings.spp,
        if range_output {
            format!(", samples {}", rendered.range)
        } else {
            String::new()
        },
        wall_time_s,
        rendered.stats.rays_traced as f64 / wall_time_s.max(1e-9) / 1e6
    );
    Ok(ExitCode::SUCCESS)
}

fn report_medium_mismatches(args: &RenderArgs, stats: &RenderStats) {
    if stats.medium_mismatches > 0 {
        eprintln!(
            "{}: warning: paths met a medium boundary {} times from a medium other than the \
             one it declares on that side: check the shapes' interior_medium and \
             exterior_medium (overlapping or nested boundaries must agree)",
            args.scene.display(),
            stats.medium_mismatches
        );
    }
}

/// Writes the finished image (EXR with every layer and the spectral bins, or PNG/HDR) with
/// `metadata` as header text.
fn write_output(
    output: &Path,
    film: &FilmImage,
    metadata: &[(String, String)],
) -> Result<(), String> {
    let mut image = to_image(film)?;
    image.metadata.extend(metadata.iter().cloned());
    match &film.spectral {
        Some(bins) => write_exr_with_spectral_bands(
            output,
            &image,
            &bins.centres_nm,
            &bins.planes,
            &ExrWriteOptions::default(),
        ),
        None => write_image(output, &image),
    }
    .map_err(|e| e.to_string())
}

/// `--plan adaptive`: passes chosen from the image so far (no ranges or checkpoints).
fn render_adaptive(
    args: &RenderArgs,
    description: &prism_scene::SceneDescription,
    pool: &rayon::ThreadPool,
    scene: &RenderScene,
    settings: &RenderSettings,
    output: &Path,
    threads: usize,
) -> Result<(), String> {
    let progress = crate::progress::Progress::start(
        args.progress,
        args.progress_every,
        total_samples(scene.resolution, settings.spp),
        &args.scene.display().to_string(),
    );
    let start = Instant::now();
    let result = pool.install(|| {
        prism_render::adaptive::render_adaptive(scene, settings, settings.spp, &|n| progress.inc(n))
    });
    progress.finish();
    let (mut film, stats) = result.map_err(|e| format!("{}: {e}", args.scene.display()))?;
    let wall_time_s = start.elapsed().as_secs_f64();
    if !matches!(ImageFormat::from_path(output), Ok(ImageFormat::Exr)) {
        film.aovs
            .retain(|a| !a.name.starts_with("bandwidth.") && !a.name.starts_with("plan."));
    }
    write_output(output, &film, &[])?;
    if args.false_colour == Some(crate::falsecolour::FalseColourQuantity::Luminance) {
        let path = crate::falsecolour::write_luminance(
            output,
            &film.luminance_cd_m2(),
            (film.width as usize, film.height as usize),
            args.false_colour_scale,
            args.false_colour_range,
        )?;
        eprintln!("wrote {}", path.display());
    }
    if !description.sensors.is_empty() {
        measure_and_write_sensors(args, pool, scene, &description.sensors, settings, output)?;
    }
    if let Some(path) = &args.stats_json {
        let value =
            prism_render::stats_json::stats_json(scene, settings, threads, wall_time_s, &stats);
        write_json(path, &value)?;
    }
    report_medium_mismatches(args, &stats);
    eprintln!(
        "wrote {} ({}×{}, {} spp, {:.2} s, {:.3} M rays/s)",
        output.display(),
        scene.resolution.x,
        scene.resolution.y,
        settings.spp,
        wall_time_s,
        stats.rays_traced as f64 / wall_time_s.max(1e-9) / 1e6
    );
    Ok(())
}

/// The statistics of a (possibly partial or resumed) render: the common ones, the sample
/// range with the time spent on it in this run and in earlier runs, and the predictor's
/// time where the plan was predicted.
fn write_stats(
    path: &Path,
    scene: &RenderScene,
    settings: &RenderSettings,
    threads: usize,
    rendered: &crate::partial::job::Rendered,
    predictor_time: Option<crate::predictor_time::PredictorTime>,
) -> Result<(), String> {
    let mut value = prism_render::stats_json::stats_json(
        scene,
        settings,
        threads,
        rendered.wall_time_s,
        &rendered.stats,
    );
    value["ranges"] = json!([{
        "samples": [rendered.range.start, rendered.range.end],
        "complete": rendered.complete,
        "wall_time_s": rendered.wall_time_s,
        "earlier_wall_time_s": rendered.earlier_wall_time_s,
    }]);
    if let Some(time) = predictor_time {
        value["predictor"] = time.json();
    }
    write_json(path, &value)
}

fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), String> {
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())? + "\n";
    crate::atomic_write::write_atomic(path, text.as_bytes(), "statistics")
}

/// A range render's share of the sensors: their sums beside the part, for `prism merge`
/// (`partial::sensor_sums`). Adaptive sensors cannot be split: the part whose range starts
/// at 0 measures them whole, the others say so.
fn measure_sensor_share(
    args: &RenderArgs,
    pool: &rayon::ThreadPool,
    scene: &RenderScene,
    description: &prism_scene::SceneDescription,
    settings: &RenderSettings,
    rendered: &crate::partial::job::Rendered,
    output: &Path,
) -> Result<(), String> {
    let share = prism_render::sensor::SampleShare {
        start: rendered.range.start,
        end: rendered.range.end,
        total: settings.spp,
    };
    let result = pool.install(|| {
        prism_render::sensor::measure_sensor_share(
            scene,
            &description.sensors,
            settings.seed,
            share,
            &|_| {},
        )
    });
    match result {
        Ok((sums, _)) => {
            let path = crate::partial::sensor_sums::sidecar_path(output);
            let value = crate::partial::sensor_sums::to_json(
                &rendered.identity.hash(),
                &rendered.range.to_string(),
                &sums,
            );
            let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())? + "\n";
            crate::atomic_write::write_atomic(&path, text.as_bytes(), "sensor sums")?;
            eprintln!("wrote {}", path.display());
            Ok(())
        }
        Err(why) if rendered.range.start == 0 => {
            eprintln!(
                "{}: {why}; this part (samples {}) measures the sensors whole",
                args.scene.display(),
                rendered.range
            );
            measure_and_write_sensors(args, pool, scene, &description.sensors, settings, output)
        }
        Err(why) => {
            eprintln!(
                "{}: {why}; the part whose range starts at 0 measures them, not this one",
                args.scene.display()
            );
            Ok(())
        }
    }
}

/// `--load-solution`, `--save-solution`, `--export-solution`: refused for other methods;
/// a loaded solution replaces solving, a saved or exported one is solved here (the render
/// then reuses it).
fn radiosity_solution_files(args: &RenderArgs, scene: &RenderScene) -> Result<(), String> {
    use prism_render::integrator::radiosity::solution_io;
    let flags = [
        ("--load-solution", &args.load_solution),
        ("--save-solution", &args.save_solution),
        ("--export-solution", &args.export_solution),
    ];
    let given: Vec<&str> = flags
        .iter()
        .filter(|(_, v)| v.is_some())
        .map(|(f, _)| *f)
        .collect();
    if given.is_empty() {
        return Ok(());
    }
    if !matches!(scene.integrator, prism_render::Integrator::Radiosity(_)) {
        return Err(format!(
            "{}: {} needs the `radiosity` integrator; {} renders with `{}`",
            given.join(", "),
            if given.len() == 1 { "it" } else { "they" },
            args.scene.display(),
            scene.integrator.name()
        ));
    }
    for (flag, path) in &flags[1..] {
        if let Some(path) = path {
            crate::atomic_write::check_parent(flag, path)?;
        }
    }
    if let Some(path) = &args.load_solution {
        let bytes =
            std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        scene.set_radiosity_solution(solution_io::load_solution(scene, path, &bytes)?)?;
    }
    if args.save_solution.is_some() || args.export_solution.is_some() {
        let solved = scene
            .radiosity_solution()
            .ok_or("the scene has no radiosity solution")??;
        if let Some(path) = &args.save_solution {
            crate::atomic_write::write_atomic(
                path,
                &solved.solution.to_bytes(),
                "radiosity solution",
            )?;
            eprintln!("wrote {} (radiosity solution)", path.display());
        }
        if let Some(path) = &args.export_solution {
            crate::atomic_write::write_atomic(
                path,
                solution_io::to_ply(&solved).as_bytes(),
                "radiosity solution PLY",
            )?;
            eprintln!(
                "wrote {} (illuminance and luminance per vertex)",
                path.display()
            );
        }
    }
    Ok(())
}

/// Measures the scene's sensors on `pool` and writes their readings beside the image.
fn measure_and_write_sensors(
    args: &RenderArgs,
    pool: &rayon::ThreadPool,
    scene: &RenderScene,
    sensors: &[prism_scene::Sensor],
    settings: &RenderSettings,
    output: &Path,
) -> Result<(), String> {
    let bar = crate::progress::Progress::start(
        args.progress,
        args.progress_every,
        prism_render::sensor::total_points(sensors),
        &args.scene.display().to_string(),
    );
    // A radiosity solution that cannot be built is an error here, not path-traced lux.
    if let Some(Err(e)) = scene.radiosity_solution() {
        return Err(e);
    }
    let start = Instant::now();
    let (readings, stats) = pool.install(|| {
        prism_render::sensor::measure_sensors(scene, sensors, settings.seed, &|n| bar.inc(n))
    });
    let wall_time_s = start.elapsed().as_secs_f64();
    bar.finish();
    let (json_path, csv_path) = crate::sensors::sensor_paths(output);
    let mut value = crate::sensors::readings_json(&args.scene, &readings, &stats, wall_time_s);
    let mut csv = crate::sensors::readings_csv(&readings);
    // Daylight factor under the scene's daylight sky (docs/daylight.md).
    let outdoor_lx =
        prism_render::light::daylight::outdoor_horizontal_illuminance_lx(&scene.lights)
            .filter(|e| *e > 0.0);
    if let Some(e_out) = outdoor_lx {
        crate::daylight_factor::add_to_json(&mut value, &readings, e_out);
        csv = crate::daylight_factor::add_to_csv(&csv, &readings, e_out);
    }
    let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())? + "\n";
    crate::atomic_write::write_atomic(&json_path, text.as_bytes(), "sensor readings")?;
    crate::atomic_write::write_atomic(&csv_path, csv.as_bytes(), "sensor readings")?;
    if args.false_colour == Some(crate::falsecolour::FalseColourQuantity::Illuminance) {
        for path in crate::falsecolour::write_illuminance(
            output,
            &readings,
            args.false_colour_scale,
            args.false_colour_range,
        )? {
            eprintln!("wrote {}", path.display());
        }
    }
    for r in &readings {
        let u = r.uniformity();
        eprintln!(
            "sensor {}: {} points, E_avg {:.4} lx, E_min {:.4} lx, E_max {:.4} lx, \
             E_min/E_avg {:.3}, E_min/E_max {:.3}",
            r.name,
            r.points.len(),
            u.average_lx,
            u.min_lx,
            u.max_lx,
            u.min_over_average,
            u.min_over_max
        );
        if let Some(e_out) = outdoor_lx {
            eprintln!(
                "sensor {}: daylight factor average {:.3} %, min {:.3} %, max {:.3} % \
                 (outdoor unobstructed sky {:.1} lx)",
                r.name,
                100.0 * u.average_lx / e_out,
                100.0 * u.min_lx / e_out,
                100.0 * u.max_lx / e_out,
                e_out
            );
        }
    }
    eprintln!(
        "wrote {} and {} ({} samples, {:.2} s)",
        json_path.display(),
        csv_path.display(),
        stats.samples,
        wall_time_s
    );
    Ok(())
}
