//! The comparison of [`super::PreparedReference`] over two images read in strips of rows
//! ([`RowSource`]), so that `prism compare` never holds either image whole: bit for bit
//! the same numbers and maps, in bounded memory (docs/reliability.md gives the peak).
//!
//! Two passes over the files:
//! 1. strip by strip, without halo: the per-pixel metrics (squared and relative errors,
//!    ΔE₀₀ into a map of all pixels, needed whole for its 95th percentile), the
//!    reference's peaks and counts, the luminance means SSIM centres on, and the
//!    reference luminances HDR-FLIP's exposure range needs (a median: kept whole, then
//!    dropped);
//! 2. strip by strip with a halo of rows (FLIP's filter radius; SSIM's 11-row window):
//!    the LDR-FLIP and HDR-FLIP maps (kept whole, as the CLI writes them and their
//!    percentiles need them) and the SSIM window sums.
//!
//! Sums come out in the whole-image path's order: the fused pass's per-chunk sums continue
//! across a strip boundary from where the previous strip left them ([`ChunkSums`]), and
//! SSIM's ordered sum likewise ([`OrderedSum`]); every per-pixel value is computed by the
//! same code from the same neighbourhood, with the image edges clamped as before.

use std::ops::Range;

use prism_cpu::Simd;
use prism_image::io::convert_pixels;
use prism_image::io::strips::RowSource;
use prism_image::rgb_matrix::same_colorimetry;
use prism_image::{ImageError, Result};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::ciede2000::{LabBlock, LabConverter, BLOCK};
use super::flip::{self, ExposureRange, FlipMap, FlipRows};
use super::ordered_sum::OrderedSum;
use super::prepared::{compare_chunk, finite, reference_block, Sums};
use super::ssim;
use super::{CompareOptions, Comparison, ErrorMaps, FlipMaps, FlipSummary, PerChannel};
use crate::tonemap::kernels::avx2;
use crate::tonemap::pixels::{sanitise, CHUNK};

/// Pixels per strip the CLI reads at a time (rounded to whole rows): 2 Mpx, 24 MB per copy
/// of a strip, small beside a picture large enough for memory to matter.
pub const STRIP_PIXELS: usize = 1 << 21;

/// Peak bytes per pixel of [`compare_rows`] beyond its strips when both images are read in
/// strips: the ΔE₀₀ map (8, f64) and HDR-FLIP's reference luminances (8, f64) in the first
/// pass, then the two FLIP maps (4 each) and a copy of one for its percentile in the
/// second; 4 more with the ΔE₀₀ map asked for. Measured in docs/reliability.md; the memory
/// check's estimate, with 4 bytes per stored channel for an input that is decoded whole.
pub const STRIP_COMPARE_BYTES_PER_PIXEL: u64 = 20;

/// The per-chunk sums of the fused pass, in chunk order; a chunk cut by a strip boundary
/// is continued from its partial sums, so each chunk is accumulated pixel by pixel in the
/// whole-image order.
struct ChunkSums {
    done: Vec<Sums>,
    partial: Sums,
}

/// Rows `rows` of `source` as the whole-image path sees them: the test image converted to
/// the reference's colour space, the reference sanitised.
struct Strip {
    rows: Range<usize>,
    /// Test pixels in the reference's colour space (not sanitised).
    test: Vec<[f32; 3]>,
    /// Reference pixels as read.
    reference_raw: Vec<[f32; 3]>,
    /// Sanitised reference pixels.
    reference: Vec<[f32; 3]>,
}

struct Sources<'a> {
    test: &'a RowSource,
    reference: &'a RowSource,
    space: RgbColorSpace,
    width: usize,
    height: usize,
}

