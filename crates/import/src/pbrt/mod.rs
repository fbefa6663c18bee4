//! pbrt-v4 scenes → Prism JSON.
use std::path::Path;

use crate::error::ImportError;
use crate::output::Imported;
use crate::ImportOptions;

pub fn import(path: &Path, _options: &ImportOptions) -> Result<Imported, ImportError> {
    Err(ImportError::file(path, "pbrt import: not yet"))
}
