//! Generates the RGB → sigmoid-polynomial coefficient tables of prism-spectrum
//! (Jakob & Hanika 2019, "A Low-Dimensional Function Space for Efficient Spectral
//! Upsampling", §4; layout and continuation scheme of pbrt-v4's rgb2spec_opt).
//!
//! ```text
//! cargo run --release -p rgb2spec -- --gamut srgb --resolution 64 \
//!     -o crates/spectrum/data/rgb2spec_srgb.bin
//! ```
//!
//! For every node (max component l, z index k, y index j, x index i) the target linear RGB is
//! rgb[l] = z_k, rgb[l+1] = x_i z_k, rgb[l+2] = y_j z_k (indices mod 3). The three
//! coefficients of s(t) = S(A t² + B t + C), t = (λ − 360 nm) / 470 nm, are fitted by
//! Levenberg–Marquardt-damped Gauss–Newton minimising the CIELAB difference between the
//! target and the reflectance's colour under the space's white illuminant (D65; D60 for
//! ACEScg) with the CIE 1931 2° observer, summed on the 1 nm grid 360–830 nm. Each (l, j)
//! row is solved in sequence: along z outwards from k = res/5 and back down (continuation,
//! paper §4.2), each column's first solve starting from its x-neighbour's. Rows run in
//! parallel (rayon); every row is deterministic, so the output bytes are too.

// 3 × 3 linear algebra reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::process::ExitCode;
use std::time::Instant;

use prism_spectrum::data::{cmfs, Observer};
use prism_spectrum::rgb_upsample::{
    solve3, white_illuminant_dense, z_nodes, RgbGamut, RgbToSpectrumTable,
};
use rayon::prelude::*;

const LAMBDA_MIN_NM: f64 = 360.0;
const LAMBDA_RANGE_NM: f64 = 470.0;
/// Stop when the CIELAB residual norm is below this (ΔE*ab units).
const LAB_TOLERANCE: f64 = 1e-7;
const MAX_ITERATIONS: usize = 200;
/// Bound on |A|, |B|, |C| (normalised wavelength). Colours outside the object-colour solid
/// (reachable only in the limit of a step spectrum, or not at all) drive the coefficients
/// to infinity; the bound keeps them finite and f32-evaluable in nm (c0 λ² ≲ 6e4).
/// Reachable sRGB colours need at most ~2e3.
const COEFFICIENT_LIMIT: f64 = 2e4;

/// What colour a reflectance has, on the 1 nm grid: the normalised wavelength t of each
/// sample and the XYZ per unit reflectance there (illuminant × CMFs / Σ illuminant · ȳ).
struct Colorimetry {
    t: Vec<f64>,
    xyz_weights: Vec<[f64; 3]>,
    /// XYZ of the illuminant itself (Y = 1), the CIELAB reference white.
    white_xyz: [f64; 3],
    /// Linear RGB → XYZ of the space (row-major).
    rgb_to_xyz: [[f64; 3]; 3],
}

impl Colorimetry {
    fn new(gamut: RgbGamut) -> Self {
        let space = gamut.color_space();
        let c = cmfs(Observer::Cie1931);
        // Normalised so that Σ I ȳ = Σ ȳ; dividing by Σ ȳ then gives Y(flat 1) = 1.
        let illum = white_illuminant_dense(&space);
        let y_sum: f64 = c.y_bar.values().iter().sum();
        let xyz_weights: Vec<[f64; 3]> = (0..illum.len())
            .map(|i| {
                [
                    illum[i] * c.x_bar.values()[i] / y_sum,
                    illum[i] * c.y_bar.values()[i] / y_sum,
                    illum[i] * c.z_bar.values()[i] / y_sum,
                ]
            })
            .collect();
        let mut white_xyz = [0.0; 3];
        for w in &xyz_weights {
            for k in 0..3 {
                white_xyz[k] += w[k];
            }
        }
        let m = space.rgb_to_xyz;
        let rgb_to_xyz = std::array::from_fn(|row| std::array::from_fn(|col| m.col(col)[row]));
        Self {
            t: (0..illum.len())
                .map(|i| i as f64 / LAMBDA_RANGE_NM)
                .collect(),
            xyz_weights,
            white_xyz,
            rgb_to_xyz,
        }
    }

