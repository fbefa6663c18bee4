//! The commands' outputs: their folder checked before any work (`check_parent`), and text and
//! byte outputs (JSON, CSV, charts, sensor sums) written as the
//! images are: into a temporary sibling, renamed over the destination (through a symbolic
//! link to its target), the temporary removed when the write fails or panics
//! (`prism_image::io::write_bytes_atomically`). One place, so that every output follows the
//! same rules (docs/reliability.md, "What is atomic").

use std::path::Path;

/// The folder of an output `path` must exist: checked before any work, so that a render
/// is not lost to a missing folder at the end.
pub fn check_parent(what: &str, path: &Path) -> Result<(), String> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if dir.is_dir() {
        Ok(())
    } else {
        Err(format!(
            "{what} {}: the directory {} does not exist",
            path.display(),
            dir.display()
        ))
    }
}

/// Writes `bytes` to `path` atomically; `what` names the output in the error.
pub fn write_atomic(path: &Path, bytes: &[u8], what: &str) -> Result<(), String> {
    prism_image::io::write_bytes_atomically(path, bytes)
        .map_err(|e| format!("cannot write the {what}: {e}"))
}
