//! Image comparison metrics (`prism compare TEST REFERENCE`). Conventions, all stated once:
//! - the second image is the reference; the test image is converted to the reference's
//!   colour space (through XYZ) before comparing;
//! - non-finite or negative samples are treated as the tone operators treat them (black /
//!   clamped to 0) and counted in `non_finite_pixels`;
//! - mse, rmse: mean over pixels and channels of (a − b)²;
//! - relmse: mean of (a − b)² / (b² + ε), ε = 1e-2 (Rousselle et al. 2011 style);
//! - psnr_db = 10 log10(peak² / mse), peak = the largest channel value of the reference
//!   (∞, written as JSON null, for identical images);
//! - ssim: Wang et al. 2004 on relative luminance Y, dynamic range L = the reference's
//!   largest Y (see [`ssim`]); null for images smaller than 11×11;
//! - ΔE2000: XYZ → CIELAB against the white of the reference's colour space with Y
//!   normalised so that RGB (1, 1, 1) (Y = 1) is the reference white (L* = 100), i.e.
//!   display-referred relative colorimetry; mean and 95th percentile (nearest rank).

mod ssim;

use prism_spectrum::colorimetry::{delta_e_2000, xyz_to_lab};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{PostError, Result};
use crate::image::Image;
use crate::io::convert_pixels;
use crate::tonemap::pixels::{sanitise, CHUNK};

/// ε of relMSE.
pub const RELMSE_EPSILON: f64 = 1e-2;

/// Per-channel (R, G, B) errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerChannel {
    pub mse: [f64; 3],
    pub rmse: [f64; 3],
    pub relmse: [f64; 3],
    pub psnr_db: [f64; 3],
}

/// Everything `prism compare --json` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    pub width: usize,
    pub height: usize,
    pub mse: f64,
    pub rmse: f64,
    pub relmse: f64,
    pub psnr_db: f64,
    pub ssim: Option<f64>,
    pub delta_e2000_mean: f64,
    pub delta_e2000_p95: f64,
    pub per_channel: PerChannel,
    pub non_finite_pixels: u64,
}

fn clean(pixels: &[[f32; 3]]) -> (Vec<[f32; 3]>, u64) {
    let bad = pixels
        .par_iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count() as u64;
    (pixels.par_iter().map(|p| sanitise(*p, 1.0)).collect(), bad)
}

/// Which of the costlier metrics `compare_with` computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompareOptions {
    /// SSIM (an 11×11 window per pixel: the costliest metric). `prism converge` leaves it
    /// out of its checkpoints so that the metric thread steals less time from the render.
    pub ssim: bool,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self { ssim: true }
    }
}

/// Compares `test` against `reference`; an error when the sizes differ.
pub fn compare(test: &Image, reference: &Image) -> Result<Comparison> {
    compare_with(test, reference, &CompareOptions::default())
}

