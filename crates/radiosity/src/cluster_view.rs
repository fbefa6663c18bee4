//! What a cluster shows to a point that sees it from afar: its patches projected from the
//! point into a software Z-buffer, the opaque patches first and the see-through ones over
//! them (Mostefaoui, Dischler & Ghazanfarpour §3: a cluster's energy is "summed up
//! according to an internal visibility, that is computed using a software Z-buffer
//! technique, that first projects all of the opaque patches, and then the transparent
//! ones"). A cluster source's link weighs each patch by what of it the cluster itself
//! leaves in view, where rays to sample points could not tell the cluster's own occlusion
//! from the scene's.

use std::sync::OnceLock;

use glam::Vec3A;

use crate::element::ElementShape;
use crate::hierarchy::{Hierarchy, NodeKind};
use crate::solver::{r2, Visibility};

/// Pixels along each side of a cluster's image.
const CLUSTER_IMAGE_PIXELS: usize = 32;

/// What a block of pixels shows of one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Fragment {
    pub patch: u32,
    /// Where the pixels' view lines meet the patch, area-weighted.
    pub point_m: Vec3A,
    pub normal: Vec3A,
    /// The patch's surface area the pixels stand for, times what the see-through patches
    /// in front of it let through, m².
    pub area_m2: f32,
    /// Nothing of the cluster lies in front of it: a ray towards it meets only what lies
    /// outside the cluster.
    pub in_front: bool,
}

/// A patch drawn over the opaque image: its distance along the pixel's view line, its
/// index in the cluster and its transparency.
#[derive(Clone, Copy)]
struct SeeThrough {
    distance: f32,
    local: u32,
    transparency: f32,
}

/// Pixels along each side of the square blocks whose pixels on the same patch (and
/// behind the same see-through layers) make one fragment, at their area-weighted mean
/// point: an eighth of the cluster's width is fine enough for the 1/d² of a receiver three
/// of the cluster's radii away, and the links' time goes into each receiver point's sum
/// over the fragments.
const FRAGMENT_BLOCK_PIXELS: usize = 4;

/// A patch covering at least this many pixels has them scaled to its exact area; below,
/// the count is too coarse to scale by (a triangle on one pixel would count whole while
/// it hides the others on that pixel, which then count for nothing: a woven panel of
/// 36 864 triangles read its sensors 0.1 % darker that way), and point sampling stands.
const EXACT_AREA_MIN_PIXELS: u32 = 8;

/// No patch, or a patch's side facing away from the receiver, in the opaque image.
const NOTHING_SHOWN: u32 = u32::MAX;

