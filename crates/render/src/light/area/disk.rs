//! A disk emitter (local XY plane, centred, normal +Z, any affine placement — an ellipse
//! under non-uniform scale): points uniform in area by the concentric map (Shirley & Chiu
//! 1997), density 1/A, converted to solid angle.

use glam::{Vec2, Vec3A};
use prism_geometry::{Disk, Transform};

use super::{area_to_solid_angle, plane_normal_and_area_scale, ShapeSample};
use crate::light::LightHit;
use crate::sampling::sample_uniform_disk_concentric;

#[derive(Clone, Debug, PartialEq)]
pub struct DiskEmitter {
    pub disk: Disk,
    pub to_world: Transform,
    normal: Vec3A,
    area_m2: f32,
}

impl DiskEmitter {
    pub fn new(disk: Disk, to_world: Transform) -> Self {
        let (normal, scale) = plane_normal_and_area_scale(&to_world);
        let area = std::f32::consts::PI * disk.radius_m * disk.radius_m * scale;
        Self {
            disk,
            to_world,
            normal,
            // NaN/∞ (a degenerate transform) count as no area: nothing is sampled.
            area_m2: if area.is_finite() { area.max(0.0) } else { 0.0 },
        }
    }

    /// The unit world normal of the emitting side (zero for a degenerate transform).
    pub(crate) fn normal(&self) -> Vec3A {
        self.normal
    }

    pub fn area_m2(&self) -> f64 {
        f64::from(self.area_m2)
    }

    #[inline]
    pub fn sample(&self, reference: Vec3A, u: Vec2) -> Option<ShapeSample> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        let d = sample_uniform_disk_concentric(u) * self.disk.radius_m;
        let p = self.to_world.point(Vec3A::new(d.x, d.y, 0.0));
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
        let d = sample_uniform_disk_concentric(u) * self.disk.radius_m;
        let p = self.to_world.point(Vec3A::new(d.x, d.y, 0.0));
        Some((p, self.normal, 1.0 / self.area_m2))
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
