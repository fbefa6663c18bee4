//! Image comparison metrics (`prism compare TEST REFERENCE`). Conventions, all stated once:
//! - the second image is the reference; the test image is converted to the reference's
//!   colour space (through XYZ) before comparing;
//! - non-finite or negative samples are treated as the tone operators treat them (black /
//!   clamped to 0) and counted in `non_finite_pixels`;
//! - mse, rmse: mean over pixels and channels of (a − b)²;
//! - relmse: mean of (a − b)² / (b² + ε), ε = 1e-2 (Rousselle et al. 2011 style);
//! - psnr_db = 10 log10(peak² / mse), peak = the largest channel value of the reference:
//!   +∞ for identical images (a black pair included), −∞ for a black reference and a test
//!   image that is not; JSON has null there and `psnr_note` says why. No metric is NaN.
//! - ssim: Wang et al. 2004 on relative luminance Y, dynamic range L = the reference's
//!   largest Y (see [`ssim`]); null for images smaller than 11×11;
//! - ΔE2000: XYZ → CIELAB against the white of the reference's colour space with Y
//!   normalised so that RGB (1, 1, 1) (Y = 1) is the reference white (L* = 100), i.e.
//!   display-referred relative colorimetry; mean and 95th percentile (nearest rank);
//! - FLIP ([`flip`]): LDR-FLIP and HDR-FLIP means and 95th percentiles (nearest rank) at a
//!   viewing condition in pixels per degree, both images in linear Rec.709 (converted
//!   when the reference is in another space); LDR clips to [0, 1], HDR clamps negative
//!   samples to 0 and counts them.
//!
//! All metrics come from one fused pass over the pixels against a [`PreparedReference`]
//! (the reference's clean pixels, CIELAB and peaks, computed once), with CIELAB and
//! CIEDE2000 in the arithmetic-heavy form of [`ciede2000`] (equal to prism-spectrum's
//! reference formulas to rounding, tested there).

pub mod ciede2000;
mod fast_f64;
pub mod flip;
mod ordered_sum;
mod prepared;
mod ssim;
pub mod strips;
pub mod tmqi;

use serde::Serialize;

use prism_image::Image;
use prism_image::Result;

pub use flip::{ExposureRange, FlipMap};
pub use prepared::PreparedReference;

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
    /// Why `psnr_db` is infinite (JSON writes ±∞ as null); absent when it is finite.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub psnr_note: Option<&'static str>,
    pub ssim: Option<f64>,
    pub delta_e2000_mean: f64,
    pub delta_e2000_p95: f64,
    pub per_channel: PerChannel,
    pub non_finite_pixels: u64,
    /// FLIP, when asked for: its keys at the top level of the JSON object.
    #[serde(flatten)]
    pub flip: Option<FlipSummary>,
}

/// LDR-FLIP and HDR-FLIP of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlipSummary {
    /// The viewing condition, pixels per degree.
    pub flip_ppd: f64,
    pub ldr_flip_mean: f64,
    pub ldr_flip_p95: f64,
    pub hdr_flip_mean: f64,
    pub hdr_flip_p95: f64,
    /// The exposures HDR-FLIP took the maximum over (from the reference).
    pub hdr_flip_exposures: ExposureRange,
    /// Samples below 0 (either image, as read or after conversion to Rec.709) that
    /// HDR-FLIP clamped to 0.
    pub hdr_flip_negative_samples: u64,
}

/// The per-pixel FLIP maps behind a [`FlipSummary`].
#[derive(Debug, Clone, PartialEq)]
pub struct FlipMaps {
    pub ldr: FlipMap,
    pub hdr: FlipMap,
}

/// The per-pixel maps behind a [`Comparison`], as far as they were asked for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ErrorMaps {
    /// LDR-FLIP and HDR-FLIP (with [`CompareOptions::flip_ppd`]).
    pub flip: Option<FlipMaps>,
    /// ΔE2000 per pixel, row-major (with [`CompareOptions::delta_e2000_map`]).
    pub delta_e2000: Option<Vec<f32>>,
}

