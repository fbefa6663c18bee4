//! An image file's size read from its header only, so that a command can estimate what
//! decoding it will allocate before it does (`prism compare`, `prism tonemap`).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use super::ImageFormat;
use crate::error::{ImageError, Result};

/// Width, height and stored channels (every layer's) of an image file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageDimensions {
    pub width: usize,
    pub height: usize,
    /// Channels per pixel as stored (an EXR's layers included; 3 for RGBE, the PNG's).
    pub channels: usize,
}

impl ImageDimensions {
    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

/// Reads the header of an EXR, Radiance HDR or PNG file (chosen by extension).
pub fn read_dimensions(path: &Path) -> Result<ImageDimensions> {
    let format = ImageFormat::from_path(path)?;
    let file = File::open(path).map_err(|e| ImageError::io(path, "open", e))?;
    let mut input = BufReader::new(file);
    match format {
        ImageFormat::Exr => {
            let meta = ::exr::meta::MetaData::read_from_buffered(input, false)
                .map_err(|e| ImageError::format(path, format!("not a readable EXR file: {e}")))?;
            let mut out = ImageDimensions {
                width: 0,
                height: 0,
                channels: 0,
            };
            for header in &meta.headers {
                out.width = out.width.max(header.layer_size.0);
                out.height = out.height.max(header.layer_size.1);
                out.channels += header.channels.list.len();
            }
            Ok(out)
        }
        ImageFormat::Hdr => {
            let header = super::rgbe::read_header(path, &mut input)?;
            Ok(ImageDimensions {
                width: header.width,
                height: header.height,
                channels: 3,
            })
        }
        ImageFormat::Png => {
            let reader = ::png::Decoder::new(input)
                .read_info()
                .map_err(|e| ImageError::format(path, format!("not a readable PNG file: {e}")))?;
            let info = reader.info();
            Ok(ImageDimensions {
                width: info.width as usize,
                height: info.height as usize,
                channels: info.color_type.samples(),
            })
        }
    }
}
