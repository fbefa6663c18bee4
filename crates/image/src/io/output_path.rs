//! Where a write to an output path lands. An output that is a symbolic link is written
//! through to the file it points at (the link stays a link, as `cp` and shell
//! redirection do), instead of being replaced by a regular file when the finished
//! temporary file is renamed over it.

use std::path::{Path, PathBuf};

/// `path`, or the file its chain of symbolic links ends at (which need not exist yet).
pub fn write_target(path: &Path) -> PathBuf {
    let mut current = path.to_path_buf();
    // A bounded walk: a cycle of links ends here and the rename reports the error.
    for _ in 0..40 {
        let is_link = std::fs::symlink_metadata(&current).is_ok_and(|m| m.file_type().is_symlink());
        if !is_link {
            return current;
        }
        match std::fs::read_link(&current) {
            // A relative target is relative to the link's folder.
            Ok(target) => {
                current = match current.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            Err(_) => return current,
        }
    }
    current
}

/// Whether `a` and `b` name the same existing file (through links and `..`).
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn links_are_followed_to_their_target() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let target = dir.join("sub/real.png");
        std::os::unix::fs::symlink("sub/real.png", dir.join("link.png")).unwrap();
        std::os::unix::fs::symlink(dir.join("link.png"), dir.join("link2.png")).unwrap();
        assert_eq!(write_target(&dir.join("link2.png")), target);
        assert_eq!(write_target(&target), target);
        std::fs::write(&target, "x").unwrap();
        assert!(same_file(&dir.join("link2.png"), &target));
        assert!(!same_file(&dir.join("none.png"), &target));
    }
}
