//! `prism.read_image`, `prism.write_image` and the `prism.Image` they exchange: linear
//! Rec.709 RGB, the named layers (AOVs), the metadata, the absolute scale and, for a
//! spectral EXR (Fichet et al. 2021 layout), the emissive bands.

use std::path::{Path, PathBuf};

use numpy::ndarray::Array3;
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike1, PyArrayLike3, PyArrayMethods};
use prism_image::io::exr::ExrWriteOptions;
use prism_image::io::spectral_exr::{
    has_emissive_channels, read_spectral_exr, write_exr_with_spectral_bands, SpectralImage,
};
use prism_image::io::{convert_pixels, read_image as read_file, write_image as write_file};
use prism_image::io::{read_dimensions, ImageFormat};
use prism_image::rgb_matrix::same_colorimetry;
use prism_image::Image;
use prism_spectrum::rgb_space::RgbColorSpace;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::arrays::{array_to_pixels, interleaved_to_array, pixels_to_array};
use crate::errors::{self, argument};

/// An image as NumPy arrays, with the Rust image it came from (so that tone mapping and
/// comparison see its layers, metadata and scale as the CLI sees the file's).
#[pyclass(name = "Image", module = "prism", frozen)]
pub struct PyImage {
    pub image: Image,
    /// Emissive bands, pixel-major, with their wavelengths.
    pub spectral: Option<SpectralImage>,
}

#[pymethods]
impl PyImage {
    /// `Image(rgb, layers=None, cd_m2_per_unit=None, spectral=None, wavelengths_nm=None,
    /// metadata=None)`: `rgb` (H, W, 3) linear Rec.709; `layers` a dict of name → (H, W) or
    /// (H, W, C) arrays (channels named X, Y, Z, … by position); `spectral` (H, W, N)
    /// radiance bands in W·m⁻²·sr⁻¹·nm⁻¹ at `wavelengths_nm` (strictly increasing).
    #[new]
    #[pyo3(signature = (rgb, layers=None, cd_m2_per_unit=None, spectral=None, wavelengths_nm=None, metadata=None))]
    fn new(
        rgb: PyArrayLike3<'_, f32, AllowTypeChange>,
        layers: Option<&Bound<'_, PyDict>>,
        cd_m2_per_unit: Option<f64>,
        spectral: Option<PyArrayLike3<'_, f32, AllowTypeChange>>,
        wavelengths_nm: Option<PyArrayLike1<'_, f64, AllowTypeChange>>,
        metadata: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let (pixels, width, height) = array_to_pixels(&rgb, "rgb")?;
        let mut image =
            Image::new(width, height, pixels, RgbColorSpace::srgb()).map_err(errors::image)?;
        if let Some(scale) = cd_m2_per_unit {
            if !(scale.is_finite() && scale > 0.0) {
                return Err(argument(format!(
                    "cd_m2_per_unit {scale}: expected a positive finite number of cd/m² per unit"
                )));
            }
            image.cd_m2_per_unit = Some(scale);
        }
        if let Some(layers) = layers {
            for (name, value) in layers.iter() {
                let name: String = name.extract()?;
                add_layer(&mut image, &name, &value)?;
            }
        }
        if let Some(metadata) = metadata {
            for (key, value) in metadata.iter() {
                image.metadata.insert(key.extract()?, value.extract()?);
            }
        }
        let spectral = match (spectral, wavelengths_nm) {
            (None, None) => None,
            (Some(bands), Some(wavelengths)) => {
                Some(spectral_image(&bands, &wavelengths, width, height)?)
            }
            (Some(_), None) | (None, Some(_)) => {
                return Err(argument(
                    "spectral and wavelengths_nm go together: give both or neither",
                ))
            }
        };
        Ok(Self { image, spectral })
    }