/// Which of the costlier metrics `compare_with` computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompareOptions {
    /// SSIM (an 11×11 window per pixel: the costliest metric). `prism converge` leaves it
    /// out of its checkpoints so that the metric thread steals less time from the render.
    pub ssim: bool,
    /// LDR-FLIP and HDR-FLIP at this many pixels per degree (`None`: not computed; a
    /// 4K pair costs about as much as the other metrics together, times HDR-FLIP's
    /// exposure count).
    pub flip_ppd: Option<f64>,
    /// Keep the per-pixel ΔE2000 map ([`ErrorMaps::delta_e2000`]; 4 bytes per pixel more):
    /// the HTML report shows it.
    pub delta_e2000_map: bool,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            ssim: true,
            flip_ppd: Some(flip::DEFAULT_PPD),
            delta_e2000_map: false,
        }
    }
}

/// PSNR in dB of `mse` at `peak`: 10 log10(peak² / mse), +∞ when mse is 0 (equal images,
/// whatever the peak: 0/0 would be NaN for a black pair), −∞ when the peak is 0 and the
/// images differ.
pub fn psnr_db(peak: f64, mse: f64) -> f64 {
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (peak * peak / mse).log10()
    }
}

/// Why [`psnr_db`] is infinite, for readers of JSON (where ±∞ is null).
pub fn psnr_note(peak: f64, mse: f64) -> Option<&'static str> {
    if mse == 0.0 {
        Some("identical images: PSNR is +∞")
    } else if peak == 0.0 {
        Some("black reference (peak 0) and a test image that is not: PSNR is −∞")
    } else {
        None
    }
}

/// Bytes per pixel of `prism compare` beyond the two images as decoded: the prepared
/// reference's clean pixels and CIELAB, ΔE per pixel, SSIM planes and FLIP's maps. With
/// 24 for two RGB images it is 136, above the 123 measured on a 2048² pair of float EXRs
/// (docs/reliability.md); the memory check's estimate.
pub const COMPARE_BYTES_PER_PIXEL: u64 = 112;

/// Compares `test` against `reference`; an error when the sizes differ.
pub fn compare(test: &Image, reference: &Image) -> Result<Comparison> {
    compare_with(test, reference, &CompareOptions::default())
}

