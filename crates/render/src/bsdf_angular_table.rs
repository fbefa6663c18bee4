//! ρ of a material per pair of directions: the BSDF angular bandwidth tables of Bagher et al.
//! 2013 §2.3 ("Reflectance (angular)"). For 16×16 incident directions the lobe
//! f(ωᵢ, ·) is taken over the outgoing hemisphere at 64×64 (θ_o linear over [0, π/2), φ_o
//! over [0, 2π)), reduced by eq. 7 (prism-bandwidth's `LocalBandwidth`) to cycles per
//! texel, divided by the texel's angular size (the larger of Δθ and sin θ_o Δφ, the map's
//! Jacobian) and max-filtered to 16×16 (a coarse cell keeps its sharpest texel: §2.3 scales
//! high-resolution slices down so that the resolution does not cap the bandwidth).
//!
//! Built once per material, only when the predictor runs. A Lambertian lobe (ρ = 0) and a
//! purely specular one (ρ = ∞) need no table; lobes with a Dirac part (a smooth coat) and
//! directions through the surface keep the lobe's own closed-form value
//! (`Bxdf::angular_bandwidth_cycles_per_rad`).

use glam::{UVec2, Vec3A};
use prism_bandwidth::local_bandwidth::{Boundary, LocalBandwidth};
use prism_spectrum::SampledWavelengths;
use rayon::prelude::*;

use crate::bsdf::{Bsdf, Bxdf, TransportMode};
use crate::material::Material;
use crate::plan::probe_hit;
use crate::probe::reflectance_y;
use prism_spectrum::XyzWeights;

/// Incident and outgoing cells per axis (θ, φ) of a table.
pub const TABLE_CELLS: usize = 16;
/// Texels per axis of one lobe slice before max-filtering.
pub const SLICE_TEXELS: usize = 64;

/// The direction at the centre of cell (iθ, iφ) of an `n`×`n` hemisphere grid.
pub(crate) fn cell_direction(i_theta: usize, i_phi: usize, n: usize) -> Vec3A {
    let theta = std::f32::consts::FRAC_PI_2 * (i_theta as f32 + 0.5) / n as f32;
    let phi = std::f32::consts::TAU * (i_phi as f32 + 0.5) / n as f32;
    Vec3A::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The cell of a local direction (z up) in an `n`×`n` hemisphere grid; `None` below.
fn cell_of(w: Vec3A, n: usize) -> Option<(usize, usize)> {
    if w.z <= 0.0 {
        return None;
    }
    let theta = w.z.clamp(0.0, 1.0).acos();
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let i_theta = ((theta / std::f32::consts::FRAC_PI_2 * n as f32) as usize).min(n - 1);
    let i_phi = ((phi / std::f32::consts::TAU * n as f32) as usize).min(n - 1);
    Some((i_theta, i_phi))
}

/// A material's angular bandwidth, cycles/rad.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialAngularBandwidth {
    /// The same everywhere: 0 (Lambert), ∞ (Dirac lobes), or the closed form of a lobe
    /// the table cannot hold.
    Constant(f32),
    /// ρ per (incident cell, outgoing cell), `TABLE_CELLS`⁴ values, incident-major.
    Table(Vec<f32>),
}

impl MaterialAngularBandwidth {
    /// The table of `material` at a neutral hit (its textures at uv = (0.5, 0.5)).
    pub fn build(material: &Material) -> Self {
        match with_tabulated_bsdf(material, |bsdf, wavelengths| {
            Self::Table(Self::tabulate(bsdf, wavelengths))
        }) {
            Ok(table) => table,
            Err(closed_form) => Self::Constant(closed_form),
        }
    }

