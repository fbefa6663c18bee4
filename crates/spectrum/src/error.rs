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
    /// 1-based column (in characters, a tab counting one) of the offending field, for
    /// formats whose fields are positional (BFC-450 matrices).
    pub column: Option<usize>,
    /// What was wrong and what was expected.
    pub message: String,
}

impl SpectrumFileError {
    pub fn new(path: impl Into<PathBuf>, line: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            line,
            column: None,
            message: message.into(),
        }
    }

    /// An error at `line`:`column` (both 1-based).
    pub fn at(
        path: impl Into<PathBuf>,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        Self {
            path: path.into(),
            line: Some(line),
            column: Some(column),
            message: message.into(),
        }
    }
}

impl fmt::Display for SpectrumFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, self.column) {
            (Some(line), Some(column)) => write!(
                f,
                "{}:{}:{}: {}",
                self.path.display(),
                line,
                column,
                self.message
            ),
            (Some(line), None) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            (None, _) => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for SpectrumFileError {}