/// `compare` with a choice of metrics (`ssim` is `None` when not asked for); every metric
/// it computes is the one `compare` computes, bit for bit. To compare many images against
/// one reference, prepare it once ([`PreparedReference`]): the same code, the same numbers.
pub fn compare_with(
    test: &Image,
    reference: &Image,
    options: &CompareOptions,
) -> Result<Comparison> {
    PreparedReference::new(reference).compare(test, options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_image::io::convert_pixels;
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

    /// The fused pass's kernels at every ISA the machine runs (`prism_cpu::each_isa`, which
    /// reports the others as skipped) give the scalar pass's numbers bit for bit, on an
    /// image with special values and in another colour space (so the conversion runs). One
    /// thread, so that the sums are reduced in the same order.
    #[test]
    fn every_isa_gives_the_scalar_comparison() {
        let reference = gradient(67, 31);
        let mut test = gradient(67, 31);
        for (i, p) in test.pixels_mut().iter_mut().enumerate() {
            *p = match i % 11 {
                0 => [f32::NAN, 0.2, 0.3],
                1 => [-0.5, f32::INFINITY, 0.1],
                2 => [0.0; 3],
                _ => p.map(|c| c * 1.3 + 0.01 * (i % 7) as f32),
            };
        }
        let mut p3 = test.clone();
        p3.color_space = RgbColorSpace::display_p3();
        // On the test's thread, so that skipped ISAs are reported under its name.
        let isas = prism_cpu::each_isa();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| {
            let options = CompareOptions::default();
            let at = |simd, test: &Image| {
                PreparedReference::with_simd(&reference, simd)
                    .compare(test, &options)
                    .unwrap()
            };
            for test in [&test, &p3] {
                // Debug prints f64 exactly (shortest round trip), so equal text is equal bits.
                let scalar = format!("{:?}", at(prism_cpu::Simd::SCALAR, test));
                for &simd in &isas {
                    assert_eq!(format!("{:?}", at(simd, test)), scalar, "{simd}");
                }
            }
        });
    }

    #[test]
    fn identical_images_have_zero_error_and_unit_ssim() {
        let a = gradient(32, 24);
        let c = compare(&a, &a).unwrap();
        assert_eq!(c.mse, 0.0);
        assert_eq!(c.relmse, 0.0);
        assert_eq!(c.delta_e2000_mean, 0.0);
        assert_eq!(c.psnr_db, f64::INFINITY);
        assert_eq!(c.per_channel.psnr_db, [f64::INFINITY; 3]);
        assert_eq!(c.psnr_note, Some("identical images: PSNR is +∞"));
        assert!((c.ssim.unwrap() - 1.0).abs() < 1e-6);
        let flip = c.flip.unwrap();
        assert_eq!((flip.ldr_flip_mean, flip.hdr_flip_p95), (0.0, 0.0));
    }

    /// Every number of a comparison, in a fixed order.
    fn numbers(c: &Comparison) -> Vec<(String, f64)> {
        let mut v = vec![
            ("mse".to_string(), c.mse),
            ("rmse".into(), c.rmse),
            ("relmse".into(), c.relmse),
            ("psnr_db".into(), c.psnr_db),
            ("delta_e2000_mean".into(), c.delta_e2000_mean),
            ("delta_e2000_p95".into(), c.delta_e2000_p95),
        ];
        v.extend(c.ssim.map(|s| ("ssim".to_string(), s)));
        for k in 0..3 {
            v.push((format!("mse[{k}]"), c.per_channel.mse[k]));
            v.push((format!("relmse[{k}]"), c.per_channel.relmse[k]));
            v.push((format!("psnr_db[{k}]"), c.per_channel.psnr_db[k]));
        }
        if let Some(f) = &c.flip {
            v.push(("ldr_flip_mean".into(), f.ldr_flip_mean));
            v.push(("ldr_flip_p95".into(), f.ldr_flip_p95));
            v.push(("hdr_flip_mean".into(), f.hdr_flip_mean));
            v.push(("hdr_flip_p95".into(), f.hdr_flip_p95));
        }
        v
    }

    #[test]
    fn black_images_give_no_nan() {
        let black = Image::new(16, 16, vec![[0.0; 3]; 256], RgbColorSpace::srgb()).unwrap();
        let c = compare(&black, &black).unwrap();
        for (name, value) in numbers(&c) {
            assert!(!value.is_nan(), "{name} is NaN for two black images");
        }
        assert_eq!(c.psnr_db, f64::INFINITY);
        assert_eq!((c.mse, c.relmse, c.delta_e2000_mean), (0.0, 0.0, 0.0));
        // A black reference against a grey test image: the peak is 0.
        let grey = Image::new(16, 16, vec![[0.5; 3]; 256], RgbColorSpace::srgb()).unwrap();
        let c = compare(&grey, &black).unwrap();
        for (name, value) in numbers(&c) {
            assert!(!value.is_nan(), "{name} is NaN against a black reference");
        }
        assert_eq!(c.psnr_db, f64::NEG_INFINITY);
        assert!(c.psnr_note.unwrap().contains("black reference"));
        let json = serde_json::to_value(&c).unwrap();
        assert!(json["psnr_db"].is_null() && json["psnr_note"].is_string());
    }

    /// FLIP runs on Rec.709: a P3 test against its sRGB conversion scores 0 (to rounding),
    /// and the JSON carries the keys at the top level.
    #[test]
    fn flip_converts_to_rec709_and_serialises_flat() {
        let b = gradient(24, 16);
        let mut p3 = b.clone();
        convert_pixels(
            p3.pixels_mut(),
            &RgbColorSpace::srgb(),
            &RgbColorSpace::display_p3(),
        );
        p3.color_space = RgbColorSpace::display_p3();
        let c = compare(&p3, &b).unwrap();
        let flip = c.flip.clone().unwrap();
        assert!(
            flip.ldr_flip_mean < 1e-3 && flip.hdr_flip_mean < 1e-3,
            "{flip:?}"
        );
        let json = serde_json::to_value(&c).unwrap();
        for key in [
            "ldr_flip_mean",
            "hdr_flip_mean",
            "ldr_flip_p95",
            "hdr_flip_p95",
        ] {
            assert!(json[key].is_number(), "{key}: {json}");
        }
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
        let lean = compare_with(
            &a,
            &b,
            &CompareOptions {
                ssim: false,
                flip_ppd: None,
                delta_e2000_map: false,
            },
        )
        .unwrap();
        assert!(full.ssim.is_some() && full.flip.is_some());
        assert_eq!(
            lean,
            Comparison {
                ssim: None,
                flip: None,
                ..full
            }
        );
    }

    #[test]
    fn mismatched_sizes_are_an_error() {
        let err = compare(&gradient(4, 4), &gradient(4, 5))
            .unwrap_err()
            .to_string();
        assert!(err.contains("4×4") && err.contains("4×5"), "{err}");
    }
}
