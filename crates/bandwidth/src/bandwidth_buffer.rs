//! The bandwidth buffer (Bagher et al. 2013 §3.1): per pixel the pyramid level it must be
//! shaded at (eq. 11), the predicted variance V̂_p and the screen-space curvature, with a
//! MIP pyramid that takes the min of levels (a coarse texel is as fine as its finest
//! child) and the max of variance and curvature, so every coarse test stays conservative.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, pixel_index, BandwidthError};

/// The finest level eq. 11 may ask for: −2 = 4×4 samples per pixel (anti-aliasing of edges
/// and highlights narrower than a pixel). Negative levels are sub-pixel sampling.
pub const FINEST_LEVEL: i32 = -2;

/// Eq. 11: the level at which a pixel with b_p cycles/pixel is shaded, clamp(⌊log2(1/(2 b_p))⌋,
/// −2, ⌊log2 min(W, H)⌋). Level k shades one sample per 2^k × 2^k pixels (Nyquist: two
/// samples per cycle, so 1/(2 b_p) pixels per sample); b_p = 0 is the coarsest level.
pub fn shading_level(image_bandwidth_cycles_per_px: f32, resolution: UVec2) -> i32 {
    let coarsest = resolution.x.min(resolution.y).max(1).ilog2() as i32;
    // b_p = 0 and NaN (nothing predicted) shade at the coarsest level.
    if image_bandwidth_cycles_per_px.is_nan() || image_bandwidth_cycles_per_px <= 0.0 {
        return coarsest;
    }
    let level = (1.0 / (2.0 * image_bandwidth_cycles_per_px)).log2().floor();
    if level >= coarsest as f32 {
        coarsest
    } else if level <= FINEST_LEVEL as f32 {
        FINEST_LEVEL
    } else {
        level as i32
    }
}

/// One level of the buffer: per texel the finest shading level, the largest variance and
/// the largest curvature of the pixels it covers.
#[derive(Clone, Debug, PartialEq)]
pub struct BandwidthLevel {
    pub resolution: UVec2,
    pub shading_level: Vec<i32>,
    pub variance: Vec<f32>,
    pub curvature_per_m: Vec<f32>,
}

impl BandwidthLevel {
    fn at(&self, texel: UVec2) -> usize {
        (texel.y * self.resolution.x + texel.x) as usize
    }

    /// The next coarser level: 2×2 texels (1×2 or 2×1 at an odd border) into one.
    fn coarser(&self) -> BandwidthLevel {
        let resolution = (self.resolution + 1) / 2;
        let n = (resolution.x * resolution.y) as usize;
        let mut out = BandwidthLevel {
            resolution,
            shading_level: vec![i32::MAX; n],
            variance: vec![0.0; n],
            curvature_per_m: vec![0.0; n],
        };
        for y in 0..self.resolution.y {
            for x in 0..self.resolution.x {
                let (i, o) = (self.at(UVec2::new(x, y)), out.at(UVec2::new(x / 2, y / 2)));
                out.shading_level[o] = out.shading_level[o].min(self.shading_level[i]);
                out.variance[o] = out.variance[o].max(self.variance[i]);
                out.curvature_per_m[o] = out.curvature_per_m[o].max(self.curvature_per_m[i]);
            }
        }
        out
    }
}

/// The buffer at full resolution (level 0) and its MIP pyramid down to 1×1.
#[derive(Clone, Debug, PartialEq)]
pub struct BandwidthBuffer {
    levels: Vec<BandwidthLevel>,
}

impl BandwidthBuffer {
    /// From per-pixel b_p (cycles/pixel), V̂_p and |curvature| (1/m), row-major.
    pub fn new(
        resolution: UVec2,
        image_bandwidth_cycles_per_px: &[f32],
        variance: &[f32],
        curvature_per_m: &[f32],
    ) -> Result<Self, BandwidthError> {
        let n = pixel_count("bandwidth buffer", resolution)?;
        check_lengths(
            resolution,
            n,
            &[
                ("bandwidth buffer b_p", image_bandwidth_cycles_per_px.len()),
                ("bandwidth buffer variance", variance.len()),
                ("bandwidth buffer curvature", curvature_per_m.len()),
            ],
        )?;
        let mut levels = vec![BandwidthLevel {
            resolution,
            shading_level: image_bandwidth_cycles_per_px
                .iter()
                .map(|&b| shading_level(b, resolution))
                .collect(),
            variance: variance.to_vec(),
            curvature_per_m: curvature_per_m.iter().map(|c| c.abs()).collect(),
        }];
        while levels.last().unwrap().resolution != UVec2::ONE {
            let next = levels.last().unwrap().coarser();
            levels.push(next);
        }
        Ok(Self { levels })
    }

    /// Level 0 (full resolution) first, 1×1 last.
    pub fn levels(&self) -> &[BandwidthLevel] {
        &self.levels
    }

    /// The shading level of one full-resolution pixel (eq. 11).
    pub fn shading_level(&self, pixel: UVec2) -> Result<i32, BandwidthError> {
        let base = &self.levels[0];
        Ok(base.shading_level[pixel_index("bandwidth buffer", pixel, base.resolution)?])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq11_levels_follow_nyquist_and_clamp_at_both_ends() {
        let r = UVec2::new(64, 32); // coarsest = log2(32) = 5
        assert_eq!(shading_level(0.0, r), 5);
        assert_eq!(
            shading_level(0.5, r),
            0,
            "one sample per pixel at 0.5 cycles/px"
        );
        assert_eq!(shading_level(0.25, r), 1);
        assert_eq!(shading_level(0.3, r), 0, "the floor keeps Nyquist");
        assert_eq!(shading_level(1.0, r), -1);
        assert_eq!(shading_level(2.0, r), -2);
        assert_eq!(shading_level(f32::INFINITY, r), FINEST_LEVEL);
        assert_eq!(shading_level(1e-6, r), 5);
        assert_eq!(shading_level(f32::NAN, r), 5);
    }

    #[test]
    fn the_pyramid_keeps_the_finest_level_and_the_largest_variance() {
        let r = UVec2::new(5, 3);
        let mut b = vec![0.0; 15];
        b[7] = 1.0; // (2, 1): level −1
        let mut v = vec![0.5; 15];
        v[14] = 9.0; // (4, 2)
        let c = vec![-2.0; 15];
        let buffer = BandwidthBuffer::new(r, &b, &v, &c).unwrap();
        let sizes: Vec<UVec2> = buffer.levels().iter().map(|l| l.resolution).collect();
        assert_eq!(
            sizes,
            [
                UVec2::new(5, 3),
                UVec2::new(3, 2),
                UVec2::new(2, 1),
                UVec2::ONE
            ]
        );
        assert_eq!(buffer.shading_level(UVec2::new(2, 1)).unwrap(), -1);
        assert_eq!(buffer.shading_level(UVec2::new(0, 0)).unwrap(), 1);
        let l1 = &buffer.levels()[1];
        assert_eq!(l1.shading_level, [1, -1, 1, 1, 1, 1]);
        assert_eq!(l1.variance[5], 9.0);
        assert_eq!(l1.curvature_per_m[0], 2.0);
        let top = buffer.levels().last().unwrap();
        assert_eq!((top.shading_level[0], top.variance[0]), (-1, 9.0));
        assert!(buffer.shading_level(UVec2::new(5, 0)).is_err());
        assert!(BandwidthBuffer::new(r, &b[..14], &v, &c).is_err());
    }
}
