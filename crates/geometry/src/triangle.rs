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

use glam::Vec3A;

/// Per-ray constants of the watertight test (paper §3, "precomputation").
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub origin: Vec3A,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
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
        Self {
            origin,
            kx,
            ky,
            kz,
            sx: -direction[kx] / dz,
            sy: -direction[ky] / dz,
            sz: 1.0 / dz,
            t_min,
        }
    }

    /// Intersect the triangle `p0 p1 p2` within `(t_min, t_max)`; two-sided.
    #[inline(always)]
    pub fn intersect(&self, p0: Vec3A, p1: Vec3A, p2: Vec3A, t_max: f32) -> Option<TriangleHit> {
        let a = p0 - self.origin;
        let b = p1 - self.origin;
        let c = p2 - self.origin;
        let (az, bz, cz) = (a[self.kz], b[self.kz], c[self.kz]);
        let ax = a[self.kx] + self.sx * az;
        let ay = a[self.ky] + self.sy * az;
        let bx = b[self.kx] + self.sx * bz;
        let by = b[self.ky] + self.sy * bz;
        let cx = c[self.kx] + self.sx * cz;
        let cy = c[self.ky] + self.sy * cz;

        // Edge functions (paper eq. 4), plain products for exact antisymmetry.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Paper §3.1: fall back to double precision on exact zeros.
            let (axd, ayd, bxd, byd, cxd, cyd) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            u = (cxd * byd - cyd * bxd) as f32;
            v = (axd * cyd - ayd * cxd) as f32;
            w = (bxd * ayd - byd * axd) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        // Scaled hit distance (paper eq. 6) compared against the interval without dividing.
        let t_scaled = (u * az + v * bz + w * cz) * self.sz;
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
        Some(TriangleHit {
            t,
            b0: u * inv_det,
            b1: v * inv_det,
            b2: w * inv_det,
        })
    }
}
