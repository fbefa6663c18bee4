//! Which pixels the probe samples, and whose answer the others take (beyond the paper;
//! docs/bandwidth.md, "Sparse probing").
//!
//! The variance model pools V̂_p and L̂_p over a (2r+1)² window of one surface
//! (`variance_pooling`), so a pixel's own n_b samples are a small part of what it is given.
//! Probing one pixel in S×S keeps n_b samples at each probed pixel and divides the probe's
//! cost by about S²: the pooling then averages the probed pixels of the window only. A pixel
//! of a surface with no probed pixel of that surface within r (a thin object, a small patch)
//! is probed itself, so every surface keeps its own answer; S = 1 is the paper's probe at
//! every pixel. A pixel that is not probed takes the bandwidth ν and the shadow rays'
//! summary of the nearest probed pixel of its surface and keeps everything its own centre
//! hit gives (depth, footprint, curvature, texture, edges).

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::pixel_neighbours::ring;
use crate::variance_pooling::PixelClass;

/// The default probe stride: [`ProbeStride::Auto`].
pub const DEFAULT_PROBE_STRIDE: ProbeStride = ProbeStride::Auto;

/// The largest stride [`ProbeStride::Auto`] picks: measured up to 256² (r = 8, S = 4) in
/// docs/bandwidth.md; wider strides leave shadow edges and bandwidth to fewer probes than
/// were measured.
pub const AUTO_MAX_STRIDE_PX: u32 = 4;

/// The probe stride S, pixels between probed pixels along x and y (`--plan-probe-stride`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeStride {
    /// Half the pooling radius r, S = ⌊r/2⌋ within [1, [`AUTO_MAX_STRIDE_PX`]]: a
    /// (2r+1)² window then holds about 20 probed pixels of one surface at every resolution,
    /// so that the probe's cost grows with the windows rather than the pixels (1 at 64²,
    /// 2 at 128², 4 from 256² with the automatic radius; 1 where r ≤ 3, 0 = the paper's
    /// unpooled probe included). 1 for hierarchical shading, whose lattice pixels are
    /// shaded for their neighbours and take each its own probe (fig17 at 128² and 256 spp:
    /// relMSE 10–46 % above the probe at every pixel with S = 2, docs/bandwidth.md).
    Auto,
    /// A fixed stride in pixels; 1 = every pixel, as the paper.
    Px(u32),
}

impl ProbeStride {
    /// The stride in pixels for a pooling radius of `pool_radius_px`, for a plan shaded
    /// hierarchically (Bagher et al. 2013 §3.2) or not.
    pub fn px(self, pool_radius_px: u32, hierarchical: bool) -> u32 {
        match self {
            ProbeStride::Auto if hierarchical => 1,
            ProbeStride::Auto => (pool_radius_px / 2).clamp(1, AUTO_MAX_STRIDE_PX),
            ProbeStride::Px(s) => s,
        }
    }
}

impl std::fmt::Display for ProbeStride {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ProbeStride::Auto => f.write_str("auto"),
            ProbeStride::Px(s) => write!(f, "{s}"),
        }
    }
}

/// The samples a probed pixel takes at stride S for `per_pixel` at every pixel (n_b, or the
/// indirect estimates): `per_pixel`·S²/4, at least `per_pixel`. A probed pixel stands for the
/// S² pixels of its lattice cell, and a quarter of their samples keeps the expected gain of
/// the probe at every pixel where n_b alone loses 2–5 % at S = 4 (the pooled V̂ averages S²
/// fewer samples; docs/bandwidth.md, "Sparse probing"): the probe then costs about a
/// quarter of the paper's at every stride from 2.
pub fn samples_per_probed_pixel(per_pixel: u32, stride_px: u32) -> u32 {
    let quarter_cell = u64::from(per_pixel) * u64::from(stride_px).pow(2) / 4;
    u32::try_from(quarter_cell)
        .unwrap_or(u32::MAX)
        .max(per_pixel)
}

/// True for a pixel on the stride's lattice (both coordinates multiples of S).
fn on_lattice(x: usize, y: usize, stride: usize) -> bool {
    x.is_multiple_of(stride) && y.is_multiple_of(stride)
}

/// True for pixel (x, y) on the lattice of stride `stride_px` (every pixel at 1, and at 0,
/// which [`probed_pixels`] refuses): the pixels [`probed_pixels`] probes wherever their
/// surface is, so that a renderer can probe them before it knows the surfaces.
pub fn on_probe_lattice(x: u32, y: u32, stride_px: u32) -> bool {
    stride_px <= 1 || on_lattice(x as usize, y as usize, stride_px as usize)
}

