//! The cache directory that derived data is kept in (`--cache-dir`): references of
//! `prism converge`, tile pyramids of `prism tile-brdf`. Files are named by a stable hash
//! of everything they depend on, so a changed input is a new name, never a stale file.

use std::path::{Path, PathBuf};

use prism_render::stable_hash::Fnv1a64;

/// The stable hash (`prism_render::stable_hash`) of `parts`, each followed by a 0xff
/// byte so that ("ab", "c") and ("a", "bc") differ.
pub fn fnv1a64(parts: &[&[u8]]) -> u64 {
    let mut h = Fnv1a64::new();
    for part in parts {
        h.write(part);
        h.write(&[0xff]);
    }
    h.finish()
}

/// The platform cache directory of Prism: `$XDG_CACHE_HOME/prism`, else
/// `$HOME/.cache/prism` (XDG Base Directory specification), else the system's temporary
/// directory's `prism-cache`.
pub fn default_cache_dir() -> PathBuf {
    let non_empty = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(xdg) = non_empty("XDG_CACHE_HOME") {
        return xdg.join("prism");
    }
    if let Some(home) = non_empty("HOME") {
        return home.join(".cache").join("prism");
    }
    std::env::temp_dir().join("prism-cache")
}

/// The cache directory (`given` or the default), created if missing and checked writable
/// before any work starts; `what` names the cache and `instead` what the user may give in
/// place of a writable directory (" or a --reference", or "").
pub fn prepare_cache_dir(
    given: Option<&Path>,
    what: &str,
    instead: &str,
) -> Result<PathBuf, String> {
    let dir = given.map_or_else(default_cache_dir, Path::to_path_buf);
    let what = match given {
        Some(_) => "--cache-dir".to_string(),
        None => format!("{what} (--cache-dir)"),
    };
    std::fs::create_dir_all(&dir).map_err(|e| {
        format!(
            "{what} {}: cannot create the directory ({e}); give a writable --cache-dir \
             DIR{instead}",
            dir.display()
        )
    })?;
    let probe = dir.join(format!(".prism-write-test.{}", std::process::id()));
    match std::fs::write(&probe, b"") {
        Ok(()) => {
            let _ = std::fs::remove_file(&probe);
            Ok(dir)
        }
        Err(e) => Err(format!(
            "{what} {}: cannot write there ({e}); give a writable --cache-dir DIR{instead}",
            dir.display()
        )),
    }
}

/// A cache directory for work that may also be done without one (the predictor's BSDF
/// tables): `given` must be usable (an error otherwise); without it `prepared` (a
/// directory the command prepared already) or the default, and `None` when the default is
/// not writable.
pub fn optional_cache_dir(
    given: Option<&Path>,
    prepared: Option<&Path>,
) -> Result<Option<PathBuf>, String> {
    match (given, prepared) {
        (Some(dir), _) => prepare_cache_dir(Some(dir), "", "").map(Some),
        (None, Some(dir)) => Ok(Some(dir.to_path_buf())),
        (None, None) => Ok(prepare_cache_dir(None, "the BSDF table cache", "").ok()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_the_published_test_vectors() {
        // FNV-1a 64 of "a" is 0xaf63dc4c8601ec8c (Fowler, Noll, Vo test suite); our part
        // separator adds one more round, so check the core on a single byte by hand.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        h ^= u64::from(b'a');
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
        assert_eq!(h, 0xaf63_dc4c_8601_ec8c);
        assert_ne!(fnv1a64(&[b"ab", b"c"]), fnv1a64(&[b"a", b"bc"]));
    }

    #[test]
    fn an_unwritable_cache_is_refused_before_rendering() {
        let dir = tempfile::tempdir().unwrap();
        let made = prepare_cache_dir(
            Some(&dir.path().join("a/b")),
            "the reference cache",
            " or a --reference",
        )
        .unwrap();
        assert!(made.is_dir());
        let file = dir.path().join("file");
        std::fs::write(&file, "").unwrap();
        let e = prepare_cache_dir(
            Some(&file.join("sub")),
            "the reference cache",
            " or a --reference",
        )
        .unwrap_err();
        assert!(
            e.contains("--cache-dir") && e.contains("cannot create"),
            "{e}"
        );
    }
}
