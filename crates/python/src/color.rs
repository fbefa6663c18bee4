//! `prism.color`: the report of `prism color --json` for one spectrum, or the XYZ of many
//! spectra on one wavelength grid in one call.

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike1, PyArrayLike2};
use prism_spectrum::adaptation::AdaptationMethod;
use prism_spectrum::color_report::{
    color_report, illuminant_white, resolve_spectrum, ReportIlluminant, SpectrumRole,
    COLORCHECKER_PREFIX,
};
use prism_spectrum::colorimetry::{emission_to_xyz_cd_per_m2, reflectance_to_xyz};
use prism_spectrum::{Observer, Tabulated};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::errors::{argument, SpectrumError};

fn observer_of(name: &str) -> PyResult<Observer> {
    match name.to_ascii_lowercase().as_str() {
        "cie1931" => Ok(Observer::Cie1931),
        "cie1964" => Ok(Observer::Cie1964),
        _ => Err(argument(format!(
            "observer {name:?}: expected \"cie1931\" (2°) or \"cie1964\" (10°)"
        ))),
    }
}

fn adaptation_of(name: Option<&str>) -> PyResult<AdaptationMethod> {
    // The CLI's default, `--adapt bradford`.
    let Some(name) = name else {
        return Ok(AdaptationMethod::Bradford);
    };
    match name.to_ascii_lowercase().as_str() {
        "bradford" => Ok(AdaptationMethod::Bradford),
        "cat16" => Ok(AdaptationMethod::Cat16),
        "cat02" => Ok(AdaptationMethod::Cat02),
        "von-kries" => Ok(AdaptationMethod::VonKries),
        "none" => Ok(AdaptationMethod::None),
        _ => Err(argument(format!(
            "adapt {name:?}: expected one of bradford, cat16, cat02, von-kries, none"
        ))),
    }
}

/// A table from an (N, 2) array of (wavelength_nm, value) rows.
fn table_of_pairs(
    pairs: &PyArrayLike2<'_, f64, AllowTypeChange>,
    what: &str,
) -> PyResult<Tabulated> {
    let view = pairs.as_array();
    let (rows, columns) = view.dim();
    if columns != 2 || rows == 0 {
        return Err(argument(format!(
            "{what}: expected an (N, 2) array of (wavelength_nm, value) rows, got shape ({rows}, {columns})"
        )));
    }
    let wavelengths: Vec<f64> = view.column(0).iter().copied().collect();
    let values: Vec<f64> = view.column(1).iter().copied().collect();
    table_of(wavelengths, values, what)
}

fn table_of(wavelengths: Vec<f64>, values: Vec<f64>, what: &str) -> PyResult<Tabulated> {
    if let Some(i) = wavelengths.iter().position(|w| !w.is_finite()) {
        return Err(SpectrumError::new_err(format!(
            "{what}: row {i}: wavelength {} nm is not a finite number",
            wavelengths[i]
        )));
    }
    if let Some(i) = wavelengths.windows(2).position(|w| w[0] >= w[1]) {
        return Err(SpectrumError::new_err(format!(
            "{what}: row {}: wavelength {} nm after {} nm: expected strictly increasing wavelengths",
            i + 1,
            wavelengths[i + 1],
            wavelengths[i]
        )));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(SpectrumError::new_err(format!(
            "{what}: row {i}: value {} is not a finite number",
            values[i]
        )));
    }
    Tabulated::new(wavelengths, values)
        .ok_or_else(|| SpectrumError::new_err(format!("{what}: expected at least one row")))
}

/// A spectrum argument: a name or path (str or os.PathLike, resolved as the CLI resolves
/// `--spectrum`), or anything NumPy reads as an (N, 2) array of (wavelength_nm, value).
#[derive(FromPyObject)]
pub enum SpectrumSpec<'py> {
    Text(PathBuf),
    Array(Bound<'py, PyAny>),
}

/// The table, its label and the text it was given as.
fn resolve(
    spec: &SpectrumSpec<'_>,
    role: SpectrumRole,
    flag: &str,
) -> PyResult<(Tabulated, String, String)> {
    match spec {
        SpectrumSpec::Text(path) => {
            let text = path.to_string_lossy().into_owned();
            let (table, label) =
                resolve_spectrum(&text, role, flag).map_err(SpectrumError::new_err)?;
            Ok((table, label, text))
        }
        SpectrumSpec::Array(value) => {
            let pairs: PyArrayLike2<'_, f64, AllowTypeChange> = value.extract().map_err(|_| {
                argument(format!(
                    "{flag}: expected a name (\"D65\", \"colorchecker:dark skin\", \"blackbody:2856\"), a CSV path or an (N, 2) array of (wavelength_nm, value) rows"
                ))
            })?;
            let table = table_of_pairs(&pairs, flag)?;
            Ok((table, "<array>".to_string(), "<array>".to_string()))
        }
    }
}

