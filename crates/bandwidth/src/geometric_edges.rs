//! The G-buffer's own discontinuities in the bandwidth buffer (beyond eq. 6).
//!
//! Eq. 6 gives the shading's bandwidth at a pixel's centre hit. Bagher et al. (§3.2) ask more
//! of the buffer: it "predicts whether, for any sub-pixel of the current level pixel, the
//! computation will yield similar estimates despite potential variation in the depths,
//! normals and illumination". A pixel whose footprint holds a silhouette, a crease or a
//! change of material has a step in its image, and a step is not band-limited: such a pixel
//! gets eq. 11's finest anti-aliasing level. A step the eye cannot see (the two sides' L̂
//! within `EDGE_MIN_CONTRAST` of each other, Weber's fraction) is no edge.
//!
//! A mirror or smooth glass shows another surface: its pixels are compared also by what
//! their Dirac chain reaches ([`SeenSurface`]), so that the outline of an object, or the
//! horizon, seen in a mirror sphere is an edge as it would be seen directly.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::hierarchical_shading::{SurfacePoint, CREASE_MIN_COS};
use crate::variance_pooling::PixelClass;

/// A neighbour's hit further off a pixel's tangent plane than sin 30° of the chord to it is
/// on another surface (a depth step), whatever the depths: a floor seen at grazing angles
/// changes depth fast but stays in its plane.
const STEP_MIN_SINE: f32 = 0.5;

/// The smallest step in L̂, relative to the brighter side, that counts as an edge: the
/// Weber fraction of luminance discrimination, about 2 % over the photopic range. Noise
/// in L̂ can pass an invisible step, which costs samples at a real discontinuity; also
/// asking for 3 standard errors lost real edges (docs/bandwidth.md, "Geometric edges").
pub const EDGE_MIN_CONTRAST: f32 = 0.02;

/// What a pixel whose centre hit is a Dirac surface (mirror, smooth glass) shows: where its
/// centre ray's chain of Dirac vertices ends (a surface's class and point, or the
/// background's class and no point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeenSurface {
    pub class: PixelClass,
    pub surface: Option<SurfacePoint>,
}

/// Each pixel's L̂ (row-major), pooled over its class and its own: named fields, where two
/// slices side by side in an argument list could be swapped unnoticed.
#[derive(Clone, Copy, Debug)]
pub struct MeanLuminance<'a> {
    pub pooled_y: &'a [f32],
    pub own_y: &'a [f32],
}

