//! Analytic sphere centred on the object-space origin (pbrt-v4 §6.2 "Spheres"), full sphere,
//! z the polar axis: u = φ/2π, v = θ/π.

use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

use crate::interaction::LocalGeometry;
use crate::ray::Ray;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub radius_m: f32,
}

impl Sphere {
    /// Nearest `t` in `(t_min, t_max)`. The quadratic is solved in f64 with the discriminant
    /// in the form `4a(r² − |o − (o·d/|d|²) d|²)` (Haines et al., "Precision improvements for
    /// ray/sphere intersection", Ray Tracing Gems ch. 7, as pbrt-v4 §6.2.2 does) and the
    /// numerically stable root pair `q/a, c/q`.
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let o = ray.origin.as_dvec3();
        let d = ray.direction.as_dvec3();
        let r = self.radius_m as f64;
        let a = d.length_squared();
        if a == 0.0 {
            return None;
        }
        let b = 2.0 * d.dot(o);
        let c = o.length_squared() - r * r;
        let v = o - (b / (2.0 * a)) * d;
        let len = v.length();
        let disc = 4.0 * a * (r + len) * (r - len);
        if disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        let q = if b < 0.0 {
            -0.5 * (b - root)
        } else {
            -0.5 * (b + root)
        };
        let (mut t0, mut t1) = (q / a, c / q);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let (lo, hi) = (ray.t_min as f64, ray.t_max as f64);
        [t0, t1]
            .into_iter()
            .find(|&t| t > lo && t < hi)
            .map(|t| t as f32)
            .filter(|&t| t > ray.t_min && t < ray.t_max)
    }

    /// Differential geometry at the object-space point `p_hit` (reprojected onto the sphere).
    /// Outward normal `n = p/r`, so `∂n/∂u = (∂p/∂u)/r`, `∂n/∂v = (∂p/∂v)/r` — the
    /// Weingarten equations for a sphere (pbrt-v4 §6.2.3).
    pub fn local_geometry(&self, p_hit: Vec3A) -> LocalGeometry {
        let r = self.radius_m;
        let mut p = p_hit * (r / p_hit.length());
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * r; // pbrt-v4: avoid the undefined φ at the poles
        }
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let cos_theta = (p.z / r).clamp(-1.0, 1.0);
        let theta = cos_theta.acos();
        let u = phi / (2.0 * PI);
        let v = theta / PI;
        let z_radius = (p.x * p.x + p.y * p.y).sqrt();
        let (cos_phi, sin_phi) = (p.x / z_radius, p.y / z_radius);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi_max = 2.0 * PI;
        let dpdu = Vec3A::new(-phi_max * p.y, phi_max * p.x, 0.0);
        let dpdv = PI * Vec3A::new(p.z * cos_phi, p.z * sin_phi, -r * sin_theta);
        let n = p / r;
        LocalGeometry {
            p,
            n_geometric: n,
            n_shading: n,
            uv: Vec2::new(u, v),
            dpdu,
            dpdv,
            dndu: dpdu / r,
            dndv: dpdv / r,
        }
    }

    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        (Vec3A::splat(-self.radius_m), Vec3A::splat(self.radius_m))
    }
}