/// `color(spectrum, illuminant="D65", observer="cie1931", adapt=None, wavelengths_nm=None)`.
///
/// Without `wavelengths_nm`, `spectrum` is one spectrum (a name such as
/// "colorchecker:dark skin" or "blackbody:2856", a CSV path, or an (N, 2) array of
/// (wavelength_nm, value) rows) and the result is the dict `prism color --json` prints.
/// `illuminant=None` treats the spectrum as spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹, XYZ in
/// cd/m²); otherwise it is a reflectance under the illuminant (Y = 100 for a perfect
/// reflector). `adapt=None` is the CLI's default, Bradford.
///
/// With `wavelengths_nm` (M wavelengths, strictly increasing), `spectrum` is an (N, M)
/// array of N spectra on that grid (or one (M,) spectrum) and the result is their (N, 3)
/// (or (3,)) XYZ with `observer`, each row as the single-spectrum call computes it.
#[pyfunction]
#[pyo3(signature = (spectrum, illuminant=Some(SpectrumSpec::Text(PathBuf::from("D65"))), observer="cie1931", adapt=None, wavelengths_nm=None))]
pub fn color<'py>(
    py: Python<'py>,
    spectrum: SpectrumSpec<'py>,
    illuminant: Option<SpectrumSpec<'py>>,
    observer: &str,
    adapt: Option<&str>,
    wavelengths_nm: Option<PyArrayLike1<'py, f64, AllowTypeChange>>,
) -> PyResult<Bound<'py, PyAny>> {
    let observer = observer_of(observer)?;
    let adapt = adaptation_of(adapt)?;
    let illuminant = illuminant
        .as_ref()
        .map(|i| resolve(i, SpectrumRole::Illuminant, "--illuminant"))
        .transpose()?;
    if let Some(grid) = wavelengths_nm {
        let SpectrumSpec::Array(values) = spectrum else {
            return Err(argument(
                "wavelengths_nm is for an (N, M) array of spectra on that grid; give a named or file spectrum without it",
            ));
        };
        return xyz_of_rows(py, &values, &grid, illuminant.as_ref(), observer);
    }
    let role = match illuminant {
        Some(_) => SpectrumRole::Reflectance,
        None => SpectrumRole::Emission,
    };
    if let (SpectrumSpec::Text(text), None) = (&spectrum, &illuminant) {
        let text = text.to_string_lossy();
        if text.to_lowercase().starts_with(COLORCHECKER_PREFIX) {
            let message = std::ffi::CString::new(format!(
                "{text} is a reflectance but illuminant=None: it is treated as spectral radiance; give illuminant=\"D65\" (or another) for its colour under a light"
            ))
            .map_err(|e| argument(e.to_string()))?;
            PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 1)?;
        }
    }
    let (table, label, _) = resolve(&spectrum, role, "--spectrum")?;
    let report = match &illuminant {
        Some((light, light_label, light_spec)) => color_report(
            &table,
            label,
            Some(ReportIlluminant {
                spec: light_spec,
                table: light,
                label: light_label.clone(),
            }),
            observer,
            adapt,
        ),
        None => color_report(&table, label, None, observer, adapt),
    }
    .map_err(SpectrumError::new_err)?;
    crate::json::to_python(py, &report.to_json())
}

/// The XYZ of every row of `values` on `grid`.
fn xyz_of_rows<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    grid: &PyArrayLike1<'py, f64, AllowTypeChange>,
    illuminant: Option<&(Tabulated, String, String)>,
    observer: Observer,
) -> PyResult<Bound<'py, PyAny>> {
    let wavelengths: Vec<f64> = grid.as_array().iter().copied().collect();
    let numpy = py.import("numpy")?;
    let array = numpy.call_method1("asarray", (values, "float64"))?;
    let one = array.getattr("ndim")?.extract::<usize>()? == 1;
    let array = if one {
        array.call_method1("reshape", ((1, wavelengths.len() as isize),))?
    } else {
        array
    };
    let rows: PyArrayLike2<'_, f64, AllowTypeChange> = array.extract().map_err(|_| {
        argument("spectrum: expected an (N, M) array of spectra, one per row, on wavelengths_nm")
    })?;
    let view = rows.as_array();
    let (n, m) = view.dim();
    if m != wavelengths.len() {
        return Err(argument(format!(
            "spectrum: {m} values per row but wavelengths_nm has {}: expected one value per wavelength",
            wavelengths.len()
        )));
    }
    let tables: Vec<Tabulated> = view
        .outer_iter()
        .enumerate()
        .map(|(i, row)| {
            table_of(
                wavelengths.clone(),
                row.to_vec(),
                &format!("spectrum row {i}"),
            )
        })
        .collect::<PyResult<_>>()?;
    let light = match illuminant {
        Some((table, _, spec)) => {
            let dense = table.to_dense();
            illuminant_white(&dense, spec, observer).map_err(SpectrumError::new_err)?;
            Some(dense)
        }
        None => None,
    };
    let xyz: Vec<f64> = py.detach(|| {
        tables
            .par_iter()
            .flat_map_iter(|table| {
                let dense = table.to_dense();
                let xyz = match &light {
                    Some(light) => reflectance_to_xyz(&dense, light, observer),
                    None => emission_to_xyz_cd_per_m2(&dense, observer),
                };
                xyz.to_array()
            })
            .collect()
    });
    let array = Array2::from_shape_vec((n, 3), xyz).map_err(|e| argument(e.to_string()))?;
    let out = array.into_pyarray(py).into_any();
    if one {
        out.call_method1("reshape", (3,))
    } else {
        Ok(out)
    }
}