    /// The table's values for a lobe that gets one (`with_tabulated_bsdf`).
    fn tabulate(bsdf: &Bsdf, wavelengths: &SampledWavelengths) -> Vec<f32> {
        if bsdf.lobe.is_isotropic() {
            // One incident azimuth per θᵢ: the slice at φᵢ = k·2π/16 is that of φᵢ = 0
            // rotated by k cells in φₒ (the lobe depends on φₒ − φᵢ only). 16× fewer
            // lobe evaluations and eq. 7 reductions; with φₒ padded periodically
            // (slice_bandwidth) only the alignment of the coarse wavelets to the lobe
            // differs from a slice taken at φᵢ itself, which the test below bounds.
            let first: Vec<Vec<f32>> = (0..TABLE_CELLS)
                .into_par_iter()
                .map(|it| slice_bandwidth(bsdf, cell_direction(it, 0, TABLE_CELLS), wavelengths))
                .collect();
            let rotated: Vec<f32> = (0..TABLE_CELLS * TABLE_CELLS)
                .flat_map(|i| rotated_in_phi(&first[i / TABLE_CELLS], i % TABLE_CELLS))
                .collect();
            return rotated;
        }
        full_table(bsdf, wavelengths)
    }

    /// ρ for light from `wi_local` seen from `wo_local` (shading frame, z = normal).
    pub fn at(&self, wi_local: Vec3A, wo_local: Vec3A, fallback: f32) -> f32 {
        match self {
            Self::Constant(v) => *v,
            Self::Table(table) => {
                // Reciprocity: either side may be "incident"; a direction through the
                // surface has no table.
                match (
                    cell_of(wi_local, TABLE_CELLS),
                    cell_of(wo_local, TABLE_CELLS),
                ) {
                    (Some((it, ip)), Some((ot, op))) => {
                        let n = TABLE_CELLS;
                        table[((it * n + ip) * n + ot) * n + op]
                    }
                    _ => fallback,
                }
            }
        }
    }
}

/// `f` of the BSDF a table is built from — `material`'s at the neutral hit, at the
/// table's wavelengths — or, for a lobe that gets no table (Lambert: 0, Dirac: ∞, a smooth
/// coat's Dirac part: its closed form), `Err` of the lobe's closed-form bandwidth. The one
/// decision `build` and the cache's fingerprint (`bsdf_table_cache.rs`) share.
pub(crate) fn with_tabulated_bsdf<R>(
    material: &Material,
    f: impl FnOnce(&Bsdf, &SampledWavelengths) -> R,
) -> Result<R, f32> {
    let hit = probe_hit();
    let wavelengths = SampledWavelengths::sample_visible(0.5);
    let bsdf = material.bsdf(&hit, &wavelengths);
    let closed_form = bsdf.lobe.angular_bandwidth_cycles_per_rad();
    if bsdf.is_specular() || bsdf.has_specular() || closed_form == 0.0 {
        return Err(closed_form);
    }
    Ok(f(&bsdf, &wavelengths))
}

/// Every incident cell's slice taken at its own direction (any lobe).
fn full_table(bsdf: &Bsdf, wavelengths: &SampledWavelengths) -> Vec<f32> {
    let slices: Vec<Vec<f32>> = (0..TABLE_CELLS * TABLE_CELLS)
        .into_par_iter()
        .map(|i| {
            let wi = cell_direction(i / TABLE_CELLS, i % TABLE_CELLS, TABLE_CELLS);
            slice_bandwidth(bsdf, wi, wavelengths)
        })
        .collect();
    slices.concat()
}

/// A 16×16 outgoing slice (row = θₒ, column = φₒ) for an incident azimuth `k` cells on:
/// column c takes column c − k (mod 16).
fn rotated_in_phi(slice: &[f32], k: usize) -> Vec<f32> {
    let n = TABLE_CELLS;
    (0..n * n)
        .map(|i| {
            let (row, column) = (i / n, i % n);
            slice[row * n + (column + n - k) % n]
        })
        .collect()
}