/// The pixels the probe samples (row-major): for `stride_px` S and pooling radius r, every
/// lattice pixel of a surface, every surface pixel with no lattice pixel of its own class
/// within r (Chebyshev distance), and every pixel that sees the background (its prediction
/// costs no shadow ray). Unpredicted pixels are never probed. S = 1 probes every predicted
/// pixel.
pub fn probed_pixels(
    resolution: UVec2,
    class: &[PixelClass],
    stride_px: u32,
    radius_px: u32,
) -> Result<Vec<bool>, BandwidthError> {
    let count = pixel_count("probed pixels", resolution)?;
    check_lengths(resolution, count, &[("pixel classes", class.len())])?;
    if stride_px == 0 {
        return Err(BandwidthError::invalid(
            "sparse probing",
            "stride_px",
            stride_px,
            "at least 1",
        ));
    }
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let (s, r) = (stride_px as usize, radius_px as usize);
    let mut probed = Vec::with_capacity(count);
    for y in 0..h {
        for x in 0..w {
            let own = class[y * w + x];
            probed.push(match own {
                PixelClass::Unpredicted => false,
                PixelClass::Background => true,
                PixelClass::Material(_) => {
                    on_lattice(x, y, s)
                        // Ring by ring: the nearest lattice pixel is usually within S − 1.
                        || !(0..=r).any(|d| {
                            ring((x, y), d, (w, h)).any(|(xx, yy)| {
                                on_lattice(xx, yy, s) && class[yy * w + xx] == own
                            })
                        })
                }
            });
        }
    }
    Ok(probed)
}

