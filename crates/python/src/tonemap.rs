//! `prism.tonemap` and `prism.operators`: `prism tonemap`'s stages (exposure, white
//! balance, tone operator, gamut mapping) on an image in memory, by the same library
//! function (`prism_post::pipeline::tonemap_image`).

use std::collections::BTreeMap;
use std::path::PathBuf;

use prism_post::colour::{GamutMethod, GamutTarget, WhiteBalance};
use prism_post::pipeline::{tonemap_image, OperatorChoice, TonemapOptions};
use prism_post::sheet::TileOrder;
use prism_post::tonemap::ToneOperator;
use prism_spectrum::AdaptationMethod;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use crate::arrays::pixels_to_array;
use crate::errors::{self, argument};
use crate::image_io::{image_argument, path_of};

fn cat_of(name: &str) -> PyResult<AdaptationMethod> {
    match name.to_ascii_lowercase().as_str() {
        "bradford" => Ok(AdaptationMethod::Bradford),
        "cat16" => Ok(AdaptationMethod::Cat16),
        "cat02" => Ok(AdaptationMethod::Cat02),
        "von-kries" => Ok(AdaptationMethod::VonKries),
        _ => Err(argument(format!(
            "cat {name:?}: expected one of bradford, cat16, cat02, von-kries"
        ))),
    }
}

/// `exposure`: None, a number of stops, or "auto"; returns (EV, auto).
fn exposure_of(value: Option<&Bound<'_, PyAny>>) -> PyResult<(f64, bool)> {
    let Some(value) = value else {
        return Ok((0.0, false));
    };
    if value.is_instance_of::<PyString>() {
        let text: String = value.extract()?;
        return prism_args::tone_values::parse_exposure(&text)
            .map_err(|e| argument(format!("exposure: {e}")));
    }
    let ev: f64 = value
        .extract()
        .map_err(|_| argument("exposure: expected a number of stops or \"auto\""))?;
    if !ev.is_finite() {
        return Err(argument(format!(
            "exposure {ev}: expected a finite number of stops"
        )));
    }
    Ok((ev, false))
}

/// `tonemap(image, op="reinhard02", wb="none", gamut="clip", *, target="srgb",
/// cat="bradford", exposure=None, luminance_scale=None, encode=False, report=False,
/// **params)`.
///
/// `image`: an (H, W, 3) array of linear Rec.709 RGB, a `prism.Image` (its
/// `cd_m2_per_unit` and `illumination` layer are used as the CLI uses the file's) or a
/// path. `params` are the operator's parameters (`prism.operators()`), e.g. `key=0.18`.
/// Returns float32 (H, W, 3) display values of `target` in [0, 1]: linear (what the CLI
/// writes to an EXR) or, with `encode=True`, encoded with the target's transfer function
/// (what it writes to a PNG). With `report=True`, returns `(values, report)` with the dict
/// `prism tonemap --json` prints.
#[pyfunction]
#[pyo3(signature = (image, op="reinhard02", wb="none", gamut="clip", *, target="srgb", cat="bradford", exposure=None, luminance_scale=None, encode=false, report=false, **params))]
#[allow(clippy::too_many_arguments)]
pub fn tonemap<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    op: &str,
    wb: &str,
    gamut: &str,
    target: &str,
    cat: &str,
    exposure: Option<&Bound<'py, PyAny>>,
    luminance_scale: Option<f64>,
    encode: bool,
    report: bool,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let label = path_of(image)?.unwrap_or_else(|| PathBuf::from("<array>"));
    let input = image_argument(image, "image")?;
    let (exposure_ev, auto_exposure) = exposure_of(exposure)?;
    let mut values = BTreeMap::new();
    if let Some(params) = params {
        for (key, value) in params.iter() {
            let key: String = key.extract()?;
            let number: f64 = value.extract().map_err(|_| {
                argument(format!(
                    "{key}={value}: expected a number (an operator parameter; see prism.operators())"
                ))
            })?;
            values.insert(key, number);
        }
    }
    let options = TonemapOptions {
        operator: OperatorChoice::parse(op).map_err(|e| argument(format!("--op {op}: {e}")))?,
        params: values,
        wb: WhiteBalance::parse(wb).map_err(|e| argument(e.to_string()))?,
        cat: cat_of(cat)?,
        gamut: GamutMethod::parse(gamut).map_err(|e| argument(e.to_string()))?,
        target: GamutTarget::parse(target).map_err(|e| argument(e.to_string()))?,
        exposure_ev,
        auto_exposure,
        auto_exposure_if_photometric: exposure.is_none(),
        luminance_scale_cd_m2: luminance_scale,
        score: None,
        order: TileOrder::Catalogue,
    };
    let (out, tone_report) = py
        .detach(|| tonemap_image(input, &label, &options))
        .map_err(errors::image)?;
    let pixels: Vec<[f32; 3]> = if encode {
        let transfer = out.color_space.transfer;
        out.pixels()
            .iter()
            .map(|p| p.map(|v| transfer.encode(f64::from(v)) as f32))
            .collect()
    } else {
        out.pixels().to_vec()
    };
    let array = pixels_to_array(py, &pixels, out.width(), out.height())?.into_any();
    if report {
        let dict = crate::json::serialize_to_python(py, &tone_report)?;
        return Ok(PyTuple::new(py, [array, dict])?.into_any());
    }
    Ok(array)
}

/// `operators()`: every tone operator with its parameters (name, default, range, doc),
/// whether it needs absolute luminance, and its reference (`prism tonemap --list --json`).
#[pyfunction]
pub fn operators(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    crate::json::serialize_to_python(py, &ToneOperator::catalogue())
}
