//! The G-buffer's own discontinuities in the bandwidth buffer (beyond eq. 6).
//!
//! Eq. 6 gives the shading's bandwidth at a pixel's centre hit. Bagher et al. (§3.2) ask more
//! of the buffer: it "predicts whether, for any sub-pixel of the current level pixel, the
//! computation will yield similar estimates despite potential variation in the depths,
//! normals and illumination". A pixel whose footprint holds a silhouette, a crease or a
//! change of material has a step in its image, and a step is not band-limited: such a pixel
//! gets eq. 11's finest anti-aliasing level. A step the eye cannot see (the two sides' L̂
//! within `EDGE_MIN_CONTRAST` of each other) is no edge.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::hierarchical_shading::{SurfacePoint, CREASE_MIN_COS};
use crate::pixel_neighbours::four_neighbours;
use crate::variance_pooling::PixelClass;

/// A neighbour's hit further off a pixel's tangent plane than sin 30° of the chord to it is
/// on another surface (a depth step), whatever the depths: a floor seen at grazing angles
/// changes depth fast but stays in its plane.
const STEP_MIN_SINE: f32 = 0.5;

/// The smallest step in L̂, relative to the brighter side, that counts as an edge.
pub const EDGE_MIN_CONTRAST: f32 = 0.1;

/// Per pixel (row-major): true where a 4-neighbour lies across a visible geometric edge.
/// `class` and `surface` come from the G-buffer (`surface` is `None` off surfaces),
/// `mean_y` is L̂ (pooled per surface). Unpredicted pixels are never edges, nor do they make
/// their neighbours one.
pub fn geometric_edges(
    resolution: UVec2,
    class: &[PixelClass],
    surface: &[Option<SurfacePoint>],
    mean_y: &[f32],
) -> Result<Vec<bool>, BandwidthError> {
    let count = pixel_count("geometric edges", resolution)?;
    check_lengths(
        resolution,
        count,
        &[
            ("pixel classes", class.len()),
            ("surface points", surface.len()),
            ("L̂", mean_y.len()),
        ],
    )?;
    Ok((0..count)
        .map(|i| {
            if class[i] == PixelClass::Unpredicted {
                return false;
            }
            four_neighbours(i, resolution).any(|j| {
                class[j] != PixelClass::Unpredicted
                    && is_discontinuous(class[i], class[j], surface[i], surface[j])
                    && is_visible_step(mean_y[i], mean_y[j])
            })
        })
        .collect())
}

/// Another material or the background, a crease or a depth step.
fn is_discontinuous(
    class_p: PixelClass,
    class_q: PixelClass,
    p: Option<SurfacePoint>,
    q: Option<SurfacePoint>,
) -> bool {
    if class_p != class_q {
        return true;
    }
    match (p, q) {
        (Some(p), Some(q)) => {
            p.normal.dot(q.normal) < CREASE_MIN_COS
                || p.off_plane_sine(&q).max(q.off_plane_sine(&p)) > STEP_MIN_SINE
        }
        // Two background pixels, or a class without surface points: no geometry to differ.
        (None, None) | (Some(_), None) | (None, Some(_)) => false,
    }
}

fn is_visible_step(a: f32, b: f32) -> bool {
    (a - b).abs() > EDGE_MIN_CONTRAST * a.abs().max(b.abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    fn point(x: f32, z: f32, normal: Vec3A) -> Option<SurfacePoint> {
        Some(SurfacePoint {
            position_m: Vec3A::new(x, 0.0, z),
            normal,
        })
    }

    #[test]
    fn silhouettes_creases_and_steps_are_edges_and_a_grazing_plane_is_not() {
        let m = PixelClass::Material(0);
        // A row of five pixels on one material: a plane receding fast (z grows 1 → 16 m
        // along the row, still in the plane y = 0), no edge.
        let plane: Vec<_> = [1.0, 2.0, 4.0, 8.0, 16.0]
            .iter()
            .map(|&z| point(0.0, z, Vec3A::Y))
            .collect();
        let l = [1.0; 5];
        let none = geometric_edges(UVec2::new(5, 1), &[m; 5], &plane, &l).unwrap();
        assert_eq!(none, vec![false; 5]);
        // A depth step between pixels 2 and 3: pixel 3 lies 1 m above pixel 2's plane.
        let mut step = plane.clone();
        step[3] = point(0.0, 4.0, Vec3A::Y).map(|mut s| {
            s.position_m.y = 1.0;
            s
        });
        step[4] = step[3];
        let l = [1.0, 1.0, 1.0, 2.0, 2.0];
        let edges = geometric_edges(UVec2::new(5, 1), &[m; 5], &step, &l).unwrap();
        assert_eq!(edges, vec![false, false, true, true, false]);
        // The same step with equal radiance on both sides is invisible.
        let flat = geometric_edges(UVec2::new(5, 1), &[m; 5], &step, &[1.0; 5]).unwrap();
        assert_eq!(flat, vec![false; 5]);
        // A crease: normals 90° apart at pixels 1 | 2.
        let crease = [
            point(0.0, 1.0, Vec3A::Y),
            point(0.1, 1.0, Vec3A::Y),
            point(0.2, 1.0, Vec3A::X),
        ];
        let edges = geometric_edges(UVec2::new(3, 1), &[m; 3], &crease, &[1.0, 1.0, 0.5]).unwrap();
        assert_eq!(edges, vec![false, true, true]);
        // A silhouette against the background marks both sides; unpredicted pixels neither.
        let class = [m, PixelClass::Background, PixelClass::Unpredicted];
        let surface = [point(0.0, 1.0, Vec3A::Y), None, None];
        let edges = geometric_edges(UVec2::new(3, 1), &class, &surface, &[1.0, 3.0, 0.0]).unwrap();
        assert_eq!(edges, vec![true, true, false]);
    }

    #[test]
    fn mismatched_lengths_are_refused() {
        let m = PixelClass::Material(0);
        assert!(geometric_edges(UVec2::new(2, 1), &[m; 2], &[None], &[1.0; 2]).is_err());
    }
}
