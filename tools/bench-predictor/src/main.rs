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

use glam::UVec2;
use prism_cpu::clock::{load_average_1m, process_cpu_s};
use prism_render::predictor::{predict_with_probe, PredictorSettings};
use prism_render::probe::RenderProbe;
use prism_render::RenderScene;
use serde_json::json;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| -> Vec<String> {
        args.windows(2)
            .filter(|w| w[0] == flag)
            .map(|w| w[1].clone())
            .collect()
    };
    let number = |flag: &str, default: usize| -> usize {
        value(flag).first().map_or(default, |v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{flag} takes a whole number, not {v:?}"))
        })
    };
    let rounds = number("--rounds", 15).max(2);
    let threads = number("--threads", 1);
    let side = number("--resolution", 128) as u32;
    let mut scenes = value("--scene");
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
    if !args.iter().any(|a| a == "--no-file") {
        let _ = std::fs::write("tools/bench-results/bench-predictor.json", text + "\n");
    }
}
