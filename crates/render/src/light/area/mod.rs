//! Area lights: a shape of the scene that emits a uniform radiance L(λ) (Lambertian
//! emission, pbrt-v4 §12.3 `DiffuseAreaLight`) from the side its geometric normal points
//! to, or from both sides when `two_sided`.
//!
//! Each shape samples a point as seen from the reference point and gives the solid-angle
//! density of the direction towards it:
//! - sphere: uniform in the cone that the sphere subtends (only its visible cap) from
//!   outside (pbrt-v4 §6.2.4); uniform in area from inside, and under a non-uniform scale
//!   (an ellipsoid);
//! - disk: uniform in area;
//! - rectangle: uniform in solid angle from reference points near it (Ureña et al. 2013,
//!   `spherical_rectangle`), uniform in area from further away;
//! - triangle meshes (every instance of the shape): a triangle in proportion to its world
//!   area, then a uniform point in it (Heitz 2019).
//!
//! An area density p_A becomes a solid-angle density p_ω = p_A · d² / |cos θ_light|
//! (pbrt-v4 eq. 4.9), d the distance and θ_light the angle between the emitter's normal
//! and the direction back to the reference point.
//!
//! Directions towards points that do not emit towards the reference point (the back of a
//! one-sided emitter) are not sampled (`sample_li` returns `None`) and have density 0 in
//! `pdf_li`, so the two stay consistent.
//!
//! Emitted rays (pbrt-v4 §12.3 `DiffuseAreaLight::SampleLe`): a point by the shape's area
//! sampling (`AreaShape::sample_area`: uniform in area for disk, rectangle and meshes, and
//! for spheres the uniform local sphere mapped to the world, so an ellipsoid's density
//! follows Nanson's stretch), then a cosine-weighted direction about the normal — about
//! either side with probability ½ each when two-sided: pdf_dir = |cos θ| / π, or
//! |cos θ| / 2π. The power estimator L |cos θ| / (pdf_pos pdf_dir) then has mean
//! π A · sides · ∫ L dλ = `power_w`.

mod disk;
mod mesh;
mod rectangle;
mod sphere;
mod spherical_rectangle;

pub use disk::DiskEmitter;
pub use mesh::{EmitterMesh, MeshEmitter};
pub use rectangle::{RectangleEmitter, SolidAngleSampling};
pub use sphere::SphereEmitter;

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::{Frame, Ray};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::point::integrate_nm;
use super::scene_sphere::SceneSphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};
use crate::sampling::sample_cosine_hemisphere;

/// A point sampled on a shape as seen from a reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    /// World position, metres.
    pub p: Vec3A,
    /// Unit geometric normal there (the same one a ray hitting the point reports).
    pub n: Vec3A,
    /// Solid-angle density of the direction from the reference point to `p`, sr⁻¹.
    pub pdf: f32,
}