    /// CIELAB of `xyz` relative to the illuminant's white, and d(Lab)/d(XYZ) (row-major).
    fn lab(&self, xyz: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        const DELTA: f64 = 6.0 / 29.0;
        let f = |t: f64| {
            if t > DELTA * DELTA * DELTA {
                (t.cbrt(), 1.0 / (3.0 * t.cbrt() * t.cbrt()))
            } else {
                (
                    t / (3.0 * DELTA * DELTA) + 4.0 / 29.0,
                    1.0 / (3.0 * DELTA * DELTA),
                )
            }
        };
        let (fx, gx) = f(xyz[0] / self.white_xyz[0]);
        let (fy, gy) = f(xyz[1] / self.white_xyz[1]);
        let (fz, gz) = f(xyz[2] / self.white_xyz[2]);
        let (gx, gy, gz) = (
            gx / self.white_xyz[0],
            gy / self.white_xyz[1],
            gz / self.white_xyz[2],
        );
        let lab = [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)];
        let jac = [
            [0.0, 116.0 * gy, 0.0],
            [500.0 * gx, -500.0 * gy, 0.0],
            [0.0, 200.0 * gy, -200.0 * gz],
        ];
        (lab, jac)
    }

    /// XYZ of the reflectance S(A t² + B t + C) and, when asked, d(XYZ)/d(A, B, C).
    fn xyz(&self, c: [f64; 3], with_jacobian: bool) -> ([f64; 3], [[f64; 3]; 3]) {
        let mut xyz = [0.0; 3];
        let mut jac = [[0.0; 3]; 3];
        for (&t, w) in self.t.iter().zip(&self.xyz_weights) {
            let x = (c[0] * t + c[1]) * t + c[2];
            let inv = 1.0 / (1.0 + x * x).sqrt();
            let s = 0.5 + 0.5 * x * inv;
            for k in 0..3 {
                xyz[k] += s * w[k];
            }
            if with_jacobian {
                // S'(x) = 1 / (2 (1 + x²)^{3/2}); ∂x/∂(A, B, C) = (t², t, 1).
                let ds = 0.5 * inv * inv * inv;
                let d = [ds * t * t, ds * t, ds];
                for k in 0..3 {
                    for p in 0..3 {
                        jac[k][p] += w[k] * d[p];
                    }
                }
            }
        }
        (xyz, jac)
    }

    /// Lab residual (fitted − target) and its Jacobian w.r.t. (A, B, C).
    fn residual(
        &self,
        c: [f64; 3],
        target_lab: [f64; 3],
        with_jacobian: bool,
    ) -> ([f64; 3], [[f64; 3]; 3]) {
        let (xyz, j_xyz) = self.xyz(c, with_jacobian);
        let (lab, j_lab) = self.lab(xyz);
        let r = std::array::from_fn(|k| lab[k] - target_lab[k]);
        (
            r,
            if with_jacobian {
                mat_mul(j_lab, j_xyz)
            } else {
                [[0.0; 3]; 3]
            },
        )
    }

    /// Fits (A, B, C) to linear `rgb`, starting from `c`; returns the final ΔE*ab.
    fn fit(&self, rgb: [f64; 3], c: &mut [f64; 3]) -> f64 {
        let m = &self.rgb_to_xyz;
        let target_xyz = std::array::from_fn(|r| (0..3).map(|k| m[r][k] * rgb[k]).sum());
        let (target_lab, _) = self.lab(target_xyz);
        let (mut r, mut jac) = self.residual(*c, target_lab, true);
        let mut cost = norm(r);
        let mut damping = 0.0;
        for _ in 0..MAX_ITERATIONS {
            if cost < LAB_TOLERANCE {
                break;
            }
            // Normal equations (JᵀJ + μ diag JᵀJ) δ = −Jᵀr; μ = 0 is plain Gauss–Newton.
            let jt = transpose(jac);
            let a = mat_mul(jt, jac);
            let g: [f64; 3] = std::array::from_fn(|p| (0..3).map(|k| jt[p][k] * r[k]).sum());
            let mut accepted = false;
            for _ in 0..8 {
                let mut ad = a;
                for p in 0..3 {
                    ad[p][p] *= 1.0 + damping;
                }
                let Some(step) = solve3(ad, g.map(|v| -v)) else {
                    damping = if damping == 0.0 { 1e-3 } else { damping * 10.0 };
                    continue;
                };
                let trial: [f64; 3] = std::array::from_fn(|p| c[p] + step[p]);
                if trial.iter().any(|v| v.abs() > COEFFICIENT_LIMIT) {
                    damping = if damping == 0.0 { 1e-3 } else { damping * 10.0 };
                    continue;
                }
                let (r_trial, _) = self.residual(trial, target_lab, false);
                let cost_trial = norm(r_trial);
                if cost_trial < cost {
                    *c = trial;
                    damping *= 0.1;
                    if damping < 1e-6 {
                        damping = 0.0;
                    }
                    accepted = true;
                    break;
                }
                damping = if damping == 0.0 { 1e-3 } else { damping * 10.0 };
            }
            if !accepted {
                break; // no descent along any damped step: at a (boundary) minimum
            }
            (r, jac) = self.residual(*c, target_lab, true);
            let new_cost = norm(r);
            let improved = cost - new_cost;
            cost = new_cost;
            // Stalled (a colour the family reaches only in the limit, or not at all).
            if improved < 1e-4 * cost {
                break;
            }
        }
        cost
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn transpose(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[c][r]))
}

