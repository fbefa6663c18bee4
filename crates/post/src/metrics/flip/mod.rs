//! NVIDIA's FLIP image difference, as its reference implementation (`flip-evaluator` 1.7)
//! computes it with its defaults:
//! - LDR-FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström & Fairchild 2020,
//!   "FLIP: A Difference Evaluator for Alternating Images"): contrast sensitivity filters
//!   in YyCxCz, colour difference as HyAB of Hunt-adjusted CIELAB, redistributed and
//!   raised to the power of one minus the edge/point feature difference ([`kernels`],
//!   [`colour`], [`band`]);
//! - HDR-FLIP (Andersson et al. 2021, "Visualizing Errors in Rendered High Dynamic Range
//!   Images"): the per-pixel maximum of LDR-FLIP over the reference's automatic exposure
//!   range ([`exposure`]).
//!
//! Inputs are linear Rec.709. LDR-FLIP clips them to [0, 1]; HDR-FLIP takes them as they
//! are with negative samples clamped to 0 (counted). Non-finite samples are black. The
//! viewing condition is given in pixels per degree; the default is the reference's: a
//! 0.7 m wide 3840-pixel display seen from 0.7 m (67.02 px/°).

mod band;
mod colour;
pub mod exposure;
mod kernels;
mod pow;

use crate::falsecolour::{false_colour, FalseColourOptions, FalseColourScale, Palette};
use prism_image::{Image, ImageError, Result};

use band::Filters;
use colour::map3;
pub use exposure::ExposureRange;
use kernels::Kernels;
use prism_cpu::Simd;

/// The reference implementation's default viewing condition: 3840 px across 0.7 m, seen
/// from 0.7 m, in pixels per degree.
pub const DEFAULT_PPD: f64 = 0.7 * (3840.0 / 0.7) * std::f64::consts::PI / 180.0;

/// A per-pixel FLIP error map, values in [0, 1], row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct FlipMap {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f32>,
}

impl FlipMap {
    pub fn mean(&self) -> f64 {
        self.values.iter().map(|&v| f64::from(v)).sum::<f64>() / self.values.len() as f64
    }

    /// The 95th percentile, nearest rank (as ΔE2000's p95).
    pub fn p95(&self) -> f64 {
        let mut v = self.values.clone();
        let rank = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
        let (_, p, _) = v.select_nth_unstable_by(rank, f32::total_cmp);
        f64::from(*p)
    }
}

impl FlipMap {
    /// The map in magma over [0, 1] (FLIP's own presentation), one pixel per value, with
    /// a legend titled `title`.
    pub fn to_image(&self, title: &str) -> Result<Image> {
        false_colour(
            &self.values,
            self.width,
            self.height,
            &Self::false_colour_options(title),
        )
    }

    /// How FLIP maps are drawn: magma over [0, 1], one pixel per value, the legend titled
    /// `title`.
    pub fn false_colour_options(title: &str) -> FalseColourOptions {
        FalseColourOptions {
            scale: FalseColourScale::Linear,
            range: Some((0.0, 1.0)),
            unit: title.into(),
            cell_px: 1,
            palette: Palette::Magma,
        }
    }
}

/// HDR-FLIP's map, the exposures it ran and the negative samples it clamped to 0.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrFlip {
    pub map: FlipMap,
    pub exposures: ExposureRange,
    pub negative_samples: u64,
}

/// An error unless `ppd` is a finite number > 0.
pub fn check_ppd(ppd: f64) -> Result<()> {
    if ppd.is_finite() && ppd > 0.0 {
        Ok(())
    } else {
        Err(ImageError::invalid(format!(
            "pixels per degree must be a finite number > 0, got {ppd}"
        )))
    }
}

fn check(test: &[[f32; 3]], reference: &[[f32; 3]], w: usize, h: usize, ppd: f64) -> Result<()> {
    check_ppd(ppd)?;
    if w == 0 || h == 0 || test.len() != w * h || reference.len() != w * h {
        return Err(ImageError::invalid(format!(
            "FLIP needs two {w}×{h} images, got {} and {} pixels",
            test.len(),
            reference.len()
        )));
    }
    Ok(())
}