/// p_ω = p_A · d² / |cos θ_light|: area density → solid-angle density at `reference`
/// (pbrt-v4 eq. 4.9). 0 at grazing angles.
#[inline]
pub fn area_to_solid_angle(pdf_area: f32, reference: Vec3A, p: Vec3A, n: Vec3A) -> f32 {
    let to = p - reference;
    let d2 = to.length_squared();
    if d2 <= 0.0 {
        return 0.0;
    }
    let cos = n.dot(to).abs() / d2.sqrt();
    if cos <= 0.0 {
        return 0.0;
    }
    let pdf = pdf_area * d2 / cos;
    if pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

/// The emitting shape of an area light.
#[derive(Clone, Debug, PartialEq)]
pub enum AreaShape {
    Sphere(SphereEmitter),
    Disk(DiskEmitter),
    Rectangle(RectangleEmitter),
    Mesh(MeshEmitter),
}

impl AreaShape {
    // Always inlined: as a call (LLVM's choice, the mesh arm is large) the Cornell box's
    // rectangle sample returned through memory, ≈ 30 instructions per light sample.
    #[inline(always)]
    pub fn sample(&self, reference: Vec3A, normal: Vec3A, u: Vec2) -> Option<ShapeSample> {
        match self {
            AreaShape::Sphere(s) => s.sample(reference, u),
            AreaShape::Disk(s) => s.sample(reference, u),
            AreaShape::Rectangle(s) => s.sample(reference, normal, u),
            AreaShape::Mesh(s) => s.sample(reference, u),
        }
    }

    /// Solid-angle density with which `sample` from `reference` (a receiver of unit
    /// geometric `normal`, zero in a medium) picks the direction to `hit`, a point of this
    /// shape.
    #[inline]
    pub fn pdf(&self, reference: Vec3A, normal: Vec3A, hit: &LightHit) -> f32 {
        match self {
            AreaShape::Sphere(s) => s.pdf(reference, hit),
            AreaShape::Disk(s) => s.pdf(reference, hit),
            AreaShape::Rectangle(s) => s.pdf(reference, normal, hit),
            AreaShape::Mesh(s) => s.pdf(reference, hit),
        }
    }

    /// A point of the shape by its area sampling, without a reference point: (world
    /// position, unit normal as hits report it, area density m⁻²).
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> Option<(Vec3A, Vec3A, f32)> {
        match self {
            AreaShape::Sphere(s) => s.sample_area(u),
            AreaShape::Disk(s) => s.sample_area(u),
            AreaShape::Rectangle(s) => s.sample_area(u),
            AreaShape::Mesh(s) => s.sample_area(u),
        }
    }

    /// Area density (m⁻²) with which `sample_area` produces `p`, a point of this shape.
    #[inline]
    pub fn pdf_area(&self, p: Vec3A) -> f32 {
        match self {
            AreaShape::Sphere(s) => s.pdf_area(p),
            AreaShape::Disk(s) => s.pdf_area(),
            AreaShape::Rectangle(s) => s.pdf_area(),
            AreaShape::Mesh(s) => s.pdf_area(),
        }
    }

    /// This shape for a light that emits from both sides or (false) only from the side of
    /// its normal: a rectangle then samples in solid angle only from points that side.
    pub fn emitting_sides(self, two_sided: bool) -> Self {
        match self {
            AreaShape::Rectangle(r) => AreaShape::Rectangle(r.emitting_sides(two_sided)),
            AreaShape::Sphere(_) | AreaShape::Disk(_) | AreaShape::Mesh(_) => self,
        }
    }

    /// World-space surface area, m².
    pub fn area_m2(&self) -> f64 {
        match self {
            AreaShape::Sphere(s) => s.area_m2(),
            AreaShape::Disk(s) => s.area_m2(),
            AreaShape::Rectangle(s) => s.area_m2(),
            AreaShape::Mesh(s) => s.area_m2(),
        }
    }
}

/// A shape emitting radiance L(λ).
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pub shape: AreaShape,
    /// L(λ), W·m⁻²·sr⁻¹·nm⁻¹ (absolute).
    pub radiance: Spectrum,
    /// Emits from both sides instead of only the side of the geometric normal.
    pub two_sided: bool,
}

impl AreaLight {
    /// Whether a surface point of normal `n` emits in the unit direction `wo`.
    #[inline]
    fn emits_towards(&self, n: Vec3A, wo: Vec3A) -> bool {
        let cos = n.dot(wo);
        if self.two_sided {
            cos != 0.0
        } else {
            cos > 0.0
        }
    }

    /// Density of `sample_le`'s directions about the normal `n`: |cos θ| / π on the
    /// emitting side (|cos θ| / 2π on each side when two-sided), 0 elsewhere.
    #[inline]
    fn direction_pdf(&self, n: Vec3A, w: Vec3A) -> f32 {
        if !self.emits_towards(n, w) {
            return 0.0;
        }
        n.dot(w).abs() / (self.sides() as f32 * PI)
    }

    /// `sample_li` with L(λ) at the path's wavelengths from `radiance` (called only when a
    /// direction is returned): a path evaluates the spectrum once (`RadianceCache`).
    #[inline]
    pub fn sample_li_with(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        radiance: impl FnOnce() -> SampledSpectrum,
    ) -> Option<LightSample> {
        let s = self.shape.sample(ctx.p, ctx.n, u)?;
        let to = s.p - ctx.p;
        let d = to.length();
        // 0 < x < ∞ is "positive and finite" (false for NaN) in one comparison pair each,
        // where `is_finite` compiles to integer classification (≈ 20 instructions).
        if !(d > 0.0 && d < f32::INFINITY && s.pdf > 0.0 && s.pdf < f32::INFINITY) {
            return None;
        }
        let wi = to / d;
        if !self.emits_towards(s.n, -wi) {
            return None;
        }
        Some(LightSample {
            wi,
            radiance: radiance(),
            pdf: s.pdf,
            p_light: s.p,
            distance_m: d,
            delta: false,
            n_light: s.n,
        })
    }

