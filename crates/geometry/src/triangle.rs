//! Watertight ray/triangle intersection: Woop, Benthin & Wald 2013, "Watertight ray/triangle
//! intersection", JCGT 2(1); as written in pbrt-v4 §6.5.3 "Triangle intersection".
//!
//! The ray is translated to the origin, its axes permuted so that its largest direction
//! component is z, and sheared so that it points along +z. Each edge function is then a 2D
//! cross product of the same two sheared vertices in both triangles sharing the edge, computed
//! with plain products (not FMA) so that the two values are exact negatives of each other: a ray
//! through a shared edge or vertex is accepted by at least one of the triangles (edges with
//! edge function 0 count as inside). When an edge function is exactly 0 it is recomputed in
//! f64, as the paper and pbrt-v4 do, to resolve the sign.

use glam::{Mat3A, Vec3A, Vec3Swizzles};

/// Per-ray constants of the watertight test (paper §3, "precomputation"). The permutation and
/// shear are folded into three row vectors, so that the sheared coordinates of a vertex `a`
/// (relative to the origin) are `a·shear_x = a[kx] + Sx·a[kz]`, `a·shear_y = a[ky] + Sy·a[kz]`
/// and `a·pick_z = a[kz]`. Each row has one zero entry whose product is an exact zero, so the
/// sums round exactly like the paper's scalar code, and the same vertex always yields the same
/// bits — which is what watertightness rests on. Three vertices are transformed at once with a
/// 3×3 matrix product (SIMD) instead of branchy per-component indexing.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub origin: Vec3A,
    // Read by the many-triangles-at-once test of `crate::small_scene`, which must round
    // exactly as `intersect` does.
    pub(crate) shear_x: Vec3A,
    pub(crate) shear_y: Vec3A,
    pub(crate) pick_z: Vec3A,
    pub(crate) sz: f32,
    pub t_min: f32,
}

/// A hit on a triangle: parameter and barycentrics (`p = b0·p0 + b1·p1 + b2·p2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b0: f32,
    pub b1: f32,
    pub b2: f32,
}

impl WatertightRay {
    /// Precompute the permutation and shear for `direction` (need not be normalised).
    #[inline]
    pub fn new(origin: Vec3A, direction: Vec3A, t_min: f32) -> Self {
        let a = direction.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let dz = direction[kz];
        let unit = |k: usize| Vec3A::AXES[k];
        let (sx, sy) = (-direction[kx] / dz, -direction[ky] / dz);
        Self {
            origin,
            shear_x: unit(kx) + sx * unit(kz),
            shear_y: unit(ky) + sy * unit(kz),
            pick_z: unit(kz),
            sz: 1.0 / dz,
            t_min,
        }
    }

    /// Intersect the triangle `p0 p1 p2` within `(t_min, t_max)`; two-sided.
    #[inline(always)]
    pub fn intersect(&self, p0: Vec3A, p1: Vec3A, p2: Vec3A, t_max: f32) -> Option<TriangleHit> {
        // Rows of the vertices relative to the origin; columns (x of a, b, c), … after transpose.
        let m = Mat3A::from_cols(p0 - self.origin, p1 - self.origin, p2 - self.origin).transpose();
        let xs = m * self.shear_x; // (ax, bx, cx)
        let ys = m * self.shear_y; // (ay, by, cy)
        let zs = m * self.pick_z; // (az, bz, cz)

        // Edge functions (paper eq. 4) — u = cx·by − cy·bx, v = ax·cy − ay·cx,
        // w = bx·ay − by·ax — with plain products for exact antisymmetry between neighbours.
        let mut uvw = xs.zxy() * ys.yzx() - ys.zxy() * xs.yzx();
        if uvw.cmpeq(Vec3A::ZERO).any() {
            // Paper §3.1: fall back to double precision on exact zeros.
            let (x, y) = (xs.as_dvec3(), ys.as_dvec3());
            uvw = (x.zxy() * y.yzx() - y.zxy() * x.yzx()).as_vec3a();
        }
        if uvw.cmplt(Vec3A::ZERO).any() && uvw.cmpgt(Vec3A::ZERO).any() {
            return None;
        }
        let det = uvw.element_sum();
        if det == 0.0 {
            return None;
        }
        // Scaled hit distance (paper eq. 6) compared against the interval without dividing.
        let t_scaled = uvw.dot(zs) * self.sz;
        if det > 0.0 {
            if t_scaled <= self.t_min * det || t_scaled >= t_max * det {
                return None;
            }
        } else if t_scaled >= self.t_min * det || t_scaled <= t_max * det {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // Guard the interval after the division too (rounding can push t onto a bound).
        if !(t > self.t_min && t < t_max) {
            return None;
        }
        let b = uvw * inv_det;
        Some(TriangleHit {
            t,
            b0: b.x,
            b1: b.y,
            b2: b.z,
        })
    }
}
