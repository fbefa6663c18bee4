//! prism-import: reads Mitsuba 3 XML and pbrt-v4 scene files and writes Prism's JSON scene
//! format (docs/scene-format.md) as a `serde_json::Value`, which then goes through Prism's own
//! scene reader, so every imported scene gets the same validation as a hand-written one.
//! What maps to what, what differs and what is refused: docs/import.md.
//!
//! Everything the importer cannot express in Prism is recorded in an [`Unsupported`] report
//! (one entry per kind with its first file:line); `strict` turns the report into an error.

pub mod error;
pub mod mitsuba;
pub mod obj;
pub mod output;
pub mod pbrt;
pub mod unsupported;

use std::path::{Path, PathBuf};

pub use error::{ImportError, Location};
pub use output::{Imported, SideFile};
pub use unsupported::Unsupported;

/// The scene languages the importer reads, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceFormat {
    /// Mitsuba 3 XML (`.xml`).
    MitsubaXml,
    /// pbrt-v4 scene description (`.pbrt`).
    Pbrt,
}

impl SourceFormat {
    /// The format of `path` by its extension; `None` for anything else (e.g. Prism's JSON).
    pub fn of_path(path: &Path) -> Option<SourceFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "xml" => Some(SourceFormat::MitsubaXml),
            "pbrt" => Some(SourceFormat::Pbrt),
            _ => None,
        }
    }
}

/// How to import.
#[derive(Debug, Clone, Default)]
pub struct ImportOptions {
    /// Mitsuba `$name` parameters given on the command line (`-D name=value`); they override
    /// the scene's `<default>` values.
    pub defines: Vec<(String, String)>,
    /// The folder the JSON will be read from: asset paths are written relative to it when
    /// the asset lies below it, absolute otherwise.
    pub output_dir: PathBuf,
    /// The folder (relative to `output_dir`) for files the importer has to write, such as
    /// inline pbrt triangle meshes as OBJ files.
    pub side_dir: String,
}

/// Imports `path` (format by extension). Positioned errors for malformed input; the
/// report of what was not imported is in the result.
pub fn import_file(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    match SourceFormat::of_path(path) {
        Some(SourceFormat::MitsubaXml) => mitsuba::import(path, options),
        Some(SourceFormat::Pbrt) => pbrt::import(path, options),
        None => Err(ImportError::file(
            path,
            "expected a Mitsuba 3 scene (.xml) or a pbrt-v4 scene (.pbrt)",
        )),
    }
}

/// Scene text imported from a file, for the importers' unit tests.
#[cfg(test)]
pub(crate) mod test_support {
    use std::path::Path;

    use crate::{import_file, ImportOptions, Imported};

    /// Imports `text` as the scene file `file_name` (its extension picks the importer) in a
    /// fresh folder, removed afterwards.
    pub fn import_text(file_name: &str, text: &str) -> Imported {
        let dir = tempfile::tempdir().unwrap();
        import_text_in(dir.path(), file_name, text)
    }

    /// Imports `text` as the scene file `dir/file_name`, next to whatever files it names.
    pub fn import_text_in(dir: &Path, file_name: &str, text: &str) -> Imported {
        let path = dir.join(file_name);
        std::fs::write(&path, text).unwrap();
        let options = ImportOptions {
            output_dir: dir.to_path_buf(),
            side_dir: "a".into(),
            ..Default::default()
        };
        import_file(&path, &options).unwrap()
    }
}