impl Sources<'_> {
    fn read(&self, rows: Range<usize>) -> Result<Strip> {
        let (test, reference_raw) = rayon::join(
            || self.test.read_rows(rows.clone()),
            || self.reference.read_rows(rows.clone()),
        );
        let (mut test, reference_raw) = (test?, reference_raw?);
        if !same_colorimetry(self.test.color_space(), &self.space) {
            convert_pixels(&mut test, self.test.color_space(), &self.space);
        }
        let reference = reference_raw
            .par_iter()
            .map(|p| sanitise(*p, 1.0))
            .collect();
        Ok(Strip {
            rows,
            test,
            reference_raw,
            reference,
        })
    }
}

/// Bytes per pixel of a strip (and its halo) while it is worked on: both images as read,
/// converted and sanitised, SSIM's planes and FLIP's band planes (measured: about 100 on a
/// 1024² pair compared in one strip, docs/reliability.md).
pub const STRIP_WORKING_BYTES_PER_PIXEL: u64 = 160;

/// The estimate of [`compare_rows`]'s peak for two `width × height` images read in strips
/// of [`strip_rows`] rows: [`STRIP_COMPARE_BYTES_PER_PIXEL`] per pixel and a strip with
/// FLIP's halo at the default viewing condition (64 rows).
pub fn strip_compare_bytes(width: usize, height: usize) -> u64 {
    let pixels = (width as u64).saturating_mul(height as u64);
    let strip = (strip_rows(width) + 64).min(height) as u64 * width as u64;
    pixels
        .saturating_mul(STRIP_COMPARE_BYTES_PER_PIXEL)
        .saturating_add(strip.saturating_mul(STRIP_WORKING_BYTES_PER_PIXEL))
}

/// Row bands of `height` rows, `rows` each (the last shorter).
fn bands(height: usize, rows: usize) -> impl Iterator<Item = Range<usize>> {
    (0..height.div_ceil(rows)).map(move |b| b * rows..((b + 1) * rows).min(height))
}

/// Rows per strip for images `width` wide: [`STRIP_PIXELS`] rounded up to whole rows and
/// to a multiple of FLIP's band height.
pub fn strip_rows(width: usize) -> usize {
    STRIP_PIXELS.div_ceil(width.max(1)).next_multiple_of(64)
}

