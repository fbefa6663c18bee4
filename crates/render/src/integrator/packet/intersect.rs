//! Closest-hit and any-hit queries of `N` rays at once against every flat patch of a small
//! scene (`prism_geometry::FlatLeaf`): the rays sit in the lanes, each patch is broadcast,
//! and one straight-line loop over the lanes tests them all — code LLVM turns into `N`-wide
//! vector instructions inside the packet tracer's `target_feature` functions.
//!
//! The test is Möller & Trumbore's (1997, "Fast, minimum storage ray/triangle
//! intersection", §2), one formula for triangles (u, v ≥ 0, u + v ≤ 1) and parallelograms
//! (u, v ∈ [0, 1]). Its barycentrics are widened by [`EDGE_TOLERANCE`] so that a ray
//! through the shared edge of two triangles of a closed mesh hits at least one of them
//! (Möller–Trumbore is not watertight; the scalar path's watertight test of Woop et al.
//! 2013 is): patches grow by 1e-5 of their edge lengths, a ray through an edge may report
//! either neighbour — the same surface, normal and material where the mesh is flat.

use glam::Vec3A;
use prism_geometry::{FlatLeaf, PatchKind};

/// Relative widening of the barycentric bounds (see the module docs).
pub(crate) const EDGE_TOLERANCE: f32 = 1e-5;

/// The patches of one kind, structure-of-arrays (`p0[axis][i]`, …), with each one's index
/// in the scene's leaf list.
#[derive(Clone, Debug, Default)]
pub(crate) struct PatchSet {
    p0: [Vec<f32>; 3],
    e1: [Vec<f32>; 3],
    e2: [Vec<f32>; 3],
    leaf: Vec<u32>,
}

impl PatchSet {
    pub fn new(leaves: &[FlatLeaf], kind: PatchKind) -> Self {
        let mut set = Self::default();
        for (i, leaf) in leaves.iter().enumerate().filter(|(_, l)| l.kind == kind) {
            for axis in 0..3 {
                set.p0[axis].push(leaf.p0[axis]);
                set.e1[axis].push(leaf.e1[axis]);
                set.e2[axis].push(leaf.e2[axis]);
            }
            set.leaf.push(i as u32);
        }
        set
    }

    pub fn len(&self) -> usize {
        self.leaf.len()
    }

    #[inline(always)]
    fn patch(&self, j: usize) -> ([f32; 3], [f32; 3], [f32; 3]) {
        let v = |a: &[Vec<f32>; 3]| [a[0][j], a[1][j], a[2][j]];
        (v(&self.p0), v(&self.e1), v(&self.e2))
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

/// Möller–Trumbore for every lane against one patch: (t, hit) per lane, hit only inside
/// `(t_min, t_max)`.
#[inline(always)]
fn test_patch<const N: usize, const PARALLELOGRAM: bool>(
    rays: &RayLanes<N>,
    (p0, e1, e2): ([f32; 3], [f32; 3], [f32; 3]),
    t_max: &[f32; N],
    l: usize,
) -> (f32, bool) {
    let (dx, dy, dz) = (rays.d[0][l], rays.d[1][l], rays.d[2][l]);
    let px = dy * e2[2] - dz * e2[1];
    let py = dz * e2[0] - dx * e2[2];
    let pz = dx * e2[1] - dy * e2[0];
    let inv_det = 1.0 / (e1[0] * px + e1[1] * py + e1[2] * pz);
    let tx = rays.o[0][l] - p0[0];
    let ty = rays.o[1][l] - p0[1];
    let tz = rays.o[2][l] - p0[2];
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    let qx = ty * e1[2] - tz * e1[1];
    let qy = tz * e1[0] - tx * e1[2];
    let qz = tx * e1[1] - ty * e1[0];
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    let t = (e2[0] * qx + e2[1] * qy + e2[2] * qz) * inv_det;
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
    for j in 0..set.len() {
        let patch = set.patch(j);
        let leaf = set.leaf[j];
        for l in 0..N {
            let (t, hit) = test_patch::<N, PARALLELOGRAM>(rays, patch, best_t, l);
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
    for j in 0..set.len() {
        let patch = set.patch(j);
        let mut all = true;
        for l in 0..N {
            let (_, hit) = test_patch::<N, PARALLELOGRAM>(rays, patch, &rays.t_max, l);
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
        occluded[l] = !(rays.t_min[l] < rays.t_max[l]);
    }
    if !any_in_set::<N, true>(parallelograms, rays, &mut occluded) {
        any_in_set::<N, false>(triangles, rays, &mut occluded);
    }
    occluded
}
