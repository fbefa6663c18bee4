//! The scene's bounding sphere: infinite lights (sun, sky, environment) use its radius for
//! their power (the flux through a disk of that radius, pbrt-v4 §12.5), place the
//! `p_light` of a sample beyond it, and start emitted rays on the disk of that radius that
//! faces the emitted direction.

use glam::{Vec2, Vec3A};
use prism_geometry::{Frame, Geometry, Ray, Shape};
use prism_spectrum::SampledSpectrum;

use super::LightLeSample;
use crate::sampling::sample_uniform_disk_concentric;

/// A sphere bounding every instance of the scene (world, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSphere {
    pub center_m: Vec3A,
    /// 0 for a scene without geometry.
    pub radius_m: f32,
}

impl Default for SceneSphere {
    fn default() -> Self {
        Self {
            center_m: Vec3A::ZERO,
            radius_m: 0.0,
        }
    }
}

impl SceneSphere {
    /// The sphere around the world bounding box of every instance (the box's centre, half
    /// its diagonal).
    pub fn of_geometry(geometry: &Geometry) -> Self {
        let mut lo = Vec3A::splat(f32::INFINITY);
        let mut hi = Vec3A::splat(f32::NEG_INFINITY);
        for inst in geometry.instances() {
            let (l, h) = match inst.shape {
                Shape::Mesh(id) => {
                    let mesh = geometry.mesh(id);
                    mesh.positions.iter().fold(
                        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                        |(l, h), &p| (l.min(p), h.max(p)),
                    )
                }
                Shape::Sphere(s) => s.bounds(),
                Shape::Disk(d) => d.bounds(),
                Shape::Rectangle(r) => r.bounds(),
                Shape::Tiled(tiling) => tiling.bounds(geometry.mesh(tiling.mesh).bounds()),
            };
            if l.cmpgt(h).any() {
                continue; // an empty mesh
            }
            let (l, h) = inst.to_world.bounds(l, h);
            lo = lo.min(l);
            hi = hi.max(h);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Self::default();
        }
        Self {
            center_m: 0.5 * (lo + hi),
            radius_m: 0.5 * (hi - lo).length(),
        }
    }

    /// A point along the unit direction `wi` from `p` that lies outside the sphere (at
    /// twice the larger of the radius and p's distance from the centre, as Mitsuba 3's
    /// infinite emitters do), for the `p_light` of an infinite light's sample.
    #[inline]
    pub fn point_beyond(&self, p: Vec3A, wi: Vec3A) -> Vec3A {
        let reach = 2.0 * self.radius_m.max((p - self.center_m).length()).max(1.0);
        p + wi * reach
    }

    /// Area density of the origins of infinite lights' emitted rays: 1/(π r²) on the disk
    /// (pbrt-v4 §12.5.1 `UniformInfiniteLight::SampleLe`), 0 for an empty scene.
    #[inline]
    pub fn disk_pdf(&self) -> f32 {
        let pdf = 1.0 / (std::f32::consts::PI * self.radius_m * self.radius_m);
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    /// The emitted ray of an infinite light whose light arrives from the unit direction
    /// `wi` (towards the light): the origin uniform (concentric map of `u`) on the disk of
    /// radius r perpendicular to `wi`, centred at centre + r·wi, so every ray along −wi
    /// that crosses the sphere starts on it (pbrt-v4 §12.5.1). `None` for an empty scene or
    /// a zero `pdf_dir`.
    #[inline]
    pub(crate) fn emission(
        &self,
        wi: Vec3A,
        u: Vec2,
        radiance: SampledSpectrum,
        pdf_dir: f32,
    ) -> Option<LightLeSample> {
        let pdf_pos = self.disk_pdf();
        if !(pdf_pos > 0.0 && pdf_dir > 0.0 && pdf_dir < f32::INFINITY) {
            return None;
        }
        let frame = Frame::from_z(wi);
        let d = sample_uniform_disk_concentric(u);
        let origin = self.center_m + self.radius_m * (wi + frame.x * d.x + frame.y * d.y);
        Some(LightLeSample {
            ray: Ray::infinite(origin, -wi),
            n: -wi,
            radiance,
            pdf_pos,
            pdf_dir,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_geometry::{GeometryBuilder, Sphere, Transform};

    #[test]
    fn bounds_of_two_spheres() {
        let mut b = GeometryBuilder::new();
        for x in [-2.0, 2.0] {
            b.add_instance(
                Shape::Sphere(Sphere { radius_m: 1.0 }),
                Transform::translate(Vec3A::new(x, 0.0, 0.0)),
                None,
            );
        }
        let s = SceneSphere::of_geometry(&b.build(Default::default()));
        assert!(s.center_m.length() < 1e-6);
        // Box [−3, 3] × [−1, 1]²: half diagonal √(9 + 1 + 1).
        assert!((s.radius_m - 11f32.sqrt()).abs() < 1e-5, "{s:?}");
        let empty = SceneSphere::of_geometry(&GeometryBuilder::new().build(Default::default()));
        assert_eq!(empty, SceneSphere::default());
        let p = s.point_beyond(Vec3A::ZERO, Vec3A::X);
        assert!((p - s.center_m).length() > s.radius_m);
    }
}
