//! The reference image of `prism converge`: a file the user gives (checked before anything
//! renders: it must exist, be an image and have the render's size), or one rendered at a
//! stated spp and cached in a cache directory (`--cache-dir`, default the platform's) under a
//! name that carries a hash of everything it depends on, so that editing the scene file or
//! any file it names invalidates it. A scene's folder may be read-only or shared, so nothing
//! is written there.

use std::io::Read;
use std::path::{Path, PathBuf};

use glam::UVec2;
use prism_image::io::read_image;
use prism_image::Image;
use prism_render::stable_hash::Fnv1a64;

use crate::cache_dir::fnv1a64;

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
    /// The files the scene names (`SceneDescription::asset_files`): an edited texture or
    /// environment map changes the image as much as an edited scene file.
    pub asset_files: &'a [PathBuf],
}

impl ReferenceKey<'_> {
    /// `<dir>/<stem>.reference-<W>x<H>-<spp>spp-<hash>.exr`; the hash covers the scene
    /// file's absolute path (scenes of one name in different folders differ) and bytes, the
    /// bytes of every asset it names, the size, spp, seed, integrator and Prism's version.
    pub fn cache_path(&self, dir: &Path) -> PathBuf {
        let absolute = std::fs::canonicalize(self.scene_file)
            .unwrap_or_else(|_| self.scene_file.to_path_buf());
        let hash = fnv1a64(&[
            absolute.to_string_lossy().as_bytes(),
            self.scene_bytes,
            &assets_hash(self.asset_files).to_le_bytes(),
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

/// The stable hash of the files' contents, in order. A file that cannot be read (it was
/// read a moment ago by the scene's build) hashes as its error, so it never matches a cached
/// reference.
fn assets_hash(files: &[PathBuf]) -> u64 {
    let mut hash = Fnv1a64::new();
    let mut buffer = vec![0u8; 1 << 16];
    for file in files {
        hash.write(file.to_string_lossy().as_bytes());
        hash.write(&[0xff]);
        let read = std::fs::File::open(file).and_then(|mut f| loop {
            let n = f.read(&mut buffer)?;
            if n == 0 {
                break Ok(());
            }
            hash.write(&buffer[..n]);
        });
        if let Err(e) = read {
            hash.write(e.to_string().as_bytes());
        }
        hash.write(&[0xff]);
    }
    hash.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_name_changes_with_the_scene_file_and_the_settings() {
        let key = |bytes: &'static [u8], spp| ReferenceKey {
            scene_file: Path::new("scenes/box.json"),
            scene_bytes: bytes,
            resolution: UVec2::new(64, 48),
            spp,
            seed: 0,
            integrator: "path".into(),
            asset_files: &[],
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
    fn the_cache_name_changes_when_an_asset_is_edited() {
        let dir = tempfile::tempdir().unwrap();
        let sky = dir.path().join("sky.hdr");
        let assets = [sky.clone()];
        let key = ReferenceKey {
            scene_file: Path::new("scenes/box.json"),
            scene_bytes: b"{}",
            resolution: UVec2::new(64, 48),
            spp: 1024,
            seed: 0,
            integrator: "path".into(),
            asset_files: &assets,
        };
        std::fs::write(&sky, "first sky").unwrap();
        let first = key.cache_path(Path::new("cache"));
        assert_eq!(first, key.cache_path(Path::new("cache")), "stable");
        std::fs::write(&sky, "second sky").unwrap();
        assert_ne!(first, key.cache_path(Path::new("cache")));
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
