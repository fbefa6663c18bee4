//! `cargo run --release -p bench-post [-- WIDTH HEIGHT RUNS]`: for every tone operator, on a
//! synthetic HDR image (default 3840×2160, 7 runs, median):
//! - `compute_ms`: `ToneOperator::apply_into` with a reused output buffer, next to one
//!   read+write copy pass over the same pixels into a preallocated output (the issue's
//!   reference: global operators should take ≤ 3× that, local ones ≤ 300 ms); operator
//!   runs alternate with copy passes, and `ratio_to_copy` divides the operator's median by
//!   the median of its own interleaved copy passes (`copy_pass_ms` per operator; the
//!   top-level `copy_pass_ms` is the median over all of them); `compute_cpu_ms`,
//!   `copy_pass_cpu_ms` and `ratio_to_copy_cpu` are the same in CPU time of all threads
//!   (medians), which the shared machine's load does not stretch; `ratio_to_copy_min` and
//!   `ratio_to_copy_cpu_min` divide the fastest operator run by the fastest of its copy
//!   passes (the least disturbed of each; the copy pass's CPU time is bimodal here, as the
//!   idle rayon worker's spinning lands in it or not, which the medians can straddle);
//! - `file_ms`: the whole in-process pipeline `tonemap_file` from a float EXR to a 16-bit
//!   PNG (read, operator, gamut clip, encode, write), with its stage breakdown, and
//!   `file_cpu_ms`, its CPU time of all threads (median);
//! - `png_write`: the 16-bit PNG write alone, parallel writer against the `png` crate's
//!   sequential encoder (wall, CPU of all threads, bytes).
//!
//! Prints one JSON object (the latest full run is kept as
//! tools/bench-results/bench-post-4k.json). `bench-post --write-input PATH [WIDTH HEIGHT]`
//! only writes the synthetic image as a float EXR (for peers: tools/bench-tonemap-pfstmo.sh).
//! `--ops NAME,NAME` limits the run to those operators; `--no-file` skips `file_ms`
//! (for profiling one operator's compute); `--input PATH.exr` times `file_ms` on that
//! file instead of writing the synthetic image first (for profiling the file pipeline).

use std::path::{Path, PathBuf};
use std::time::Instant;

use prism_image::Image;
use prism_post::{tonemap_file, OperatorChoice, ToneOperator, ToneParams, TonemapOptions};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

/// CPU time of all the process's threads, ms (NaN where unavailable). On the shared
/// machine other processes' load stretches wall time; CPU time counts only the work done
/// (plus rayon's brief spinning), so `compute_cpu_ms / threads` estimates the wall time
/// on an idle machine.
fn process_cpu_ms() -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: ts is a valid timespec to write to.
        if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) } == 0 {
            return ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6;
        }
    }
    f64::NAN
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Luminance spanning 1e-3 … 1e4 over the image, with colour variation and texture; the
/// absolute scale is 1 cd/m² per unit.
fn synthetic(w: usize, h: usize) -> Image {
    let pixels: Vec<[f32; 3]> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let v = 10f32.powf(-3.0 + 7.0 * x) * (0.5 + 0.5 * (20.0 * y).sin().abs());
            [v, v * (0.3 + 0.7 * y), v * (1.0 - 0.6 * x)]
        })
        .collect();
    let mut image = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
    image.cd_m2_per_unit = Some(1.0);
    image
}

fn usage() -> ! {
    eprintln!(
        "usage: bench-post [WIDTH HEIGHT RUNS] [--ops NAME,NAME] [--no-file] [--input PATH.exr]\n       bench-post --write-input PATH.exr [WIDTH HEIGHT]"
    );
    std::process::exit(2)
}

