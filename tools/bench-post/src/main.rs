//! `cargo run --release -p bench-post [-- WIDTH HEIGHT RUNS]`: median compute time of every
//! tone operator on a synthetic HDR image (default 3840×2160, 7 runs), next to the time of
//! one read+write copy pass over the same pixels (the reference: global operators
//! should take ≤ 3× that). Prints one JSON object.

use std::time::Instant;

use prism_post::{Image, ToneOperator, ToneParams};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[runs / 2]
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("arguments: WIDTH HEIGHT RUNS (integers)"))
        .collect();
    let (w, h, runs) = (
        *args.first().unwrap_or(&3840),
        *args.get(1).unwrap_or(&2160),
        *args.get(2).unwrap_or(&7),
    );
    // Luminance spanning 1e-3 … 1e4 over the image, with colour variation.
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

    // Copy pass: read every pixel and write it to a preallocated output, in parallel,
    // no allocation (the reference for "≤ 3× a copy pass").
    let mut copy = vec![[0.0f32; 3]; w * h];
    let copy_ms = median_ms(runs, || {
        copy.par_chunks_mut(4096)
            .zip(image.pixels().par_chunks(4096))
            .for_each(|(o, i)| o.copy_from_slice(i));
        std::hint::black_box(&copy);
    });
    let mut operators = serde_json::Map::new();
    // Output buffer reused across runs and operators (ToneOperator::apply_into).
    let mut buffer = copy;
    for op in ToneOperator::ALL {
        let params = ToneParams::default();
        let ms = median_ms(runs, || {
            let b = std::mem::take(&mut buffer);
            let result = op.apply_into(&image, &params, b).unwrap();
            buffer = std::hint::black_box(result).image.into_pixels();
        });
        operators.insert(
            op.name().to_string(),
            serde_json::json!({ "ms": ms, "ratio_to_copy": ms / copy_ms }),
        );
    }
    let out = serde_json::json!({
        "width": w,
        "height": h,
        "runs": runs,
        "threads": rayon::current_num_threads(),
        "copy_pass_ms": copy_ms,
        "operators": operators,
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap());
}