fn mat_mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

/// (A, B, C) for t = (λ − 360) / 470 → (c0, c1, c2) for λ in nm (pbrt-v4 rgb2spec_opt).
fn to_nm_coefficients(c: [f64; 3]) -> [f32; 3] {
    let (l0, inv_range) = (LAMBDA_MIN_NM, 1.0 / LAMBDA_RANGE_NM);
    let [a, b, cc] = c;
    [
        (a * inv_range * inv_range) as f32,
        (b * inv_range - 2.0 * a * l0 * inv_range * inv_range) as f32,
        (cc - b * l0 * inv_range + a * (l0 * inv_range) * (l0 * inv_range)) as f32,
    ]
}

struct RowResult {
    /// [k][i][3] for this (l, j).
    coefficients: Vec<f32>,
    worst_delta_e: f64,
}

/// A fit this close (ΔE*ab) needs no other starting point.
const GOOD_ENOUGH_DELTA_E: f64 = 1e-6;

/// Fits `rgb` from each seed in turn until one converges; returns the best fit.
fn fit_from_seeds(col: &Colorimetry, rgb: [f64; 3], seeds: &[[f64; 3]]) -> ([f64; 3], f64) {
    let mut best = ([0.0; 3], f64::INFINITY);
    for &seed in seeds {
        let mut c = seed;
        let e = col.fit(rgb, &mut c);
        if e < best.1 {
            best = (c, e);
        }
        if best.1 < GOOD_ENOUGH_DELTA_E {
            break;
        }
    }
    best
}

/// Fits every node of row (l, j), column by column (x index i). Each column starts at
/// k = res/5 and is continued along z upwards, then downwards (paper §4.2, pbrt-v4). A node
/// first starts from its z-neighbour's solution; if that does not converge (Gauss–Newton
/// can settle in a wrong basin, e.g. a band-pass where a band-stop is needed), it restarts
/// from the x-neighbour's solution at the same z, then from zero (flat ½), keeping the best.
fn solve_row(col: &Colorimetry, z: &[f32], res: usize, l: usize, j: usize) -> RowResult {
    let y = j as f64 / (res - 1) as f64;
    let start = res / 5;
    let mut out = vec![0.0f32; res * res * 3];
    let mut worst: f64 = 0.0;
    let mut previous_column = vec![[0.0f64; 3]; res];
    let mut column = vec![[0.0f64; 3]; res];
    for i in 0..res {
        let x = i as f64 / (res - 1) as f64;
        let target = |k: usize| {
            let b = z[k] as f64;
            let mut rgb = [0.0; 3];
            rgb[l] = b;
            rgb[(l + 1) % 3] = x * b;
            rgb[(l + 2) % 3] = y * b;
            rgb
        };
        // Upwards from `start`, then downwards from it.
        for k in (start..res).chain((1..start).rev()) {
            let from_z = match k {
                _ if k == start => previous_column[start],
                _ if k > start => column[k - 1],
                _ => column[k + 1],
            };
            let (c, e) = fit_from_seeds(col, target(k), &[from_z, previous_column[k], [0.0; 3]]);
            worst = worst.max(e);
            if verbose() && e > 1e-5 {
                eprintln!(
                    "l={l} k={k} j={j} i={i} rgb={:?} dE={e:.3e} c={c:?}",
                    target(k)
                );
            }
            column[k] = c;
        }
        // z = 0 is black for every (x, y): only r = 0 reaches it, at c2 → −∞. Store the
        // z_1 node's coefficients instead (error ≤ z_1 ≈ 1.6e−6 at res 64).
        column[0] = column[1];
        for (k, c) in column.iter().enumerate() {
            let o = (k * res + i) * 3;
            out[o..o + 3].copy_from_slice(&to_nm_coefficients(*c));
        }
        previous_column.copy_from_slice(&column);
    }
    RowResult {
        coefficients: out,
        worst_delta_e: worst,
    }
}

