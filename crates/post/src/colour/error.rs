//! Errors for user input (CLI values) and for images a method cannot work on. No function
//! of this crate panics on user input; they return these instead.

use std::fmt;

/// What went wrong, with a message that says what was expected.
#[derive(Debug, Clone, PartialEq)]
pub enum PostColourError {
    /// A value for a CLI option (`--wb`, `--gamut`, `--target`) that does not parse.
    InvalidValue {
        /// The option, e.g. `--wb`.
        option: &'static str,
        /// What the user gave.
        given: String,
        /// Why it was rejected, the valid forms and, when one is close, a suggestion.
        message: String,
    },
    /// The scene white could not be estimated from the image (empty, no finite pixel, or
    /// an estimate without positive X, Y and Z).
    NoSceneWhite {
        /// The white-balance method, in its CLI form.
        method: String,
        /// What was found instead.
        reason: String,
    },
}

impl fmt::Display for PostColourError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidValue {
                option,
                given,
                message,
            } => write!(f, "{option} `{given}`: {message}"),
            Self::NoSceneWhite { method, reason } => write!(
                f,
                "white balance `{method}`: cannot estimate the scene white: {reason}"
            ),
        }
    }
}

impl std::error::Error for PostColourError {}