/// One incident direction's 16×16 outgoing bandwidths (row = θ_o, column = φ_o).
fn slice_bandwidth(bsdf: &Bsdf, wi: Vec3A, wavelengths: &SampledWavelengths) -> Vec<f32> {
    let n = SLICE_TEXELS;
    let xyz = XyzWeights::new(wavelengths);
    let values: Vec<f32> = (0..n * n)
        .map(|k| {
            let wo = cell_direction(k / n, k % n, n);
            reflectance_y(bsdf.eval(wo, wi, TransportMode::Radiance), &xyz)
        })
        .collect();
    // φₒ is periodic: the map is continued by a full period on either side (3n columns),
    // so that every wavelet over a texel of the middle period (blocks up to n wide) sees
    // the lobe as on a circle, wherever φᵢ puts it; the middle period is kept.
    let padded: Vec<f32> = (0..n * 3 * n)
        .map(|k| values[(k / (3 * n)) * n + (k % (3 * n)) % n])
        .collect();
    let Ok(local) = LocalBandwidth::estimate(
        &padded,
        UVec2::new(3 * n as u32, n as u32),
        1.0,
        Boundary::InsideOnly,
    ) else {
        return vec![bsdf.lobe.angular_bandwidth_cycles_per_rad(); TABLE_CELLS * TABLE_CELLS];
    };
    let d_theta = std::f32::consts::FRAC_PI_2 / n as f32;
    let d_phi = std::f32::consts::TAU / n as f32;
    let per_texel = local.cycles_per_unit();
    let mut out = vec![0.0f32; TABLE_CELLS * TABLE_CELLS];
    let block = n / TABLE_CELLS;
    for row in 0..n {
        for column in 0..n {
            let texel = per_texel[row * 3 * n + n + column];
            let theta = (row as f32 + 0.5) * d_theta;
            let rad_per_texel = d_theta.max(theta.sin() * d_phi);
            let cell = (row / block) * TABLE_CELLS + column / block;
            out[cell] = out[cell].max(texel / rad_per_texel);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_scene::parse_scene_str;

    use crate::scene_build::RenderScene;

    fn material(json_material: &str) -> MaterialAngularBandwidth {
        let json = format!(
            r#"{{"materials": {{"m": {json_material}}},
                "shapes": [{{"type": "sphere", "material": "m"}}]}}"#
        );
        let scene = RenderScene::build(&parse_scene_str(&json, "t.json").unwrap(), None).unwrap();
        MaterialAngularBandwidth::build(scene.material(0))
    }

    /// ρ for light at normal incidence seen along the mirror direction (the peak).
    fn at_peak(m: &MaterialAngularBandwidth) -> f32 {
        let w = cell_direction(0, 0, TABLE_CELLS);
        m.at(w, Vec3A::new(-w.x, -w.y, w.z), f32::NAN)
    }

    /// The isotropic shortcut against slices taken at every incident azimuth: the same
    /// at φᵢ = 0 and close elsewhere (the coarse wavelets' alignment to the lobe is the
    /// only difference; measured: every quantile printed is 1.000).
    #[test]
    fn rotated_slices_of_an_isotropic_lobe_match_slices_taken_at_each_azimuth() {
        for roughness in [0.05, 0.1, 0.3] {
            let json = format!(
                r#"{{"materials": {{"m": {{"type": "conductor", "metal": "Au", "roughness": {roughness}}}}},
                    "shapes": [{{"type": "sphere", "material": "m"}}]}}"#
            );
            let scene =
                RenderScene::build(&parse_scene_str(&json, "t.json").unwrap(), None).unwrap();
            let MaterialAngularBandwidth::Table(fast) =
                MaterialAngularBandwidth::build(scene.material(0))
            else {
                panic!("a rough conductor has a table");
            };
            let wavelengths = SampledWavelengths::sample_visible(0.5);
            let bsdf = scene.material(0).bsdf(&probe_hit(), &wavelengths);
            assert!(bsdf.lobe.is_isotropic());
            let full = full_table(&bsdf, &wavelengths);
            let n2 = TABLE_CELLS * TABLE_CELLS;
            let mut ratios = Vec::new();
            for (i, (a, b)) in fast.iter().zip(&full).enumerate() {
                let incident_phi = (i / n2) % TABLE_CELLS;
                if incident_phi == 0 {
                    assert_eq!(a, b, "cell {i}");
                } else if *b > 0.0 && b.is_finite() {
                    ratios.push(a / b);
                }
            }
            ratios.sort_by(f32::total_cmp);
            let q = |p: f64| ratios[((ratios.len() - 1) as f64 * p) as usize];
            eprintln!(
                "roughness {roughness}: rotated / taken, 1 %, 5 %, 50 %, 95 %, 99 %: {:.3}, {:.3}, {:.3}, {:.3}, {:.3}",
                q(0.01),
                q(0.05),
                q(0.5),
                q(0.95),
                q(0.99)
            );
            assert!((q(0.5) - 1.0).abs() < 0.02, "median {}", q(0.5));
            assert!(q(0.05) > 0.9 && q(0.95) < 1.25, "{} {}", q(0.05), q(0.95));
        }
    }

    #[test]
    fn lambert_and_mirror_need_no_table() {
        assert_eq!(
            material(r#"{"type": "lambert", "reflectance": 0.5}"#),
            MaterialAngularBandwidth::Constant(0.0)
        );
        assert_eq!(
            material(r#"{"type": "conductor", "metal": "Ag", "roughness": 0}"#),
            MaterialAngularBandwidth::Constant(f32::INFINITY)
        );
    }

    /// The 95 %-energy radius (cycles/rad) of the 2-D DFT of the lobe at normal incidence,
    /// sampled on a 64×64 grid of tangent-plane angles 2.5/α·… wide: the reference of test c.
    fn lobe_fft_bandwidth(json_material: &str, half_width_rad: f32) -> f32 {
        let json = format!(
            r#"{{"materials": {{"m": {json_material}}},
                "shapes": [{{"type": "sphere", "material": "m"}}]}}"#
        );
        let scene = RenderScene::build(&parse_scene_str(&json, "t.json").unwrap(), None).unwrap();
        let wavelengths = SampledWavelengths::sample_visible(0.5);
        let bsdf = scene.material(0).bsdf(&probe_hit(), &wavelengths);
        let n = 64usize;
        let step = 2.0 * half_width_rad / n as f32;
        let values: Vec<f64> = (0..n * n)
            .map(|k| {
                let (ax, ay) = (
                    ((k % n) as f32 + 0.5) * step - half_width_rad,
                    ((k / n) as f32 + 0.5) * step - half_width_rad,
                );
                let wo = Vec3A::new(ax.sin(), ay.sin(), 1.0).normalize();
                f64::from(reflectance_y(
                    bsdf.eval(wo, Vec3A::Z, TransportMode::Radiance),
                    &XyzWeights::new(&wavelengths),
                ))
            })
            .collect();
        // Power spectrum by a direct DFT, then the radius holding 95 % of the energy
        // (the DC term included, as for a lobe's spectrum).
        let mut power = Vec::with_capacity(n * n);
        for fy in 0..n {
            for fx in 0..n {
                let (mut re, mut im) = (0.0f64, 0.0f64);
                for (k, v) in values.iter().enumerate() {
                    let phase = std::f64::consts::TAU
                        * ((fx * (k % n)) as f64 + (fy * (k / n)) as f64)
                        / n as f64;
                    re += v * phase.cos();
                    im -= v * phase.sin();
                }
                let signed = |f: usize| {
                    if f > n / 2 {
                        f as f64 - n as f64
                    } else {
                        f as f64
                    }
                };
                let radius = (signed(fx).powi(2) + signed(fy).powi(2)).sqrt();
                power.push((radius, re * re + im * im));
            }
        }
        power.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = power.iter().map(|p| p.1).sum();
        let mut running = 0.0;
        for (radius, p) in &power {
            running += p;
            if running >= 0.95 * total {
                return (*radius / (n as f64 * f64::from(step))) as f32;
            }
        }
        f32::NAN
    }

    #[test]
    fn ggx_tables_are_sharper_for_smoother_lobes_and_near_the_lobes_fft() {
        let mut previous = f32::INFINITY;
        for alpha in [0.05f32, 0.1, 0.3] {
            let json = format!(r#"{{"type": "conductor", "metal": "Al", "roughness": {alpha}}}"#);
            let m = material(&json);
            assert!(matches!(m, MaterialAngularBandwidth::Table(_)));
            let rho = at_peak(&m);
            assert!(rho < previous, "α {alpha}: ρ {rho} not below {previous}");
            previous = rho;
            let reference = lobe_fft_bandwidth(&json, (8.0 * alpha).min(1.2));
            eprintln!("α {alpha}: table ρ {rho:.3} cycles/rad, lobe FFT {reference:.3}");
            assert!(
                rho > 0.5 * reference && rho < 2.0 * reference,
                "α {alpha}: ρ {rho} vs the lobe's FFT {reference}"
            );
        }
    }
}