fn generate(gamut: RgbGamut, res: usize) -> (RgbToSpectrumTable, f64) {
    let col = Colorimetry::new(gamut);
    let z = z_nodes(res);
    let rows: Vec<RowResult> = (0..3 * res)
        .into_par_iter()
        .map(|lj| solve_row(&col, &z, res, lj / res, lj % res))
        .collect();
    let mut coefficients = vec![0.0f32; 3 * res * res * res * 3];
    let mut worst: f64 = 0.0;
    for (lj, row) in rows.iter().enumerate() {
        let (l, j) = (lj / res, lj % res);
        worst = worst.max(row.worst_delta_e);
        for k in 0..res {
            for i in 0..res {
                let dst = 3 * (((l * res + k) * res + j) * res + i);
                let src = 3 * (k * res + i);
                coefficients[dst..dst + 3].copy_from_slice(&row.coefficients[src..src + 3]);
            }
        }
    }
    let table = RgbToSpectrumTable::new(res, gamut.name(), z, coefficients)
        .unwrap_or_else(|e| panic!("generated table is invalid: {e}"));
    (table, worst)
}

fn verbose() -> bool {
    std::env::var_os("RGB2SPEC_VERBOSE").is_some()
}

fn usage() -> &'static str {
    "usage: rgb2spec --gamut srgb|rec2020|acescg --resolution N -o OUTPUT.bin"
}

fn run() -> Result<(), String> {
    let mut gamut = None;
    let mut resolution = None;
    let mut output = None;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next()
                .ok_or_else(|| format!("{arg} needs a value\n{}", usage()))
        };
        match arg.as_str() {
            "--gamut" => gamut = Some(RgbGamut::from_name(&value()?).map_err(|e| e.to_string())?),
            "--resolution" => {
                let v = value()?;
                let n: usize = v
                    .parse()
                    .map_err(|_| format!("--resolution `{v}` is not a whole number"))?;
                if !(8..=256).contains(&n) {
                    return Err(format!(
                        "--resolution {n} is out of range: expected 8 to 256"
                    ));
                }
                resolution = Some(n);
            }
            "-o" | "--output" => output = Some(value()?),
            "-h" | "--help" => {
                println!("{}", usage());
                return Ok(());
            }
            other => return Err(format!("unknown argument `{other}`\n{}", usage())),
        }
    }
    let (Some(gamut), Some(res), Some(output)) = (gamut, resolution, output) else {
        return Err(format!("missing arguments\n{}", usage()));
    };
    let started = Instant::now();
    let (table, worst) = generate(gamut, res);
    let seconds = started.elapsed().as_secs_f64();
    let bytes = table.to_bytes();
    std::fs::write(&output, &bytes).map_err(|e| format!("cannot write {output}: {e}"))?;
    println!(
        "{{\"gamut\": \"{}\", \"resolution\": {res}, \"threads\": {}, \"seconds\": {seconds:.2}, \
         \"worst_node_delta_e\": {worst:.3e}, \"bytes\": {}, \"output\": \"{output}\"}}",
        gamut.name(),
        rayon::current_num_threads(),
        bytes.len()
    );
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rgb2spec: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nm_coefficients_evaluate_like_normalised_ones() {
        let c = [3.0, -2.0, 0.5];
        let nm = to_nm_coefficients(c);
        for lambda in [360.0, 512.0, 830.0] {
            let t = (lambda - LAMBDA_MIN_NM) / LAMBDA_RANGE_NM;
            let p_norm = (c[0] * t + c[1]) * t + c[2];
            let p_nm = (nm[0] as f64 * lambda + nm[1] as f64) * lambda + nm[2] as f64;
            assert!((p_norm - p_nm).abs() < 1e-5, "{lambda}: {p_norm} vs {p_nm}");
        }
    }

    #[test]
    fn fit_reaches_an_srgb_colour() {
        let col = Colorimetry::new(RgbGamut::Srgb);
        let mut c = [0.0; 3];
        let e = col.fit([0.6, 0.3, 0.1], &mut c);
        assert!(e < 1e-6, "ΔE {e}");
    }

    #[test]
    fn solve3_inverts_and_reports_singular() {
        let a = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = solve3(a, [3.0, 5.0, 5.0]).unwrap();
        for (row, b) in a.iter().zip([3.0, 5.0, 5.0]) {
            assert!((row[0] * x[0] + row[1] * x[1] + row[2] * x[2] - b).abs() < 1e-12);
        }
        assert!(solve3(
            [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]],
            [1.0; 3]
        )
        .is_none());
    }
}
