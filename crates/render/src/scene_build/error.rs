//! The error of turning a scene description into render's runtime objects: the scene file,
//! the place in it (a JSON path such as `shapes[3]` or `camera`) and what went wrong
//! (house rule: every user input gets an error naming the file and the place).

use std::fmt;
use std::path::PathBuf;

/// A scene that parsed but cannot be rendered as described.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneBuildError {
    /// The scene file.
    pub file: PathBuf,
    /// JSON path of the offending entry, e.g. `shapes[3]` or `film.filter`; empty for the
    /// scene as a whole.
    pub place: String,
    /// What is wrong; for mesh files this includes the mesh file and line.
    pub message: String,
}

impl SceneBuildError {
    pub fn new(
        file: impl Into<PathBuf>,
        place: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.into(),
            place: place.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneBuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if !self.place.is_empty() {
            write!(f, ": {}", self.place)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneBuildError {}
