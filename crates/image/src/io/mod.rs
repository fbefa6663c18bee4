//! Image files: OpenEXR (RGB + AOV layers, spectral layout), Radiance RGBE and PNG.
//! Every write goes to a temporary file in the destination's directory that is renamed
//! over the destination only once complete, so a failed write never leaves half a file.

mod dimensions;
pub mod exr;
mod exr_rgb;
mod output_path;
pub mod png;
pub mod quantise;
pub mod raw_exr;
pub mod rgbe;
pub mod spectral_exr;
pub mod strips;
mod zlib_strips;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use prism_spectrum::rgb_space::RgbColorSpace;

pub use dimensions::{read_dimensions, ImageDimensions};
pub use output_path::{same_file, write_target};

use crate::error::{ImageError, Result};
use crate::image::Image;

/// File formats, chosen from the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Hdr,
    Png,
}

impl ImageFormat {
    /// `.exr`, `.hdr`/`.pic`/`.rgbe`, `.png` (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("exr") => Ok(ImageFormat::Exr),
            Some("hdr") | Some("pic") | Some("rgbe") => Ok(ImageFormat::Hdr),
            Some("png") => Ok(ImageFormat::Png),
            _ => Err(ImageError::format(
                path,
                "unknown image extension: expected .exr, .hdr (Radiance RGBE) or .png",
            )),
        }
    }
}

/// Reads an EXR, Radiance HDR or PNG image, chosen by extension. A spectral EXR (Fichet et
/// al. 2021 layout) without RGB channels is reduced to XYZ with the CIE 1931 observer and
/// expressed in linear sRGB.
pub fn read_image(path: &Path) -> Result<Image> {
    match ImageFormat::from_path(path)? {
        ImageFormat::Exr => exr::read_exr(path),
        ImageFormat::Hdr => rgbe::read_hdr(path),
        ImageFormat::Png => png::read_png(path),
    }
}

/// Writes `image` in the format named by the extension of `path`, with default options
/// (EXR: float, ZIP; PNG: 16-bit).
pub fn write_image(path: &Path, image: &Image) -> Result<()> {
    match ImageFormat::from_path(path)? {
        ImageFormat::Exr => exr::write_exr(path, image, &exr::ExrWriteOptions::default()),
        ImageFormat::Hdr => rgbe::write_hdr(path, image),
        ImageFormat::Png => png::write_png(path, image, png::PngBitDepth::Sixteen),
    }
}

/// The temporary sibling a write goes to before it is renamed over `path` (a process that
/// must remove it from a signal handler computes it in advance).
pub fn temp_sibling(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Runs `write` on a temporary path beside `path`, then renames it to `path`; on failure
/// the temporary file is removed and the destination is left as it was.
/// An output that is a symbolic link is written through to its target ([`write_target`]).
pub(crate) fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let target = write_target(path);
    let path = target.as_path();
    let tmp = TempFile(temp_sibling(path));
    let result = write(&tmp.0).and_then(|()| {
        std::fs::rename(&tmp.0, path)
            .map_err(|e| ImageError::io(path, "rename the finished file", e))
    });
    // The guard removes the temporary file on every way out — an error, or a panic
    // unwinding through `write`; after the rename it is gone and the removal fails quietly.
    drop(tmp);
    result
}

/// Removes its path when dropped.
struct TempFile(PathBuf);

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// [`write_atomically`] through a buffered writer; errors name `path`, not the temp file.
pub fn write_stream_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<()> {
    write_atomically(path, |tmp| {
        let file = File::create(tmp).map_err(|e| ImageError::io(path, "create", e))?;
        let mut out = BufWriter::new(file);
        // On disk before the rename: a crash after it must not leave an empty file.
        write(&mut out)
            .and_then(|()| out.into_inner().map_err(|e| e.into_error()))
            .and_then(|file| file.sync_all())
            .map_err(|e| ImageError::io(path, "write", e))
    })
}

/// Writes `bytes` to `path` atomically (a temporary sibling, then a rename): readers see
/// the old file or the whole new one, never a part.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_stream_atomically(path, |out| out.write_all(bytes))
}

/// The built-in colour space whose primaries and white match `primaries_xy`/`white_xy`
/// within 5e-4 (the precision files usually print), else a linear space built from them.
pub fn color_space_from_chromaticities(
    primaries_xy: [[f64; 2]; 3],
    white_xy: [f64; 2],
) -> RgbColorSpace {
    const TOLERANCE: f64 = 5e-4;
    let close =
        |a: &[f64; 2], b: &[f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) < TOLERANCE;
    RgbColorSpace::all()
        .into_iter()
        .find(|s| {
            close(&s.white_xy, &white_xy)
                && s.primaries_xy
                    .iter()
                    .zip(primaries_xy.iter())
                    .all(|(a, b)| close(a, b))
        })
        .unwrap_or_else(|| {
            RgbColorSpace::from_primaries(
                "file chromaticities",
                primaries_xy,
                white_xy,
                "D65",
                prism_spectrum::rgb_space::TransferFunction::Linear,
            )
        })
}

/// `pixels` (linear RGB in `from`) in `to`: borrowed when the two spaces have the same
/// colorimetry, else a converted copy ([`convert_pixels`]).
pub fn pixels_in<'a>(
    pixels: &'a [[f32; 3]],
    from: &RgbColorSpace,
    to: &RgbColorSpace,
) -> std::borrow::Cow<'a, [[f32; 3]]> {
    if crate::rgb_matrix::same_colorimetry(from, to) {
        pixels.into()
    } else {
        let mut copy = pixels.to_vec();
        convert_pixels(&mut copy, from, to);
        copy.into()
    }
}

/// Converts linear RGB pixels from one colour space to another through XYZ (no chromatic
/// adaptation: white balance is a separate, explicit step).
pub fn convert_pixels(pixels: &mut [[f32; 3]], from: &RgbColorSpace, to: &RgbColorSpace) {
    if from.primaries_xy == to.primaries_xy && from.white_xy == to.white_xy {
        return;
    }
    let m = crate::rgb_matrix::rgb_to_rgb_matrix(
        from,
        to,
        prism_spectrum::adaptation::AdaptationMethod::None,
    );
    crate::rgb_matrix::apply_rgb_matrix(pixels, m);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_or_panicking_write_leaves_no_temporary_file_and_the_old_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("image.exr");
        std::fs::write(&path, b"previous").unwrap();
        let tmp = temp_sibling(&path);
        let failed = write_atomically(&path, |t| {
            std::fs::write(t, b"half").unwrap();
            Err(ImageError::invalid("stopped"))
        });
        assert!(failed.is_err());
        assert!(!tmp.exists());
        let panicked = std::panic::catch_unwind(|| {
            let _ = write_atomically(&path, |t| {
                std::fs::write(t, b"half").unwrap();
                panic!("a writer panics");
            });
        });
        assert!(panicked.is_err());
        assert!(!tmp.exists(), "the panic left {}", tmp.display());
        assert_eq!(std::fs::read(&path).unwrap(), b"previous");
        write_atomically(&path, |t| {
            std::fs::write(t, b"new").map_err(|e| ImageError::io(t, "write", e))
        })
        .unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert!(!tmp.exists());
    }
}
