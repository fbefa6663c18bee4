//! Errors for user-supplied spectral data: they name the file, the line and what was expected.

use std::fmt;
use std::path::PathBuf;

/// A spectrum file (or named spectrum) that could not be used.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumFileError {
    /// The file (or the name the user gave, for unknown names).
    pub path: PathBuf,
    /// 1-based line number, when the problem is on one line.
    pub line: Option<usize>,
    /// What was wrong and what was expected.
    pub message: String,
}

impl SpectrumFileError {
    pub fn new(path: impl Into<PathBuf>, line: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            line,
            message: message.into(),
        }
    }
}

impl fmt::Display for SpectrumFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for SpectrumFileError {}