    /// `emitted_radiance` with L(λ) from `radiance` (see `sample_li_with`).
    #[inline]
    pub fn emitted_radiance_with(
        &self,
        hit: &LightHit,
        wo: Vec3A,
        radiance: impl FnOnce() -> SampledSpectrum,
    ) -> SampledSpectrum {
        if self.emits_towards(hit.n, wo) {
            radiance()
        } else {
            SampledSpectrum::splat(0.0)
        }
    }

    /// Number of emitting sides (1, or 2 when two-sided).
    pub fn sides(&self) -> f64 {
        if self.two_sided {
            2.0
        } else {
            1.0
        }
    }
}

impl LightSource for AreaLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        self.sample_li_with(ctx, u, || self.radiance.eval(wavelengths))
    }

    #[inline]
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3A, hit: Option<&LightHit>) -> f32 {
        match hit {
            Some(hit) if self.emits_towards(hit.n, -wi) => self.shape.pdf(ctx.p, ctx.n, hit),
            Some(_) | None => 0.0,
        }
    }

    #[inline]
    fn emitted_radiance(
        &self,
        hit: &LightHit,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.emitted_radiance_with(hit, wo, || self.radiance.eval(wavelengths))
    }

    #[inline]
    fn infinite_radiance(&self, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    fn sample_le(
        &self,
        _scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (p, n, pdf_pos) = self.shape.sample_area(u_pos)?;
        if !(pdf_pos > 0.0 && pdf_pos < f32::INFINITY) {
            return None;
        }
        // Two-sided: u_dir.x picks the side, then is stretched back to [0, 1).
        let (side, ux) = if !self.two_sided {
            (n, u_dir.x)
        } else if u_dir.x < 0.5 {
            (n, 2.0 * u_dir.x)
        } else {
            (-n, 2.0 * u_dir.x - 1.0)
        };
        let local = sample_cosine_hemisphere(Vec2::new(ux.min(1.0), u_dir.y));
        let w = Frame::from_z(side).from_local(local).normalize();
        let pdf_dir = self.direction_pdf(n, w);
        if !(pdf_dir > 0.0 && pdf_dir < f32::INFINITY) {
            return None;
        }
        Some(LightLeSample {
            ray: Ray::spawn(p, w),
            n,
            radiance: self.radiance.eval(wavelengths),
            pdf_pos,
            pdf_dir,
        })
    }

    fn pdf_le(&self, _: &SceneSphere, origin: Vec3A, n: Vec3A, direction: Vec3A) -> (f32, f32) {
        (
            self.shape.pdf_area(origin),
            self.direction_pdf(n, direction),
        )
    }

    /// Φ = π A · sides · ∫ L dλ (Lambertian emission), W.
    fn power_w(&self, _scene_radius_m: f32) -> f64 {
        std::f64::consts::PI * self.shape.area_m2() * self.sides() * integrate_nm(&self.radiance)
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::area(self)
    }

    #[inline]
    fn is_delta(&self) -> bool {
        false
    }

    #[inline]
    fn is_infinite(&self) -> bool {
        false
    }
}

/// For a shape in its local XY plane placed by `to_world`: the world unit normal (the
/// image of +Z under the inverse transpose, as hits report it) and the factor by which
/// areas grow, |M x̂ × M ŷ| (the affine map sends a uniform density on the plane to a
/// uniform density on its image).
pub(crate) fn plane_normal_and_area_scale(to_world: &prism_geometry::Transform) -> (Vec3A, f32) {
    let normal = to_world.normal(Vec3A::Z).normalize_or_zero();
    let scale = to_world
        .vector(Vec3A::X)
        .cross(to_world.vector(Vec3A::Y))
        .length();
    (normal, scale)
}

#[cfg(test)]
mod tests;
