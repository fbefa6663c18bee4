//! A rectangle emitter (local XY plane, centred, normal +Z, any affine placement — a
//! parallelogram under shear): points uniform in area, density 1/A, converted to solid
//! angle.

use glam::{Vec2, Vec3A};
use prism_geometry::{Rectangle, Transform};

use super::{area_to_solid_angle, plane_normal_and_area_scale, ShapeSample};
use crate::light::LightHit;

#[derive(Clone, Debug, PartialEq)]
pub struct RectangleEmitter {
    pub rectangle: Rectangle,
    pub to_world: Transform,
    normal: Vec3A,
    area_m2: f32,
}

impl RectangleEmitter {
    pub fn new(rectangle: Rectangle, to_world: Transform) -> Self {
        let (normal, scale) = plane_normal_and_area_scale(&to_world);
        let area = 4.0 * rectangle.half_width_m * rectangle.half_height_m * scale;
        Self {
            rectangle,
            to_world,
            normal,
            // NaN/∞ (a degenerate transform) count as no area: nothing is sampled.
            area_m2: if area.is_finite() { area.max(0.0) } else { 0.0 },
        }
    }

    pub fn area_m2(&self) -> f64 {
        f64::from(self.area_m2)
    }

    /// The world unit normal (the side a one-sided emitter lights).
    pub fn normal(&self) -> Vec3A {
        self.normal
    }

    #[inline]
    pub fn sample(&self, reference: Vec3A, u: Vec2) -> Option<ShapeSample> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        let (w, h) = (self.rectangle.half_width_m, self.rectangle.half_height_m);
        let local = Vec3A::new((2.0 * u.x - 1.0) * w, (2.0 * u.y - 1.0) * h, 0.0);
        let p = self.to_world.point(local);
        let pdf = area_to_solid_angle(1.0 / self.area_m2, reference, p, self.normal);
        Some(ShapeSample {
            p,
            n: self.normal,
            pdf,
        })
    }

    /// A point uniform in area (`sample_le`): world position, normal, density 1/A.
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> Option<(Vec3A, Vec3A, f32)> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        let (w, h) = (self.rectangle.half_width_m, self.rectangle.half_height_m);
        let local = Vec3A::new((2.0 * u.x - 1.0) * w, (2.0 * u.y - 1.0) * h, 0.0);
        Some((self.to_world.point(local), self.normal, 1.0 / self.area_m2))
    }

    /// Area density of `sample_area`: 1/A (0 without area).
    #[inline]
    pub fn pdf_area(&self) -> f32 {
        if self.area_m2 > 0.0 {
            1.0 / self.area_m2
        } else {
            0.0
        }
    }

    #[inline]
    pub fn pdf(&self, reference: Vec3A, hit: &LightHit) -> f32 {
        if self.area_m2 <= 0.0 {
            return 0.0;
        }
        area_to_solid_angle(1.0 / self.area_m2, reference, hit.p, self.normal)
    }
}
