//! The exception hierarchy: `prism.PrismError` and one subclass per kind of failure, each
//! carrying the message the CLI prints for the same input (file, JSON path or argument,
//! and what was expected).

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    prism,
    PrismError,
    PyException,
    "Base class of every error Prism raises."
);
create_exception!(
    prism,
    SceneError,
    PrismError,
    "A scene that cannot be read or built (file, JSON path, expectation)."
);
create_exception!(
    prism,
    SpectrumError,
    PrismError,
    "A spectrum or illuminant that cannot be resolved or used."
);
create_exception!(
    prism,
    ImageError,
    PrismError,
    "An image file that cannot be read or written, or image data that is unusable."
);
create_exception!(
    prism,
    RenderError,
    PrismError,
    "A render that failed after the scene was built."
);
create_exception!(
    prism,
    ArgumentError,
    PrismError,
    "An argument outside what the function accepts (name, range, array shape)."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("PrismError", py.get_type::<PrismError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SpectrumError", py.get_type::<SpectrumError>())?;
    m.add("ImageError", py.get_type::<ImageError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add("ArgumentError", py.get_type::<ArgumentError>())?;
    Ok(())
}

/// An `ArgumentError` with `message`.
pub fn argument(message: impl Into<String>) -> PyErr {
    ArgumentError::new_err(message.into())
}

/// prism-image's errors: an argument that is not usable is an `ArgumentError`, a file
/// that cannot be opened or decoded an `ImageError`.
pub fn image(error: prism_image::ImageError) -> PyErr {
    match error {
        prism_image::ImageError::Invalid(message) => ArgumentError::new_err(message),
        other @ (prism_image::ImageError::Io { .. } | prism_image::ImageError::Format { .. }) => {
            ImageError::new_err(other.to_string())
        }
    }
}