/// Non-finite → black (the caller counts them as every metric does).
#[inline(always)]
fn finite_or_black(p: [f32; 3]) -> [f32; 3] {
    if p.iter().all(|v| v.is_finite()) {
        p
    } else {
        [0.0; 3]
    }
}

/// HDR-FLIP's view of a sample: non-finite → black, negatives → 0.
#[inline(always)]
fn hdr_clean(p: [f32; 3]) -> [f32; 3] {
    map3(finite_or_black(p), |v| v.max(0.0))
}

/// The samples below 0 in `test` and `reference`, which HDR-FLIP clamps to 0.
pub(crate) fn negative_samples(test: &[[f32; 3]], reference: &[[f32; 3]]) -> u64 {
    [test, reference]
        .iter()
        .flat_map(|img| img.iter().flatten())
        .filter(|v| **v < 0.0)
        .count() as u64
}

/// The luminance of a reference pixel (linear Rec.709) that HDR-FLIP's exposure range is
/// computed from ([`ExposureRange::from_luminances`]).
pub(crate) fn exposure_luminance(p: [f32; 3]) -> f64 {
    exposure::luminance(hdr_clean(p))
}

/// Rows `first …` of an image `w` pixels wide (a strip of it, or all of it from row 0).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rows<'a> {
    pixels: &'a [[f32; 3]],
    first: usize,
}

impl<'a> Rows<'a> {
    pub(crate) fn new(pixels: &'a [[f32; 3]], first: usize) -> Self {
        Self { pixels, first }
    }

    /// Image row `y` (which the strip must hold).
    fn row(&self, y: usize, w: usize) -> &'a [[f32; 3]] {
        let at = (y - self.first) * w;
        &self.pixels[at..at + w]
    }
}

/// LDR-FLIP and HDR-FLIP maps for bands of rows, at one viewing condition: what
/// [`ldr_flip`] and [`hdr_flip`] compute, a strip of rows at a time.
pub(crate) struct FlipRows {
    filters: Filters,
    simd: Simd,
}

/// LDR-FLIP's view of a sample: non-finite → black, clipped to [0, 1].
#[inline(always)]
fn ldr_clip(p: [f32; 3]) -> [f32; 3] {
    map3(finite_or_black(p), |v| v.clamp(0.0, 1.0))
}

impl FlipRows {
    /// For `ppd` pixels per degree (checked by the caller, [`check_ppd`]), with the
    /// filter kernels of the process-wide ISA (`prism_cpu::active`; every ISA gives the
    /// same bits).
    pub(crate) fn new(ppd: f64) -> Self {
        Self {
            filters: Filters::new(&Kernels::new(ppd)),
            simd: prism_cpu::active(),
        }
    }

    /// Rows above and below a band that its filters read.
    pub(crate) fn halo_rows(&self) -> usize {
        self.filters.halo()
    }

    /// LDR-FLIP of the image rows from `first_row` that `out` covers; `test` and
    /// `reference` hold them and [`Self::halo_rows`] around them (clamped to the image).
    pub(crate) fn ldr(
        &self,
        test: Rows<'_>,
        reference: Rows<'_>,
        size: (usize, usize),
        first_row: usize,
        out: &mut [f32],
    ) {
        band::flip_map_into(
            test,
            reference,
            size,
            first_row,
            &self.filters,
            &[ldr_clip],
            out,
            self.simd,
        );
    }

    /// HDR-FLIP over `exposures` of the rows as [`Self::ldr`].
    pub(crate) fn hdr(
        &self,
        test: Rows<'_>,
        reference: Rows<'_>,
        size: (usize, usize),
        exposures: &ExposureRange,
        first_row: usize,
        out: &mut [f32],
    ) {
        let tones: Vec<_> = (0..exposures.count)
            .map(|i| {
                let scale = exposures.stops(i).exp2() as f32;
                move |p: [f32; 3]| map3(hdr_clean(p), |v| exposure::aces(v * scale))
            })
            .collect();
        band::flip_map_into(
            test,
            reference,
            size,
            first_row,
            &self.filters,
            &tones,
            out,
            self.simd,
        );
    }
}

