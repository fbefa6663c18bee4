//! A reference image prepared once for many comparisons (`prism converge` compares every
//! checkpoint of a render against the same reference; `prism compare` prepares it for its
//! one comparison, so both compute the same numbers by the same code).
//!
//! Preparing does what does not depend on the test image: the sanitised reference pixels,
//! their CIELAB values and chromas ([`LabC`]), the per-channel peaks for PSNR and the count
//! of non-finite pixels. A comparison is then one fused pass over the pixels
//! ([`PreparedReference::compare`]): sanitise the test pixel, accumulate the squared and
//! relative squared errors, convert it to CIELAB and take its ΔE₀₀ against the prepared
//! reference colour — in chunks of [`CHUNK`] pixels, in parallel on the current rayon pool.

use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::ciede2000::{delta_e_2000, LabC, LabConverter};
use super::{ssim, CompareOptions, Comparison, PerChannel, RELMSE_EPSILON};
use crate::colour::rgb_matrix::same_colorimetry;
use crate::error::{PostError, Result};
use crate::image::Image;
use crate::io::convert_pixels;
use crate::tonemap::pixels::{sanitise, CHUNK};

/// The reference side of [`crate::metrics::compare`], computed once.
#[derive(Debug, Clone)]
pub struct PreparedReference {
    width: usize,
    height: usize,
    color_space: RgbColorSpace,
    /// Sanitised pixels (non-finite → black, negatives → 0).
    pixels: Vec<[f32; 3]>,
    /// CIELAB of `pixels` with chroma.
    lab: Vec<LabC>,
    /// Largest value per channel (PSNR's peak).
    peak_c: [f64; 3],
    /// Pixels with a non-finite channel.
    non_finite: u64,
    lab_converter: LabConverter,
}

/// Per-chunk sums of the fused pass.
#[derive(Clone, Copy, Default)]
struct Sums {
    se: [f64; 3],
    rel: [f64; 3],
    de: f64,
    non_finite: u64,
}

impl Sums {
    fn add(self, o: Sums) -> Sums {
        Sums {
            se: [0, 1, 2].map(|c| self.se[c] + o.se[c]),
            rel: [0, 1, 2].map(|c| self.rel[c] + o.rel[c]),
            de: self.de + o.de,
            non_finite: self.non_finite + o.non_finite,
        }
    }
}

fn finite(p: &[f32; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

impl PreparedReference {
    /// Prepares `reference` (any size ≥ 1 × 1; its colour space is the comparison's).
    pub fn new(reference: &Image) -> Self {
        let space = reference.color_space.clone();
        let lab_converter = LabConverter::new(space.rgb_to_xyz, space.white_xyz());
        let (pixels, lab): (Vec<[f32; 3]>, Vec<LabC>) = reference
            .pixels()
            .par_iter()
            .map(|p| {
                let q = sanitise(*p, 1.0);
                (q, LabC::new(lab_converter.lab(q)))
            })
            .unzip();
        let non_finite = reference.pixels().par_iter().filter(|p| !finite(p)).count() as u64;
        let peak_c = pixels
            .par_chunks(CHUNK)
            .map(|chunk| {
                chunk.iter().fold([0.0f64; 3], |m, p| {
                    [0, 1, 2].map(|c| m[c].max(f64::from(p[c])))
                })
            })
            .reduce(|| [0.0; 3], |a, b| [0, 1, 2].map(|c| a[c].max(b[c])));
        Self {
            width: reference.width(),
            height: reference.height(),
            color_space: space,
            pixels,
            lab,
            peak_c,
            non_finite,
            lab_converter,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Compares `test` against the prepared reference: exactly [`crate::metrics::compare_with`]
    /// (which calls this); an error when the sizes differ.
    pub fn compare(&self, test: &Image, options: &CompareOptions) -> Result<Comparison> {
        if (test.width(), test.height()) != (self.width, self.height) {
            return Err(PostError::invalid(format!(
                "image sizes differ: {}×{} vs reference {}×{}",
                test.width(),
                test.height(),
                self.width,
                self.height
            )));
        }
        // The test image in the reference's colour space (a copy only when they differ).
        let converted;
        let a: &[[f32; 3]] = if same_colorimetry(&test.color_space, &self.color_space) {
            test.pixels()
        } else {
            let mut copy = test.pixels().to_vec();
            convert_pixels(&mut copy, &test.color_space, &self.color_space);
            converted = copy;
            &converted
        };
        let n = a.len() as f64;
        let mut de = vec![0.0f64; a.len()];
        let conv = &self.lab_converter;
        let sums = a
            .par_chunks(CHUNK)
            .zip(self.pixels.par_chunks(CHUNK))
            .zip(self.lab.par_chunks(CHUNK))
            .zip(de.par_chunks_mut(CHUNK))
            .map(|(((ca, cb), cl), out)| {
                let mut s = Sums::default();
                for (((p, q), ql), de) in ca.iter().zip(cb).zip(cl).zip(out) {
                    s.non_finite += u64::from(!finite(p));
                    let p = sanitise(*p, 1.0);
                    for c in 0..3 {
                        let d = f64::from(p[c] - q[c]);
                        let r = f64::from(q[c]);
                        s.se[c] += d * d;
                        s.rel[c] += d * d / (r * r + RELMSE_EPSILON);
                    }
                    *de = delta_e_2000(LabC::new(conv.lab(p)), *ql);
                    s.de += *de;
                }
                s
            })
            .reduce(Sums::default, Sums::add);

        let mse_c = sums.se.map(|s| s / n);
        let relmse_c = sums.rel.map(|s| s / n);
        let peak = self.peak_c.iter().cloned().fold(0.0, f64::max);
        let psnr = |peak: f64, mse: f64| 10.0 * (peak * peak / mse).log10();
        let mse = mse_c.iter().sum::<f64>() / 3.0;

        let ssim = if options.ssim {
            let w = crate::image::luminance_weights(&self.color_space);
            let luminance = |p: &[f32; 3]| w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
            let ya: Vec<f32> = a
                .par_iter()
                .map(|p| luminance(&sanitise(*p, 1.0)))
                .collect();
            let yb: Vec<f32> = self.pixels.par_iter().map(luminance).collect();
            let y_peak = yb.par_iter().cloned().reduce(|| 0.0, f32::max) as f64;
            ssim::ssim(
                &ya,
                &yb,
                self.width,
                self.height,
                if y_peak > 0.0 { y_peak } else { 1.0 },
            )
        } else {
            None
        };

        let rank = ((0.95 * de.len() as f64).ceil() as usize).clamp(1, de.len()) - 1;
        let (_, p95, _) = de.select_nth_unstable_by(rank, f64::total_cmp);
        let de_p95 = *p95;

        Ok(Comparison {
            width: self.width,
            height: self.height,
            mse,
            rmse: mse.sqrt(),
            relmse: relmse_c.iter().sum::<f64>() / 3.0,
            psnr_db: psnr(peak, mse),
            ssim,
            delta_e2000_mean: sums.de / n,
            delta_e2000_p95: de_p95,
            per_channel: PerChannel {
                mse: mse_c,
                rmse: mse_c.map(f64::sqrt),
                relmse: relmse_c,
                psnr_db: [0, 1, 2].map(|c| psnr(self.peak_c[c], mse_c[c])),
            },
            non_finite_pixels: sums.non_finite + self.non_finite,
        })
    }
}
