//! Closest-hit and any-hit queries of `N` rays at once against every flat patch of a small
//! scene (`prism_geometry::FlatLeaf`): the rays sit in the lanes, each patch is broadcast,
//! and one straight-line loop over the lanes tests them all — code LLVM turns into `N`-wide
//! vector instructions inside the packet tracer's `target_feature` functions.
//!
//! The test (after Baldwin & Weber 2016, "Fast ray-triangle intersections by coordinate
//! transformation", JCGT 5(3)) stores per patch the affine map from world space to the
//! patch's own coordinates (u, v along its edges, w along its normal): the ray meets the
//! plane w = 0 at t = −w(o)/w′(d), and u, v there decide the hit — one formula for
//! triangles (u, v ≥ 0, u + v ≤ 1) and parallelograms (u, v ∈ [0, 1]), ≈ 40 operations per
//! patch for all lanes at once. The bounds are widened by [`EDGE_TOLERANCE`] so that a ray
//! through the shared edge of two triangles of a closed mesh hits at least one of them
//! (each triangle rounds with its own map, so the test is not watertight; the scalar path's
//! watertight test of Woop et al. 2013 is): patches grow by 1e-5 of their edge lengths,
//! and a ray through an edge may report either neighbour — the same surface, normal and
//! material where the mesh is flat.

// Lanes index several arrays at once: `for l in 0..N` is the clearest form.
#![allow(clippy::needless_range_loop)]

use glam::Vec2;
use glam::{Mat3A, Vec3A};
use prism_geometry::fast_path::{BoxFace, FlatBox, FlatLeaf, PatchKind};

/// Relative widening of the barycentric bounds (see the module docs).
pub(crate) const EDGE_TOLERANCE: f32 = 1e-5;

/// One patch: rows `u`, `v`, `w` of the world → patch map, each (x, y, z, offset), then the
/// patch's index in the scene's leaf list; one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct PatchRow {
    m: [f32; 12],
    leaf: u32,
}

/// The patches of one kind.
#[derive(Clone, Debug, Default)]
pub(crate) struct PatchSet {
    rows: Vec<PatchRow>,
}

impl PatchSet {
    /// The patches of `kind` among `leaves`; degenerate ones (no area, non-finite) are left
    /// out, as no ray can hit them.
    /// Leaves with `skip[i]` set (the triangles of boxes) are left out too.
    pub fn new(leaves: &[FlatLeaf], kind: PatchKind, skip: &[bool]) -> Self {
        let mut rows = Vec::new();
        for (i, leaf) in leaves
            .iter()
            .enumerate()
            .filter(|&(i, l)| l.kind == kind && !skip[i])
        {
            let n = leaf.e1.cross(leaf.e2);
            let to_world = Mat3A::from_cols(leaf.e1, leaf.e2, n);
            let det = to_world.determinant();
            if !(det.is_finite() && det != 0.0) {
                continue;
            }
            let world_to_patch = to_world.inverse();
            let offset = -(world_to_patch * leaf.p0);
            // Rows of the world → patch map are the columns of its transpose.
            let inv = world_to_patch.transpose();
            let row = |r: Vec3A, c: f32| [r.x, r.y, r.z, c];
            let (u, v, w) = (
                row(inv.x_axis, offset.x),
                row(inv.y_axis, offset.y),
                row(inv.z_axis, offset.z),
            );
            let m = [
                u[0], u[1], u[2], u[3], v[0], v[1], v[2], v[3], w[0], w[1], w[2], w[3],
            ];
            if m.iter().all(|x| x.is_finite()) {
                rows.push(PatchRow { m, leaf: i as u32 });
            }
        }
        Self { rows }
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }
}

/// Marks a closest hit on box `leaf & !BOX_HIT` (resolved to its triangle by
/// [`BoxSet::triangle_at`]).
pub(crate) const BOX_HIT: u32 = 1 << 31;

/// One box: rows of the world → box-space map ([−1, 1]³), one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct BoxRow {
    m: [f32; 12],
}

