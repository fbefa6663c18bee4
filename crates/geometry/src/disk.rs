//! Analytic disk in the object-space plane z = 0, centred on the origin, normal +z
//! (pbrt-v4 §6.4 "Disks"; no inner radius): u = φ/2π, v = 1 − r_hit/r.

use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

use crate::interaction::LocalGeometry;
use crate::ray::Ray;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub radius_m: f32,
}

impl Disk {
    /// Two-sided hit with the plane z = 0 inside the radius.
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        if ray.direction.z == 0.0 {
            return None;
        }
        let t = -ray.origin.z / ray.direction.z;
        if !(t > ray.t_min && t < ray.t_max) {
            return None;
        }
        let p = ray.at(t);
        (p.x * p.x + p.y * p.y <= self.radius_m * self.radius_m).then_some(t)
    }

    /// Differential geometry at `p_hit` (z snapped to 0). A plane: ∂n/∂u = ∂n/∂v = 0.
    pub fn local_geometry(&self, p_hit: Vec3A) -> LocalGeometry {
        let p = Vec3A::new(p_hit.x, p_hit.y, 0.0);
        let r_hit = (p.x * p.x + p.y * p.y).sqrt();
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let phi_max = 2.0 * PI;
        let dpdu = Vec3A::new(-phi_max * p.y, phi_max * p.x, 0.0);
        // pbrt-v4: dp/dv = (x, y, 0)·(r_inner − r)/r_hit; at the centre use the φ = 0 direction.
        let dpdv = if r_hit > 0.0 {
            Vec3A::new(p.x, p.y, 0.0) * (-self.radius_m / r_hit)
        } else {
            Vec3A::new(-self.radius_m, 0.0, 0.0)
        };
        LocalGeometry {
            p,
            n_geometric: Vec3A::Z,
            n_shading: Vec3A::Z,
            uv: Vec2::new(phi / (2.0 * PI), 1.0 - r_hit / self.radius_m),
            dpdu,
            dpdv,
            dndu: Vec3A::ZERO,
            dndv: Vec3A::ZERO,
        }
    }

    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        let r = self.radius_m;
        (Vec3A::new(-r, -r, 0.0), Vec3A::new(r, r, 0.0))
    }
}