/// The fragments that the patches of cluster node `cluster` show to a receiver centred at
/// `eye` with corners `receiver_corners`, seen from `eye`, which lies outside the
/// cluster's box (the solver asks for clusters three of their radii away or more). A
/// patch shows its emitting side where the eye or any of the receiver's corners lies in
/// front of it (the caller weighs each receiver point by its own cosine, which is 0 behind
/// the patch), and hides what lies behind it either way: a desk top at the height of a
/// wall element's middle faces the element's upper half, and leaving it out by the
/// centre's view lost what the upper half receives. Where `vis` has see-through patches,
/// `vis.transparency(patch, towards)` is the share of a patch's area seen through from
/// direction `towards` (unit, from the patch to the eye; a tiled carrier's τ, 0 for an
/// opaque patch); a see-through surface has a patch per side, and the one facing the eye
/// stands for it. A see-through patch counts with its whole area, since its radiosity is
/// per area of the surface it stands for, holes included.
///
/// Each pixel samples the image at one point and stands for the area of the patch's plane
/// it covers there (larger where the patch is farther or more oblique): point sampling,
/// whose expected coverage of each patch is its area, however small the patch. A patch
/// that covers [`EXACT_AREA_MIN_PIXELS`] pixels or more has its pixels scaled to cover its
/// exact area, so that a patch in full view counts whole whatever the pixels' alignment
/// with its edges.
///
/// `None` where the view cannot be framed: `cluster` is not a cluster, or part of its box
/// lies at or behind the eye.
pub(crate) fn cluster_fragments(
    hierarchy: &Hierarchy,
    cluster: u32,
    eye: Vec3A,
    receiver_corners: &[Vec3A],
    vis: &dyn Visibility,
) -> Option<Vec<Fragment>> {
    let node = &hierarchy.nodes[cluster as usize];
    let NodeKind::Cluster { patches, .. } = node.kind else {
        return None;
    };
    let members = &hierarchy.order[patches.0 as usize..patches.1 as usize];
    let shape_of = |local: usize| {
        let root = hierarchy.patch_root[members[local] as usize];
        match hierarchy.nodes[root as usize].kind {
            NodeKind::Element { shape, .. } => shape,
            NodeKind::Cluster { .. } => unreachable!("patch roots are elements"),
        }
    };
    let any_see_through = vis.any_see_through();
    let (lo, hi) = (node.lo, node.hi);
    let image = Image::framing(eye, lo, hi)?;
    let size = CLUSTER_IMAGE_PIXELS;
    // Coplanar patches of a two-sided surface: the side facing the eye wins the tie.
    let facing_bias = 1e-5 * (hi - lo).length();
    let mut distance = vec![f32::INFINITY; size * size];
    let mut front = vec![NOTHING_SHOWN; size * size];
    // Per member: its exact area over the area its pixels cover, which the rounding of
    // its edges to pixels leaves a little off 1.
    let mut area_scale = vec![0.0f32; members.len()];
    let mut normals = vec![Vec3A::ZERO; members.len()];
    let mut see_through_members = Vec::new();
    for (local, &patch) in members.iter().enumerate() {
        let shape = &shape_of(local);
        let normal = shape.normal();
        normals[local] = normal;
        let to_eye = eye - shape.centre();
        let on_plane = shape.point(0.0, 0.0);
        let faces_eye = normal.dot(to_eye) > 0.0;
        let facing = faces_eye
            || receiver_corners
                .iter()
                .any(|&c| normal.dot(c - on_plane) > 0.0);
        let tau = if any_see_through {
            vis.transparency(patch, to_eye.normalize_or_zero())
        } else {
            0.0
        };
        if tau > 0.0 {
            // Drawn after every opaque patch, by the side facing the eye only (both sides
            // would let τ² through).
            if faces_eye {
                see_through_members.push((local, tau));
            }
            continue;
        }
        let bias = if facing { facing_bias } else { 0.0 };
        let shown = if facing { local as u32 } else { NOTHING_SHOWN };
        let covered = image.raster(shape, normal, |pixel, t| {
            if t - bias < distance[pixel] {
                distance[pixel] = t - bias;
                front[pixel] = shown;
            }
        });
        if facing {
            area_scale[local] = covered.exact_area_scale(shape);
        }
    }
    let mut see_through: Vec<Vec<SeeThrough>> = Vec::new();
    if !see_through_members.is_empty() {
        see_through.resize_with(size * size, Vec::new);
        for &(local, tau) in &see_through_members {
            let shape = &shape_of(local);
            let covered = image.raster(shape, normals[local], |pixel, t| {
                if t < distance[pixel] {
                    see_through[pixel].push(SeeThrough {
                        distance: t,
                        local: local as u32,
                        transparency: tau,
                    });
                }
            });
            area_scale[local] = covered.exact_area_scale(shape);
        }
    }
    // The pixels block by block; a block's fragments, one per patch and layer, are merged
    // as they come and lie from `block_start` on.
    let mut fragments: Vec<(u32, Fragment)> = Vec::new();
    let emit = |fragments: &mut Vec<(u32, Fragment)>,
                block_start: usize,
                local: u32,
                pixel: usize,
                through: f32| {
        let (shape, normal) = (&shape_of(local as usize), normals[local as usize]);
        let (point_m, pixel_m2) = image.on_plane(shape, normal, pixel);
        let area_m2 = pixel_m2 * area_scale[local as usize] * through;
        let in_front = through == 1.0;
        match fragments[block_start..]
            .iter_mut()
            .find(|(l, f)| *l == local && f.in_front == in_front)
        {
            // The point becomes the area-weighted mean of the block's pixels on the patch.
            Some((_, f)) => {
                let total = f.area_m2 + area_m2;
                if total > 0.0 {
                    f.point_m = (f.point_m * f.area_m2 + point_m * area_m2) / total;
                }
                f.area_m2 = total;
            }
            None => fragments.push((
                local,
                Fragment {
                    patch: members[local as usize],
                    point_m,
                    normal,
                    area_m2,
                    in_front,
                },
            )),
        }
    };
    let block = FRAGMENT_BLOCK_PIXELS;
    for block_y in (0..size).step_by(block) {
        for block_x in (0..size).step_by(block) {
            let block_start = fragments.len();
            for y in block_y..block_y + block {
                for x in block_x..block_x + block {
                    let pixel = y * size + x;
                    let mut through = 1.0f32;
                    if let Some(layers) = see_through.get_mut(pixel) {
                        layers.sort_by(|a, b| a.distance.total_cmp(&b.distance));
                        for layer in layers.iter() {
                            emit(&mut fragments, block_start, layer.local, pixel, through);
                            through *= layer.transparency;
                        }
                    }
                    let shown = front[pixel];
                    if shown != NOTHING_SHOWN && through > 0.0 {
                        emit(&mut fragments, block_start, shown, pixel, through);
                    }
                }
            }
        }
    }
    Some(fragments.into_iter().map(|(_, f)| f).collect())
}

