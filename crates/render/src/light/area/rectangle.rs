//! A rectangle emitter (local XY plane, centred, normal +Z, any affine placement — a
//! parallelogram under shear). Seen from a reference point within
//! `SOLID_ANGLE_SAMPLING_RANGE` half-diagonals of its centre (on its emitting side, when
//! one-sided), a rectangle (not a sheared parallelogram) is sampled uniformly in solid
//! angle (`SphericalRectangle`, density 1/Ω); from further away, or where that solid angle
//! is not positive and finite, points are uniform in area, density 1/A converted to solid
//! angle. Both `sample` and `pdf` make the choice from the reference point alone, so they
//! agree.

use glam::{Vec2, Vec3A};
use prism_geometry::{Rectangle, Transform};

use super::spherical_rectangle::SphericalRectangle;
use super::{area_to_solid_angle, plane_normal_and_area_scale, ShapeSample};
use crate::light::LightHit;

/// Distance from the centre, in half-diagonals, within which a rectangle emitter is
/// sampled in solid angle. Nearer, uniform area sampling's density d²/(A cos θ_light)
/// varies over the light by far more than the receiver's cosine; further, the two
/// densities differ little and the solid angle's arithmetic (four arc cosines and a
/// sine–cosine pair in f64) is not worth its cost (docs/lights.md, "Sampling").
pub const SOLID_ANGLE_SAMPLING_RANGE: f32 = 1.5;

#[derive(Clone, Debug, PartialEq)]
pub struct RectangleEmitter {
    pub rectangle: Rectangle,
    pub to_world: Transform,
    normal: Vec3A,
    area_m2: f32,
    /// The rectangle for solid-angle sampling and where it is used; `None` under shear or
    /// without area.
    solid_angle: Option<SolidAngleSampling>,
}

/// Where and how a rectangle emitter samples in solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidAngleSampling {
    rectangle: SphericalRectangle,
    centre: Vec3A,
    range2_m2: f32,
    /// The emitter's normal, and whether it emits from both sides: points behind a
    /// one-sided emitter see nothing emitted and take the cheap area sampling (whose
    /// samples the light then refuses).
    normal: Vec3A,
    two_sided: bool,
}

impl SolidAngleSampling {
    /// Whether `reference` is sampled in solid angle: within the range and, for a one-sided
    /// emitter, on its emitting side. Plain f32 arithmetic in a fixed order, so that the
    /// packet tracer's lanes (`in_range_lanes`) decide with the same bits; where the solid
    /// angle then turns out not positive and finite (a point in the plane of a two-sided
    /// emitter), `sample` and `pdf` fall back to area sampling alike.
    #[inline(always)]
    pub fn in_range(&self, reference: Vec3A) -> bool {
        self.in_range_at(reference.to_array())
    }

    /// `in_range` for every lane's point `p[axis][lane]`.
    #[inline(always)]
    pub fn in_range_lanes<const N: usize>(&self, p: &[[f32; N]; 3]) -> [bool; N] {
        std::array::from_fn(|l| self.in_range_at([p[0][l], p[1][l], p[2][l]]))
    }

    #[inline(always)]
    fn in_range_at(&self, p: [f32; 3]) -> bool {
        let (c, n) = (self.centre.to_array(), self.normal.to_array());
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let distance2 = (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
        let side = (d[0] * n[0] + d[1] * n[1]) + d[2] * n[2];
        distance2 < self.range2_m2 && (self.two_sided || side > 0.0)
    }

    /// A point in solid angle, warped by the receiver's corner cosines
    /// (`SphericalRectangle::sample_cosine_warped`), and its density (sr⁻¹), where
    /// `in_range` and the solid angle is positive and finite.
    #[inline]
    fn sample(&self, reference: Vec3A, normal: Vec3A, u: Vec2) -> Option<(Vec3A, f64)> {
        if !self.in_range(reference) {
            return None;
        }
        self.sample_in_range(reference, normal, u)
    }

    #[inline(never)]
    fn sample_in_range(&self, reference: Vec3A, normal: Vec3A, u: Vec2) -> Option<(Vec3A, f64)> {
        self.rectangle.sample_cosine_warped(reference, normal, u)
    }

    /// The density (sr⁻¹) of `sample` towards `point`, where `sample` samples in solid
    /// angle.
    #[inline]
    fn pdf(&self, reference: Vec3A, normal: Vec3A, point: Vec3A) -> Option<f64> {
        if !self.in_range(reference) {
            return None;
        }
        self.pdf_in_range(reference, normal, point)
    }

    #[inline(never)]
    fn pdf_in_range(&self, reference: Vec3A, normal: Vec3A, point: Vec3A) -> Option<f64> {
        self.rectangle.pdf_cosine_warped(reference, normal, point)
    }
}

impl RectangleEmitter {
    pub fn new(rectangle: Rectangle, to_world: Transform) -> Self {
        let (normal, scale) = plane_normal_and_area_scale(&to_world);
        let area = 4.0 * rectangle.half_width_m * rectangle.half_height_m * scale;
        let (w, h) = (rectangle.half_width_m, rectangle.half_height_m);
        let corner = to_world.point(Vec3A::new(-w, -h, 0.0));
        let centre = to_world.point(Vec3A::ZERO);
        let half_diagonal_m = (centre - corner).length();
        let solid_angle = SphericalRectangle::new(
            corner,
            to_world.vector(Vec3A::new(2.0 * w, 0.0, 0.0)),
            to_world.vector(Vec3A::new(0.0, 2.0 * h, 0.0)),
        )
        .map(|rectangle| SolidAngleSampling {
            rectangle,
            centre,
            range2_m2: (SOLID_ANGLE_SAMPLING_RANGE * half_diagonal_m).powi(2),
            normal,
            two_sided: true,
        })
        .filter(|s| s.range2_m2 > 0.0 && s.range2_m2.is_finite());
        Self {
            solid_angle,
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

    /// This emitter for a light emitting from both sides, or (false) only from the side of
    /// its normal (`AreaShape::emitting_sides`).
    pub fn emitting_sides(mut self, two_sided: bool) -> Self {
        if let Some(s) = &mut self.solid_angle {
            s.two_sided = two_sided;
        }
        self
    }

    /// Its solid-angle sampling (`None` under shear): the packet tracer asks it which
    /// reference points it serves.
    pub fn solid_angle_sampling(&self) -> Option<&SolidAngleSampling> {
        self.solid_angle.as_ref()
    }

    /// The world unit normal (the side a one-sided emitter lights).
    pub fn normal(&self) -> Vec3A {
        self.normal
    }

    #[inline]
    pub fn sample(&self, reference: Vec3A, normal: Vec3A, u: Vec2) -> Option<ShapeSample> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        if let Some((p, pdf)) = self
            .solid_angle
            .as_ref()
            .and_then(|s| s.sample(reference, normal, u))
        {
            return Some(ShapeSample {
                p,
                n: self.normal,
                pdf: pdf as f32,
            });
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
    pub fn pdf(&self, reference: Vec3A, normal: Vec3A, hit: &LightHit) -> f32 {
        if self.area_m2 <= 0.0 {
            return 0.0;
        }
        if let Some(pdf) = self
            .solid_angle
            .as_ref()
            .and_then(|s| s.pdf(reference, normal, hit.p))
        {
            return pdf as f32;
        }
        area_to_solid_angle(1.0 / self.area_m2, reference, hit.p, self.normal)
    }
}
