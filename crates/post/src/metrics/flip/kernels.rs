//! FLIP's filters at a viewing condition (pixels per degree), all separable:
//! - contrast sensitivity (sec. 3.1.1): per YyCxCz channel a sum of Gaussians
//!   g(r) = Σ aᵢ √(π/bᵢ) exp(−π² r² / bᵢ), r in degrees, on a square of radius
//!   ⌈3 √(b_max / 2π²) · ppd⌉ px normalised to unit sum. Each Gaussian term is a product
//!   of 1-D factors, so the 2-D filter is one separable pass per term (two for Cz);
//! - feature detectors (sec. 3.2): first (edges) and second (points) derivatives of a
//!   Gaussian, σ = ½ · 0.082° · ppd, radius ⌈3σ⌉, positive and negative weights each
//!   normalised to ±1. The 2-D filter is the derivative factor times a Gaussian factor, and
//!   the normalisation splits the same way (the Gaussian factor to unit sum).

use std::f64::consts::PI;

/// (a₁, b₁, a₂, b₂) of the contrast sensitivity functions: achromatic, red–green,
/// blue–yellow (b in deg²).
const CSF_Y: [f64; 4] = [1.0, 0.0047, 0.0, 1e-5];
const CSF_CX: [f64; 4] = [1.0, 0.0053, 0.0, 1e-5];
const CSF_CZ: [f64; 4] = [34.1, 0.04, 13.5, 0.025];

/// Peak-to-trough width of the human edge detector, degrees.
const FEATURE_WIDTH_DEG: f64 = 0.082;

#[derive(Debug, Clone)]
pub(super) struct Kernels {
    pub spatial_radius_px: usize,
    /// 1-D factors (length 2 r + 1), each applied horizontally and vertically; Cz is
    /// `cz1 ⊗ cz1 + cz2 ⊗ cz2`.
    pub y: Vec<f32>,
    pub cx: Vec<f32>,
    pub cz1: Vec<f32>,
    pub cz2: Vec<f32>,
    pub feature_radius_px: usize,
    pub gauss: Vec<f32>,
    pub d1: Vec<f32>,
    pub d2: Vec<f32>,
}

/// exp(−π² (i/ppd)² / b) for i in −r..=r.
fn csf_factor(b: f64, r: usize, ppd: f64) -> Vec<f64> {
    (0..=2 * r)
        .map(|i| {
            let x = (i as f64 - r as f64) / ppd;
            (-PI * PI * x * x / b).exp()
        })
        .collect()
}

/// The 1-D factors of one channel's filter, scaled so the 2-D sum of the terms is 1.
fn csf_terms(p: [f64; 4], r: usize, ppd: f64) -> [Vec<f32>; 2] {
    let (e1, e2) = (csf_factor(p[1], r, ppd), csf_factor(p[3], r, ppd));
    let (s1, s2): (f64, f64) = (e1.iter().sum(), e2.iter().sum());
    let (w1, w2) = (p[0] * (PI / p[1]).sqrt(), p[2] * (PI / p[3]).sqrt());
    let total = w1 * s1 * s1 + w2 * s2 * s2;
    let scale = |e: Vec<f64>, w: f64| {
        let f = (w / total).sqrt();
        e.into_iter().map(|v| (v * f) as f32).collect()
    };
    [scale(e1, w1), scale(e2, w2)]
}

/// Scales positive and negative weights to sum to +1 and −1.
fn balance(k: Vec<f64>) -> Vec<f32> {
    let pos: f64 = k.iter().filter(|v| **v > 0.0).sum();
    let neg: f64 = -k.iter().filter(|v| **v < 0.0).sum::<f64>();
    k.into_iter()
        .map(|v| (if v > 0.0 { v / pos } else { v / neg }) as f32)
        .collect()
}

impl Kernels {
    pub fn new(ppd: f64) -> Self {
        let b_max = [CSF_Y, CSF_CX, CSF_CZ]
            .iter()
            .flat_map(|p| [p[1], p[3]])
            .fold(0.0, f64::max);
        let r = (3.0 * (b_max / (2.0 * PI * PI)).sqrt() * ppd).ceil() as usize;
        let [y, _] = csf_terms(CSF_Y, r, ppd);
        let [cx, _] = csf_terms(CSF_CX, r, ppd);
        let [cz1, cz2] = csf_terms(CSF_CZ, r, ppd);

        let sd = 0.5 * FEATURE_WIDTH_DEG * ppd;
        let fr = (3.0 * sd).ceil() as usize;
        let xs: Vec<f64> = (0..=2 * fr).map(|i| i as f64 - fr as f64).collect();
        let g: Vec<f64> = xs
            .iter()
            .map(|x| (-x * x / (2.0 * sd * sd)).exp())
            .collect();
        let g_sum: f64 = g.iter().sum();
        let mut d1 = balance(xs.iter().zip(&g).map(|(x, g)| -x * g).collect());
        // The positive and negative sums of the odd d1 are equal but summed in different
        // orders: mirror the right half so the kernel is exactly antisymmetric (the band
        // filters fold it, `band::Folded`).
        for t in 1..=fr {
            d1[fr - t] = -d1[fr + t];
        }
        let d2 = balance(
            xs.iter()
                .zip(&g)
                .map(|(x, g)| (x * x / (sd * sd) - 1.0) * g)
                .collect(),
        );
        Self {
            spatial_radius_px: r,
            y,
            cx,
            cz1,
            cz2,
            feature_radius_px: fr,
            gauss: g.iter().map(|v| (v / g_sum) as f32).collect(),
            d1,
            d2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radii_and_normalisation_at_67_ppd() {
        let k = Kernels::new(67.0);
        // ⌈3 √(0.04 / 2π²) · 67⌉ = ⌈9.05⌉; ⌈3 · 0.041 · 67⌉ = ⌈8.24⌉.
        assert_eq!((k.spatial_radius_px, k.feature_radius_px), (10, 9));
        let sum2 = |a: &[f32]| a.iter().sum::<f32>().powi(2);
        assert!((sum2(&k.y) - 1.0).abs() < 1e-5);
        assert!((sum2(&k.cx) - 1.0).abs() < 1e-5);
        assert!((sum2(&k.cz1) + sum2(&k.cz2) - 1.0).abs() < 1e-5);
        assert!((k.gauss.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        for d in [&k.d1, &k.d2] {
            let pos: f32 = d.iter().filter(|v| **v > 0.0).sum();
            let neg: f32 = d.iter().filter(|v| **v < 0.0).sum();
            assert!((pos - 1.0).abs() < 1e-5 && (neg + 1.0).abs() < 1e-5);
        }
    }
}
