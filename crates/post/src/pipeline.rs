//! File-to-file entry points for the CLI (`prism tonemap`, `prism compare`), which stays a
//! thin wrapper: parse arguments, call these, print the serialisable report.
//! Pipeline (DESIGN.md): read → convert to the target primaries → tone operator →
//! per-channel clip to [0, 1] (the only gamut method so far) → write (EXR: linear display
//! values; PNG: encoded with the target's transfer function).

use std::path::Path;

use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{PostError, Result};
use crate::io::{convert_pixels, read_image, write_image};
use crate::metrics::{compare, Comparison};
use crate::tonemap::{ToneOperator, ToneParams, ToneReport};

/// Options of `prism tonemap`.
#[derive(Debug, Clone)]
pub struct TonemapOptions {
    pub operator: ToneOperator,
    pub params: ToneParams,
    /// Output primaries (`--target srgb|p3|rec2020`).
    pub target: RgbColorSpace,
}

/// What `prism tonemap --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct TonemapFileReport {
    pub input: String,
    pub output: String,
    pub width: usize,
    pub height: usize,
    pub target: &'static str,
    pub tone: ToneReport,
    /// Fraction of pixels with a channel outside [0, 1] before clipping.
    pub clipped_fraction: f64,
}

/// Tone-maps `input` into `output` (format from its extension).
pub fn tonemap_file(
    input: &Path,
    output: &Path,
    options: &TonemapOptions,
) -> Result<TonemapFileReport> {
    let mut image = read_image(input)?;
    let source = image.color_space.clone();
    convert_pixels(image.pixels_mut(), &source, &options.target);
    image.color_space = options.target.clone();
    let result = options
        .operator
        .apply(&image, &options.params)
        .map_err(|e| match e {
            PostError::Invalid(m) => PostError::format(input, m),
            other => other,
        })?;
    let mut out = result.image;
    let clipped = out
        .pixels_mut()
        .par_iter_mut()
        .map(|p| {
            let outside = p.iter().any(|c| !(0.0..=1.0).contains(c));
            *p = p.map(|c| c.clamp(0.0, 1.0));
            outside as u64
        })
        .sum::<u64>();
    write_image(output, &out)?;
    Ok(TonemapFileReport {
        input: input.display().to_string(),
        output: output.display().to_string(),
        width: out.width(),
        height: out.height(),
        target: options.target.name,
        clipped_fraction: clipped as f64 / out.pixels().len() as f64,
        tone: result.report,
    })
}

/// Compares the image at `test` with the reference at `reference`; mismatched sizes are an
/// error naming both files.
pub fn compare_files(test: &Path, reference: &Path) -> Result<Comparison> {
    let a = read_image(test)?;
    let b = read_image(reference)?;
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(PostError::invalid(format!(
            "{} is {}×{} but {} is {}×{}: compare needs equal sizes",
            test.display(),
            a.width(),
            a.height(),
            reference.display(),
            b.width(),
            b.height()
        )));
    }
    compare(&a, &b)
}
