//! The reference image of `prism converge`: a file the user gives (checked before anything
//! renders: it must exist, be an image and have the render's size), or one rendered at a
//! stated spp and cached in a cache directory (`--cache-dir`, default the platform's) under a
//! name that carries a hash of everything it depends on, so that editing the scene file
//! invalidates it. A scene's folder may be read-only or shared, so nothing is written there.

use std::path::{Path, PathBuf};

use glam::UVec2;
use prism_image::io::read_image;
use prism_image::Image;

/// Reads the reference at `path` and checks that it is `resolution` pixels.
pub fn load_reference(path: &Path, resolution: UVec2) -> Result<Image, String> {
    match std::fs::metadata(path) {
        Err(e) => {
            return Err(format!(
                "reference {}: cannot open it ({e}); give an EXR, HDR or PNG image of the \
                 scene, or leave --reference out to render one",
                path.display()
            ))
        }
        Ok(m) if !m.is_file() => {
            return Err(format!(
                "reference {}: not a file (expected an EXR, HDR or PNG image)",
                path.display()
            ))
        }
        Ok(_) => {}
    }
    let image = read_image(path).map_err(|e| {
        format!(
            "reference {}: not a readable image (expected EXR, HDR or PNG): {e}",
            path.display()
        )
    })?;
    let size = UVec2::new(image.width() as u32, image.height() as u32);
    if size != resolution {
        return Err(format!(
            "reference {}: it is {}×{} px but the render is {}×{} px (the scene's \
             film.resolution, or --resolution); render the reference at the same size",
            path.display(),
            size.x,
            size.y,
            resolution.x,
            resolution.y
        ));
    }
    Ok(image)
}

/// 64-bit FNV-1a (Fowler–Noll–Vo): a stable hash for cache names (std's `DefaultHasher`
/// may change between Rust releases).
pub fn fnv1a64(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in *part {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        // Separate the parts so that ("ab", "c") and ("a", "bc") differ.
        h ^= 0xff;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
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
/// before anything renders.
pub fn prepare_cache_dir(given: Option<&Path>) -> Result<PathBuf, String> {
    let dir = given.map_or_else(default_cache_dir, Path::to_path_buf);
    let what = match given {
        Some(_) => "--cache-dir",
        None => "the reference cache (--cache-dir)",
    };
    std::fs::create_dir_all(&dir).map_err(|e| {
        format!(
            "{what} {}: cannot create the directory ({e}); give a writable --cache-dir DIR              or a --reference",
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
            "{what} {}: cannot write there ({e}); give a writable --cache-dir DIR or a              --reference",
            dir.display()
        )),
    }
}

/// What a cached reference depends on.
pub struct ReferenceKey<'a> {
    pub scene_file: &'a Path,
    /// The scene file's bytes.
    pub scene_bytes: &'a [u8],
    pub resolution: UVec2,
    pub spp: u32,
    pub seed: u64,
    /// The integrator's description (e.g. `path max_depth 7 …`).
    pub integrator: String,
}

impl ReferenceKey<'_> {
    /// `<dir>/<stem>.reference-<W>x<H>-<spp>spp-<hash>.exr`; the hash covers the scene
    /// file's absolute path (scenes of one name in different folders differ) and bytes, the
    /// size, spp, seed, integrator and Prism's version.
    pub fn cache_path(&self, dir: &Path) -> PathBuf {
        let absolute = std::fs::canonicalize(self.scene_file)
            .unwrap_or_else(|_| self.scene_file.to_path_buf());
        let hash = fnv1a64(&[
            absolute.to_string_lossy().as_bytes(),
            self.scene_bytes,
            format!("{}x{}", self.resolution.x, self.resolution.y).as_bytes(),
            &self.spp.to_le_bytes(),
            &self.seed.to_le_bytes(),
            self.integrator.as_bytes(),
            env!("CARGO_PKG_VERSION").as_bytes(),
        ]);
        let stem = self
            .scene_file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        let name = format!(
            "{stem}.reference-{}x{}-{}spp-{hash:016x}.exr",
            self.resolution.x, self.resolution.y, self.spp
        );
        dir.join(name)
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
    fn the_cache_name_changes_with_the_scene_file_and_the_settings() {
        let key = |bytes: &'static [u8], spp| ReferenceKey {
            scene_file: Path::new("scenes/box.json"),
            scene_bytes: bytes,
            resolution: UVec2::new(64, 48),
            spp,
            seed: 0,
            integrator: "path".into(),
        };
        let a = key(b"{}", 1024).cache_path(Path::new("cache"));
        assert!(a.starts_with("cache"));
        let name = a.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with("box.reference-64x48-1024spp-"), "{name}");
        assert!(name.ends_with(".exr"));
        assert_ne!(a, key(b"{ }", 1024).cache_path(Path::new("cache")));
        assert_ne!(a, key(b"{}", 2048).cache_path(Path::new("cache")));
        let elsewhere = ReferenceKey {
            scene_file: Path::new("other/box.json"),
            ..key(b"{}", 1024)
        };
        assert_ne!(
            a,
            elsewhere.cache_path(Path::new("cache")),
            "the folder counts"
        );
    }

    #[test]
    fn an_unwritable_cache_is_refused_before_rendering() {
        let dir = tempfile::tempdir().unwrap();
        let made = prepare_cache_dir(Some(&dir.path().join("a/b"))).unwrap();
        assert!(made.is_dir());
        let file = dir.path().join("file");
        std::fs::write(&file, "").unwrap();
        let e = prepare_cache_dir(Some(&file.join("sub"))).unwrap_err();
        assert!(
            e.contains("--cache-dir") && e.contains("cannot create"),
            "{e}"
        );
    }

    #[test]
    fn bad_references_are_named_with_what_was_expected() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("none.exr");
        let e = load_reference(&missing, UVec2::new(4, 4)).unwrap_err();
        assert!(e.contains("none.exr") && e.contains("cannot open"), "{e}");
        let text = dir.path().join("notes.exr");
        std::fs::write(&text, "not an image").unwrap();
        let e = load_reference(&text, UVec2::new(4, 4)).unwrap_err();
        assert!(e.contains("not a readable image"), "{e}");
        let e = load_reference(dir.path(), UVec2::new(4, 4)).unwrap_err();
        assert!(e.contains("not a file"), "{e}");
    }
}
