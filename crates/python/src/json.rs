//! JSON values (the objects the CLI prints with `--json`) as Python objects, through the
//! standard library's `json` module so that keys, order, `null` and numbers are exactly
//! the CLI's (serde_json writes the shortest text that reads back to the same f64).

use pyo3::prelude::*;

pub fn to_python<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = value.to_string();
    py.import("json")?.call_method1("loads", (text,))
}

/// A serialisable report as a Python object.
pub fn serialize_to_python<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(value)
        .map_err(|e| crate::errors::PrismError::new_err(format!("cannot convert a report: {e}")))?;
    to_python(py, &value)
}
