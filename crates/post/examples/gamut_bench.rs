//! Throughput of white balance and every gamut method on 2 Mpixel of random Rec.2020
//! colours mapped to sRGB; prints one JSON line per method (Mpixel/s) for tools/ to chart.
//! Run: cargo run --release -p prism-post --example gamut_bench

use std::time::Instant;

use prism_post::colour::{apply_white_balance, map_gamut, GamutMethod, GamutTarget, WhiteBalance};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::AdaptationMethod;

const PIXELS: usize = 2_000_000;

fn main() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 40) as f32) / (1u64 << 24) as f32 * 1.2 - 0.1
    };
    let pixels: Vec<[f32; 3]> = (0..PIXELS).map(|_| [next(), next(), next()]).collect();
    let rec2020 = RgbColorSpace::rec2020();
    let threads = rayon::current_num_threads();
    let mut p = pixels.clone();
    let start = Instant::now();
    apply_white_balance(
        &mut p,
        &rec2020,
        &WhiteBalance::GreyWorld,
        AdaptationMethod::Bradford,
    )
    .unwrap();
    print_line("wb:grey-world", start.elapsed().as_secs_f64(), 0.0, threads);
    for method in GamutMethod::names() {
        let method = GamutMethod::parse(method).unwrap();
        let mut p = pixels.clone();
        let start = Instant::now();
        let report = map_gamut(&mut p, &rec2020, GamutTarget::Srgb, method);
        let seconds = start.elapsed().as_secs_f64();
        print_line(
            &format!("gamut:{method}"),
            seconds,
            report.fraction_outside,
            threads,
        );
    }
}

fn print_line(name: &str, seconds: f64, fraction_outside: f64, threads: usize) {
    println!(
        "{{\"bench\":\"{name}\",\"pixels\":{PIXELS},\"threads\":{threads},\"seconds\":{seconds:.4},\
         \"mpixel_per_s\":{:.2},\"fraction_outside\":{fraction_outside:.4}}}",
        PIXELS as f64 / seconds / 1e6
    );
}
