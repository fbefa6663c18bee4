//! An image with raw channels beside its pixels in one EXR part: exact data that is not
//! a picture (a render's f64 sums as two 32-bit halves, sample counts) stored as 32-bit
//! `UINT` channels, which OpenEXR keeps bit for bit, and read back by name with the
//! header's text attributes. What `prism render` writes into checkpoints and sample-range
//! parts (docs/rendering.md).

use std::collections::BTreeMap;
use std::path::Path;

use ::exr::meta::attribute::AttributeValue;
use ::exr::prelude::FlatSamples;

use super::exr::{
    chromaticities_of, image_channels, read_exr_channels, write_exr_channels, ExrWriteOptions,
};
use super::spectral_exr::write_exr_with_spectral_bands_and_raw;
use crate::error::{ImageError, Result};
use crate::image::Image;

/// Spectral bands to write beside the pixels: centre wavelengths (nm) and one row-major
/// plane per band (see `spectral_exr::write_exr_with_spectral_bands`).
pub type SpectralBands<'a> = (&'a [f64], &'a [Vec<f32>]);

/// Writes `image` (as `exr::write_exr`, or with `spectral` bands) plus `raw` 32-bit
/// unsigned channels (full names, one row-major value per pixel) in the same part,
/// through a temporary file renamed over `path`.
pub fn write_exr_with_raw(
    path: &Path,
    image: &Image,
    spectral: Option<SpectralBands>,
    raw: Vec<(String, Vec<u32>)>,
    options: &ExrWriteOptions,
) -> Result<()> {
    let n = image.width() * image.height();
    if let Some((name, plane)) = raw.iter().find(|(_, p)| p.len() != n) {
        return Err(ImageError::invalid(format!(
            "raw channel {name} has {} values; a {}×{} image needs {n}",
            plane.len(),
            image.width(),
            image.height()
        )));
    }
    let raw: Vec<(String, FlatSamples)> = raw
        .into_iter()
        .map(|(name, plane)| (name, FlatSamples::U32(plane)))
        .collect();
    match spectral {
        Some((wavelengths_nm, planes)) => {
            write_exr_with_spectral_bands_and_raw(path, image, wavelengths_nm, planes, raw, options)
        }
        None => {
            let (mut channels, attributes) = image_channels(path, image, options)?;
            channels.extend(raw);
            write_exr_channels(
                path,
                image.width(),
                image.height(),
                channels,
                Some(chromaticities_of(&image.color_space)),
                attributes,
                options,
            )
        }
    }
}

/// What [`read_raw_channels`] found: the size, every `UINT` channel by full name, every
/// other channel as f32 (half floats widened exactly), and the header's text attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct RawChannels {
    pub width: usize,
    pub height: usize,
    pub raw: BTreeMap<String, Vec<u32>>,
    pub floats: BTreeMap<String, Vec<f32>>,
    pub text: BTreeMap<String, String>,
}

/// Reads the `UINT` channels and text attributes of an EXR file.
pub fn read_raw_channels(path: &Path) -> Result<RawChannels> {
    let channels = read_exr_channels(path)?;
    let mut raw = BTreeMap::new();
    let mut floats = BTreeMap::new();
    for (name, samples) in channels.channels {
        match samples {
            FlatSamples::U32(values) => {
                raw.insert(name, values);
            }
            FlatSamples::F32(values) => {
                floats.insert(name, values);
            }
            FlatSamples::F16(values) => {
                floats.insert(name, values.iter().map(|h| h.to_f32()).collect());
            }
        }
    }
    let text = channels
        .attributes
        .into_iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k, t.to_string())),
            _ => None,
        })
        .collect();
    Ok(RawChannels {
        width: channels.width,
        height: channels.height,
        raw,
        floats,
        text,
    })
}

/// The text attributes of an EXR file's first part, read from the header alone (the
/// pixels are not decoded).
pub fn read_text_attributes(path: &Path) -> Result<BTreeMap<String, String>> {
    let meta = ::exr::meta::MetaData::read_from_file(path, false).map_err(|e| match e {
        ::exr::error::Error::Io(io) => ImageError::io(path, "read", io),
        other => ImageError::format(path, format!("not a readable OpenEXR file: {other}")),
    })?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| ImageError::format(path, "the file holds no image part"))?;
    Ok(header
        .own_attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::rgb_space::RgbColorSpace;

    #[test]
    fn raw_channels_and_text_round_trip_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("raw.exr");
        let mut image = Image::new(3, 2, vec![[0.5, 0.25, 1.0]; 6], RgbColorSpace::srgb()).unwrap();
        image.metadata.insert("prism:test".into(), "a value".into());
        // Bit patterns that are NaNs and denormals as floats stay as they are.
        let plane: Vec<u32> = vec![0x7fc0_0001, 1, u32::MAX, 0, 0xffff_0000, 42];
        write_exr_with_raw(
            &path,
            &image,
            None,
            vec![("sums.x.hi".into(), plane.clone())],
            &ExrWriteOptions::default(),
        )
        .unwrap();
        let read = read_raw_channels(&path).unwrap();
        assert_eq!((read.width, read.height), (3, 2));
        assert_eq!(read.raw["sums.x.hi"], plane);
        assert_eq!(read.floats["G"], vec![0.25; 6]);
        assert_eq!(read.text["prism:test"], "a value");
        assert_eq!(
            read_text_attributes(&path).unwrap()["prism:test"],
            "a value"
        );
        let bad = write_exr_with_raw(
            &path,
            &image,
            None,
            vec![("short".into(), vec![1])],
            &ExrWriteOptions::default(),
        );
        assert!(bad.is_err());
    }
}