/// Compares the image of `test` against the reference of `reference` strip by strip,
/// `rows` rows at a time: [`super::PreparedReference::compare_with_maps`]'s comparison and
/// maps, bit for bit. Mismatched sizes are an error.
pub fn compare_rows(
    test: &RowSource,
    reference: &RowSource,
    options: &CompareOptions,
    rows: usize,
) -> Result<(Comparison, ErrorMaps)> {
    if let Some(ppd) = options.flip_ppd {
        flip::check_ppd(ppd)?;
    }
    if (test.width(), test.height()) != (reference.width(), reference.height()) {
        return Err(ImageError::invalid(format!(
            "image sizes differ: {}×{} vs reference {}×{}",
            test.width(),
            test.height(),
            reference.width(),
            reference.height()
        )));
    }
    let sources = Sources {
        test,
        reference,
        space: reference.color_space().clone(),
        width: reference.width(),
        height: reference.height(),
    };
    let rows = rows.max(1);
    let (w, h) = (sources.width, sources.height);
    let n = w * h;
    let simd = prism_cpu::active();
    let lab_converter = LabConverter::new(sources.space.rgb_to_xyz, sources.space.white_xyz());
    let rec709 = RgbColorSpace::srgb();
    let flip_space_differs = !same_colorimetry(&sources.space, &rec709);
    let luminance_w = prism_image::image::luminance_weights(&sources.space);
    let luminance =
        |p: &[f32; 3]| luminance_w[0] * p[0] + luminance_w[1] * p[1] + luminance_w[2] * p[2];

    // Pass 1: per-pixel metrics, the reference's statistics, SSIM's means, FLIP's range.
    let mut de = vec![0.0f64; n];
    let mut chunks = ChunkSums {
        done: Vec::with_capacity(n.div_ceil(CHUNK)),
        partial: Sums::default(),
    };
    let mut peak_c = [0.0f64; 3];
    let (mut reference_non_finite, mut reference_negative) = (0u64, 0u64);
    let (mut sum_x, mut sum_y) = (OrderedSum::new(), OrderedSum::new());
    let mut y_peak = 0.0f32;
    let mut flip_luminance: Vec<f64> = if options.flip_ppd.is_some() {
        Vec::with_capacity(n)
    } else {
        Vec::new()
    };
    let mut flip_negative = 0u64;
    for band in bands(h, rows) {
        let strip = sources.read(band)?;
        let first = strip.rows.start * w;
        fused_pass(
            &strip,
            first,
            &lab_converter,
            simd,
            &mut chunks,
            &mut de[first..first + strip.test.len()],
        );
        reference_non_finite += strip
            .reference_raw
            .par_iter()
            .filter(|p| !finite(p))
            .count() as u64;
        reference_negative += strip
            .reference_raw
            .par_iter()
            .map(|p| p.iter().filter(|v| **v < 0.0).count() as u64)
            .sum::<u64>();
        let strip_peak = strip
            .reference
            .par_chunks(CHUNK)
            .map(|chunk| {
                chunk.iter().fold([0.0f64; 3], |m, p| {
                    [0, 1, 2].map(|c| m[c].max(f64::from(p[c])))
                })
            })
            .reduce(|| [0.0; 3], |a, b| [0, 1, 2].map(|c| a[c].max(b[c])));
        peak_c = [0, 1, 2].map(|c| peak_c[c].max(strip_peak[c]));
        if options.ssim {
            let ya: Vec<f32> = strip
                .test
                .par_iter()
                .map(|p| luminance(&sanitise(*p, 1.0)))
                .collect();
            let yb: Vec<f32> = strip.reference.par_iter().map(luminance).collect();
            y_peak = y_peak.max(yb.par_iter().cloned().reduce(|| 0.0, f32::max));
            sum_x.add_range(first, ya.len(), |i| ya[i] as f64);
            sum_y.add_range(first, yb.len(), |i| yb[i] as f64);
        }
        if options.flip_ppd.is_some() {
            let (test709, reference709) = flip_inputs(&strip, &sources.space, flip_space_differs);
            flip_negative += flip::negative_samples(&test709, &reference709);
            flip_luminance.extend(reference709.iter().map(|p| flip::exposure_luminance(*p)));
        }
    }
    let sums = chunks
        .done
        .into_iter()
        .chain((!n.is_multiple_of(CHUNK)).then_some(chunks.partial))
        .fold(Sums::default(), Sums::add);
    let delta_e2000_map = options
        .delta_e2000_map
        .then(|| de.par_iter().map(|&d| d as f32).collect::<Vec<f32>>());
    let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1;
    let (_, p95, _) = de.select_nth_unstable_by(rank, f64::total_cmp);
    let de_p95 = *p95;
    drop(de);
    let exposures = options
        .flip_ppd
        .map(|_| ExposureRange::from_luminances(std::mem::take(&mut flip_luminance)));

    // Pass 2: the windowed metrics, strips with a halo of rows.
    let ssim_setup = (options.ssim && ssim::fits(w, h)).then(|| {
        let mean = |s: OrderedSum| (s.finish() / n as f64) as f32;
        (
            mean(sum_x),
            mean(sum_y),
            if y_peak > 0.0 { f64::from(y_peak) } else { 1.0 },
        )
    });
    let mut ssim_sum = OrderedSum::new();
    let flip_rows = options.flip_ppd.map(FlipRows::new);
    let flip_halo = flip_rows.as_ref().map_or(0, FlipRows::halo_rows);
    let mut ldr = vec![0.0f32; if flip_rows.is_some() { n } else { 0 }];
    let mut hdr = ldr.clone();
    if ssim_setup.is_some() || flip_rows.is_some() {
        for band in bands(h, rows) {
            let read = band.start.saturating_sub(flip_halo)
                ..(band.end + flip_halo.max(ssim::WINDOW - 1)).min(h);
            let strip = sources.read(read.clone())?;
            if let (Some(flip_rows), Some(exposures)) = (&flip_rows, &exposures) {
                let (test709, reference709) =
                    flip_inputs(&strip, &sources.space, flip_space_differs);
                let out = band.start * w..band.end * w;
                let (t, r) = (
                    flip::Rows::new(&test709, read.start),
                    flip::Rows::new(&reference709, read.start),
                );
                flip_rows.ldr(t, r, (w, h), band.start, &mut ldr[out.clone()]);
                flip_rows.hdr(t, r, (w, h), exposures, band.start, &mut hdr[out]);
            }
            if let Some((mean_x, mean_y, l)) = ssim_setup {
                let output = band.start..band.end.min(h + 1 - ssim::WINDOW);
                if !output.is_empty() {
                    // Input rows output.start .. output.end + 10 of the centred planes.
                    let inputs = (output.start - read.start) * w
                        ..(output.end - read.start + ssim::WINDOW - 1) * w;
                    let x: Vec<f32> = strip.test[inputs.clone()]
                        .par_iter()
                        .map(|p| luminance(&sanitise(*p, 1.0)) - mean_x)
                        .collect();
                    let y: Vec<f32> = strip.reference[inputs]
                        .par_iter()
                        .map(|p| luminance(p) - mean_y)
                        .collect();
                    let first = output.start * (w + 1 - ssim::WINDOW);
                    ssim::add_window_terms(&x, &y, w, (mean_x, mean_y), l, first, &mut ssim_sum);
                }
            }
        }
    }
    let ssim = ssim_setup
        .map(|_| ssim_sum.finish() / ((w + 1 - ssim::WINDOW) * (h + 1 - ssim::WINDOW)) as f64);

    let nf = n as f64;
    let mse_c = sums.se.map(|s| s / nf);
    let relmse_c = sums.rel.map(|s| s / nf);
    let peak = peak_c.iter().cloned().fold(0.0, f64::max);
    let mse = mse_c.iter().sum::<f64>() / 3.0;
    let psnr = super::psnr_db;
    let (flip, maps) = match (options.flip_ppd, exposures) {
        (Some(ppd), Some(exposures)) => {
            let map = |values| FlipMap {
                width: w,
                height: h,
                values,
            };
            let (ldr, hdr) = (map(ldr), map(hdr));
            let summary = FlipSummary {
                flip_ppd: ppd,
                ldr_flip_mean: ldr.mean(),
                ldr_flip_p95: ldr.p95(),
                hdr_flip_mean: hdr.mean(),
                hdr_flip_p95: hdr.p95(),
                hdr_flip_exposures: exposures,
                hdr_flip_negative_samples: flip_negative + reference_negative,
            };
            (Some(summary), Some(FlipMaps { ldr, hdr }))
        }
        _ => (None, None),
    };
    let comparison = Comparison {
        width: w,
        height: h,
        mse,
        rmse: mse.sqrt(),
        relmse: relmse_c.iter().sum::<f64>() / 3.0,
        psnr_db: psnr(peak, mse),
        psnr_note: super::psnr_note(peak, mse),
        ssim,
        delta_e2000_mean: sums.de / nf,
        delta_e2000_p95: de_p95,
        per_channel: PerChannel {
            mse: mse_c,
            rmse: mse_c.map(f64::sqrt),
            relmse: relmse_c,
            psnr_db: [0, 1, 2].map(|c| psnr(peak_c[c], mse_c[c])),
        },
        non_finite_pixels: sums.non_finite + reference_non_finite,
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

/// A strip's pixels, borrowed or converted.
type Pixels<'a> = std::borrow::Cow<'a, [[f32; 3]]>;

/// FLIP's inputs for a strip: linear Rec.709 copies when the reference space is another.
fn flip_inputs<'a>(
    strip: &'a Strip,
    space: &RgbColorSpace,
    convert: bool,
) -> (Pixels<'a>, Pixels<'a>) {
    if convert {
        let rec709 = RgbColorSpace::srgb();
        let (mut t, mut r) = (strip.test.clone(), strip.reference.clone());
        convert_pixels(&mut t, space, &rec709);
        convert_pixels(&mut r, space, &rec709);
        (Pixels::Owned(t), Pixels::Owned(r))
    } else {
        (
            Pixels::Borrowed(&strip.test),
            Pixels::Borrowed(&strip.reference),
        )
    }
}

/// The fused pass over a strip whose first pixel is `first`: chunk by chunk on the global
/// chunk grid, the first chunk continuing the previous strip's partial sums.
fn fused_pass(
    strip: &Strip,
    first: usize,
    converter: &LabConverter,
    simd: Simd,
    chunks: &mut ChunkSums,
    de: &mut [f64],
) {
    let len = strip.test.len();
    // Segments of this strip on the global chunk grid.
    let mut cuts = vec![0];
    let mut at = (first / CHUNK + 1) * CHUNK - first;
    while at < len {
        cuts.push(at);
        at += CHUNK;
    }
    cuts.push(len);
    let segments: Vec<Range<usize>> = cuts.windows(2).map(|c| c[0]..c[1]).collect();
    let continues = !first.is_multiple_of(CHUNK);
    let mut outs: Vec<&mut [f64]> = Vec::with_capacity(segments.len());
    let mut rest = de;
    for s in &segments {
        let (head, tail) = rest.split_at_mut(s.len());
        outs.push(head);
        rest = tail;
    }
    let carried = chunks.partial;
    let results: Vec<Sums> = segments
        .par_iter()
        .zip(outs.into_par_iter())
        .enumerate()
        .map(|(k, (s, out))| {
            let reference = &strip.reference[s.clone()];
            let lab: Vec<LabBlock> = reference
                .chunks(BLOCK)
                .map(|block| avx2!(simd, reference_block(converter, block)))
                .collect();
            let init = if k == 0 && continues {
                carried
            } else {
                Sums::default()
            };
            let test = &strip.test[s.clone()];
            avx2!(
                simd,
                compare_chunk(converter, reference, &lab, init, test, out)
            )
        })
        .collect();
    // The last segment is complete only when it ends on the chunk grid.
    let ends_on_grid = (first + len).is_multiple_of(CHUNK);
    let count = results.len();
    for (k, sums) in results.into_iter().enumerate() {
        if k + 1 == count && !ends_on_grid {
            chunks.partial = sums;
        } else {
            chunks.done.push(sums);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::PreparedReference;
    use prism_image::Image;

    /// A noisy pair with NaN, infinities, negatives, black and very bright pixels.
    fn pair(
        w: usize,
        h: usize,
        test_space: RgbColorSpace,
        reference_space: RgbColorSpace,
    ) -> (Image, Image) {
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut reference = Vec::new();
        let mut test = Vec::new();
        for i in 0..w * h {
            // Smooth structure plus noise, so that FLIP's features and SSIM see edges.
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let base = 0.5 + 0.4 * (x * 0.3).sin() * (y * 0.2).cos();
            let r = [base + 0.2 * next(), base * next() * 3.0, base * base];
            reference.push(r);
            let t = match i % 89 {
                0 => [f32::NAN, 0.5, 0.5],
                1 => [f32::INFINITY, 0.0, 1.0],
                2 => [-0.3, 0.2, 0.1],
                3 => [0.0; 3],
                4 => [1e6, 2e6, 5e5],
                _ => r.map(|c| c * (0.7 + 0.6 * next())),
            };
            test.push(t);
        }
        if w * h > w + 5 {
            reference[5] = [f32::NEG_INFINITY, 1.0, 1.0];
            reference[w + 3] = [-0.5, 2.0, 1.0];
        }
        (
            Image::new(w, h, test, test_space).unwrap(),
            Image::new(w, h, reference, reference_space).unwrap(),
        )
    }

    /// Strips of every height give the whole-image comparison and maps bit for bit: the
    /// per-chunk sums cut by strip boundaries, the SSIM sum, FLIP's halo at the image's
    /// edges and the colour conversions (test in P3, reference in sRGB, and a reference in
    /// P3 so that FLIP converts both to Rec.709).
    #[test]
    fn strips_give_the_whole_image_comparison_bit_for_bit() {
        let options = CompareOptions {
            ssim: true,
            flip_ppd: Some(crate::metrics::flip::DEFAULT_PPD),
            delta_e2000_map: true,
        };
        let (srgb, p3) = (RgbColorSpace::srgb(), RgbColorSpace::display_p3());
        for (w, h, test_space, reference_space) in [
            (150, 40, srgb.clone(), srgb.clone()),
            (67, 31, p3.clone(), srgb.clone()),
            (45, 37, srgb.clone(), p3.clone()),
        ] {
            let (test, reference) = pair(w, h, test_space, reference_space);
            let want = PreparedReference::new(&reference)
                .compare_with_maps(&test, &options)
                .unwrap();
            let (t, r) = (
                RowSource::from_image(test),
                RowSource::from_image(reference),
            );
            for rows in [1, 5, 11, 12, 27, 64, h] {
                let got = compare_rows(&t, &r, &options, rows).unwrap();
                assert_eq!(got.0, want.0, "{w}×{h}, {rows} rows");
                assert_eq!(got.1, want.1, "{w}×{h}, {rows} rows");
                // assert_eq on f64 treats −0 and +0 alike: compare the bits of the sums.
                assert_eq!(got.0.mse.to_bits(), want.0.mse.to_bits());
                assert_eq!(got.0.ssim.map(f64::to_bits), want.0.ssim.map(f64::to_bits));
            }
        }
    }

    /// Without the windowed metrics, and for an image smaller than SSIM's window, as well.
    #[test]
    fn strips_without_ssim_or_flip_and_small_images_match_too() {
        let (srgb, p3) = (RgbColorSpace::srgb(), RgbColorSpace::display_p3());
        for (w, h) in [(9, 7), (1, 1), (300, 3)] {
            let (test, reference) = pair(w, h, p3.clone(), srgb.clone());
            for options in [
                CompareOptions::default(),
                CompareOptions {
                    ssim: false,
                    flip_ppd: None,
                    delta_e2000_map: false,
                },
            ] {
                let want = PreparedReference::new(&reference)
                    .compare_with_maps(&test, &options)
                    .unwrap();
                let t = RowSource::from_image(test.clone());
                let r = RowSource::from_image(reference.clone());
                for rows in [1, 2, 5] {
                    assert_eq!(compare_rows(&t, &r, &options, rows).unwrap(), want);
                }
            }
        }
        let (_, b) = pair(9, 7, srgb.clone(), srgb.clone());
        let (c, _) = pair(9, 8, srgb.clone(), srgb);
        let e = compare_rows(
            &RowSource::from_image(c),
            &RowSource::from_image(b),
            &CompareOptions::default(),
            4,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("sizes differ"), "{e}");
    }

    /// From EXR files read band by band (Prism's writer: ZIP blocks of 16 rows, cut by
    /// strips of 7), the comparison of the images read whole.
    #[test]
    fn strips_of_exr_files_give_the_comparison_of_the_images_read_whole() {
        use prism_image::io::exr::{write_exr, ExrWriteOptions};
        use prism_image::io::read_image;
        let (test, reference) = pair(70, 50, RgbColorSpace::display_p3(), RgbColorSpace::srgb());
        let dir = std::env::temp_dir().join(format!("prism-strips-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("test.exr"), dir.join("reference.exr"));
        write_exr(&a, &test, &ExrWriteOptions::default()).unwrap();
        write_exr(&b, &reference, &ExrWriteOptions::default()).unwrap();
        let options = CompareOptions::default();
        let want = PreparedReference::new(&read_image(&b).unwrap())
            .compare_with_maps(&read_image(&a).unwrap(), &options)
            .unwrap();
        let (t, r) = (RowSource::open(&a).unwrap(), RowSource::open(&b).unwrap());
        assert!(t.is_streamed() && r.is_streamed());
        let got = compare_rows(&t, &r, &options, 7).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(got, want);
    }
}