/// Parallelepipeds tested as boxes (slab test in box space, Kay & Kajiya 1986) instead of
/// their 12 triangles: watertight by construction, ≈ 50 operations for all lanes.
#[derive(Clone, Debug, Default)]
pub(crate) struct BoxSet {
    rows: Vec<BoxRow>,
    faces: Vec<[BoxFace; 6]>,
}

impl BoxSet {
    pub fn new(boxes: &[FlatBox]) -> Self {
        Self {
            rows: boxes
                .iter()
                .map(|b| {
                    let r = &b.world_to_box;
                    BoxRow {
                        m: [
                            r[0][0], r[0][1], r[0][2], r[0][3], r[1][0], r[1][1], r[1][2], r[1][3],
                            r[2][0], r[2][1], r[2][2], r[2][3],
                        ],
                    }
                })
                .collect(),
            faces: boxes.iter().map(|b| b.faces).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// `triangle_at` for every lane whose closest hit is a box (leaf `BOX_HIT | box`), at
    /// its hit point o + t·d: one pass over the lanes per box that any lane hit, in vector
    /// code (the face's triangles picked by selects), the same arithmetic as
    /// `triangle_at` — which, lane by lane, cost ≈ 5 % of a Cornell box render.
    #[inline(always)]
    pub fn resolve_triangles<const N: usize>(
        &self,
        rays: &RayLanes<N>,
        t: &[f32; N],
        leaf: &mut [u32; N],
    ) {
        let mut p = [[0.0f32; N]; 3];
        for l in 0..N {
            for a in 0..3 {
                p[a][l] = rays.o[a][l] + t[l] * rays.d[a][l];
            }
        }
        for (k, (row, faces)) in self.rows.iter().zip(&self.faces).enumerate() {
            let tag = BOX_HIT | k as u32;
            let mut any = false;
            for l in 0..N {
                any |= leaf[l] == tag;
            }
            if !any {
                continue;
            }
            let m = &row.m;
            for l in 0..N {
                let q = [0, 1, 2].map(|a| {
                    m[4 * a] * p[0][l]
                        + m[4 * a + 1] * p[1][l]
                        + m[4 * a + 2] * p[2][l]
                        + m[4 * a + 3]
                });
                let first_axis = q[0].abs() >= q[1].abs() && q[0].abs() >= q[2].abs();
                let second_axis = !first_axis && q[1].abs() >= q[2].abs();
                let (axis, q_axis) = if first_axis {
                    (0, q[0])
                } else if second_axis {
                    (1, q[1])
                } else {
                    (2, q[2])
                };
                let face = 2 * axis + u32::from(q_axis > 0.0);
                // The face's coordinates: the other two axes in increasing order.
                let x = Vec2::new(
                    if first_axis { q[1] } else { q[0] },
                    if first_axis || second_axis {
                        q[2]
                    } else {
                        q[1]
                    },
                );
                let (mut tri, mut first, mut second) = ([Vec2::ZERO; 3], 0u32, 0u32);
                for (f, &[(leaf_a, vertices), (leaf_b, _)]) in faces.iter().enumerate() {
                    let here = face == f as u32;
                    for (t, v) in tri.iter_mut().zip(vertices) {
                        *t = Vec2::new(if here { v.x } else { t.x }, if here { v.y } else { t.y });
                    }
                    first = if here { leaf_a } else { first };
                    second = if here { leaf_b } else { second };
                }
                let [a, b, c] = tri;
                let edge = |p0: Vec2, p1: Vec2| (p1 - p0).perp_dot(x - p0);
                let (e0, e1, e2) = (edge(a, b), edge(b, c), edge(c, a));
                let inside =
                    (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
                let resolved = if inside { first } else { second };
                leaf[l] = if leaf[l] == tag { resolved } else { leaf[l] };
            }
        }
    }

    /// The leaf (triangle) of box `index` at world point `p` on its surface: the face is
    /// the box-space axis where |q| is largest, the triangle the one of that face's two
    /// that holds q (2D edge functions). `resolve_triangles`' reference, one point at a
    /// time.
    #[cfg(test)]
    pub fn triangle_at(&self, index: usize, p: Vec3A) -> u32 {
        let m = &self.rows[index].m;
        let q = [0, 1, 2]
            .map(|a| m[4 * a] * p.x + m[4 * a + 1] * p.y + m[4 * a + 2] * p.z + m[4 * a + 3]);
        let axis = if q[0].abs() >= q[1].abs() && q[0].abs() >= q[2].abs() {
            0
        } else if q[1].abs() >= q[2].abs() {
            1
        } else {
            2
        };
        let face = 2 * axis + usize::from(q[axis] > 0.0);
        let (u, v) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let x = Vec2::new(q[u], q[v]);
        let [(first, [a, b, c]), (second, _)] = self.faces[index][face];
        let edge = |p0: Vec2, p1: Vec2| (p1 - p0).perp_dot(x - p0);
        let (e0, e1, e2) = (edge(a, b), edge(b, c), edge(c, a));
        let inside = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
        if inside {
            first
        } else {
            second
        }
    }
}

/// Slab test of lane `l` against one box: (entry or exit t, its nearest crossing of the
/// surface in `(t_min, t_max)` exists, the segment `(t_min, t_max)` crosses the surface).
#[inline(always)]
fn test_box<const N: usize>(
    rays: &RayLanes<N>,
    m: &[f32; 12],
    t_max: &[f32; N],
    l: usize,
) -> (f32, bool, bool) {
    let (ox, oy, oz) = (rays.o[0][l], rays.o[1][l], rays.o[2][l]);
    let (dx, dy, dz) = (rays.d[0][l], rays.d[1][l], rays.d[2][l]);
    let mut near = f32::NEG_INFINITY;
    let mut far = f32::INFINITY;
    for a in 0..3 {
        let r = &m[4 * a..4 * a + 4];
        let o = r[0] * ox + r[1] * oy + r[2] * oz + r[3];
        let d = r[0] * dx + r[1] * dy + r[2] * dz;
        let inv = 1.0 / d;
        let t0 = (-1.0 - o) * inv;
        let t1 = (1.0 - o) * inv;
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    let (t_min, t_end) = (rays.t_min[l], t_max[l]);
    let crosses = near <= far;
    let near_in = (near > t_min) & (near < t_end);
    let far_in = (far > t_min) & (far < t_end);
    let enters = near > t_min;
    let t = if enters { near } else { far };
    (
        t,
        crosses & (near_in | (!enters & far_in)),
        crosses & (near_in | far_in),
    )
}

/// `N` rays, structure-of-arrays. A lane with `t_min = +∞` is idle: nothing can hit it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayLanes<const N: usize> {
    pub o: [[f32; N]; 3],
    pub d: [[f32; N]; 3],
    pub t_min: [f32; N],
    pub t_max: [f32; N],
}

impl<const N: usize> RayLanes<N> {
    pub fn idle() -> Self {
        Self {
            o: [[0.0; N]; 3],
            d: [[0.0; N]; 3],
            t_min: [f32::INFINITY; N],
            t_max: [0.0; N],
        }
    }

    #[inline]
    pub fn set(&mut self, lane: usize, origin: Vec3A, direction: Vec3A, t_min: f32, t_max: f32) {
        for axis in 0..3 {
            self.o[axis][lane] = origin[axis];
            self.d[axis][lane] = direction[axis];
        }
        self.t_min[lane] = t_min;
        self.t_max[lane] = t_max;
    }
}

/// The patch test for lane `l`: (t, hit), hit only inside `(t_min, t_max)`.
#[inline(always)]
fn test_patch<const N: usize, const PARALLELOGRAM: bool>(
    rays: &RayLanes<N>,
    m: &[f32; 12],
    t_max: &[f32; N],
    l: usize,
) -> (f32, bool) {
    let (ox, oy, oz) = (rays.o[0][l], rays.o[1][l], rays.o[2][l]);
    let (dx, dy, dz) = (rays.d[0][l], rays.d[1][l], rays.d[2][l]);
    let w_o = m[8] * ox + m[9] * oy + m[10] * oz + m[11];
    let w_d = m[8] * dx + m[9] * dy + m[10] * dz;
    let t = -w_o / w_d;
    let u = (m[0] * ox + m[1] * oy + m[2] * oz + m[3]) + t * (m[0] * dx + m[1] * dy + m[2] * dz);
    let v = (m[4] * ox + m[5] * oy + m[6] * oz + m[7]) + t * (m[4] * dx + m[5] * dy + m[6] * dz);
    let lo = -EDGE_TOLERANCE;
    let hi = 1.0 + EDGE_TOLERANCE;
    // `&` not `&&`: no branches, so the lane loop vectorises (NaN compares false).
    let inside = if PARALLELOGRAM {
        (u >= lo) & (u <= hi) & (v >= lo) & (v <= hi)
    } else {
        (u >= lo) & (v >= lo) & (u + v <= hi)
    };
    (t, inside & (t > rays.t_min[l]) & (t < t_max[l]))
}

#[inline(always)]
fn closest_in_set<const N: usize, const PARALLELOGRAM: bool>(
    set: &PatchSet,
    rays: &RayLanes<N>,
    best_t: &mut [f32; N],
    best_leaf: &mut [u32; N],
) {
    // Local copies, written back once: through the references LLVM keeps them in memory,
    // and each patch's masked store then stalls the next patch's compare.
    let (mut t_best, mut leaf_best) = (*best_t, *best_leaf);
    for row in &set.rows {
        // A local, not `row.leaf` in the select: LLVM would select between the two
        // addresses and gather.
        let leaf = row.leaf;
        for l in 0..N {
            let (t, hit) = test_patch::<N, PARALLELOGRAM>(rays, &row.m, &t_best, l);
            t_best[l] = if hit { t } else { t_best[l] };
            leaf_best[l] = if hit { leaf } else { leaf_best[l] };
        }
    }
    (*best_t, *best_leaf) = (t_best, leaf_best);
}

/// Per lane the closest hit in `(t_min, t_max)`: (t, leaf index), leaf `u32::MAX` for a
/// miss.
#[inline(always)]
pub(crate) fn closest<const N: usize>(
    triangles: &PatchSet,
    parallelograms: &PatchSet,
    boxes: &BoxSet,
    rays: &RayLanes<N>,
) -> ([f32; N], [u32; N]) {
    let mut best_t = rays.t_max;
    let mut best_leaf = [u32::MAX; N];
    closest_in_set::<N, true>(parallelograms, rays, &mut best_t, &mut best_leaf);
    closest_in_set::<N, false>(triangles, rays, &mut best_t, &mut best_leaf);
    let (mut t_best, mut leaf_best) = (best_t, best_leaf);
    for (k, row) in boxes.rows.iter().enumerate() {
        let tag = BOX_HIT | k as u32;
        for l in 0..N {
            let (t, hit, _) = test_box(rays, &row.m, &t_best, l);
            t_best[l] = if hit { t } else { t_best[l] };
            leaf_best[l] = if hit { tag } else { leaf_best[l] };
        }
    }
    boxes.resolve_triangles(rays, &t_best, &mut leaf_best);
    (t_best, leaf_best)
}

#[inline(always)]
fn any_in_set<const N: usize, const PARALLELOGRAM: bool>(
    set: &PatchSet,
    rays: &RayLanes<N>,
    occluded: &mut [bool; N],
) -> bool {
    let mut blocked = *occluded;
    let mut all = false;
    for row in &set.rows {
        all = true;
        for l in 0..N {
            let (_, hit) = test_patch::<N, PARALLELOGRAM>(rays, &row.m, &rays.t_max, l);
            blocked[l] |= hit;
            all &= blocked[l];
        }
        if all {
            break;
        }
    }
    *occluded = blocked;
    all
}

/// Per lane whether anything lies in `(t_min, t_max)`; idle lanes report `true` (there is
/// nothing to see), so the search stops once every active lane is blocked.
#[inline(always)]
pub(crate) fn occluded<const N: usize>(
    triangles: &PatchSet,
    parallelograms: &PatchSet,
    boxes: &BoxSet,
    rays: &RayLanes<N>,
) -> [bool; N] {
    let mut occluded = [false; N];
    for l in 0..N {
        let active = rays.t_min[l] < rays.t_max[l];
        occluded[l] = !active;
    }
    // Boxes first: the likeliest blockers of a room's shadow rays.
    let mut all = false;
    for row in &boxes.rows {
        all = true;
        for l in 0..N {
            let (_, _, crosses) = test_box(rays, &row.m, &rays.t_max, l);
            occluded[l] |= crosses;
            all &= occluded[l];
        }
        if all {
            break;
        }
    }
    if !all && !any_in_set::<N, true>(parallelograms, rays, &mut occluded) {
        any_in_set::<N, false>(triangles, rays, &mut occluded);
    }
    occluded
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on every face of a tilted, sheared box, off and on the faces' diagonals and
    /// edges: the lanes' triangles are `triangle_at`'s.
    #[test]
    fn box_triangles_of_all_lanes_are_the_single_lookups() {
        // World → box rows of an affine box (sheared, rotated, offset) and its faces'
        // triangles split along alternating diagonals, leaves numbered 100 + 2·face (+1).
        let world_to_box = [
            [0.9, 0.2, -0.1, 0.3],
            [-0.15, 1.1, 0.05, -0.2],
            [0.1, -0.05, 0.8, 0.1],
        ];
        let corner = |x: f32, y: f32| Vec2::new(x, y);
        let faces: [BoxFace; 6] = std::array::from_fn(|f| {
            let (a, b, c, d) = (
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            );
            let first = 100 + 2 * f as u32;
            if f % 2 == 0 {
                [(first, [a, b, c]), (first + 1, [a, c, d])]
            } else {
                [(first, [b, c, d]), (first + 1, [a, b, d])]
            }
        });
        let boxes = BoxSet::new(&[FlatBox {
            world_to_box,
            faces,
        }]);
        let m = Mat3A::from_cols_array(&[
            world_to_box[0][0],
            world_to_box[1][0],
            world_to_box[2][0],
            world_to_box[0][1],
            world_to_box[1][1],
            world_to_box[2][1],
            world_to_box[0][2],
            world_to_box[1][2],
            world_to_box[2][2],
        ]);
        let offset = Vec3A::new(world_to_box[0][3], world_to_box[1][3], world_to_box[2][3]);
        let to_world = m.inverse();
        let mut checked = 0;
        for n in 0..6 * 64 {
            let face = n % 6;
            let (axis, side) = (face / 2, if face % 2 == 1 { 1.0 } else { -1.0 });
            let s = (n as f32 * 0.618_034).fract() * 2.0 - 1.0;
            let r = if n % 5 == 0 {
                s
            } else {
                (n as f32 * 0.414_214).fract() * 2.0 - 1.0
            };
            let mut q = [s, r];
            if n % 7 == 0 {
                q[1] = 1.0; // on an edge
            }
            let mut b = [0.0f32; 3];
            b[axis] = side;
            let others: Vec<usize> = (0..3).filter(|&a| a != axis).collect();
            (b[others[0]], b[others[1]]) = (q[0], q[1]);
            let world = to_world * (Vec3A::from_array(b) - offset);
            // One lane at the point, along a ray from the origin: o + t·d = world.
            const N: usize = 16;
            let mut rays = RayLanes::<N>::idle();
            let lane = n % N;
            rays.set(lane, Vec3A::ZERO, world, 0.0, f32::INFINITY);
            let mut t = [0.0f32; N];
            t[lane] = 1.0;
            let mut leaf = [u32::MAX; N];
            leaf[lane] = BOX_HIT;
            boxes.resolve_triangles(&rays, &t, &mut leaf);
            let p = Vec3A::new(
                rays.o[0][lane] + t[lane] * rays.d[0][lane],
                rays.o[1][lane] + t[lane] * rays.d[1][lane],
                rays.o[2][lane] + t[lane] * rays.d[2][lane],
            );
            assert_eq!(
                leaf[lane],
                boxes.triangle_at(0, p),
                "point {n} on face {face}"
            );
            assert!(leaf
                .iter()
                .enumerate()
                .all(|(l, &v)| l == lane || v == u32::MAX));
            checked += 1;
        }
        assert_eq!(checked, 384);
    }
}
