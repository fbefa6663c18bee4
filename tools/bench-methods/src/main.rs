//! Time per camera sample of each rendering method on example scenes, measured in the same
//! run in alternating rounds (so load changes hit every method alike), one thread each.
//!
//!     cargo run --release -p bench-methods -- [--rounds 5] [--spp 8] [--resolution 128]
//!         [--scene scenes/cornell-box.json]… [--method path|path-scalar|light|bdpt]…
//!
//! Prints JSON and writes it to tools/bench-results/bench-methods.json. `path` is the
//! path tracer as `prism render` runs it (the packet tracer where the scene is on its
//! allow-list); `path-scalar` the scalar tracer alone (the reference path).

use std::time::Instant;

use glam::UVec2;
use prism_render::integrator::{Bdpt, LightTracer, PathTracer};
use prism_render::{render_plan, Integrator, RenderScene, RenderSettings};
use serde_json::json;

fn cpu_seconds() -> f64 {
    // The process's user + system time (`/proc/self/stat`, clock ticks of 1/100 s).
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| -> Vec<String> {
        args.windows(2)
            .filter(|w| w[0] == flag)
            .map(|w| w[1].clone())
            .collect()
    };
    let rounds: usize = value("--rounds")
        .first()
        .map_or(5, |v| v.parse().expect("--rounds N"));
    let spp: u32 = value("--spp")
        .first()
        .map_or(8, |v| v.parse().expect("--spp N"));
    let side: u32 = value("--resolution")
        .first()
        .map_or(128, |v| v.parse().expect("--resolution N"));
    let mut scenes = value("--scene");
    if scenes.is_empty() {
        scenes = vec![
            "scenes/cornell-box.json".into(),
            "scenes/glossy-env.json".into(),
        ];
    }
    let mut methods = value("--method");
    if methods.is_empty() {
        methods = ["path", "path-scalar", "light", "bdpt"]
            .map(String::from)
            .to_vec();
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a thread pool");
    let load_start = prism_cpu::clock::load_average_1m();
    let mut results = Vec::new();
    for scene_path in &scenes {
        let description = prism_scene::load_scene(scene_path).expect("the scene loads");
        let resolution = UVec2::new(
            side,
            side * description.film.resolution[1] / description.film.resolution[0],
        );
        let mut scene =
            RenderScene::build(&description, Some(resolution)).expect("the scene builds");
        let path = match scene.integrator {
            Integrator::Path(p) => p,
            _ => PathTracer::default(),
        };
        let sampler = match description.integrator {
            prism_scene::Integrator::Path { sampler, .. } => sampler,
            _ => prism_render::SamplerKind::Sobol,
        };
        let settings = RenderSettings {
            spp,
            seed: 1,
            sampler,
            ..RenderSettings::default()
        };
        let plan = prism_bandwidth::SamplePlan::uniform(resolution, spp).expect("a plan");
        let mut times: Vec<Vec<(f64, f64)>> = vec![Vec::new(); methods.len()];
        for _ in 0..rounds {
            for (k, method) in methods.iter().enumerate() {
                let (integrator, packet) = match method.as_str() {
                    "path" => (Integrator::Path(path), true),
                    "path-scalar" => (Integrator::Path(path), false),
                    "light" => (
                        Integrator::Light(LightTracer {
                            max_depth: path.max_depth,
                            rr_depth: path.rr_depth,
                        }),
                        false,
                    ),
                    "bdpt" => (
                        Integrator::Bdpt(Bdpt {
                            max_depth: path.max_depth,
                            rr_depth: path.rr_depth,
                            mis: path.mis,
                            strategy: None,
                        }),
                        false,
                    ),
                    other => panic!("unknown method {other}: path, path-scalar, light, bdpt"),
                };
                scene.integrator = integrator;
                scene.set_packet_tracing(packet);
                let (cpu0, wall0) = (cpu_seconds(), Instant::now());
                pool.install(|| render_plan(&scene, &settings, &plan, &|_| {}))
                    .expect("renders");
                times[k].push((wall0.elapsed().as_secs_f64(), cpu_seconds() - cpu0));
            }
        }
        let samples = f64::from(resolution.x * resolution.y * spp);
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let per_method: Vec<_> = methods
            .iter()
            .zip(&times)
            .map(|(m, t)| {
                let wall = median(t.iter().map(|x| x.0).collect());
                let cpu = median(t.iter().map(|x| x.1).collect());
                json!({"method": m, "median_wall_s": wall, "median_cpu_s": cpu,
                       "cpu_us_per_sample": cpu / samples * 1e6,
                       "wall_s_rounds": t.iter().map(|x| x.0).collect::<Vec<_>>()})
            })
            .collect();
        results.push(
            json!({"scene": scene_path, "resolution": [resolution.x, resolution.y],
                            "spp": spp, "max_depth": path.max_depth, "methods": per_method}),
        );
    }
    let out = json!({
        "benchmark": "bench-methods",
        "rounds": rounds,
        "threads": 1,
        "load_average_1m": {"start": load_start, "end": prism_cpu::clock::load_average_1m()},
        "command": format!("cargo run --release -p bench-methods -- {}", args.join(" ")),
        "results": results,
    });
    let text = serde_json::to_string_pretty(&out).expect("JSON") + "\n";
    print!("{text}");
    let dir = std::path::Path::new("tools/bench-results");
    if dir.is_dir() {
        let _ = std::fs::write(dir.join("bench-methods.json"), &text);
    }
}
