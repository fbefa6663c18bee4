//! Why the pure table lookup (`RgbAlbedoSpectrum::from_table`) misses 1e-3 on saturated
//! Rec.2020 / ACEScg colours (docs/rgb-upsampling.md, "Why the table fails on saturated
//! wide-gamut colours"). For every LP-reachable point of the 17³ grid of
//! crates/spectrum/tests/rgb_upsample.rs whose table round trip exceeds 1e-3, it looks at the
//! 8 nodes of the point's interpolation cell: how many are themselves off (a node RGB
//! error above 1e-4 even after `refine_polynomial`, i.e. colours the sigmoid family cannot
//! reach: the fit stopped at the coefficient bound), and the largest normalised coefficient
//! |A| among them. Prints one line per gamut.
//!
//! ```text
//! cargo run --release -p rgb2spec --example diagnose_wide_gamut_table
//! ```
//!
//! Colorimetry and reachability as in that test (independent of the generator): reflectance
//! × the space's white illuminant on the 1 nm grid with the CIE 1931 CMFs, and an RGB is
//! reachable iff ∃ r ∈ [0, 1]^471 with M r = rgb, decided as a linear programme (`microlp`).

// 3-vectors read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use microlp::{ComparisonOp, OptimizationDirection, Problem};
use prism_spectrum::data::{cmfs, illuminant, Observer};
use prism_spectrum::rgb_upsample::{
    refine_polynomial, RgbAlbedoSpectrum, RgbGamut, SigmoidPolynomial,
};
use prism_spectrum::DENSE_SAMPLE_COUNT;

/// 17³ grid: components k / 16, as the round-trip test.
const GRID_STEPS: usize = 16;
const ROUND_TRIP_TOLERANCE: f64 = 1e-3;
/// A node whose own RGB is off by more than this is one the sigmoid cannot reach.
const NODE_TOLERANCE: f64 = 1e-4;

/// Linear RGB of the space per unit reflectance at each 1 nm sample (471 × 3).
fn reflectance_to_rgb(gamut: RgbGamut) -> Vec<[f64; 3]> {
    let space = gamut.color_space();
    let c = cmfs(Observer::Cie1931);
    let spd = illuminant(space.white_illuminant)
        .expect("every gamut's white illuminant is tabulated")
        .to_dense();
    let y_white = spd.inner_product(&c.y_bar);
    (0..DENSE_SAMPLE_COUNT)
        .map(|i| {
            let w = spd.values()[i] / y_white;
            let xyz = glam::DVec3::new(
                w * c.x_bar.values()[i],
                w * c.y_bar.values()[i],
                w * c.z_bar.values()[i],
            );
            (space.xyz_to_rgb * xyz).to_array()
        })
        .collect()
}

/// Samples `eval4` on the 1 nm grid, four wavelengths at a time.
fn sample_dense(eval4: impl Fn([f32; 4]) -> [f32; 4]) -> Vec<f64> {
    let mut out = Vec::with_capacity(DENSE_SAMPLE_COUNT + 3);
    for start in (0..DENSE_SAMPLE_COUNT).step_by(4) {
        let wl = std::array::from_fn(|k| 360.0 + (start + k).min(DENSE_SAMPLE_COUNT - 1) as f32);
        out.extend(eval4(wl).iter().map(|&v| v as f64));
    }
    out.truncate(DENSE_SAMPLE_COUNT);
    out
}

fn project(weights: &[[f64; 3]], values: &[f64]) -> [f64; 3] {
    let mut rgb = [0.0; 3];
    for (w, v) in weights.iter().zip(values) {
        for k in 0..3 {
            rgb[k] += w[k] * v;
        }
    }
    rgb
}

fn max_abs_diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
}

/// ∃ r ∈ [0, 1]^471 with M r = rgb?
fn reachable(weights: &[[f64; 3]], rgb: [f32; 3]) -> Result<bool, String> {
    let mut lp = Problem::new(OptimizationDirection::Minimize);
    let vars: Vec<_> = weights
        .iter()
        .map(|_| lp.add_var(0.0, (0.0, 1.0)))
        .collect();
    for k in 0..3 {
        let row: Vec<_> = vars.iter().zip(weights).map(|(&v, w)| (v, w[k])).collect();
        lp.add_constraint(row.as_slice(), ComparisonOp::Eq, rgb[k] as f64);
    }
    match lp.solve() {
        Ok(_) => Ok(true),
        Err(microlp::Error::Infeasible) => Ok(false),
        Err(e) => Err(format!("LP for {rgb:?} failed: {e:?}")),
    }
}

