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

use prism_cpu::Simd;
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::ciede2000::{delta_e_2000_block, lab_block, LabBlock, LabConverter, BLOCK};
use super::{
    flip, ssim, CompareOptions, Comparison, ErrorMaps, FlipMaps, FlipSummary, PerChannel,
    RELMSE_EPSILON,
};
use crate::tonemap::kernels::avx2;
use crate::tonemap::pixels::{sanitise, CHUNK};
use prism_image::io::convert_pixels;
use prism_image::rgb_matrix::same_colorimetry;
use prism_image::Image;
use prism_image::{ImageError, Result};

/// The reference side of [`crate::metrics::compare`], computed once.
#[derive(Debug, Clone)]
pub struct PreparedReference {
    width: usize,
    height: usize,
    color_space: RgbColorSpace,
    /// Sanitised pixels (non-finite → black, negatives → 0).
    pixels: Vec<[f32; 3]>,
    /// CIELAB of `pixels` with chroma, in blocks of [`BLOCK`] pixels (the last one padded
    /// with black).
    lab: Vec<LabBlock>,
    /// Largest value per channel (PSNR's peak).
    peak_c: [f64; 3],
    /// Pixels with a non-finite channel.
    non_finite: u64,
    /// Finite samples < 0 (HDR-FLIP's count).
    negative_samples: u64,
    lab_converter: LabConverter,
    /// The ISA of the vector kernels (`prism_cpu::active()` when prepared), for the
    /// preparation and every comparison.
    simd: Simd,
}

/// Per-chunk sums of the fused pass.
#[derive(Clone, Copy, Default)]
pub(super) struct Sums {
    pub(super) se: [f64; 3],
    pub(super) rel: [f64; 3],
    pub(super) de: f64,
    pub(super) non_finite: u64,
}

impl Sums {
    pub(super) fn add(self, o: Sums) -> Sums {
        Sums {
            se: [0, 1, 2].map(|c| self.se[c] + o.se[c]),
            rel: [0, 1, 2].map(|c| self.rel[c] + o.rel[c]),
            de: self.de + o.de,
            non_finite: self.non_finite + o.non_finite,
        }
    }
}