    /// (H, W, 3) float32 linear Rec.709 RGB (a new array on each access).
    #[getter]
    fn rgb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let i = &self.image;
        Ok(pixels_to_array(py, i.pixels(), i.width(), i.height())?.into_any())
    }

    /// The layers: name → (H, W) for one channel, (H, W, C) for more.
    #[getter]
    fn layers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let i = &self.image;
        let out = PyDict::new(py);
        for layer in i.layers() {
            let array = interleaved_to_array(
                py,
                &layer.samples,
                layer.channels.len(),
                i.width(),
                i.height(),
            )?;
            out.set_item(&layer.name, array)?;
        }
        Ok(out)
    }

    /// Each layer's channel names, in the order of the last axis of `layers[name]`.
    #[getter]
    fn layer_channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for layer in self.image.layers() {
            out.set_item(&layer.name, layer.channels.clone())?;
        }
        Ok(out)
    }

    /// Text metadata (EXR attributes, Radiance header lines).
    #[getter]
    fn metadata<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (k, v) in &self.image.metadata {
            out.set_item(k, v)?;
        }
        Ok(out)
    }

    /// cd/m² of a pixel whose relative luminance Y is 1 (`prism:cd_m2_per_unit`), or None.
    #[getter]
    fn cd_m2_per_unit(&self) -> Option<f64> {
        self.image.cd_m2_per_unit
    }

    /// (H, W, N) float32 spectral radiance bands, or None.
    #[getter]
    fn spectral<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.spectral
            .as_ref()
            .map(|s| {
                interleaved_to_array(py, &s.samples, s.wavelengths_nm.len(), s.width, s.height)
            })
            .transpose()
    }

    /// The bands' wavelengths in nm, or None.
    #[getter]
    fn wavelengths_nm<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.spectral
            .as_ref()
            .map(|s| s.wavelengths_nm.clone().into_pyarray(py).into_any())
    }

    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        (self.image.height(), self.image.width(), 3)
    }

    /// `numpy.asarray(image)` is the RGB.
    #[pyo3(signature = (dtype=None, copy=None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let _ = copy;
        let rgb = self.rgb(py)?;
        match dtype {
            Some(dtype) => rgb.call_method1("astype", (dtype,)),
            None => Ok(rgb),
        }
    }

    fn __repr__(&self) -> String {
        let names: Vec<&str> = self
            .image
            .layers()
            .iter()
            .map(|l| l.name.as_str())
            .collect();
        format!(
            "prism.Image({}×{}, layers [{}]{})",
            self.image.width(),
            self.image.height(),
            names.join(", "),
            self.spectral
                .as_ref()
                .map(|s| format!(", {} spectral bands", s.wavelengths_nm.len()))
                .unwrap_or_default()
        )
    }
}

/// Channel names of a layer given as an array of `count` channels.
fn channel_names(count: usize) -> Vec<String> {
    const NAMES: [&str; 4] = ["X", "Y", "Z", "W"];
    match count {
        1 => vec!["Y".to_string()],
        2..=4 => NAMES[..count].iter().map(|s| s.to_string()).collect(),
        _ => (0..count).map(|c| format!("C{c}")).collect(),
    }
}

fn add_layer(image: &mut Image, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
    let numpy = value.py().import("numpy")?;
    let array = numpy.call_method1("asarray", (value, "float32"))?;
    let array = array.cast_into::<numpy::PyArrayDyn<f32>>()?;
    let readonly = array.readonly();
    let view = readonly.as_array();
    let shape = view.shape().to_vec();
    let channels = match shape.as_slice() {
        [h, w] if *h == image.height() && *w == image.width() => 1,
        [h, w, c] if *h == image.height() && *w == image.width() && *c >= 1 => *c,
        _ => {
            return Err(argument(format!(
                "layers[{name:?}]: expected an ({h}, {w}) or ({h}, {w}, C) array like the RGB, got shape {shape:?}",
                h = image.height(),
                w = image.width()
            )))
        }
    };
    let samples: Vec<f32> = view.iter().copied().collect();
    let names = channel_names(channels);
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    image.set_layer(name, &refs, samples).map_err(errors::image)
}

fn spectral_image(
    bands: &PyArrayLike3<'_, f32, AllowTypeChange>,
    wavelengths: &PyArrayLike1<'_, f64, AllowTypeChange>,
    width: usize,
    height: usize,
) -> PyResult<SpectralImage> {
    let view = bands.as_array();
    let wavelengths_nm: Vec<f64> = wavelengths.as_array().iter().copied().collect();
    let (h, w, n) = view.dim();
    if (h, w) != (height, width) || n != wavelengths_nm.len() || n == 0 {
        return Err(argument(format!(
            "spectral: expected an ({height}, {width}, N) array with N = len(wavelengths_nm) = {} ≥ 1, got shape ({h}, {w}, {n})",
            wavelengths_nm.len()
        )));
    }
    if !wavelengths_nm.iter().all(|l| l.is_finite() && *l > 0.0)
        || !wavelengths_nm.windows(2).all(|p| p[0] < p[1])
    {
        return Err(argument(format!(
            "wavelengths_nm {wavelengths_nm:?}: expected strictly increasing positive wavelengths in nm"
        )));
    }
    let samples: Vec<f32> = view.iter().copied().collect();
    Ok(SpectralImage {
        width,
        height,
        wavelengths_nm,
        samples,
        emissive_units: prism_image::io::spectral_exr::RADIANCE_UNITS.to_string(),
    })
}

/// A path argument (str or os.PathLike).
pub fn path_of(value: &Bound<'_, PyAny>) -> PyResult<Option<PathBuf>> {
    if value.is_instance_of::<PyString>() {
        return Ok(Some(PathBuf::from(value.extract::<String>()?)));
    }
    let os = value.py().import("os")?;
    let pathlike = os.getattr("PathLike")?;
    if value.is_instance(&pathlike)? {
        let text: String = os.call_method1("fspath", (value,))?.extract()?;
        return Ok(Some(PathBuf::from(text)));
    }
    Ok(None)
}