/// The cell of `rgb` as `RgbToSpectrumTable::coefficients` finds it: the largest component
/// l and the lower corner (zi, yi, xi).
fn cell(gamut: RgbGamut, rgb: [f32; 3]) -> (usize, usize, usize, usize) {
    let table = gamut.table();
    let res = table.resolution();
    let l = if rgb[0] > rgb[1] {
        if rgb[0] > rgb[2] {
            0
        } else {
            2
        }
    } else if rgb[1] > rgb[2] {
        1
    } else {
        2
    };
    let z = rgb[l];
    let last = (res - 1) as f32;
    let xi = ((rgb[(l + 1) % 3] * last / z) as usize).min(res - 2);
    let yi = ((rgb[(l + 2) % 3] * last / z) as usize).min(res - 2);
    let zi = table
        .z_nodes()
        .partition_point(|&v| v < z)
        .saturating_sub(1)
        .min(res - 2);
    (l, zi, yi, xi)
}

fn diagnose(gamut: RgbGamut) -> Result<String, String> {
    let weights = reflectance_to_rgb(gamut);
    let table = gamut.table();
    let res = table.resolution();
    let z_nodes = table.z_nodes();
    let last = (res - 1) as f64;
    let node_rgb_error = |rgb: [f64; 3], p: SigmoidPolynomial| {
        max_abs_diff(project(&weights, &sample_dense(|wl| p.eval4(wl))), rgb)
    };
    let v = |i: usize| i as f32 / GRID_STEPS as f32;
    let n = GRID_STEPS + 1;
    let (mut reachable_failing, mut with_bad_node, mut with_huge) = (0, 0, 0);
    let mut bad_nodes_hist = [0usize; 9];
    for g in 0..n * n * n {
        let rgb = [v(g / (n * n)), v(g / n % n), v(g % n)];
        // Greys are flat spectra, not table lookups.
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            continue;
        }
        let s = RgbAlbedoSpectrum::from_table(gamut, rgb).map_err(|e| e.to_string())?;
        let out = project(&weights, &sample_dense(|wl| s.eval4(wl)));
        // The LP (the slow part) only for the points that fail.
        if max_abs_diff(out, rgb.map(f64::from)) <= ROUND_TRIP_TOLERANCE
            || !reachable(&weights, rgb)?
        {
            continue;
        }
        reachable_failing += 1;
        let (l, zi, yi, xi) = cell(gamut, rgb);
        let (mut bad, mut max_coeff) = (0, 0.0f64);
        for d in 0..8 {
            let (k, j, i) = (zi + (d >> 2), yi + ((d >> 1) & 1), xi + (d & 1));
            let zk = z_nodes[k] as f64;
            let mut node_rgb = [0.0; 3];
            node_rgb[l] = zk;
            node_rgb[(l + 1) % 3] = i as f64 / last * zk;
            node_rgb[(l + 2) % 3] = j as f64 / last * zk;
            let c = table.node(l, k, j, i);
            let p = SigmoidPolynomial::new(c[0], c[1], c[2]);
            // Normalised |A| (t = (λ − 360 nm) / 470 nm).
            max_coeff = max_coeff.max((c[0] as f64 * 470.0 * 470.0).abs());
            if k > 0 && node_rgb_error(node_rgb, p) > NODE_TOLERANCE {
                // Confirm with the refinement: still off → the sigmoid cannot reach it.
                let (_, e) = refine_polynomial(gamut.reflectance_rgb_weights(), p, node_rgb);
                if e > NODE_TOLERANCE {
                    bad += 1;
                }
            }
        }
        bad_nodes_hist[bad] += 1;
        if bad > 0 {
            with_bad_node += 1;
        }
        if max_coeff > 1e3 {
            with_huge += 1;
        }
    }
    Ok(format!(
        "{}: {reachable_failing} reachable points over 1e-3; {with_bad_node} have ≥ 1 \
         unreachable node in their cell (histogram of bad nodes 0..8: {bad_nodes_hist:?}); \
         {with_huge} have a node with |A| > 1e3",
        gamut.name()
    ))
}

fn main() -> std::process::ExitCode {
    for gamut in [RgbGamut::Rec2020, RgbGamut::AcesCg] {
        match diagnose(gamut) {
            Ok(line) => println!("{line}"),
            Err(e) => {
                eprintln!("diagnose_wide_gamut_table: {}: {e}", gamut.name());
                return std::process::ExitCode::FAILURE;
            }
        }
    }
    std::process::ExitCode::SUCCESS
}