pub(super) fn finite(p: &[f32; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

impl PreparedReference {
    /// Prepares `reference` (any size ≥ 1 × 1; its colour space is the comparison's).
    pub fn new(reference: &Image) -> Self {
        Self::with_simd(reference, prism_cpu::active())
    }

    /// As [`Self::new`], with the kernels of `simd` (tests compare ISAs).
    pub(crate) fn with_simd(reference: &Image, simd: Simd) -> Self {
        let space = reference.color_space.clone();
        let lab_converter = LabConverter::new(space.rgb_to_xyz, space.white_xyz());
        let pixels: Vec<[f32; 3]> = reference
            .pixels()
            .par_iter()
            .map(|p| sanitise(*p, 1.0))
            .collect();
        let lab: Vec<LabBlock> = pixels
            .par_chunks(BLOCK)
            .map(|block| avx2!(simd, reference_block(&lab_converter, block)))
            .collect();
        let non_finite = reference.pixels().par_iter().filter(|p| !finite(p)).count() as u64;
        let negative_samples = reference
            .pixels()
            .par_iter()
            .map(|p| p.iter().filter(|v| **v < 0.0).count() as u64)
            .sum();
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
            negative_samples,
            lab_converter,
            simd,
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
        self.compare_with_maps(test, options).map(|(c, _)| c)
    }

    /// [`Self::compare`] and the per-pixel maps asked for (FLIP's, ΔE2000's).
    pub fn compare_with_maps(
        &self,
        test: &Image,
        options: &CompareOptions,
    ) -> Result<(Comparison, ErrorMaps)> {
        if let Some(ppd) = options.flip_ppd {
            flip::check_ppd(ppd)?;
        }
        if (test.width(), test.height()) != (self.width, self.height) {
            return Err(ImageError::invalid(format!(
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
        let simd = self.simd;
        let mut de = vec![0.0f64; a.len()];
        let sums = a
            .par_chunks(CHUNK)
            .zip(de.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(k, (chunk, out))| {
                let (start, len) = (k * CHUNK, chunk.len());
                let reference = &self.pixels[start..start + len];
                let lab = &self.lab[start / BLOCK..];
                let converter = &self.lab_converter;
                let init = Sums::default();
                avx2!(
                    simd,
                    compare_chunk(converter, reference, lab, init, chunk, out)
                )
            })
            // Collected, then added in order: a rayon reduce would add the chunks in an
            // order that follows its splitting, and change the last bits between runs.
            .collect::<Vec<Sums>>()
            .into_iter()
            .fold(Sums::default(), Sums::add);

        let mse_c = sums.se.map(|s| s / n);
        let relmse_c = sums.rel.map(|s| s / n);
        let peak = self.peak_c.iter().cloned().fold(0.0, f64::max);
        let psnr = super::psnr_db;
        let mse = mse_c.iter().sum::<f64>() / 3.0;

        let ssim = if options.ssim {
            let w = prism_image::image::luminance_weights(&self.color_space);
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

        // Before the selection below reorders `de`.
        let delta_e2000_map = options
            .delta_e2000_map
            .then(|| de.par_iter().map(|&d| d as f32).collect::<Vec<f32>>());
        let rank = ((0.95 * de.len() as f64).ceil() as usize).clamp(1, de.len()) - 1;
        let (_, p95, _) = de.select_nth_unstable_by(rank, f64::total_cmp);
        let de_p95 = *p95;

        let (flip, maps) = match options.flip_ppd {
            Some(ppd) => {
                let (summary, maps) = self.flip(a, ppd)?;
                (Some(summary), Some(maps))
            }
            None => (None, None),
        };

        let comparison = Comparison {
            width: self.width,
            height: self.height,
            mse,
            rmse: mse.sqrt(),
            relmse: relmse_c.iter().sum::<f64>() / 3.0,
            psnr_db: psnr(peak, mse),
            psnr_note: super::psnr_note(peak, mse),
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
            flip,
        };
        Ok((
            comparison,
            ErrorMaps {
                flip: maps,
                delta_e2000: delta_e2000_map,
            },
        ))
    }

    /// LDR-FLIP and HDR-FLIP of `test` (in the reference's colour space) on Rec.709.
    fn flip(&self, test: &[[f32; 3]], ppd: f64) -> Result<(FlipSummary, FlipMaps)> {
        let rec709 = RgbColorSpace::srgb();
        // Copies only when the reference space is not Rec.709.
        let converted;
        let (test, reference): (&[[f32; 3]], &[[f32; 3]]) =
            if same_colorimetry(&self.color_space, &rec709) {
                (test, &self.pixels)
            } else {
                let (mut t, mut r) = (test.to_vec(), self.pixels.clone());
                convert_pixels(&mut t, &self.color_space, &rec709);
                convert_pixels(&mut r, &self.color_space, &rec709);
                converted = (t, r);
                (&converted.0, &converted.1)
            };
        let (w, h) = (self.width, self.height);
        let ldr = flip::ldr_flip(test, reference, w, h, ppd)?;
        let hdr = flip::hdr_flip(test, reference, w, h, ppd)?;
        let summary = FlipSummary {
            flip_ppd: ppd,
            ldr_flip_mean: ldr.mean(),
            ldr_flip_p95: ldr.p95(),
            hdr_flip_mean: hdr.map.mean(),
            hdr_flip_p95: hdr.map.p95(),
            hdr_flip_exposures: hdr.exposures,
            hdr_flip_negative_samples: hdr.negative_samples + self.negative_samples,
        };
        Ok((summary, FlipMaps { ldr, hdr: hdr.map }))
    }
}

/// CIELAB of one block of sanitised reference pixels.
#[inline(always)]
pub(super) fn reference_block(conv: &LabConverter, block: &[[f32; 3]]) -> LabBlock {
    let mut rgb = [[0.0f64; BLOCK]; 3];
    for (i, p) in block.iter().enumerate() {
        for c in 0..3 {
            rgb[c][i] = f64::from(p[c]);
        }
    }
    let mut out = LabBlock::default();
    lab_block(conv, &rgb, &mut out);
    out
}

/// The fused pass over one chunk of test pixels against the sanitised `reference` pixels
/// at the same places and their CIELAB blocks `lab` (block 0 starting at the chunk's first
/// pixel): squared and relative squared errors, non-finite count, ΔE₀₀ into `out` and its
/// sum, added pixel by pixel to `init` (a chunk's sums so far: a comparison in strips
/// continues a chunk that a strip boundary cut). Per block: the errors and the planes in a
/// scalar loop, then CIELAB and ΔE₀₀ in loops over the planes that the compiler vectorises
/// (lane by lane: a pixel's ΔE₀₀ does not depend on its block).
#[inline(always)]
pub(super) fn compare_chunk(
    converter: &LabConverter,
    reference: &[[f32; 3]],
    lab: &[LabBlock],
    init: Sums,
    chunk: &[[f32; 3]],
    out: &mut [f64],
) -> Sums {
    let mut s = init;
    let mut rgb = [[0.0f64; BLOCK]; 3];
    let mut lab_test = LabBlock::default();
    let mut de = [0.0f64; BLOCK];
    for (j, (block, out)) in chunk.chunks(BLOCK).zip(out.chunks_mut(BLOCK)).enumerate() {
        let first = j * BLOCK;
        let reference = &reference[first..first + block.len()];
        for (i, (p, q)) in block.iter().zip(reference).enumerate() {
            s.non_finite += u64::from(!finite(p));
            let p = sanitise(*p, 1.0);
            for c in 0..3 {
                let d = f64::from(p[c] - q[c]);
                let r = f64::from(q[c]);
                s.se[c] += d * d;
                s.rel[c] += d * d / (r * r + RELMSE_EPSILON);
                rgb[c][i] = f64::from(p[c]);
            }
        }
        // Padding lanes of a short last block keep stale values; only `len` lanes are read.
        lab_block(converter, &rgb, &mut lab_test);
        delta_e_2000_block(&lab_test, &lab[j], block.len(), &mut de);
        for (o, d) in out.iter_mut().zip(&de) {
            *o = *d;
            s.de += *d;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::compare_with;
    use glam::DVec3;
    use prism_spectrum::colorimetry::{delta_e_2000, xyz_to_lab};

    /// A noisy test/reference pair with every kind of pixel the conventions name: NaN,
    /// infinities, negatives, black, very bright, and more than one chunk of pixels.
    fn pair(w: usize, h: usize) -> (Image, Image) {
        let mut state = 1u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut reference = Vec::new();
        let mut test = Vec::new();
        for i in 0..w * h {
            let r = [next(), next(), next()].map(|u| u * u * 4.0);
            reference.push(r);
            let t = match i % 97 {
                0 => [f32::NAN, 0.5, 0.5],
                1 => [f32::INFINITY, 0.0, 1.0],
                2 => [-0.3, 0.2, 0.1],
                3 => [0.0; 3],
                4 => [1e6, 2e6, 5e5],
                _ => r.map(|c| c * (0.5 + next())),
            };
            test.push(t);
        }
        reference[5] = [f32::NEG_INFINITY, 1.0, 1.0];
        let space = RgbColorSpace::srgb();
        (
            Image::new(w, h, test, space.clone()).unwrap(),
            Image::new(w, h, reference, space).unwrap(),
        )
    }

    #[test]
    fn the_fused_pass_equals_the_reference_formulas() {
        // 150 × 40 = 6000 pixels: one full chunk, a partial one, a short last block.
        let (test, reference) = pair(150, 40);
        let got = PreparedReference::new(&reference)
            .compare(
                &test,
                &CompareOptions {
                    ssim: false,
                    flip_ppd: None,
                    delta_e2000_map: false,
                },
            )
            .unwrap();
        // The formulas of the module documentation, evaluated directly in f64 with
        // prism-spectrum's reference CIELAB and CIEDE2000.
        let space = &reference.color_space;
        let clean = |p: [f32; 3]| sanitise(p, 1.0);
        let lab = |p: [f32; 3]| {
            let rgb = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            xyz_to_lab(space.rgb_to_xyz * rgb, space.white_xyz())
        };
        let (mut se, mut rel, mut de) = (0.0, 0.0, Vec::new());
        let mut bad = 0;
        for (p, q) in test.pixels().iter().zip(reference.pixels()) {
            bad += u64::from(!finite(p)) + u64::from(!finite(q));
            let (p, q) = (clean(*p), clean(*q));
            for c in 0..3 {
                let d = f64::from(p[c] - q[c]);
                se += d * d;
                rel += d * d / (f64::from(q[c]).powi(2) + RELMSE_EPSILON);
            }
            de.push(delta_e_2000(lab(p), lab(q)));
        }
        let n = (test.pixels().len() * 3) as f64;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(got.mse, se / n), "{} {}", got.mse, se / n);
        assert!(close(got.relmse, rel / n), "{} {}", got.relmse, rel / n);
        let mean = de.iter().sum::<f64>() / de.len() as f64;
        assert!(
            close(got.delta_e2000_mean, mean),
            "{} {mean}",
            got.delta_e2000_mean
        );
        de.sort_by(f64::total_cmp);
        let p95 = de[(0.95 * de.len() as f64).ceil() as usize - 1];
        assert!(
            (got.delta_e2000_p95 - p95).abs() <= 1e-10 * p95,
            "{} {p95}",
            got.delta_e2000_p95
        );
        assert_eq!(got.non_finite_pixels, bad);
    }

    #[test]
    fn one_preparation_serves_many_comparisons_with_compare_s_numbers() {
        let (test, reference) = pair(64, 33);
        let prepared = PreparedReference::new(&reference);
        // FLIP included: prepared or not, the same numbers.
        let options = CompareOptions::default();
        let first = prepared.compare(&test, &options).unwrap();
        assert_eq!(prepared.compare(&test, &options).unwrap(), first);
        assert_eq!(compare_with(&test, &reference, &options).unwrap(), first);
        // A test image in another colour space is converted to the reference's first.
        let p3 = RgbColorSpace::display_p3();
        let mut moved = test.pixels().to_vec();
        convert_pixels(&mut moved, &test.color_space, &p3);
        let moved = Image::new(64, 33, moved, p3).unwrap();
        let other = prepared.compare(&moved, &options).unwrap();
        assert!((other.rmse - first.rmse).abs() < 1e-5 * first.rmse);
        assert!(prepared
            .compare(
                &Image::filled(3, 3, [0.0; 3], RgbColorSpace::srgb()).unwrap(),
                &options
            )
            .is_err());
    }
}
