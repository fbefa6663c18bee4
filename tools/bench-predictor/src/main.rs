//! CPU seconds of the bandwidth predictor's prediction (`predict_with_probe`: the G-buffer,
//! the probe and the image passes; the BSDF tables built before the clock starts, as
//! `predict_cpu_s` of `prism render --stats-json` counts them apart), repeated in one
//! process so that a change to the predictor can be timed against the noise of a shared
//! machine. The first round of each scene pays the process's first touch of its buffers
//! (page faults), as a `prism render` run does; the later rounds reuse freed memory.
//!
//!     CARGO_PROFILE_RELEASE_LTO=false cargo run --release -p bench-predictor -- \
//!         [--rounds 15] [--threads 1] [--resolution 128] [--scene SCENE]… [--no-file]
//!
//! (Without LTO: linked with the workspace's thin LTO, this binary is left with undefined
//! prism-radiosity symbols, as prism-render's integration tests are under `--release`.)
//! The default scenes are scenes/bandwidth/fig17-curved-area.json and fig9-spheres.json.
//! To time a change, build the tool at both commits and alternate the two binaries with
//! `--no-file`, so that the comparison's runs do not overwrite the benchmark's JSON.
//!
//! Prints JSON (per scene: the first round, the median and the minimum of the others, in
//! CPU seconds of the whole process) and writes it to tools/bench-results/bench-predictor.json.

use clap::Parser;
use glam::UVec2;
use prism_cpu::clock::{load_average_1m, process_cpu_s};
use prism_render::predictor::{predict_with_probe, PredictorSettings};
use prism_render::probe::RenderProbe;
use prism_render::RenderScene;
use serde_json::json;

/// The flags (module comment).
#[derive(Parser)]
#[command(about = "CPU seconds of the bandwidth predictor's prediction, repeated in one process")]
struct Args {
    /// Predictions per scene (at least 2: the first is reported apart).
    #[arg(long, default_value_t = 15, value_parser = clap::value_parser!(u32).range(2..))]
    rounds: u32,
    /// Worker threads of the prediction.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Square image side, px.
    #[arg(long, default_value_t = 128)]
    resolution: u32,
    /// Scene files (default: fig17-curved-area and fig9-spheres of scenes/bandwidth/).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Print the JSON only, leaving tools/bench-results/bench-predictor.json alone.
    #[arg(long)]
    no_file: bool,
}

fn main() {
    let args = Args::parse();
    let (rounds, threads, side) = (args.rounds as usize, args.threads, args.resolution);
    let mut scenes = args.scenes;
    if scenes.is_empty() {
        scenes = vec![
            "scenes/bandwidth/fig17-curved-area.json".into(),
            "scenes/bandwidth/fig9-spheres.json".into(),
        ];
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let load_start = load_average_1m();
    let mut results = Vec::new();
    for path in &scenes {
        let description = prism_scene::load_scene(path).expect("the scene loads");
        let scene =
            RenderScene::build(&description, Some(UVec2::splat(side))).expect("the scene builds");
        let settings = PredictorSettings::defaults(64.0, 1);
        let mut times = Vec::with_capacity(rounds);
        for _ in 0..rounds {
            let probe = RenderProbe::new(&scene, 1)
                .with_bandwidth_tables()
                .expect("the tables build");
            let (elapsed, prediction) = pool.install(|| {
                let start = process_cpu_s().expect("a process CPU clock");
                let prediction = predict_with_probe(&scene, &settings, probe);
                (
                    process_cpu_s().expect("a process CPU clock") - start,
                    prediction,
                )
            });
            prediction.expect("the prediction");
            times.push(elapsed);
        }
        let first = times[0];
        let mut rest = times[1..].to_vec();
        rest.sort_by(f64::total_cmp);
        results.push(json!({
            "scene": path,
            "first_cpu_s": first,
            "median_cpu_s": rest[rest.len() / 2],
            "min_cpu_s": rest[0],
        }));
    }
    let out = json!({
        "benchmark": "bench-predictor",
        "resolution": [side, side],
        "threads": threads,
        "rounds": rounds,
        "load_average_1m": {"start": load_start, "end": load_average_1m()},
        "scenes": results,
    });
    let text = serde_json::to_string_pretty(&out).expect("JSON");
    println!("{text}");
    if !args.no_file {
        let _ = std::fs::write("tools/bench-results/bench-predictor.json", text + "\n");
    }
}
