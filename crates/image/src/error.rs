//! The one error type of prism-image, also returned by prism-post's tone operators and
//! metrics: every failure names the file (when there is one) and what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

/// Errors from image I/O, tone operators and metrics.
#[derive(Debug)]
pub enum ImageError {
    /// The operating system refused to open, read, write or rename a file.
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    /// A file was opened but its content is not what was expected.
    Format { path: PathBuf, message: String },
    /// An argument (operator parameter, image size, option) is not usable.
    Invalid(String),
}

impl ImageError {
    pub fn format(path: &Path, message: impl Into<String>) -> Self {
        ImageError::Format {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    pub fn io(path: &Path, action: &'static str, source: std::io::Error) -> Self {
        ImageError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }

    pub fn invalid(message: impl Into<String>) -> Self {
        ImageError::Invalid(message.into())
    }
}

impl fmt::Display for ImageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImageError::Io {
                path,
                action,
                source,
            } => write!(f, "{}: cannot {action}: {source}", path.display()),
            ImageError::Format { path, message } => write!(f, "{}: {message}", path.display()),
            ImageError::Invalid(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for ImageError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ImageError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

pub type Result<T, E = ImageError> = std::result::Result<T, E>;
