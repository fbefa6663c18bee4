//! ns per `get_1d` / `get_2d` and per `stream` for the Sobol and independent samplers.
//!
//! `cargo run --release -p prism-render --example sampler_bench [-- CALLS RUNS]`
//! prints JSON: the minimum over RUNS of the mean ns per call over CALLS calls (the
//! minimum is the run least disturbed by other work on a shared machine). Each stream draws
//! 16 dimensions, as a camera sample plus a few bounces would.

use std::hint::black_box;
use std::time::Instant;

use glam::UVec2;
use prism_render::sampler::{PixelSampler, SamplerKind};

const DIMENSIONS_PER_STREAM: u32 = 16;

fn time_ns_per_call(calls: u32, runs: u32, mut body: impl FnMut(u32) -> f32) -> f64 {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            let mut acc = 0.0f32;
            for i in 0..calls {
                acc += body(i);
            }
            black_box(acc);
            start.elapsed().as_secs_f64() * 1e9 / f64::from(calls)
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let calls: u32 = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(20_000_000);
    let runs: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let streams = calls / DIMENSIONS_PER_STREAM;
    let mut results = Vec::new();
    for (name, kind) in [
        ("sobol", SamplerKind::Sobol),
        ("independent", SamplerKind::Independent),
    ] {
        let sampler = PixelSampler::with_kind(kind, 7);
        let get_1d = time_ns_per_call(streams, runs, |i| {
            let mut s = sampler.stream(black_box(UVec2::new(i & 1023, i >> 10)), i & 63);
            (0..DIMENSIONS_PER_STREAM).map(|_| s.get_1d()).sum()
        }) / f64::from(DIMENSIONS_PER_STREAM);
        let get_2d = time_ns_per_call(streams, runs, |i| {
            let mut s = sampler.stream(black_box(UVec2::new(i & 1023, i >> 10)), i & 63);
            (0..DIMENSIONS_PER_STREAM / 2)
                .map(|_| {
                    let v = s.get_2d();
                    v.x + v.y
                })
                .sum()
        }) / f64::from(DIMENSIONS_PER_STREAM / 2);
        let stream = time_ns_per_call(calls, runs, |i| {
            sampler
                .stream(black_box(UVec2::new(i & 1023, i >> 10)), i & 63)
                .dimension() as f32
        });
        results.push(format!(
            "{{\"sampler\": \"{name}\", \"ns_per_get_1d\": {get_1d:.2}, \
             \"ns_per_get_2d\": {get_2d:.2}, \"ns_per_stream\": {stream:.2}}}"
        ));
    }
    println!(
        "{{\"calls\": {calls}, \"runs\": {runs}, \"dimensions_per_stream\": \
         {DIMENSIONS_PER_STREAM}, \"results\": [{}]}}",
        results.join(", ")
    );
}
