//! Scene errors: the file, line:column, the JSON path of the offending value
//! (`shapes[3].material`) and what was expected.

use std::fmt;
use std::path::PathBuf;

pub use crate::json::Position;

/// One step of a JSON path: an object key or an array index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PathSegment {
    Key(String),
    Index(usize),
}

/// Where a value sits in the document, e.g. `shapes[3].material`; empty for the root.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct JsonPath(pub Vec<PathSegment>);

impl JsonPath {
    pub fn key(&self, key: &str) -> JsonPath {
        let mut p = self.clone();
        p.0.push(PathSegment::Key(key.to_string()));
        p
    }

    pub fn index(&self, index: usize) -> JsonPath {
        let mut p = self.clone();
        p.0.push(PathSegment::Index(index));
        p
    }

    pub fn is_root(&self) -> bool {
        self.0.is_empty()
    }
}

fn is_plain_key(key: &str) -> bool {
    !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
}

impl fmt::Display for JsonPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, segment) in self.0.iter().enumerate() {
            match segment {
                PathSegment::Key(k) if is_plain_key(k) => {
                    if i > 0 {
                        f.write_str(".")?;
                    }
                    f.write_str(k)?;
                }
                // Keys with spaces or dots are written as `materials["red paint"]`.
                PathSegment::Key(k) => write!(f, "[{k:?}]")?,
                PathSegment::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// A scene that could not be loaded. Display:
/// `scenes/room.json:12:7: shapes[3].material: unknown material `whte` (did you mean `white`?)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file (as given to `load_scene` / `parse_scene_str`).
    pub file: PathBuf,
    /// Where in the scene file; `None` when the file itself cannot be read.
    pub position: Option<Position>,
    /// The JSON path of the offending value; empty for syntax errors and the root.
    pub path: JsonPath,
    /// What was wrong and what was expected.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(p) = self.position {
            write!(f, ":{}:{}", p.line, p.column)?;
        }
        if !self.path.is_root() {
            write!(f, ": {}", self.path)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_print_like_javascript() {
        let p = JsonPath::default()
            .key("shapes")
            .index(3)
            .key("transform")
            .index(0);
        assert_eq!(p.to_string(), "shapes[3].transform[0]");
        let p = JsonPath::default().key("materials").key("red paint");
        assert_eq!(p.to_string(), "materials[\"red paint\"]");
    }
}
