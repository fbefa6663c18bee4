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

use glam::{Mat3A, Vec3A};
use prism_geometry::{FlatLeaf, PatchKind};

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
    pub fn new(leaves: &[FlatLeaf], kind: PatchKind) -> Self {
        let mut rows = Vec::new();
        for (i, leaf) in leaves.iter().enumerate().filter(|(_, l)| l.kind == kind) {
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

    #[inline]
    pub fn clear(&mut self, lane: usize) {
        self.t_min[lane] = f32::INFINITY;
        self.t_max[lane] = 0.0;
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
    for row in &set.rows {
        // A local, not `row.leaf` in the select: LLVM would select between the two
        // addresses and gather.
        let leaf = row.leaf;
        for l in 0..N {
            let (t, hit) = test_patch::<N, PARALLELOGRAM>(rays, &row.m, best_t, l);
            best_t[l] = if hit { t } else { best_t[l] };
            best_leaf[l] = if hit { leaf } else { best_leaf[l] };
        }
    }
}

/// Per lane the closest hit in `(t_min, t_max)`: (t, leaf index), leaf `u32::MAX` for a
/// miss.
#[inline(always)]
pub(crate) fn closest<const N: usize>(
    triangles: &PatchSet,
    parallelograms: &PatchSet,
    rays: &RayLanes<N>,
) -> ([f32; N], [u32; N]) {
    let mut best_t = rays.t_max;
    let mut best_leaf = [u32::MAX; N];
    closest_in_set::<N, true>(parallelograms, rays, &mut best_t, &mut best_leaf);
    closest_in_set::<N, false>(triangles, rays, &mut best_t, &mut best_leaf);
    (best_t, best_leaf)
}

#[inline(always)]
fn any_in_set<const N: usize, const PARALLELOGRAM: bool>(
    set: &PatchSet,
    rays: &RayLanes<N>,
    occluded: &mut [bool; N],
) -> bool {
    for row in &set.rows {
        let mut all = true;
        for l in 0..N {
            let (_, hit) = test_patch::<N, PARALLELOGRAM>(rays, &row.m, &rays.t_max, l);
            occluded[l] |= hit;
            all &= occluded[l];
        }
        if all {
            return true;
        }
    }
    false
}

/// Per lane whether anything lies in `(t_min, t_max)`; idle lanes report `true` (there is
/// nothing to see), so the search stops once every active lane is blocked.
#[inline(always)]
pub(crate) fn occluded<const N: usize>(
    triangles: &PatchSet,
    parallelograms: &PatchSet,
    rays: &RayLanes<N>,
) -> [bool; N] {
    let mut occluded = [false; N];
    for l in 0..N {
        let active = rays.t_min[l] < rays.t_max[l];
        occluded[l] = !active;
    }
    if !any_in_set::<N, true>(parallelograms, rays, &mut occluded) {
        any_in_set::<N, false>(triangles, rays, &mut occluded);
    }
    occluded
}
