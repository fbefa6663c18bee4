//! `cargo run --release -p bench-post --bin bench-flip -- OUT_DIR [THREADS] [RUNS] [W H]`:
//! wall time of LDR-FLIP and HDR-FLIP (prism-post) on a synthetic pair, default 3840 × 2160
//! on 2 rayon threads, median of RUNS (default 3). Writes the pair to OUT_DIR/flip-ref.f32
//! and OUT_DIR/flip-test.f32 (raw little-endian f32, H × W × RGB: flip-evaluator 1.7's EXR
//! loader crashes on Prism's ZIP EXRs) so that tools/bench_flip.py times NVIDIA's
//! reference implementation on the same pixels; prints one JSON object (times, process
//! CPU time, means, HDR exposure count).

use std::path::PathBuf;
use std::time::Instant;

use prism_post::metrics::flip::{hdr_flip, ldr_flip, DEFAULT_PPD};
use rayon::prelude::*;

/// CPU time of all the process's threads, ms (NaN where unavailable).
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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^ (x >> 16)
}

/// A render-like HDR pair: gradients under an exposure ramp (2⁻¹ … 2³), a checker, a
/// highlight disc at 500; the test adds ±20 % per-sample noise (a mid-convergence render).
fn pair(w: usize, h: usize) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let reference: Vec<[f32; 3]> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
            let (dx, dy) = (u - 0.75, v - 0.25);
            if dx * dx + dy * dy < 0.003 {
                return [500.0, 450.0, 400.0];
            }
            let mut gain = (4.0 * u - 1.0).exp2();
            if ((x / 64) + (y / 64)) % 2 == 0 {
                gain *= 0.3;
            }
            let c = [
                0.05 + 0.9 * u,
                0.05 + 0.9 * v,
                0.3 + 0.25 * (2.0 * std::f64::consts::PI * (u + v)).sin(),
            ];
            c.map(|c| (c * gain) as f32)
        })
        .collect();
    let test = reference
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            [0, 1, 2].map(|c| {
                let n = f64::from(hash32((i * 3 + c) as u32) >> 8) / f64::from(1u32 << 23) - 1.0;
                (f64::from(p[c]) * (1.0 + 0.2 * n)) as f32
            })
        })
        .collect();
    (test, reference)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!("usage: bench-flip OUT_DIR [THREADS] [RUNS] [W H]");
        std::process::exit(2);
    };
    let num = |i: usize, default: usize| args.get(i).map_or(default, |s| s.parse().unwrap());
    let (threads, runs, w, h) = (num(1, 2), num(2, 3), num(3, 3840), num(4, 2160));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let (test, reference) = pool.install(|| pair(w, h));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, px) in [("flip-ref.f32", &reference), ("flip-test.f32", &test)] {
        let bytes: Vec<u8> = px.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let (mut ldr_s, mut hdr_s, mut ldr_cpu, mut hdr_cpu) = (vec![], vec![], vec![], vec![]);
    let (mut ldr_mean, mut hdr_mean, mut exposures) = (0.0, 0.0, 0);
    pool.install(|| {
        for _ in 0..runs {
            let (c0, t0) = (process_cpu_ms(), Instant::now());
            let ldr = ldr_flip(&test, &reference, w, h, DEFAULT_PPD).unwrap();
            let (c1, t1) = (process_cpu_ms(), Instant::now());
            let hdr = hdr_flip(&test, &reference, w, h, DEFAULT_PPD).unwrap();
            let (c2, t2) = (process_cpu_ms(), Instant::now());
            ldr_s.push((t1 - t0).as_secs_f64());
            hdr_s.push((t2 - t1).as_secs_f64());
            ldr_cpu.push((c1 - c0) / 1e3);
            hdr_cpu.push((c2 - c1) / 1e3);
            ldr_mean = ldr.mean();
            hdr_mean = hdr.map.mean();
            exposures = hdr.exposures.count;
        }
    });
    let out = serde_json::json!({
        "width": w,
        "height": h,
        "threads": threads,
        "runs": runs,
        "ppd": DEFAULT_PPD,
        "ldr_wall_s": median(ldr_s),
        "hdr_wall_s": median(hdr_s),
        "ldr_cpu_s": median(ldr_cpu),
        "hdr_cpu_s": median(hdr_cpu),
        "ldr_mean": ldr_mean,
        "hdr_mean": hdr_mean,
        "hdr_exposures": exposures,
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap());
}