/// Per pixel (row-major): true where a 4-neighbour lies across a visible geometric edge,
/// directly or through a Dirac chain. `class` and `surface` come from the G-buffer
/// (`surface` is `None` off surfaces), `seen` from the Dirac chains (`None` where the
/// centre hit is not Dirac), L̂ pooled over each pixel's class and each pixel's own
/// (`mean_y`). Two pixels of different classes compare their pooled L̂ (pooling never
/// mixes classes, so it removes noise and keeps the step); two of one class (a crease, a
/// box standing on a floor of the same paint) their own, since pooling over the class
/// blurs the step between its surfaces. Unpredicted pixels are never edges, nor do they
/// make their neighbours one.
pub fn geometric_edges(
    resolution: UVec2,
    class: &[PixelClass],
    surface: &[Option<SurfacePoint>],
    seen: &[Option<SeenSurface>],
    mean_y: MeanLuminance,
) -> Result<Vec<bool>, BandwidthError> {
    let MeanLuminance {
        pooled_y: pooled_mean_y,
        own_y: own_mean_y,
    } = mean_y;
    let count = pixel_count("geometric edges", resolution)?;
    check_lengths(
        resolution,
        count,
        &[
            ("pixel classes", class.len()),
            ("surface points", surface.len()),
            ("surfaces seen through Dirac chains", seen.len()),
            ("pooled L̂", pooled_mean_y.len()),
            ("own L̂", own_mean_y.len()),
        ],
    )?;
    // Whether the pair (i, j) straddles a visible edge. Symmetric in i and j, so each pair
    // is judged once (a pixel and its right and lower neighbours) and marks both; the
    // luminance steps, cheaper than the geometry, are asked first.
    let straddles = |i: usize, j: usize| {
        let own_step = is_visible_step(own_mean_y[i], own_mean_y[j]);
        let step = if class[i] == class[j] {
            own_step
        } else {
            is_visible_step(pooled_mean_y[i], pooled_mean_y[j])
        };
        (step && is_discontinuous(class[i], class[j], surface[i], surface[j]))
            || (own_step && seen_across_edge(seen[i], seen[j]))
    };
    let width = resolution.x as usize;
    let mut edges = vec![false; count];
    for i in 0..count {
        if class[i] == PixelClass::Unpredicted {
            continue;
        }
        let right = (i % width + 1 < width).then_some(i + 1);
        let below = (i + width < count).then_some(i + width);
        for j in [right, below].into_iter().flatten() {
            if class[j] != PixelClass::Unpredicted && straddles(i, j) {
                edges[i] = true;
                edges[j] = true;
            }
        }
    }
    Ok(edges)
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

/// Two Dirac pixels that show discontinuous surfaces (a pixel whose chain was lost compares
/// as continuous). Their own L̂ decides whether the step is seen: pooling over the mirror
/// would blur the very steps it shows.
fn seen_across_edge(p: Option<SeenSurface>, q: Option<SeenSurface>) -> bool {
    match (p, q) {
        (Some(p), Some(q)) => is_discontinuous(p.class, q.class, p.surface, q.surface),
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

    fn mean<'a>(pooled_y: &'a [f32], own_y: &'a [f32]) -> MeanLuminance<'a> {
        MeanLuminance { pooled_y, own_y }
    }

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
        let none =
            geometric_edges(UVec2::new(5, 1), &[m; 5], &plane, &[None; 5], mean(&l, &l)).unwrap();
        assert_eq!(none, vec![false; 5]);
        // A depth step between pixels 2 and 3: pixel 3 lies 1 m above pixel 2's plane.
        let mut step = plane.clone();
        step[3] = point(0.0, 4.0, Vec3A::Y).map(|mut s| {
            s.position_m.y = 1.0;
            s
        });
        step[4] = step[3];
        let l = [1.0, 1.0, 1.0, 2.0, 2.0];
        let edges =
            geometric_edges(UVec2::new(5, 1), &[m; 5], &step, &[None; 5], mean(&l, &l)).unwrap();
        assert_eq!(edges, vec![false, false, true, true, false]);
        // The same step with equal radiance on both sides is invisible.
        let flat = geometric_edges(
            UVec2::new(5, 1),
            &[m; 5],
            &step,
            &[None; 5],
            mean(&[1.0; 5], &[1.0; 5]),
        )
        .unwrap();
        assert_eq!(flat, vec![false; 5]);
        // A crease: normals 90° apart at pixels 1 | 2.
        let crease = [
            point(0.0, 1.0, Vec3A::Y),
            point(0.1, 1.0, Vec3A::Y),
            point(0.2, 1.0, Vec3A::X),
        ];
        let edges = geometric_edges(
            UVec2::new(3, 1),
            &[m; 3],
            &crease,
            &[None; 3],
            mean(&[1.0, 1.0, 0.5], &[1.0, 1.0, 0.5]),
        )
        .unwrap();
        assert_eq!(edges, vec![false, true, true]);
        // A silhouette against the background marks both sides; unpredicted pixels neither.
        let class = [m, PixelClass::Background, PixelClass::Unpredicted];
        let surface = [point(0.0, 1.0, Vec3A::Y), None, None];
        let edges = geometric_edges(
            UVec2::new(3, 1),
            &class,
            &surface,
            &[None; 3],
            mean(&[1.0, 3.0, 0.0], &[1.0, 3.0, 0.0]),
        )
        .unwrap();
        assert_eq!(edges, vec![true, true, false]);
    }

    /// Four pixels on one mirror sphere (one material, normals a few degrees apart): the
    /// first two show the floor, the third the background above the horizon, the fourth a
    /// lost chain. The horizon is an edge; the mirror's own surface is smooth.
    #[test]
    fn a_horizon_seen_in_a_mirror_is_an_edge() {
        let mirror = PixelClass::Material(1);
        let floor = |x: f32| SeenSurface {
            class: PixelClass::Material(0),
            surface: point(x, 5.0, Vec3A::Y),
        };
        let sky = SeenSurface {
            class: PixelClass::Background,
            surface: None,
        };
        let tilt = |a: f32| Vec3A::new(a.sin(), 0.0, a.cos());
        let surface: Vec<_> = (0..4)
            .map(|k| {
                Some(SurfacePoint {
                    position_m: Vec3A::new(0.01 * k as f32, 0.0, 1.0),
                    normal: tilt(0.05 * k as f32),
                })
            })
            .collect();
        let seen = [Some(floor(0.0)), Some(floor(0.3)), Some(sky), None];
        // L̂ pooled over the mirror is blurred flat; each pixel's own shows what it sees.
        let pooled = [0.5; 4];
        let own = [0.2, 0.2, 1.0, 0.5];
        let edges = |seen: &[Option<SeenSurface>], own: &[f32]| {
            geometric_edges(
                UVec2::new(4, 1),
                &[mirror; 4],
                &surface,
                seen,
                mean(&pooled, own),
            )
            .unwrap()
        };
        assert_eq!(edges(&seen, &own), vec![false, true, true, false]);
        // A horizon the eye cannot see is none.
        assert_eq!(edges(&seen, &[0.5; 4]), vec![false; 4]);
        // Without the chains the same pixels have no edge.
        assert_eq!(edges(&[None; 4], &own), vec![false; 4]);
    }

    #[test]
    fn mismatched_lengths_are_refused() {
        let m = PixelClass::Material(0);
        assert!(geometric_edges(
            UVec2::new(2, 1),
            &[m; 2],
            &[None],
            &[None; 2],
            mean(&[1.0; 2], &[1.0; 2])
        )
        .is_err());
    }

    /// A silhouette against the background with steps of 5 % and 1 %: the first is seen
    /// (above Weber's 2 %), the second is not. Across classes the pooled L̂ decides, within
    /// one (a crease) each pixel's own.
    #[test]
    fn a_step_is_an_edge_where_the_eye_sees_it() {
        let m = PixelClass::Material(0);
        let class = [m, PixelClass::Background];
        let surface = [point(0.0, 1.0, Vec3A::Y), None];
        // The pixels' own L̂ has no step: only the pooled one can make this edge.
        let silhouette = |pooled: [f32; 2]| {
            geometric_edges(
                UVec2::new(2, 1),
                &class,
                &surface,
                &[None; 2],
                mean(&pooled, &[1.0; 2]),
            )
            .unwrap()
        };
        assert_eq!(silhouette([1.0, 1.05]), vec![true, true]);
        assert_eq!(silhouette([1.0, 1.01]), vec![false, false]);
        // A crease on one material: its pooled L̂ is blurred (no step), its own shows one.
        let crease = [point(0.0, 1.0, Vec3A::Y), point(0.1, 1.0, Vec3A::X)];
        let crease_edges = |own: [f32; 2]| {
            geometric_edges(
                UVec2::new(2, 1),
                &[m; 2],
                &crease,
                &[None; 2],
                mean(&[1.0; 2], &own),
            )
            .unwrap()
        };
        assert_eq!(crease_edges([1.0, 0.5]), vec![true, true]);
        assert_eq!(crease_edges([1.0, 1.0]), vec![false, false]);
    }
}
