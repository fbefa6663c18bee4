//! The image that rendering writes and post-processing works on: linear RGB in a named
//! colour space, optional absolute scale (cd/m² per unit), named extra layers (AOVs) and
//! free-form metadata.
//!
//! Pixels are stored interleaved (`[f32; 3]` per pixel, row-major, top row first): every
//! per-pixel operation reads one contiguous stream, which rayon splits by rows, so 4K
//! operations run at memory bandwidth. Extra layers keep their own interleaved channels.

use std::collections::BTreeMap;

use prism_spectrum::rgb_space::RgbColorSpace;

use crate::error::{ImageError, Result};

/// A named extra layer (AOV) such as `depth` (channel `Z`) or `normal` (`X`, `Y`, `Z`);
/// samples are interleaved by pixel, `channels.len()` values per pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct AovLayer {
    pub name: String,
    pub channels: Vec<String>,
    pub samples: Vec<f32>,
}

/// Linear RGB image with metadata.
#[derive(Debug, Clone)]
pub struct Image {
    width: usize,
    height: usize,
    pixels: Vec<[f32; 3]>,
    layers: Vec<AovLayer>,
    /// The RGB primaries and white the pixel values are expressed in.
    pub color_space: RgbColorSpace,
    /// Absolute scale: luminance in cd/m² of a pixel whose relative luminance Y is 1
    /// (`prism:cd_m2_per_unit` in our EXR header). `None` when the image is relative.
    pub cd_m2_per_unit: Option<f64>,
    /// Free-form string metadata (EXR text attributes, Radiance header lines, …).
    pub metadata: BTreeMap<String, String>,
}

impl Image {
    /// An image from interleaved pixels; `pixels.len()` must be `width * height`.
    pub fn new(
        width: usize,
        height: usize,
        pixels: Vec<[f32; 3]>,
        color_space: RgbColorSpace,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(ImageError::invalid(format!(
                "image size {width}×{height}: width and height must be at least 1"
            )));
        }
        if pixels.len() != width * height {
            return Err(ImageError::invalid(format!(
                "image of {width}×{height} needs {} pixels, got {}",
                width * height,
                pixels.len()
            )));
        }
        Ok(Self {
            width,
            height,
            pixels,
            layers: Vec::new(),
            color_space,
            cd_m2_per_unit: None,
            metadata: BTreeMap::new(),
        })
    }

    /// An image with every pixel set to `rgb`.
    pub fn filled(
        width: usize,
        height: usize,
        rgb: [f32; 3],
        color_space: RgbColorSpace,
    ) -> Result<Self> {
        Self::new(width, height, vec![rgb; width * height], color_space)
    }

    /// Same size, colour space, scale and metadata as `self`, new pixels, no extra layers.
    pub fn with_pixels(&self, pixels: Vec<[f32; 3]>) -> Result<Self> {
        let mut out = Self::new(self.width, self.height, pixels, self.color_space.clone())?;
        out.cd_m2_per_unit = self.cd_m2_per_unit;
        out.metadata = self.metadata.clone();
        Ok(out)
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }

    pub fn pixels_mut(&mut self) -> &mut [[f32; 3]] {
        &mut self.pixels
    }

    /// Moves the pixels out, leaving the image without any (its size, colour space and
    /// metadata stay): for a consumer that maps them in place and makes the result with
    /// [`Image::with_pixels`]. The emptied image is only good for its metadata.
    pub fn take_pixels(&mut self) -> Vec<[f32; 3]> {
        std::mem::take(&mut self.pixels)
    }

    pub fn into_pixels(self) -> Vec<[f32; 3]> {
        self.pixels
    }

    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        self.pixels[y * self.width + x]
    }

    pub fn layers(&self) -> &[AovLayer] {
        &self.layers
    }

    pub fn layer(&self, name: &str) -> Option<&AovLayer> {
        self.layers.iter().find(|l| l.name == name)
    }

    /// Adds (or replaces) a named layer; `samples.len()` must be
    /// `width * height * channels.len()` and names must not contain `.`. The empty name
    /// holds unprefixed channels other than R, G, B (an alpha `A`, a bare `Z`).
    pub fn set_layer(&mut self, name: &str, channels: &[&str], samples: Vec<f32>) -> Result<()> {
        if name.contains('.') || channels.is_empty() {
            return Err(ImageError::invalid(format!(
                "layer name '{name}' must not contain '.' and needs at least one channel"
            )));
        }
        let reserved = |c: &&&str| name.is_empty() && matches!(**c, "R" | "G" | "B");
        if let Some(c) = channels
            .iter()
            .find(|c| c.is_empty() || c.contains('.') || reserved(c))
        {
            return Err(ImageError::invalid(format!(
                "layer '{name}': channel name '{c}' must be non-empty, without '.', and not an \
                 unprefixed R, G or B"
            )));
        }
        let expected = self.width * self.height * channels.len();
        if samples.len() != expected {
            return Err(ImageError::invalid(format!(
                "layer '{name}' of a {}×{} image with {} channels needs {expected} samples, got {}",
                self.width,
                self.height,
                channels.len(),
                samples.len()
            )));
        }
        let layer = AovLayer {
            name: name.to_string(),
            channels: channels.iter().map(|c| c.to_string()).collect(),
            samples,
        };
        match self.layers.iter_mut().find(|l| l.name == name) {
            Some(existing) => *existing = layer,
            None => self.layers.push(layer),
        }
        Ok(())
    }

    /// Weights (second row of RGB→XYZ) giving relative luminance Y from linear RGB.
    pub fn luminance_weights(&self) -> [f32; 3] {
        luminance_weights(&self.color_space)
    }
}

/// Y = w · RGB for linear RGB in `space` (the second row of its RGB→XYZ matrix).
pub fn luminance_weights(space: &RgbColorSpace) -> [f32; 3] {
    let m = space.rgb_to_xyz;
    [m.x_axis.y as f32, m.y_axis.y as f32, m.z_axis.y as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_wrong_pixel_count_and_layer_size() {
        let space = RgbColorSpace::srgb();
        assert!(Image::new(2, 2, vec![[0.0; 3]; 3], space.clone()).is_err());
        let mut img = Image::filled(2, 2, [1.0; 3], space).unwrap();
        assert!(img.set_layer("depth", &["Z"], vec![0.0; 3]).is_err());
        assert!(img.set_layer("a.b", &["Z"], vec![0.0; 4]).is_err());
        img.set_layer("depth", &["Z"], vec![1.0; 4]).unwrap();
        img.set_layer("depth", &["Z"], vec![2.0; 4]).unwrap();
        assert_eq!(img.layers().len(), 1);
        assert_eq!(img.layer("depth").unwrap().samples[0], 2.0);
    }

    #[test]
    fn srgb_luminance_weights_are_bt709() {
        // ITU-R BT.709 luma coefficients, to the 4 printed digits.
        let w = luminance_weights(&RgbColorSpace::srgb());
        for (got, want) in w.iter().zip([0.2126, 0.7152, 0.0722]) {
            assert!((got - want).abs() < 1e-4);
        }
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }
}