fn numbers(args: &[String]) -> Vec<usize> {
    args.iter()
        .map(|a| a.parse().unwrap_or_else(|_| usage()))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--write-input") {
        let path = PathBuf::from(args.get(1).unwrap_or_else(|| usage()));
        let n = numbers(&args[2..]);
        let (w, h) = (*n.first().unwrap_or(&3840), *n.get(1).unwrap_or(&2160));
        if let Err(e) = prism_image::io::write_image(&path, &synthetic(w, h)) {
            eprintln!("{e}");
            std::process::exit(1);
        }
        return;
    }
    let mut only: Option<Vec<ToneOperator>> = None;
    let mut with_file = true;
    let mut given_input: Option<PathBuf> = None;
    let mut rest = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--ops" => {
                let list = it.next().unwrap_or_else(|| usage());
                only = Some(
                    list.split(',')
                        .map(|n| ToneOperator::from_name(n).unwrap_or_else(|_| usage()))
                        .collect(),
                );
            }
            "--no-file" => with_file = false,
            "--input" => given_input = Some(PathBuf::from(it.next().unwrap_or_else(|| usage()))),
            _ => rest.push(a.clone()),
        }
    }
    let n = numbers(&rest);
    let (w, h, runs) = (
        *n.first().unwrap_or(&3840),
        *n.get(1).unwrap_or(&2160),
        *n.get(2).unwrap_or(&7),
    );
    let image = synthetic(w, h);

    // Copy pass: read every pixel and write it to a preallocated output, in parallel,
    // no allocation (the reference for "≤ 3× a copy pass").
    let mut copy = vec![[0.0f32; 3]; w * h];
    let mut copy_pass = || {
        let (t, cpu) = (Instant::now(), process_cpu_ms());
        copy.par_chunks_mut(4096)
            .zip(image.pixels().par_chunks(4096))
            .for_each(|(o, i)| o.copy_from_slice(i));
        std::hint::black_box(&copy);
        (t.elapsed().as_secs_f64() * 1e3, process_cpu_ms() - cpu)
    };
    let mut all_copies: Vec<f64> = (0..runs).map(|_| copy_pass().0).collect();

    let dir = std::env::temp_dir().join(format!("bench-post-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = given_input.unwrap_or_else(|| dir.join("in.exr"));
    if with_file && !input.exists() {
        prism_image::io::write_image(&input, &image).unwrap();
    }
    let file_runs = runs.clamp(1, 3);

    let mut operators = serde_json::Map::new();
    // Output buffer reused across runs and operators (ToneOperator::apply_into).
    let mut buffer = vec![[0.0f32; 3]; w * h];
    for op in ToneOperator::ALL {
        if only.as_ref().is_some_and(|o| !o.contains(&op)) {
            continue;
        }
        let params = ToneParams::default();
        // Operator runs alternate with copy passes, so that the ratio compares medians
        // taken under the same machine load (the shared machine's load drifts).
        let mut copies = Vec::with_capacity(runs);
        let mut copies_cpu = Vec::with_capacity(runs);
        let mut times = Vec::with_capacity(runs);
        let mut times_cpu = Vec::with_capacity(runs);
        for _ in 0..runs {
            let (wall, cpu) = copy_pass();
            copies.push(wall);
            copies_cpu.push(cpu);
            let b = std::mem::take(&mut buffer);
            let (t, cpu) = (Instant::now(), process_cpu_ms());
            let result = op.apply_into(&image, &params, b).unwrap();
            buffer = std::hint::black_box(result).image.into_pixels();
            times.push(t.elapsed().as_secs_f64() * 1e3);
            times_cpu.push(process_cpu_ms() - cpu);
        }
        let fastest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let ratio_min = fastest(&times) / fastest(&copies);
        let ratio_cpu_min = fastest(&times_cpu) / fastest(&copies_cpu);
        let compute_ms = median(times);
        all_copies.extend(&copies);
        let copy_ms = median(copies);
        let (compute_cpu_ms, copy_cpu_ms) = (median(times_cpu), median(copies_cpu));
        let (file_ms, file_cpu_ms, stages) = if with_file {
            file_pipeline(&input, &dir.join("out.png"), op, file_runs)
        } else {
            (f64::NAN, f64::NAN, serde_json::Value::Null)
        };
        operators.insert(
            op.name().to_string(),
            serde_json::json!({
                "local": is_local(op),
                "compute_ms": compute_ms,
                "ratio_to_copy": compute_ms / copy_ms,
                "copy_pass_ms": copy_ms,
                "compute_cpu_ms": compute_cpu_ms,
                "copy_pass_cpu_ms": copy_cpu_ms,
                "ratio_to_copy_cpu": compute_cpu_ms / copy_cpu_ms,
                "ratio_to_copy_min": ratio_min,
                "ratio_to_copy_cpu_min": ratio_cpu_min,
                "file_ms": file_ms,
                "file_cpu_ms": file_cpu_ms,
                "file_stages_ms": stages,
            }),
        );
    }
    let png_write = if with_file {
        png_write_times(&image, &dir, file_runs)
    } else {
        serde_json::Value::Null
    };
    let _ = std::fs::remove_dir_all(&dir);
    let out = serde_json::json!({
        "width": w,
        "height": h,
        "runs": runs,
        "file_runs": file_runs,
        "threads": rayon::current_num_threads(),
        "copy_pass_ms": median(all_copies),
        "operators": operators,
        "png_write": png_write,
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap());
}

/// 16-bit PNG write of the reinhard02-mapped image: the parallel writer
/// (`io::png::write_png`) against the `png` crate's sequential encoder
/// (`write_png_sequential`), wall and CPU time of all threads (medians), and file bytes.
fn png_write_times(image: &Image, dir: &Path, runs: usize) -> serde_json::Value {
    use prism_image::io::png::{write_png, write_png_sequential, PngBitDepth};
    let mapped = ToneOperator::Reinhard02
        .apply(image, &ToneParams::default())
        .unwrap()
        .image;
    let path = dir.join("write.png");
    let mut result = serde_json::Map::new();
    type Writer = fn(&Path, &Image, PngBitDepth) -> prism_image::Result<()>;
    for (name, write) in [
        ("parallel", write_png as Writer),
        ("sequential", write_png_sequential as Writer),
    ] {
        let (mut wall, mut cpu) = (Vec::new(), Vec::new());
        for _ in 0..runs.max(3) {
            let (t, c) = (Instant::now(), process_cpu_ms());
            write(&path, &mapped, PngBitDepth::Sixteen).unwrap();
            wall.push(t.elapsed().as_secs_f64() * 1e3);
            cpu.push(process_cpu_ms() - c);
        }
        result.insert(
            name.to_string(),
            serde_json::json!({
                "wall_ms": median(wall),
                "cpu_ms": median(cpu),
                "bytes": std::fs::metadata(&path).unwrap().len(),
            }),
        );
    }
    serde_json::Value::Object(result)
}

fn is_local(op: ToneOperator) -> bool {
    matches!(
        op,
        ToneOperator::Reinhard02Local | ToneOperator::Durand02 | ToneOperator::Ward97Histogram
    )
}

/// Median wall time of `tonemap_file` (EXR → PNG), median CPU time of all threads, and
/// the stages of the median run.
fn file_pipeline(
    input: &Path,
    output: &Path,
    op: ToneOperator,
    runs: usize,
) -> (f64, f64, serde_json::Value) {
    let options = TonemapOptions {
        operator: OperatorChoice::One(op),
        ..Default::default()
    };
    let mut cpu = Vec::with_capacity(runs);
    let mut reports: Vec<_> = (0..runs)
        .map(|_| {
            let c = process_cpu_ms();
            let timings = tonemap_file(input, output, &options).unwrap().timings;
            cpu.push(process_cpu_ms() - c);
            timings
        })
        .collect();
    reports.sort_by(|a, b| a.total_ms.total_cmp(&b.total_ms));
    let middle = &reports[runs / 2];
    (
        middle.total_ms,
        median(cpu),
        serde_json::to_value(middle).unwrap(),
    )
}
