//! The Python package `prism` (docs/python.md): colorimetry, rendering, tone mapping,
//! metrics and image files on NumPy arrays, through the library functions the CLI calls,
//! so that results equal `prism color/render/tonemap/compare`'s.
//!
//! The native module is `prism._prism`; python/prism/__init__.py re-exports it.

mod arrays;
mod color;
mod compare;
mod errors;
mod image_io;
mod json;
mod render;
mod tonemap;

use pyo3::prelude::*;

#[pymodule]
fn _prism(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_function(wrap_pyfunction!(color::color, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_class::<render::Render>()?;
    m.add_function(wrap_pyfunction!(tonemap::tonemap, m)?)?;
    m.add_function(wrap_pyfunction!(tonemap::operators, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(image_io::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(image_io::write_image, m)?)?;
    m.add_class::<image_io::PyImage>()?;
    Ok(())
}
