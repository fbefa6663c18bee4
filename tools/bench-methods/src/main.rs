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

use clap::{Parser, ValueEnum};
use glam::UVec2;
use prism_cpu::clock::process_cpu_s;
use prism_render::integrator::{Bdpt, LightTracer, PathTracer};
use prism_render::{render_plan, Integrator, RenderScene, RenderSettings};
use serde_json::json;

/// A rendering method the benchmark times.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum Method {
    /// The path tracer as `prism render` runs it (packets where the scene is on their list).
    Path,
    /// The scalar path tracer alone (the reference path).
    PathScalar,
    Light,
    Bdpt,
}

impl Method {
    /// The name on the command line and in the JSON.
    fn name(self) -> &'static str {
        match self {
            Method::Path => "path",
            Method::PathScalar => "path-scalar",
            Method::Light => "light",
            Method::Bdpt => "bdpt",
        }
    }
}

/// The flags (module comment).
#[derive(Parser)]
#[command(about = "Time per camera sample of each rendering method, in alternating rounds")]
struct Args {
    /// Renders per method and scene.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    rounds: u32,
    /// Samples per pixel of each render.
    #[arg(long, default_value_t = 8)]
    spp: u32,
    /// Image width, px (the height keeps the scene's aspect ratio).
    #[arg(long, default_value_t = 128)]
    resolution: u32,
    /// Scene files (default: scenes/cornell-box.json and scenes/glossy-env.json).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Methods (default: all four).
    #[arg(long = "method", value_enum)]
    methods: Vec<Method>,
}

fn main() {
    let command_line: Vec<String> = std::env::args().skip(1).collect();
    let args = Args::parse();
    let (rounds, spp, side) = (args.rounds as usize, args.spp, args.resolution);
    let mut scenes = args.scenes;
    if scenes.is_empty() {
        scenes = vec![
            "scenes/cornell-box.json".into(),
            "scenes/glossy-env.json".into(),
        ];
    }
    let mut methods = args.methods;
    if methods.is_empty() {
        methods = vec![
            Method::Path,
            Method::PathScalar,
            Method::Light,
            Method::Bdpt,
        ];
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
                let (integrator, packet) = match method {
                    Method::Path => (Integrator::Path(path), true),
                    Method::PathScalar => (Integrator::Path(path), false),
                    Method::Light => (
                        Integrator::Light(LightTracer {
                            max_depth: path.max_depth,
                            rr_depth: path.rr_depth,
                        }),
                        false,
                    ),
                    Method::Bdpt => (
                        Integrator::Bdpt(Bdpt {
                            max_depth: path.max_depth,
                            rr_depth: path.rr_depth,
                            mis: path.mis,
                            strategy: None,
                        }),
                        false,
                    ),
                };
                scene.integrator = integrator;
                scene.set_packet_tracing(packet);
                let (cpu0, wall0) = (
                    process_cpu_s().expect("a process CPU clock"),
                    Instant::now(),
                );
                pool.install(|| render_plan(&scene, &settings, &plan, &|_| {}))
                    .expect("renders");
                let cpu1 = process_cpu_s().expect("a process CPU clock");
                times[k].push((wall0.elapsed().as_secs_f64(), cpu1 - cpu0));
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
                json!({"method": m.name(), "median_wall_s": wall, "median_cpu_s": cpu,
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
        "command": format!("cargo run --release -p bench-methods -- {}", command_line.join(" ")),
        "results": results,
    });
    let text = serde_json::to_string_pretty(&out).expect("JSON") + "\n";
    print!("{text}");
    let dir = std::path::Path::new("tools/bench-results");
    if dir.is_dir() {
        let _ = std::fs::write(dir.join("bench-methods.json"), &text);
    }
}