/// The pixels a patch covers and the area of its plane they cover, m².
#[derive(Clone, Copy, Default)]
struct Covered {
    pixels: u32,
    area_m2: f32,
}

impl Covered {
    /// What the patch's pixel areas are scaled by: its exact area over the area its
    /// pixels cover when they are [`EXACT_AREA_MIN_PIXELS`] or more, else 1.
    fn exact_area_scale(&self, shape: &ElementShape) -> f32 {
        if self.pixels >= EXACT_AREA_MIN_PIXELS {
            shape.area_m2() / self.area_m2
        } else {
            1.0
        }
    }
}

/// Each pixel's sample offset within it (`Image::sample`).
fn sample_offsets() -> &'static [(f32, f32)] {
    static OFFSETS: OnceLock<Vec<(f32, f32)>> = OnceLock::new();
    OFFSETS.get_or_init(|| {
        (0..CLUSTER_IMAGE_PIXELS * CLUSTER_IMAGE_PIXELS)
            .map(|k| r2(k as u32, 5))
            .collect()
    })
}

/// The perspective image from `eye` looking along `view`: the plane at unit distance,
/// spanned by `across`, with pixel (0, 0)'s corner at `origin` and pixels `pixel` wide
/// (in units of that plane).
struct Image {
    eye: Vec3A,
    view: Vec3A,
    across: (Vec3A, Vec3A),
    origin: (f32, f32),
    pixel: (f32, f32),
}

impl Image {
    /// The image from `eye` that frames the box `lo`–`hi`; `None` when part of the box
    /// lies at or behind the eye, or the box shows no extent.
    fn framing(eye: Vec3A, lo: Vec3A, hi: Vec3A) -> Option<Self> {
        let view = (0.5 * (lo + hi) - eye).normalize_or_zero();
        if view == Vec3A::ZERO {
            return None;
        }
        let across = view.any_orthonormal_pair();
        let mut image = Self {
            eye,
            view,
            across,
            origin: (0.0, 0.0),
            pixel: (1.0, 1.0),
        };
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
        for corner in 0..8 {
            let p = Vec3A::new(
                if corner & 1 == 0 { lo.x } else { hi.x },
                if corner & 2 == 0 { lo.y } else { hi.y },
                if corner & 4 == 0 { lo.z } else { hi.z },
            );
            let (x, y) = image.project(p)?;
            x_lo = x_lo.min(x);
            x_hi = x_hi.max(x);
            y_lo = y_lo.min(y);
            y_hi = y_hi.max(y);
        }
        let size = CLUSTER_IMAGE_PIXELS as f32;
        image.origin = (x_lo, y_lo);
        image.pixel = ((x_hi - x_lo) / size, (y_hi - y_lo) / size);
        (image.pixel.0 > 0.0 && image.pixel.1 > 0.0).then_some(image)
    }

    /// Pixel coordinates of a point in front of the eye (pixel i spans [i, i + 1)).
    fn project(&self, p: Vec3A) -> Option<(f32, f32)> {
        let q = p - self.eye;
        let depth = q.dot(self.view);
        (depth > 0.0).then(|| {
            (
                (q.dot(self.across.0) / depth - self.origin.0) / self.pixel.0,
                (q.dot(self.across.1) / depth - self.origin.1) / self.pixel.1,
            )
        })
    }

