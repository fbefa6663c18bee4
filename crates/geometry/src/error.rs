//! Errors for user-supplied geometry (mesh files): they name the file, the line where the
//! format has lines, and what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

/// A mesh file that could not be used.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshLoadError {
    /// The file the user named.
    pub path: PathBuf,
    /// 1-based line number, when the problem is on one line of a text file.
    pub line: Option<usize>,
    /// What was wrong and what was expected.
    pub message: String,
}

impl MeshLoadError {
    pub fn new(path: impl AsRef<Path>, line: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            path: path.as_ref().to_path_buf(),
            line,
            message: message.into(),
        }
    }
}

impl fmt::Display for MeshLoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for MeshLoadError {}