/// Reads `path` as the CLI does, with every pixel in linear Rec.709.
pub fn read_prism_image(path: &Path) -> PyResult<PyImage> {
    // The header first, as `prism tonemap` and `prism compare` read it for their memory
    // check before decoding: a missing or broken file gets the CLI's message.
    read_dimensions(path).map_err(errors::image)?;
    let mut image = read_file(path).map_err(errors::image)?;
    let srgb = RgbColorSpace::srgb();
    if !same_colorimetry(&image.color_space, &srgb) {
        let from = image.color_space.clone();
        convert_pixels(image.pixels_mut(), &from, &srgb);
        image.color_space = srgb;
    }
    let spectral = match ImageFormat::from_path(path).map_err(errors::image)? {
        ImageFormat::Exr if has_emissive_channels(path).map_err(errors::image)? => {
            Some(read_spectral_exr(path).map_err(errors::image)?)
        }
        ImageFormat::Exr | ImageFormat::Hdr | ImageFormat::Png => None,
    };
    Ok(PyImage { image, spectral })
}

/// An image argument: a `prism.Image`, an (H, W, 3) array of linear Rec.709 RGB, or a
/// path (read as `prism.read_image` reads it).
pub fn image_argument(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Image> {
    if let Ok(image) = value.cast::<PyImage>() {
        return Ok(image.get().image.clone());
    }
    if let Some(path) = path_of(value)? {
        return Ok(read_prism_image(&path)?.image);
    }
    let array: PyArrayLike3<'_, f32, AllowTypeChange> = value.extract().map_err(|_| {
        argument(format!(
            "{what}: expected a prism.Image, an (H, W, 3) array of linear Rec.709 RGB or an image path"
        ))
    })?;
    let (pixels, width, height) = array_to_pixels(&array, what)?;
    Image::new(width, height, pixels, RgbColorSpace::srgb()).map_err(errors::image)
}

/// `read_image(path)`: an EXR (RGB, layers, spectral bands), Radiance HDR or PNG file as a
/// `prism.Image`; pixels in other primaries are converted to linear Rec.709.
#[pyfunction]
pub fn read_image(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<PyImage> {
    let path = path_of(path)?.ok_or_else(|| argument("read_image: expected a path"))?;
    py.detach(|| read_prism_image(&path))
}

/// `write_image(path, image, *, spectral=None, wavelengths_nm=None, cd_m2_per_unit=None)`:
/// writes a `prism.Image` or an (H, W, 3) array as EXR (float, ZIP; layers and spectral
/// bands), Radiance HDR or 16-bit PNG (sRGB-encoded), atomically (temporary file, then
/// rename), the format chosen by the extension as in the CLI.
#[pyfunction]
#[pyo3(signature = (path, image, *, spectral=None, wavelengths_nm=None, cd_m2_per_unit=None))]
pub fn write_image(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    image: &Bound<'_, PyAny>,
    spectral: Option<PyArrayLike3<'_, f32, AllowTypeChange>>,
    wavelengths_nm: Option<PyArrayLike1<'_, f64, AllowTypeChange>>,
    cd_m2_per_unit: Option<f64>,
) -> PyResult<()> {
    let path = path_of(path)?.ok_or_else(|| argument("write_image: expected a path"))?;
    let (mut rgb, mut bands) = match image.cast::<PyImage>() {
        Ok(given) => (given.get().image.clone(), given.get().spectral.clone()),
        Err(_) => (image_argument(image, "image")?, None),
    };
    if let Some(scale) = cd_m2_per_unit {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(argument(format!(
                "cd_m2_per_unit {scale}: expected a positive finite number of cd/m² per unit"
            )));
        }
        rgb.cd_m2_per_unit = Some(scale);
    }
    match (spectral, wavelengths_nm) {
        (None, None) => {}
        (Some(s), Some(w)) => bands = Some(spectral_image(&s, &w, rgb.width(), rgb.height())?),
        (Some(_), None) | (None, Some(_)) => {
            return Err(argument(
                "spectral and wavelengths_nm go together: give both or neither",
            ))
        }
    }
    let format = ImageFormat::from_path(&path).map_err(errors::image)?;
    py.detach(|| match (&bands, format) {
        (None, _) => write_file(&path, &rgb).map_err(errors::image),
        (Some(s), ImageFormat::Exr) => {
            let n = s.wavelengths_nm.len();
            let planes: Vec<Vec<f32>> = (0..n)
                .map(|k| s.samples.iter().skip(k).step_by(n).copied().collect())
                .collect();
            write_exr_with_spectral_bands(
                &path,
                &rgb,
                &s.wavelengths_nm,
                &planes,
                &ExrWriteOptions::default(),
            )
            .map_err(errors::image)
        }
        (Some(_), ImageFormat::Hdr | ImageFormat::Png) => Err(argument(format!(
            "{}: spectral bands need an .exr file (channels S0.<λ>nm beside R, G, B)",
            path.display()
        ))),
    })
}

/// An (H, W, N) float32 array of row-major planes (one per band).
pub fn planes_to_array<'py>(
    py: Python<'py>,
    planes: &[Vec<f32>],
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let n = planes.len();
    let mut samples = Vec::with_capacity(width * height * n);
    for i in 0..width * height {
        samples.extend(planes.iter().map(|p| p[i]));
    }
    let array = Array3::from_shape_vec((height, width, n), samples)
        .map_err(|e| argument(format!("{width}×{height}×{n} bands: {e}")))?;
    Ok(array.into_pyarray(py).into_any())
}