/// For each pixel that is not probed, the nearest probed pixel of its class within the
/// Chebyshev radius r (Euclidean distance; ties go to the first in row-major order); `None`
/// for probed pixels and for those with no such pixel. [`probed_pixels`] leaves no surface
/// pixel without one.
pub fn nearest_probed(
    resolution: UVec2,
    class: &[PixelClass],
    probed: &[bool],
    radius_px: u32,
) -> Result<Vec<Option<usize>>, BandwidthError> {
    let count = pixel_count("nearest probed pixels", resolution)?;
    check_lengths(
        resolution,
        count,
        &[
            ("pixel classes", class.len()),
            ("probed mask", probed.len()),
        ],
    )?;
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let r = radius_px as usize;
    let mut donors = Vec::with_capacity(count);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if probed[i] || class[i] == PixelClass::Unpredicted {
                donors.push(None);
                continue;
            }
            // (squared distance, index): the least wins, so ties go to the first in
            // row-major order. Ring d lies at a Euclidean distance of at least d, so the
            // search stops past the best one found.
            let mut best: Option<(usize, usize)> = None;
            for d in 0..=r {
                if best.is_some_and(|(b, _)| d * d > b) {
                    break;
                }
                for (xx, yy) in ring((x, y), d, (w, h)) {
                    let j = yy * w + xx;
                    if !probed[j] || class[j] != class[i] {
                        continue;
                    }
                    let d2 = x.abs_diff(xx).pow(2) + y.abs_diff(yy).pow(2);
                    if best.is_none_or(|b| (d2, j) < b) {
                        best = Some((d2, j));
                    }
                }
            }
            donors.push(best.map(|(_, j)| j));
        }
    }
    Ok(donors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_automatic_stride_is_half_the_pooling_radius_within_one_to_four_and_one_for_hier() {
        let s = |r| ProbeStride::Auto.px(r, false);
        assert_eq!(
            [s(0), s(1), s(2), s(3), s(4), s(5), s(8), s(16)],
            [1, 1, 1, 1, 2, 2, 4, 4]
        );
        assert_eq!(ProbeStride::Auto.px(8, true), 1);
        assert_eq!(ProbeStride::Px(3).px(16, false), 3);
        assert_eq!(ProbeStride::Px(3).px(16, true), 3);
        assert_eq!(ProbeStride::Auto.to_string(), "auto");
        assert_eq!(ProbeStride::Px(2).to_string(), "2");
    }

    #[test]
    fn a_probed_pixel_takes_a_quarter_of_its_cells_samples_at_least_its_own() {
        let n = |s| samples_per_probed_pixel(16, s);
        assert_eq!([n(1), n(2), n(3), n(4), n(8)], [16, 16, 36, 64, 256]);
        assert_eq!(samples_per_probed_pixel(0, 4), 0);
        assert_eq!(samples_per_probed_pixel(u32::MAX, 4), u32::MAX);
    }

    #[test]
    fn every_surface_pixel_on_the_lattice_is_probed_and_the_lattice_is_all_at_stride_one() {
        let class: Vec<PixelClass> = (0..36)
            .map(|i| match i % 3 {
                0 => PixelClass::Material(0),
                1 => PixelClass::Material(1),
                _ => PixelClass::Background,
            })
            .collect();
        let probed = probed_pixels(UVec2::new(6, 6), &class, 2, 1).unwrap();
        for (i, &probed) in probed.iter().enumerate() {
            let (x, y) = ((i % 6) as u32, (i / 6) as u32);
            if on_probe_lattice(x, y, 2) {
                assert!(probed, "pixel ({x}, {y})");
            }
            assert!(on_probe_lattice(x, y, 1));
        }
        assert!(on_probe_lattice(4, 2, 2) && !on_probe_lattice(3, 2, 2));
    }

    #[test]
    fn stride_one_probes_every_predicted_pixel() {
        let class = [
            PixelClass::Material(0),
            PixelClass::Background,
            PixelClass::Unpredicted,
            PixelClass::Material(1),
        ];
        let p = probed_pixels(UVec2::new(2, 2), &class, 1, 2).unwrap();
        assert_eq!(p, vec![true, true, false, true]);
        let donors = nearest_probed(UVec2::new(2, 2), &class, &p, 2).unwrap();
        assert_eq!(donors, vec![None; 4]);
    }

    #[test]
    fn stride_two_probes_a_quarter_of_one_surface_and_each_pixel_has_a_donor() {
        let resolution = UVec2::new(8, 8);
        let class = vec![PixelClass::Material(3); 64];
        let p = probed_pixels(resolution, &class, 2, 2).unwrap();
        assert_eq!(p.iter().filter(|b| **b).count(), 16);
        let donors = nearest_probed(resolution, &class, &p, 2).unwrap();
        for (i, d) in donors.iter().enumerate() {
            match d {
                None => assert!(p[i]),
                Some(j) => {
                    assert!(p[*j]);
                    let (x, y, xj, yj) = (i % 8, i / 8, j % 8, j / 8);
                    // The nearest lattice pixel is at most one step away along each axis,
                    // and ties go to the first in row-major order (up and left).
                    assert!(x.abs_diff(xj) <= 1 && y.abs_diff(yj) <= 1);
                    assert!(xj <= x && yj <= y);
                }
            }
        }
    }

    #[test]
    fn a_surface_without_a_lattice_pixel_nearby_is_probed_itself() {
        // A one-pixel-wide column of material 1 at x = 3 (off the stride-2 lattice) in a
        // field of material 0: all its pixels are probed, the field's only on the lattice.
        let resolution = UVec2::new(6, 4);
        let class: Vec<PixelClass> = (0..24)
            .map(|i| PixelClass::Material(u32::from(i % 6 == 3)))
            .collect();
        let p = probed_pixels(resolution, &class, 2, 2).unwrap();
        for (i, probed) in p.iter().enumerate() {
            let (x, y) = (i % 6, i / 6);
            let expected = x == 3 || (x % 2 == 0 && y % 2 == 0);
            assert_eq!(*probed, expected, "pixel ({x}, {y})");
        }
        // Without pooling (r = 0) no pixel has a probed neighbour to borrow from: all are
        // probed.
        let p = probed_pixels(resolution, &class, 2, 0).unwrap();
        assert!(p.iter().all(|b| *b));
    }

    #[test]
    fn the_background_is_always_probed_and_a_zero_stride_is_refused() {
        let class = vec![PixelClass::Background; 9];
        let p = probed_pixels(UVec2::new(3, 3), &class, 3, 1).unwrap();
        assert!(p.iter().all(|b| *b));
        let e = probed_pixels(UVec2::new(3, 3), &class, 0, 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("stride_px"), "{e}");
    }

    /// The ring search finds the definition's donor: the nearest probed pixel of the class
    /// in the whole window, ties to the first in row-major order.
    #[test]
    fn the_ring_search_finds_the_window_s_nearest_donor() {
        let resolution = UVec2::new(19, 13);
        let (w, h) = (19usize, 13usize);
        let class: Vec<PixelClass> = (0..w * h)
            .map(|i| PixelClass::Material(((i * 7 + i / 5) % 3) as u32))
            .collect();
        let probed: Vec<bool> = (0..w * h).map(|i| (i * 13) % 11 == 0).collect();
        for r in [0usize, 1, 3, 8, 30] {
            let got = nearest_probed(resolution, &class, &probed, r as u32).unwrap();
            for i in 0..w * h {
                let want = if probed[i] {
                    None
                } else {
                    crate::pixel_neighbours::window((i % w, i / w), r, (w, h))
                        .map(|(xx, yy)| yy * w + xx)
                        .filter(|&j| probed[j] && class[j] == class[i])
                        .map(|j| {
                            let d2 =
                                (i % w).abs_diff(j % w).pow(2) + (i / w).abs_diff(j / w).pow(2);
                            (d2, j)
                        })
                        .min()
                        .map(|(_, j)| j)
                };
                assert_eq!(got[i], want, "pixel {i}, r {r}");
            }
        }
    }
}
