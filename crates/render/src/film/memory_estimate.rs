//! What a render of a given film allocates, estimated before anything is built, so that a
//! command can refuse a size that would not fit (`prism_cpu::memory::MemoryBudget`)
//! instead of being killed half-way.
//!
//! Per pixel: the film's accumulators (`PixelAccum`, `AovAccum`, 16-byte fixed-point
//! spectral sums, the
//! light plane of estimators that splat), the resolved `FilmImage` (XYZ, RGB, Y, AOV and
//! spectral planes in f32) and the output image with its layers, counted twice (the image
//! and the encoder's buffer). It is an upper estimate: the stages do not all live at once.
//! docs/reliability.md states the measured peak against it.

use glam::UVec2;

use super::tile::{AovAccum, PixelAccum};
use super::{AovSelection, FixedSum};

/// Bytes of one exact sum.
const FIXED: u64 = std::mem::size_of::<FixedSum>() as u64;

/// The film a render will allocate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilmMemory {
    pub resolution: UVec2,
    pub aovs: AovSelection,
    /// Spectral bins (0: none).
    pub spectral_bins: u32,
    /// The estimator splats light paths (a light plane beside the pixels).
    pub light_plane: bool,
}

impl FilmMemory {
    /// The film a render of a scene with `integrator` allocates at `resolution` with
    /// `spectral_bins`, every AOV counted (which ones the scene records is known only once
    /// it is built).
    pub fn for_integrator(
        integrator: &prism_scene::Integrator,
        resolution: UVec2,
        spectral_bins: u32,
    ) -> Self {
        Self {
            resolution,
            aovs: AovSelection::ALL,
            spectral_bins,
            light_plane: integrator.splats_light_paths(),
        }
    }

    /// f32 channels of the AOV layers, `spp.Y` included.
    fn aov_channels(&self) -> u64 {
        let a = self.aovs;
        1 + u64::from(a.depth)
            + 3 * u64::from(a.normal)
            + 3 * u64::from(a.albedo)
            + 3 * u64::from(a.illumination)
            + u64::from(a.variance)
    }

    /// Bytes per pixel of every stage together (see the module docs).
    pub fn bytes_per_pixel(&self) -> u64 {
        let bins = u64::from(self.spectral_bins);
        let accumulators = std::mem::size_of::<PixelAccum>() as u64
            + if self.aovs.any() {
                std::mem::size_of::<AovAccum>() as u64
            } else {
                0
            }
            + FIXED * bins
            + if self.light_plane {
                3 * FIXED + FIXED * bins
            } else {
                0
            };
        let layers = 4 * (self.aov_channels() + bins);
        // XYZ, RGB and Y in f32, then the layers.
        let film_image = 28 + layers;
        // RGB and luminance in f32, the layers; the encoder holds as much again; and the
        // temporaries of building the image (luminance in cd/m², layers interleaved) with
        // what the allocator keeps of freed tiles, 64 bytes as measured (docs/reliability.md).
        let output = 2 * (16 + layers) + 64;
        accumulators + film_image + output
    }

    /// Bytes of the whole film (saturating: a resolution beyond u64 bytes is refused anyway).
    pub fn total_bytes(&self) -> u64 {
        let pixels = u64::from(self.resolution.x) * u64::from(self.resolution.y);
        pixels.saturating_mul(self.bytes_per_pixel())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_grows_with_the_layers_and_the_size() {
        let base = FilmMemory {
            resolution: UVec2::new(100, 10),
            aovs: AovSelection::NONE,
            spectral_bins: 0,
            light_plane: false,
        };
        let bins = FilmMemory {
            spectral_bins: 10,
            ..base
        };
        let all = FilmMemory {
            aovs: AovSelection::ALL,
            ..base
        };
        assert!(bins.bytes_per_pixel() >= base.bytes_per_pixel() + 10 * (16 + 4));
        assert!(all.bytes_per_pixel() > base.bytes_per_pixel() + 100);
        assert_eq!(base.total_bytes(), 1000 * base.bytes_per_pixel());
        let huge = FilmMemory {
            resolution: UVec2::new(u32::MAX, u32::MAX),
            ..all
        };
        assert!(huge.total_bytes() > 1 << 60);
    }
}
