//! NumPy arrays to and from the libraries' pixel buffers (row-major, top row first, one
//! `[f32; 3]` per pixel) and planes.

use numpy::ndarray::{Array2, Array3};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArray3, PyArrayLike3};
use pyo3::prelude::*;

use crate::errors::argument;

/// An (H, W, 3) float32 array of `pixels` (`width * height` of them).
pub fn pixels_to_array<'py>(
    py: Python<'py>,
    pixels: &[[f32; 3]],
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let flat: Vec<f32> = pixels.iter().flatten().copied().collect();
    let array = Array3::from_shape_vec((height, width, 3), flat)
        .map_err(|e| argument(format!("{width}×{height} pixels: {e}")))?;
    Ok(array.into_pyarray(py))
}

/// An (H, W, C) float32 array of pixel-interleaved `samples`, or (H, W) when C is 1.
pub fn interleaved_to_array<'py>(
    py: Python<'py>,
    samples: &[f32],
    channels: usize,
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyAny>> {
    if channels == 1 {
        let array = Array2::from_shape_vec((height, width), samples.to_vec())
            .map_err(|e| argument(format!("{width}×{height} plane: {e}")))?;
        return Ok(array.into_pyarray(py).into_any());
    }
    let array = Array3::from_shape_vec((height, width, channels), samples.to_vec())
        .map_err(|e| argument(format!("{width}×{height}×{channels} samples: {e}")))?;
    Ok(array.into_pyarray(py).into_any())
}

/// An (H, W) float32 array of a row-major plane.
pub fn plane_to_array<'py>(
    py: Python<'py>,
    plane: &[f32],
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let array = Array2::from_shape_vec((height, width), plane.to_vec())
        .map_err(|e| argument(format!("{width}×{height} plane: {e}")))?;
    Ok(array.into_pyarray(py))
}

/// The pixels of an (H, W, 3) array (any real dtype; converted to float32), with width and
/// height; `what` names the argument in messages.
pub fn array_to_pixels(
    array: &PyArrayLike3<'_, f32, AllowTypeChange>,
    what: &str,
) -> PyResult<(Vec<[f32; 3]>, usize, usize)> {
    let view = array.as_array();
    let (height, width, channels) = view.dim();
    if channels != 3 || width == 0 || height == 0 {
        return Err(argument(format!(
            "{what}: expected an (H, W, 3) array of linear Rec.709 RGB with H, W ≥ 1, got shape ({height}, {width}, {channels})"
        )));
    }
    let mut pixels = Vec::with_capacity(width * height);
    for row in view.outer_iter() {
        for px in row.outer_iter() {
            pixels.push([px[0], px[1], px[2]]);
        }
    }
    Ok((pixels, width, height))
}
