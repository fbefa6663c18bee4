//! Principal curvatures from the shape operator (Weingarten map).
//!
//! With tangents `∂p/∂u, ∂p/∂v` and the derivatives `∂n/∂u, ∂n/∂v` of the *unit* normal, the
//! Weingarten equations (do Carmo, "Differential Geometry of Curves and Surfaces", §3-3;
//! pbrt-v4 §6.2.3 eq. 6.5) say `[∂n/∂u ∂n/∂v] = [∂p/∂u ∂p/∂v]·A` with `A = I⁻¹·II`, where
//! `I = [[E, F], [F, G]]` is the first fundamental form and `II` the second. Here
//! `II = [[∂p/∂u·∂n/∂u, ∂p/∂u·∂n/∂v], [∂p/∂v·∂n/∂u, ∂p/∂v·∂n/∂v]]` (symmetrised) — the
//! least-squares solution when the normal derivatives come from interpolated normals and are
//! not exactly tangent. The eigenvalues of `A` are the principal curvatures.
//!
//! Sign convention: curvature is positive where the normal turns *away* from the surface as
//! one moves along it (`∂n = +k ∂p`), so a sphere with outward normals has `k1 = k2 = 1/r`
//! (in 1/m), a plane 0, and a sphere seen from inside (normals inward) `−1/r`.

use glam::Vec3A;

/// Principal curvatures (1/m) and directions at a surface point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Curvature {
    /// Larger principal curvature, 1/m.
    pub k1: f32,
    /// Smaller principal curvature, 1/m.
    pub k2: f32,
    /// Unit tangent direction of `k1`.
    pub dir1: Vec3A,
    /// Unit tangent direction of `k2` (orthogonal to `dir1`).
    pub dir2: Vec3A,
}

impl Curvature {
    /// Mean curvature `(k1 + k2)/2`, 1/m.
    pub fn mean(&self) -> f32 {
        0.5 * (self.k1 + self.k2)
    }

    /// Gaussian curvature `k1·k2`, 1/m².
    pub fn gaussian(&self) -> f32 {
        self.k1 * self.k2
    }

    /// Curvature from tangents and unit-normal derivatives; `n` is the unit normal the
    /// derivatives belong to (used for directions at umbilic points and degenerate input).
    pub fn from_derivatives(dpdu: Vec3A, dpdv: Vec3A, dndu: Vec3A, dndv: Vec3A, n: Vec3A) -> Self {
        let fallback_dir = || {
            dpdu.try_normalize()
                .map(|d| (d - n * n.dot(d)).normalize_or_zero())
                .unwrap_or(Vec3A::ZERO)
        };
        // Flat (every face of a polygon mesh without vertex normals, rectangles, disks):
        // the second fundamental form is zero, so both curvatures are exactly 0 — the same
        // result as the general path below, without its arithmetic (path tracers ask for
        // an interaction at every vertex).
        if dndu == Vec3A::ZERO && dndv == Vec3A::ZERO {
            let dir1 = fallback_dir();
            return Self {
                k1: 0.0,
                k2: 0.0,
                dir1,
                dir2: n.cross(dir1),
            };
        }
        let (e1, f1, g1) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
        let (e2, g2) = (dpdu.dot(dndu), dpdv.dot(dndv));
        let f2 = 0.5 * (dpdu.dot(dndv) + dpdv.dot(dndu));
        let det = e1 * g1 - f1 * f1;
        let fallback_dir = fallback_dir();
        if det.is_nan() || det <= 0.0 || det.is_infinite() {
            return Self {
                k1: 0.0,
                k2: 0.0,
                dir1: fallback_dir,
                dir2: n.cross(fallback_dir),
            };
        }
        let inv = 1.0 / det;
        // A = I⁻¹ · II
        let a11 = (g1 * e2 - f1 * f2) * inv;
        let a12 = (g1 * f2 - f1 * g2) * inv;
        let a21 = (e1 * f2 - f1 * e2) * inv;
        let a22 = (e1 * g2 - f1 * f2) * inv;
        let half_tr = 0.5 * (a11 + a22);
        let d = a11 * a22 - a12 * a21;
        // Real eigenvalues in exact arithmetic (A is self-adjoint w.r.t. I); clamp rounding.
        let disc = (half_tr * half_tr - d).max(0.0).sqrt();
        let (k1, k2) = (half_tr + disc, half_tr - disc);
        // Eigenvector (x, y) of k1 in the (dpdu, dpdv) basis: (A − k1) (x, y)ᵀ = 0.
        let c1 = Vec3A::new(a12, k1 - a11, 0.0);
        let c2 = Vec3A::new(k1 - a22, a21, 0.0);
        let c = if c1.length_squared() >= c2.length_squared() {
            c1
        } else {
            c2
        };
        let scale = (k1.abs() + k2.abs()).max(f32::MIN_POSITIVE);
        let dir1 = if c.length_squared() > (1e-6 * scale) * (1e-6 * scale) {
            let t = dpdu * c.x + dpdv * c.y;
            (t - n * n.dot(t)).try_normalize().unwrap_or(fallback_dir)
        } else {
            fallback_dir // umbilic point: every direction is principal
        };
        Self {
            k1,
            k2,
            dir1,
            dir2: n.cross(dir1),
        }
    }
}

/// Derivative of the unit normal `N/|N|` given the derivative `dN` of an unnormalised normal
/// field `N` (quotient rule): `(dN − n̂(n̂·dN)) / |N|`.
#[inline]
pub fn unit_normal_derivative(n_unnormalised: Vec3A, dn: Vec3A) -> Vec3A {
    let len = n_unnormalised.length();
    if len == 0.0 {
        return Vec3A::ZERO;
    }
    let n = n_unnormalised / len;
    (dn - n * n.dot(dn)) / len
}
