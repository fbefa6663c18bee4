//! The one error type of the constructors in this crate: which parameter, what value, and
//! the range it must lie in (house rule: no panics on user input).

use std::fmt;

/// A constructor parameter outside its valid range.
#[derive(Clone, Debug, PartialEq)]
pub struct InvalidParameter {
    /// What was being built, e.g. "thin-lens camera".
    pub context: &'static str,
    /// The parameter's name as in the API, with its unit, e.g. `focus_distance_m`.
    pub parameter: &'static str,
    /// The offending value, formatted.
    pub value: String,
    /// The valid range or rule in words, e.g. "(0, π) rad".
    pub valid: String,
}

impl InvalidParameter {
    pub fn new(
        context: &'static str,
        parameter: &'static str,
        value: impl fmt::Display,
        valid: impl Into<String>,
    ) -> Self {
        Self {
            context,
            parameter,
            value: value.to_string(),
            valid: valid.into(),
        }
    }
}

impl fmt::Display for InvalidParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: `{}` = {} is invalid; valid: {}",
            self.context, self.parameter, self.value, self.valid
        )
    }
}

impl std::error::Error for InvalidParameter {}

/// `Ok(value)` when `value` is finite and `> 0`, else an error naming `parameter`.
pub(crate) fn positive(
    context: &'static str,
    parameter: &'static str,
    value: f32,
) -> Result<f32, InvalidParameter> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(InvalidParameter::new(
            context,
            parameter,
            value,
            "a finite number > 0",
        ))
    }
}