/// `compare` with a choice of metrics (`ssim` is `None` when not asked for); every metric
/// it computes is the one `compare` computes, bit for bit.
pub fn compare_with(
    test: &Image,
    reference: &Image,
    options: &CompareOptions,
) -> Result<Comparison> {
    if (test.width(), test.height()) != (reference.width(), reference.height()) {
        return Err(PostError::invalid(format!(
            "image sizes differ: {}×{} vs reference {}×{}",
            test.width(),
            test.height(),
            reference.width(),
            reference.height()
        )));
    }
    let mut a = test.pixels().to_vec();
    convert_pixels(&mut a, &test.color_space, &reference.color_space);
    let (a, bad_a) = clean(&a);
    let (b, bad_b) = clean(reference.pixels());
    let n = a.len() as f64;

    // Squared and relative squared errors, f64 sums per chunk.
    let (se, rel) = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(ca, cb)| {
            let (mut se, mut rel) = ([0.0f64; 3], [0.0f64; 3]);
            for (p, q) in ca.iter().zip(cb) {
                for c in 0..3 {
                    let d = (p[c] - q[c]) as f64;
                    let r = q[c] as f64;
                    se[c] += d * d;
                    rel[c] += d * d / (r * r + RELMSE_EPSILON);
                }
            }
            (se, rel)
        })
        .reduce(
            || ([0.0; 3], [0.0; 3]),
            |x, y| {
                (
                    [x.0[0] + y.0[0], x.0[1] + y.0[1], x.0[2] + y.0[2]],
                    [x.1[0] + y.1[0], x.1[1] + y.1[1], x.1[2] + y.1[2]],
                )
            },
        );
    let mse_c = se.map(|s| s / n);
    let relmse_c = rel.map(|s| s / n);
    let peak_c: [f64; 3] =
        [0, 1, 2].map(|c| b.par_iter().map(|p| p[c] as f64).reduce(|| 0.0, f64::max));
    let peak = peak_c.iter().cloned().fold(0.0, f64::max);
    let psnr = |peak: f64, mse: f64| 10.0 * (peak * peak / mse).log10();
    let mse = mse_c.iter().sum::<f64>() / 3.0;

    let space = &reference.color_space;
    let w = crate::image::luminance_weights(space);
    let luminance = |p: &[[f32; 3]]| -> Vec<f32> {
        p.par_iter()
            .map(|c| w[0] * c[0] + w[1] * c[1] + w[2] * c[2])
            .collect()
    };
    let ssim = if options.ssim {
        let (ya, yb) = (luminance(&a), luminance(&b));
        let y_peak = yb.par_iter().cloned().reduce(|| 0.0, f32::max) as f64;
        ssim::ssim(
            &ya,
            &yb,
            test.width(),
            test.height(),
            if y_peak > 0.0 { y_peak } else { 1.0 },
        )
    } else {
        None
    };

    let m = space.rgb_to_xyz;
    let white = space.white_xyz();
    let lab = |p: [f32; 3]| {
        let xyz = m * glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        xyz_to_lab(xyz, white)
    };
    let mut de: Vec<f64> = a
        .par_iter()
        .zip(b.par_iter())
        .map(|(p, q)| delta_e_2000(lab(*p), lab(*q)))
        .collect();
    let de_mean = de.par_iter().sum::<f64>() / n;
    let rank = ((0.95 * de.len() as f64).ceil() as usize).clamp(1, de.len()) - 1;
    let (_, p95, _) = de.select_nth_unstable_by(rank, f64::total_cmp);
    let de_p95 = *p95;

    Ok(Comparison {
        width: test.width(),
        height: test.height(),
        mse,
        rmse: mse.sqrt(),
        relmse: relmse_c.iter().sum::<f64>() / 3.0,
        psnr_db: psnr(peak, mse),
        ssim,
        delta_e2000_mean: de_mean,
        delta_e2000_p95: de_p95,
        per_channel: PerChannel {
            mse: mse_c,
            rmse: mse_c.map(f64::sqrt),
            relmse: relmse_c,
            psnr_db: [0, 1, 2].map(|c| psnr(peak_c[c], mse_c[c])),
        },
        non_finite_pixels: bad_a + bad_b,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::rgb_space::RgbColorSpace;

    fn gradient(w: usize, h: usize) -> Image {
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                [x, y, 0.5 * (x + y)]
            })
            .collect();
        Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap()
    }

    #[test]
    fn identical_images_have_zero_error_and_unit_ssim() {
        let a = gradient(32, 24);
        let c = compare(&a, &a).unwrap();
        assert_eq!(c.mse, 0.0);
        assert_eq!(c.relmse, 0.0);
        assert_eq!(c.delta_e2000_mean, 0.0);
        assert!(c.psnr_db.is_infinite());
        assert!((c.ssim.unwrap() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn constant_offset_gives_known_mse_psnr_and_relmse() {
        // b = reference, a = b + 0.1 on every channel: mse = 0.01, psnr = 10 log10(peak²/0.01).
        let b = gradient(20, 20);
        let a = b
            .with_pixels(b.pixels().iter().map(|p| p.map(|c| c + 0.1)).collect())
            .unwrap();
        let c = compare(&a, &b).unwrap();
        // f32 storage of c + 0.1: error ≤ 2^-24 · 1.1 per sample → mse within 1e-7.
        assert!((c.mse - 0.01).abs() < 1e-7, "{}", c.mse);
        assert!((c.rmse - 0.1).abs() < 1e-6);
        let peak = b.pixels().iter().flatten().cloned().fold(0.0f32, f32::max) as f64;
        assert!((c.psnr_db - 10.0 * (peak * peak / 0.01).log10()).abs() < 1e-4);
        let want_rel: f64 = b
            .pixels()
            .iter()
            .flatten()
            .map(|&r| 0.01 / ((r as f64).powi(2) + RELMSE_EPSILON))
            .sum::<f64>()
            / (b.pixels().len() * 3) as f64;
        assert!((c.relmse - want_rel).abs() < 1e-5 * want_rel);
        assert!(c.delta_e2000_mean > 0.0 && c.delta_e2000_p95 >= c.delta_e2000_mean * 0.5);
    }

    #[test]
    fn delta_e_uses_reference_white_at_l_100() {
        // White vs 18 % grey: ΔE00 between L* = 100 and L* = 49.496, a = b = 0 is the pure
        // lightness term ΔL / S_L, S_L = 1 + 0.015 (L̄ − 50)² / sqrt(20 + (L̄ − 50)²).
        let white = Image::filled(4, 4, [1.0; 3], RgbColorSpace::srgb()).unwrap();
        let grey = Image::filled(4, 4, [0.18; 3], RgbColorSpace::srgb()).unwrap();
        let c = compare(&grey, &white).unwrap();
        let l = 116.0 * 0.18f64.cbrt() - 16.0;
        let l_bar: f64 = (100.0 + l) / 2.0;
        let s_l = 1.0 + 0.015 * (l_bar - 50.0).powi(2) / (20.0 + (l_bar - 50.0).powi(2)).sqrt();
        // The sRGB matrix maps (1,1,1) to its white to 1e-12, and f32 0.18 is exact to 1e-8.
        assert!((c.delta_e2000_mean - (100.0 - l) / s_l).abs() < 1e-5);
        assert_eq!(c.ssim, None);
    }

    #[test]
    fn compare_without_ssim_gives_the_same_other_metrics() {
        let b = gradient(16, 16);
        let a = b
            .with_pixels(b.pixels().iter().map(|p| p.map(|c| c * 1.1)).collect())
            .unwrap();
        let full = compare(&a, &b).unwrap();
        let lean = compare_with(&a, &b, &CompareOptions { ssim: false }).unwrap();
        assert!(full.ssim.is_some());
        assert_eq!(lean, Comparison { ssim: None, ..full });
    }

    #[test]
    fn mismatched_sizes_are_an_error() {
        let err = compare(&gradient(4, 4), &gradient(4, 5))
            .unwrap_err()
            .to_string();
        assert!(err.contains("4×4") && err.contains("4×5"), "{err}");
    }
}
