//! `prism.compare`: the metrics of `prism compare --json` (MSE, relMSE, PSNR, SSIM,
//! ΔE2000, LDR- and HDR-FLIP, per channel) of a test image against a reference.

use prism_image::io::read_dimensions;
use prism_post::metrics::flip::DEFAULT_PPD;
use prism_post::metrics::{compare_with, CompareOptions};
use prism_post::pipeline::compare_files_with;
use pyo3::prelude::*;

use crate::errors::{self, argument};
use crate::image_io::{image_argument, path_of};

/// `compare(test, reference, ppd=67.02)`: `test` and `reference` are paths, `prism.Image`s
/// or (H, W, 3) arrays of linear Rec.709 RGB of the same size; `ppd` is FLIP's viewing
/// condition in pixels per degree (the CLI's `--ppd`). Two paths are compared exactly as
/// the CLI compares the files (in strips of rows); arrays and images whole, with the same
/// numbers. Returns the dict `prism compare --json` prints.
#[pyfunction]
#[pyo3(signature = (test, reference, ppd=DEFAULT_PPD))]
pub fn compare<'py>(
    py: Python<'py>,
    test: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    ppd: f64,
) -> PyResult<Bound<'py, PyAny>> {
    if !(ppd.is_finite() && ppd > 0.0) {
        return Err(argument(format!(
            "ppd {ppd}: expected a positive number of pixels per degree"
        )));
    }
    let options = CompareOptions {
        flip_ppd: Some(ppd),
        ..CompareOptions::default()
    };
    let comparison = match (path_of(test)?, path_of(reference)?) {
        (Some(a), Some(b)) => py
            .detach(|| {
                // Both headers first, as `prism compare`'s memory check reads them: the
                // CLI's message for a missing or broken file.
                read_dimensions(&a)?;
                read_dimensions(&b)?;
                compare_files_with(&a, &b, &options)
            })
            .map(|(comparison, _)| comparison),
        _ => {
            let a = image_argument(test, "test")?;
            let b = image_argument(reference, "reference")?;
            py.detach(|| compare_with(&a, &b, &options))
        }
    }
    .map_err(errors::image)?;
    crate::json::serialize_to_python(py, &comparison)
}