/// LDR-FLIP of `test` against `reference` (linear Rec.709, `w × h`), clipped to [0, 1].
pub fn ldr_flip(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    w: usize,
    h: usize,
    ppd: f64,
) -> Result<FlipMap> {
    check(test, reference, w, h, ppd)?;
    let mut values = vec![0.0f32; w * h];
    let (test, reference) = (Rows::new(test, 0), Rows::new(reference, 0));
    FlipRows::new(ppd).ldr(test, reference, (w, h), 0, &mut values);
    Ok(FlipMap {
        width: w,
        height: h,
        values,
    })
}

/// HDR-FLIP of `test` against `reference` (linear Rec.709, `w × h`, negatives clamped to 0).
pub fn hdr_flip(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    w: usize,
    h: usize,
    ppd: f64,
) -> Result<HdrFlip> {
    check(test, reference, w, h, ppd)?;
    let negative_samples = negative_samples(test, reference);
    let exposures = ExposureRange::automatic(reference.iter().map(|&p| hdr_clean(p)));
    let mut values = vec![0.0f32; w * h];
    let (test, reference) = (Rows::new(test, 0), Rows::new(reference, 0));
    FlipRows::new(ppd).hdr(test, reference, (w, h), &exposures, 0, &mut values);
    Ok(HdrFlip {
        map: FlipMap {
            width: w,
            height: h,
            values,
        },
        exposures,
        negative_samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: usize, h: usize, gain: f32) -> Vec<[f32; 3]> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                [x * gain, y * gain, 0.5 * (x + y) * gain]
            })
            .collect()
    }

    #[test]
    fn identical_images_have_zero_flip_and_errors_grow_with_the_difference() {
        let a = gradient(40, 30, 1.0);
        assert!(ldr_flip(&a, &a, 40, 30, DEFAULT_PPD)
            .unwrap()
            .values
            .iter()
            .all(|v| *v == 0.0));
        let small = ldr_flip(&gradient(40, 30, 0.9), &a, 40, 30, DEFAULT_PPD).unwrap();
        let large = ldr_flip(&gradient(40, 30, 0.5), &a, 40, 30, DEFAULT_PPD).unwrap();
        assert!(0.0 < small.mean() && small.mean() < large.mean());
        assert!(large.values.iter().all(|v| (0.0..=1.0).contains(v)));
        assert!(large.p95() >= large.mean());
        let img = large.to_image("LDR-FLIP").unwrap();
        assert_eq!(
            img.pixel(0, 0),
            Palette::Magma.colour(f64::from(large.values[0]))
        );
        assert!(img.width() > 40 && img.height() >= 30);
    }

    #[test]
    fn hdr_counts_negatives_and_bad_ppd_is_an_error() {
        let a = gradient(16, 12, 8.0);
        let mut b = a.clone();
        b[3] = [-1.0, 0.5, -2.0];
        let r = hdr_flip(&b, &a, 16, 12, DEFAULT_PPD).unwrap();
        assert_eq!(r.negative_samples, 2);
        assert!(r.exposures.count >= 2 && r.map.mean() > 0.0);
        for ppd in [0.0, -3.0, f64::NAN] {
            let e = ldr_flip(&a, &a, 16, 12, ppd).unwrap_err().to_string();
            assert!(e.contains("pixels per degree"), "{e}");
        }
        assert!(ldr_flip(&a, &a, 16, 11, DEFAULT_PPD).is_err());
    }

    /// Highlights near the f32 limit (and a 1×1 image, smaller than every filter) give
    /// finite maps in [0, 1].
    #[test]
    fn extreme_highlights_and_tiny_images_stay_finite() {
        let mut a = gradient(16, 12, 4.0);
        a[40] = [3e38, 1e30, 1e25];
        let mut b = a.clone();
        b[41] = [1e30; 3];
        let r = hdr_flip(&b, &a, 16, 12, DEFAULT_PPD).unwrap();
        assert!(
            r.map.values.iter().all(|v| (0.0..=1.0).contains(v)),
            "{r:?}"
        );
        let one = hdr_flip(&[[2.0; 3]], &[[1.0; 3]], 1, 1, DEFAULT_PPD).unwrap();
        assert!(one.map.values[0] > 0.0 && one.map.values[0] <= 1.0);
    }
}
