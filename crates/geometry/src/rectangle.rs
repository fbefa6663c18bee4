//! Analytic rectangle (quad) in the object-space plane z = 0, centred on the origin, normal
//! +z, spanning `[-half_width_m, half_width_m] × [-half_height_m, half_height_m]`; uv from
//! (0, 0) at the (−x, −y) corner to (1, 1) at (+x, +y).

use glam::{Vec2, Vec3A};

use crate::interaction::LocalGeometry;
use crate::ray::Ray;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rectangle {
    pub half_width_m: f32,
    pub half_height_m: f32,
}

impl Rectangle {
    /// Two-sided hit with the plane z = 0 inside the rectangle (edges included).
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        if ray.direction.z == 0.0 {
            return None;
        }
        let t = -ray.origin.z / ray.direction.z;
        if !(t > ray.t_min && t < ray.t_max) {
            return None;
        }
        let p = ray.at(t);
        (p.x.abs() <= self.half_width_m && p.y.abs() <= self.half_height_m).then_some(t)
    }

    /// Differential geometry at `p_hit`: constant tangents, zero normal derivatives.
    pub fn local_geometry(&self, p_hit: Vec3A) -> LocalGeometry {
        let p = Vec3A::new(p_hit.x, p_hit.y, 0.0);
        let (w, h) = (self.half_width_m, self.half_height_m);
        LocalGeometry {
            p,
            n_geometric: Vec3A::Z,
            n_shading: Vec3A::Z,
            uv: Vec2::new((p.x + w) / (2.0 * w), (p.y + h) / (2.0 * h)),
            dpdu: Vec3A::new(2.0 * w, 0.0, 0.0),
            dpdv: Vec3A::new(0.0, 2.0 * h, 0.0),
            dndu: Vec3A::ZERO,
            dndv: Vec3A::ZERO,
        }
    }

    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        (
            Vec3A::new(-self.half_width_m, -self.half_height_m, 0.0),
            Vec3A::new(self.half_width_m, self.half_height_m, 0.0),
        )
    }
}
