//! `cargo run --release -p bench-spectrum`: nanoseconds per 4-wavelength `Spectrum::eval`
//! for every spectrum kind, per hero-wavelength sample, and per spectrum → XYZ of a 1 nm
//! table, and per RGB → coefficients conversion. Prints one JSON object (kept as
//! tools/bench-results/bench-spectrum.json); docs/colour.md, "Speed", explains the fields.

use std::hint::black_box;
use std::time::Instant;

use prism_spectrum::data::{cmfs, Observer};
use prism_spectrum::{
    DenseSpectrum, RgbAlbedoSpectrum, RgbGamut, SampledSpectrum, SampledWavelengths, Spectrum,
};

const RUNS: usize = 9;
/// Interleaved rounds over all kinds for the eval timings.
const ROUNDS: usize = 15;
const EVALS_PER_RUN: usize = 1_000_000;
const WAVELENGTH_SETS: usize = 4096;

/// Median and minimum of `RUNS` timings of `per_run` calls of `body(i)`, in ns per call
/// (the minimum is the steadier figure on a loaded machine).
fn median_ns(per_run: usize, mut body: impl FnMut(usize)) -> (f64, f64) {
    let mut timings: Vec<f64> = (0..RUNS)
        .map(|_| {
            let start = Instant::now();
            for i in 0..per_run {
                body(i);
            }
            start.elapsed().as_secs_f64() * 1e9 / per_run as f64
        })
        .collect();
    timings.sort_by(|a, b| a.total_cmp(b));
    (timings[RUNS / 2], timings[0])
}

