//! The error of a data file the renderer reads itself (MERL tables, `.vol` grids): what is
//! wrong, and the file when there is one (parsing from bytes has none).

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong reading or writing a data file.
#[derive(Debug, Clone, PartialEq)]
pub struct FileError {
    /// The file, when there is one.
    pub path: Option<PathBuf>,
    pub message: String,
}

impl FileError {
    pub(crate) fn new(message: impl Into<String>) -> Self {
        Self {
            path: None,
            message: message.into(),
        }
    }

    /// The same error, naming `path`.
    pub(crate) fn at(mut self, path: &Path) -> Self {
        self.path = Some(path.to_path_buf());
        self
    }
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(p) => write!(f, "{}: {}", p.display(), self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for FileError {}
