//! `cargo run --release -p bench-post --bin bench-compare -- REFERENCE.exr [TEST.exr] [RUNS]`:
//! the cost of one `prism converge` checkpoint's metrics (RMSE, relMSE, ΔE₀₀ mean and
//! p95; no SSIM) on one thread, as the metric thread runs them. Without TEST, the test image
//! is the reference with deterministic multiplicative noise (±50 %, like a few-spp render).
//!
//! Prints one JSON object: `prepare_cpu_ms` (`PreparedReference::new`, once per run),
//! `compare_cpu_ms` (`PreparedReference::compare`, per checkpoint), `compare_with_cpu_ms`
//! (prepare + compare: what `prism compare` does), their per-pixel ns, and a peer measured
//! in the same run, `sse_pass_cpu_ms` (one pass summing squared differences: the memory
//! floor of any metric); medians over RUNS (default 31) of the thread's CPU time.

use std::path::Path;

use prism_image::io::read_image;
use prism_image::Image;
use prism_post::metrics::{compare_with, CompareOptions, PreparedReference};

fn thread_cpu_ms() -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: ts is a valid timespec to write to.
        if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0 {
            return ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6;
        }
    }
    f64::NAN
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn noisy(reference: &Image) -> Image {
    let pixels = reference
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut h = (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
            p.map(|c| {
                h = (h ^ (h >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                let u = (h >> 40) as f32 / (1u64 << 24) as f32;
                c * (0.5 + u)
            })
        })
        .collect();
    reference.with_pixels(pixels).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        eprintln!("usage: bench-compare REFERENCE.exr [TEST.exr] [RUNS]");
        std::process::exit(2);
    }
    let reference = read_image(Path::new(&args[0])).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let (test, runs) = match args.get(1) {
        Some(a) if a.parse::<usize>().is_err() => (
            read_image(Path::new(a)).unwrap_or_else(|e| {
                eprintln!("{e}");
                std::process::exit(1)
            }),
            args.get(2).and_then(|r| r.parse().ok()).unwrap_or(31),
        ),
        other => (
            noisy(&reference),
            other.and_then(|r| r.parse().ok()).unwrap_or(31),
        ),
    };
    // One thread, like converge's metric thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let options = CompareOptions {
        ssim: false,
        flip_ppd: None,
        delta_e2000_map: false,
    };
    let (mut prep, mut cmp, mut full, mut sse) = (vec![], vec![], vec![], vec![]);
    let mut last = None;
    pool.install(|| {
        for _ in 0..runs {
            let t0 = thread_cpu_ms();
            let prepared = PreparedReference::new(&reference);
            let t1 = thread_cpu_ms();
            let c = prepared.compare(&test, &options).unwrap();
            let t2 = thread_cpu_ms();
            let d = compare_with(&test, &reference, &options).unwrap();
            let t3 = thread_cpu_ms();
            let s: f64 = test
                .pixels()
                .iter()
                .zip(reference.pixels())
                .map(|(a, b)| (0..3).map(|k| f64::from(a[k] - b[k]).powi(2)).sum::<f64>())
                .sum();
            let t4 = thread_cpu_ms();
            std::hint::black_box(s);
            assert_eq!(c.delta_e2000_p95, d.delta_e2000_p95);
            prep.push(t1 - t0);
            cmp.push(t2 - t1);
            full.push(t3 - t2);
            sse.push(t4 - t3);
            last = Some(c);
        }
    });
    let n = reference.pixels().len() as f64;
    let c = last.unwrap();
    let out = serde_json::json!({
        "reference": args[0],
        "test": args.get(1).filter(|a| a.parse::<usize>().is_err()),
        "width": reference.width(),
        "height": reference.height(),
        "runs": runs,
        "threads": 1,
        "prepare_cpu_ms": median(prep.clone()),
        "compare_cpu_ms": median(cmp.clone()),
        "compare_with_cpu_ms": median(full),
        "sse_pass_cpu_ms": median(sse),
        "compare_ns_per_pixel": median(cmp) * 1e6 / n,
        "prepare_ns_per_pixel": median(prep) * 1e6 / n,
        "rmse": c.rmse,
        "relmse": c.relmse,
        "delta_e2000_mean": c.delta_e2000_mean,
        "delta_e2000_p95": c.delta_e2000_p95,
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap());
}