/// SplitMix64 for the wavelength variates.
fn splitmix(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// `Spectrum::eval` as one out-of-line call per evaluation, as a renderer's BSDF or light
/// code calls it (and one symbol to disassemble).
#[inline(never)]
fn eval_not_inlined(spectrum: &Spectrum, wavelengths: &SampledWavelengths) -> SampledSpectrum {
    spectrum.eval(wavelengths)
}

/// ns per `eval` over one run of `EVALS_PER_RUN` calls.
fn bench_eval(spectrum: &Spectrum, wavelengths: &[SampledWavelengths]) -> f64 {
    let mut acc = SampledSpectrum::zero();
    let start = Instant::now();
    for i in 0..EVALS_PER_RUN {
        // Wavelengths vary every call; black_box keeps the spectrum from being hoisted.
        let w = &wavelengths[i % WAVELENGTH_SETS];
        acc += eval_not_inlined(black_box(spectrum), black_box(w));
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / EVALS_PER_RUN as f64;
    black_box(acc);
    ns
}

/// Σ over the 471 grid samples of S(λ)·(x̄, ȳ, z̄)(λ)·1 nm (colorimetry.rs has the real one).
fn dense_to_xyz(spectrum: &DenseSpectrum, observer: &prism_spectrum::data::Cmfs) -> [f64; 3] {
    let s = spectrum.values();
    let (x, y, z) = (
        observer.x_bar.values(),
        observer.y_bar.values(),
        observer.z_bar.values(),
    );
    let mut xyz = [0.0; 3];
    for i in 0..s.len() {
        xyz[0] += s[i] * x[i];
        xyz[1] += s[i] * y[i];
        xyz[2] += s[i] * z[i];
    }
    xyz
}

fn main() {
    let mut state = 0x00be_ac40;
    let wavelengths: Vec<SampledWavelengths> = (0..WAVELENGTH_SETS)
        .map(|_| SampledWavelengths::sample_visible(splitmix(&mut state)))
        .collect();

    let uniform_table: Vec<f64> = (0..=94).map(|i| 360.0 + 5.0 * i as f64).collect();
    let uniform_values: Vec<f64> = uniform_table
        .iter()
        .map(|wl| (wl / 50.0).sin().abs())
        .collect();
    // 95 samples, irregular spacing (as measured reflectances often are).
    let irregular_table: Vec<f64> = (0..95)
        .map(|i| 360.0 + 470.0 * (i as f64 / 94.0).powf(1.3))
        .collect();
    let irregular_values: Vec<f64> = irregular_table
        .iter()
        .map(|wl| (wl / 40.0).cos().abs())
        .collect();

    let kinds: Vec<(&str, Spectrum)> = vec![
        ("constant", Spectrum::constant(0.5)),
        (
            "piecewise_linear_uniform",
            Spectrum::piecewise_linear(&uniform_table, &uniform_values).unwrap(),
        ),
        (
            "piecewise_linear_non_uniform",
            Spectrum::piecewise_linear(&irregular_table, &irregular_values).unwrap(),
        ),
        (
            "dense",
            Spectrum::from_dense(&cmfs(Observer::Cie1931).y_bar).unwrap(),
        ),
        ("blackbody", Spectrum::blackbody_normalized(6500.0).unwrap()),
        (
            "named_illuminant_d65",
            Spectrum::cie_illuminant("D65").unwrap(),
        ),
        (
            "rgb_albedo",
            Spectrum::rgb_albedo(RgbGamut::Srgb, [0.8, 0.3, 0.1]).unwrap(),
        ),
        (
            "rgb_unbounded",
            Spectrum::rgb_unbounded(RgbGamut::Rec2020, [2.0, 0.5, 0.25]).unwrap(),
        ),
        (
            "rgb_illuminant",
            Spectrum::rgb_illuminant(RgbGamut::AcesCg, [4.0, 2.0, 1.0]).unwrap(),
        ),
    ];

    // `BENCH_SPECTRUM_ONLY=<kind>`: time that kind alone (e.g. under `perf stat`, whose
    // per-task cycle counts do not see other processes' load) and stop.
    if let Ok(only) = std::env::var("BENCH_SPECTRUM_ONLY") {
        let (_, spectrum) = kinds
            .iter()
            .find(|(name, _)| *name == only)
            .unwrap_or_else(|| panic!("no kind {only}"));
        let ns: Vec<f64> = (0..ROUNDS)
            .map(|_| bench_eval(spectrum, &wavelengths))
            .collect();
        let min = ns.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "{{\"kind\": \"{only}\", \"evals\": {}, \"min_ns\": {min:.2}}}",
            ROUNDS * EVALS_PER_RUN
        );
        return;
    }

    // Rounds interleave the kinds, so load from other processes spreads over all of them
    // and ratios between kinds measured in the same run stay meaningful.
    let mut timings: Vec<Vec<f64>> = vec![Vec::new(); kinds.len()];
    for _ in 0..ROUNDS {
        for (t, (_, spectrum)) in timings.iter_mut().zip(&kinds) {
            t.push(bench_eval(spectrum, &wavelengths));
        }
    }
    let (mut medians, mut minima, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    let dense_min = kinds
        .iter()
        .position(|(name, _)| *name == "dense")
        .map(|k| timings[k].iter().copied().fold(f64::INFINITY, f64::min))
        .unwrap();
    for ((name, _), t) in kinds.iter().zip(&mut timings) {
        t.sort_by(|a, b| a.total_cmp(b));
        let (median, min) = (t[t.len() / 2], t[0]);
        medians.push(format!("\"{name}\": {median:.2}"));
        minima.push(format!("\"{name}\": {min:.2}"));
        ratios.push(format!("\"{name}\": {:.2}", min / dense_min));
    }

    let mut u_state = 7u64;
    let mut sink = 0.0f32;
    let sample_ns = median_ns(EVALS_PER_RUN, |_| {
        let w = SampledWavelengths::sample_visible(black_box(splitmix(&mut u_state)));
        sink += w.pdf()[0];
    });
    let rng_ns = median_ns(EVALS_PER_RUN, |_| {
        sink += black_box(splitmix(&mut u_state));
    });
    black_box(sink);

    let observer = cmfs(Observer::Cie1931);
    let d65 = Spectrum::cie_illuminant("D65").unwrap().to_dense();
    let mut xyz_sink = 0.0;
    let xyz_ns = median_ns(200_000, |_| {
        xyz_sink += dense_to_xyz(black_box(&d65), observer)[1];
    });
    black_box(xyz_sink);

    // RGB → coefficients: the pure table lookup (textures) and the refined path
    // (`RgbAlbedoSpectrum::new`, constant colours), over saturated Rec.2020 colours (one
    // component scaled by 0.1; many lie outside the object-colour solid, where the
    // refinement runs to its iteration limit).
    let colours: Vec<[f32; 3]> = (0..256)
        .map(|_| {
            let mut c = [
                splitmix(&mut u_state),
                splitmix(&mut u_state),
                splitmix(&mut u_state),
            ];
            c[(u_state % 3) as usize] *= 0.1;
            c
        })
        .collect();
    let mut poly_sink = 0.0f32;
    let lookup_ns = median_ns(200_000, |i| {
        let s = RgbAlbedoSpectrum::from_table(RgbGamut::Rec2020, black_box(colours[i % 256]));
        poly_sink += s.unwrap().polynomial.c2;
    });
    let refined_ns = median_ns(2_000, |i| {
        let s = RgbAlbedoSpectrum::new(RgbGamut::Rec2020, black_box(colours[i % 256]));
        poly_sink += s.unwrap().polynomial.c2;
    });
    // Moderate colours (components in [0.2, 0.8]): reachable, Newton converges in a few steps.
    let moderate: Vec<[f32; 3]> = (0..256)
        .map(|_| std::array::from_fn(|_| 0.2 + 0.6 * splitmix(&mut u_state)))
        .collect();
    let refined_moderate_ns = median_ns(2_000, |i| {
        let s = RgbAlbedoSpectrum::new(RgbGamut::Rec2020, black_box(moderate[i % 256]));
        poly_sink += s.unwrap().polynomial.c2;
    });
    black_box(poly_sink);

    println!(
        "{{\"benchmark\": \"prism-spectrum\", \"unit\": \"ns\", \"runs\": {RUNS}, \"eval_rounds\": {ROUNDS}, \"statistic\": \"median\", \
\"eval_4_wavelengths_ns\": {{{}}}, \
\"eval_4_wavelengths_min_ns\": {{{}}}, \
\"eval_4_wavelengths_min_over_dense_min\": {{{}}}, \
\"sample_visible_wavelengths_ns\": {:.2}, \
\"spectrum_to_xyz_1nm_ns\": {:.1}, \
\"spectrum_to_xyz_1nm_min_ns\": {:.1}, \
\"rgb_albedo_from_table_ns\": {:.1}, \
\"rgb_albedo_from_table_min_ns\": {:.1}, \
\"rgb_albedo_refined_ns\": {:.0}, \
\"rgb_albedo_refined_min_ns\": {:.0}, \
\"rgb_albedo_refined_moderate_ns\": {:.0}, \
\"rgb_albedo_refined_moderate_min_ns\": {:.0}}}",
        medians.join(", "),
        minima.join(", "),
        ratios.join(", "),
        (sample_ns.0 - rng_ns.0).max(0.0),
        xyz_ns.0,
        xyz_ns.1,
        lookup_ns.0,
        lookup_ns.1,
        refined_ns.0,
        refined_ns.1,
        refined_moderate_ns.0,
        refined_moderate_ns.1
    );
}