    /// The view line's direction through pixel coordinates (x, y).
    fn line(&self, x: f32, y: f32) -> Vec3A {
        self.view
            + self.across.0 * (self.origin.0 + x * self.pixel.0)
            + self.across.1 * (self.origin.1 + y * self.pixel.1)
    }

    /// How far along `line` (in its lengths) the plane of `shape` (unit normal `normal`)
    /// lies.
    fn distance_along(&self, normal: Vec3A, shape: &ElementShape, line: Vec3A) -> f32 {
        normal.dot(shape.point(0.0, 0.0) - self.eye) / normal.dot(line)
    }

    /// Where `pixel` samples the image: a point placed in it by the R2 sequence, so that
    /// edges aligned with the pixel grid (a symmetric view of a symmetric cluster) are not
    /// all sampled at the same offset.
    fn sample(pixel: usize) -> (f32, f32) {
        let size = CLUSTER_IMAGE_PIXELS;
        let (a, b) = sample_offsets()[pixel];
        ((pixel % size) as f32 + a, (pixel / size) as f32 + b)
    }

    /// Where the view line through `pixel`'s sample meets the shape's plane (unit normal
    /// `normal`), and the area of that plane the pixel covers, m².
    fn on_plane(&self, shape: &ElementShape, normal: Vec3A, pixel: usize) -> (Vec3A, f32) {
        let (x, y) = Self::sample(pixel);
        let line = self.line(x, y);
        let t = self.distance_along(normal, shape, line);
        (self.eye + line * t, self.pixel_area_along(normal, line, t))
    }

    /// The area of a plane (unit normal `normal`) that a pixel covers where its view line
    /// `line` meets the plane at `t` line lengths: dA = dA_image · t² / |n · line| (the
    /// pixel's solid angle dA_image / |line|³ times distance² over the cosine at the plane).
    fn pixel_area_along(&self, normal: Vec3A, line: Vec3A, t: f32) -> f32 {
        self.pixel.0 * self.pixel.1 * t * t / normal.dot(line).abs()
    }

    /// Calls `draw(pixel, distance)` once for every pixel whose sample the (convex) shape
    /// (unit normal `normal`) covers; how much it covers. Shapes seen edge-on draw none.
    fn raster(
        &self,
        shape: &ElementShape,
        normal: Vec3A,
        mut draw: impl FnMut(usize, f32),
    ) -> Covered {
        let size = CLUSTER_IMAGE_PIXELS;
        let mut covered = Covered::default();
        let to_eye = self.eye - shape.centre();
        if normal.dot(to_eye).abs() < 1e-6 * to_eye.length() {
            return covered;
        }
        let (corners, count) = shape.corners();
        let mut polygon = [(0.0f32, 0.0f32); 4];
        for (q, &p) in polygon.iter_mut().zip(&corners[..count]) {
            // The framing put the whole box in front of the eye.
            let Some(projected) = self.project(p) else {
                return covered;
            };
            *q = projected;
        }
        let polygon = &polygon[..count];
        // The winding's sign, so that inside is where every edge function is ≥ 0; each
        // edge as e(x, y) = a x + b y + c.
        let (p0, p1, p2) = (polygon[0], polygon[1], polygon[2]);
        let winding = ((p1.0 - p0.0) * (p2.1 - p0.1) - (p1.1 - p0.1) * (p2.0 - p0.0)).signum();
        let mut edges = [(0.0f32, 0.0f32, 0.0f32); 4];
        for (i, edge) in edges.iter_mut().enumerate().take(count) {
            let (p, q) = (polygon[i], polygon[(i + 1) % count]);
            let (a, b) = (-(q.1 - p.1) * winding, (q.0 - p.0) * winding);
            *edge = (a, b, -a * p.0 - b * p.1);
        }
        let edges = &edges[..count];
        // n · line(x, y) is linear in the pixel coordinates; t = n · (p0 − eye) / n · line.
        let along_0 = normal.dot(self.view)
            + normal.dot(self.across.0) * self.origin.0
            + normal.dot(self.across.1) * self.origin.1;
        let along_x = normal.dot(self.across.0) * self.pixel.0;
        let along_y = normal.dot(self.across.1) * self.pixel.1;
        let numerator = normal.dot(shape.point(0.0, 0.0) - self.eye);
        let pixel_image = self.pixel.0 * self.pixel.1;
        let (x_min, x_max) = polygon.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
        let (y_min, y_max) = polygon.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
        // Truncation is the floor at and above 0 (libm's floor is a call on x86-64 v1).
        let first = |v: f32| (v.max(0.0) as usize).min(size);
        let end = |v: f32| (v.max(-1.0) as usize + 1).min(size);
        let offsets = sample_offsets();
        for y in first(y_min)..end(y_max) {
            for x in first(x_min)..end(x_max) {
                let pixel = y * size + x;
                let (cx, cy) = (x as f32 + offsets[pixel].0, y as f32 + offsets[pixel].1);
                if edges.iter().all(|&(a, b, c)| a * cx + b * cy + c >= 0.0) {
                    let along = along_0 + along_x * cx + along_y * cy;
                    let t = numerator / along;
                    draw(pixel, t);
                    covered.pixels += 1;
                    covered.area_m2 += pixel_image * t * t / along.abs();
                }
            }
        }
        covered
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Unoccluded;

    /// An eye far above the origin: the view is nearly orthographic.
    const FAR_ABOVE: Vec3A = Vec3A::new(0.0, 0.0, 1.0e3);

    fn square(centre: Vec3A, half_m: f32, normal_z: f32) -> ElementShape {
        let (e1, e2) = if normal_z > 0.0 {
            (Vec3A::X * 2.0 * half_m, Vec3A::Y * 2.0 * half_m)
        } else {
            (Vec3A::Y * 2.0 * half_m, Vec3A::X * 2.0 * half_m)
        };
        ElementShape::Parallelogram {
            p0: centre - Vec3A::new(half_m, half_m, 0.0),
            e1,
            e2,
        }
    }

    #[test]
    fn a_stack_shows_its_top_plate_only() {
        // Five unit plates stacked along z, each smaller one higher up: seen from above,
        // each shows the ring the ones above leave.
        let plates: Vec<ElementShape> = (0..5)
            .map(|k| {
                square(
                    Vec3A::new(0.0, 0.0, k as f32 * 0.1),
                    0.5 - 0.08 * k as f32,
                    1.0,
                )
            })
            .collect();
        let h = Hierarchy::build(&plates);
        let fragments = cluster_fragments(&h, h.root, FAR_ABOVE, &[], &Unoccluded).unwrap();
        let mut seen = [0.0f32; 5];
        for f in &fragments {
            seen[f.patch as usize] += f.area_m2;
            assert!(f.in_front);
        }
        let side = |k: usize| 1.0 - 0.16 * k as f32;
        for (k, &seen_k) in seen.iter().enumerate() {
            let expected = side(k).powi(2) - if k < 4 { side(k + 1).powi(2) } else { 0.0 };
            let pixel = (1.0 / 32.0f32).powi(2);
            // A pixel's width of error along each edge of the ring.
            let edge_error = 8.0 * side(k) / 32.0 + pixel;
            assert!(
                (seen_k - expected).abs() <= edge_error,
                "plate {k}: {seen_k} against {expected}"
            );
        }
        // From below, the plates face away: nothing is shown.
        assert!(cluster_fragments(&h, h.root, -FAR_ABOVE, &[], &Unoccluded)
            .unwrap()
            .is_empty());
    }

    #[test]
    fn a_back_side_hides_what_lies_behind_it_and_a_two_sided_surface_shows_its_front() {
        // A plate facing down above one facing up: from above, the upper plate's back
        // hides the lower one.
        let shapes = [
            square(Vec3A::ZERO, 0.5, 1.0),
            square(Vec3A::new(0.0, 0.0, 0.2), 0.5, -1.0),
        ];
        let h = Hierarchy::build(&shapes);
        assert!(cluster_fragments(&h, h.root, FAR_ABOVE, &[], &Unoccluded)
            .unwrap()
            .is_empty());
        // Both sides of one surface: the side facing the viewer is shown, whole.
        let shapes = [
            square(Vec3A::ZERO, 0.5, -1.0),
            square(Vec3A::ZERO, 0.5, 1.0),
        ];
        let h = Hierarchy::build(&shapes);
        let fragments = cluster_fragments(&h, h.root, FAR_ABOVE, &[], &Unoccluded).unwrap();
        let area: f32 = fragments.iter().map(|f| f.area_m2).sum();
        assert!(fragments.iter().all(|f| f.patch == 1));
        assert!((area - 1.0).abs() < 1e-4, "{area}");
    }

    #[test]
    fn a_see_through_patch_lets_its_transparency_through() {
        // A see-through sheet (τ 0.3, a patch per side) over an opaque plate.
        let shapes = [
            square(Vec3A::ZERO, 0.5, 1.0),
            square(Vec3A::new(0.0, 0.0, 0.2), 0.5, 1.0),
            square(Vec3A::new(0.0, 0.0, 0.2), 0.5, -1.0),
        ];
        let h = Hierarchy::build(&shapes);
        struct Sheet;
        impl Visibility for Sheet {
            fn visible(&self, _: Vec3A, _: Vec3A, _: Vec3A, _: Vec3A) -> bool {
                true
            }
            fn transparency(&self, patch: u32, _: Vec3A) -> f32 {
                if patch == 0 {
                    0.0
                } else {
                    0.3
                }
            }
            fn any_see_through(&self) -> bool {
                true
            }
        }
        let fragments = cluster_fragments(&h, h.root, FAR_ABOVE, &[], &Sheet).unwrap();
        let mut seen = [0.0f32; 3];
        for f in &fragments {
            seen[f.patch as usize] += f.area_m2;
            assert_eq!(f.in_front, f.patch == 1, "{f:?}");
        }
        assert!((seen[1] - 1.0).abs() < 1e-4, "{seen:?}");
        assert!((seen[0] - 0.3).abs() < 1e-4, "{seen:?}");
        assert_eq!(seen[2], 0.0);
        // Fragments lie on their patch's plane.
        for f in &fragments {
            let z = if f.patch == 0 { 0.0 } else { 0.2 };
            // f32 along a view line from 1 km away.
            assert!((f.point_m.z - z).abs() < 1e-3);
        }
    }

    #[test]
    fn patches_smaller_than_a_pixel_cover_what_they_cover() {
        // A 1 m plate of 100 × 100 squares, ten to a pixel's width, over a second one
        // 0.1 m below: the top plate shows its whole area and hides the lower one.
        let mut shapes = Vec::new();
        for layer in 0..2 {
            for i in 0..100 {
                for j in 0..100 {
                    let p0 = Vec3A::new(
                        i as f32 * 0.01 - 0.5,
                        j as f32 * 0.01 - 0.5,
                        -0.1 * layer as f32,
                    );
                    shapes.push(ElementShape::Parallelogram {
                        p0,
                        e1: Vec3A::X * 0.01,
                        e2: Vec3A::Y * 0.01,
                    });
                }
            }
        }
        let h = Hierarchy::build(&shapes);
        let fragments = cluster_fragments(&h, h.root, FAR_ABOVE, &[], &Unoccluded).unwrap();
        let top: f32 = fragments
            .iter()
            .filter(|f| f.patch < 10_000)
            .map(|f| f.area_m2)
            .sum();
        let lower: f32 = fragments
            .iter()
            .filter(|f| f.patch >= 10_000)
            .map(|f| f.area_m2)
            .sum();
        assert!((top - 1.0).abs() < 0.01, "{top}");
        assert_eq!(lower, 0.0);
    }

    #[test]
    fn a_cluster_beside_or_behind_the_eye_cannot_be_framed() {
        let shapes = [
            square(Vec3A::ZERO, 0.5, 1.0),
            square(Vec3A::new(0.0, 0.0, 0.2), 0.5, 1.0),
        ];
        let h = Hierarchy::build(&shapes);
        // The eye inside the box: part of it lies behind.
        assert!(
            cluster_fragments(&h, h.root, Vec3A::new(0.0, 0.0, 0.1), &[], &Unoccluded).is_none()
        );
        // A patch's root is not a cluster.
        assert!(cluster_fragments(&h, h.patch_root[0], FAR_ABOVE, &[], &Unoccluded).is_none());
    }
}
