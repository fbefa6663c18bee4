//! A sphere emitter (centred on its local origin, any affine placement).
//!
//! - Placed by a similarity (rotation, uniform scale, translation) and seen from outside:
//!   a direction uniform in the cone of half-angle θ_max, sin θ_max = R/d, that the sphere
//!   subtends, mapped to the point of the visible cap it points at (pbrt-v4 §6.2.4
//!   `Sphere::Sample(ctx, u)`): density 1 / (2π (1 − cos θ_max)). 1 − cos θ_max is computed
//!   as sin²θ_max / (1 + cos θ_max), which needs no small-angle special case.
//! - From inside, or under a non-uniform scale (an ellipsoid): a point uniform on the local
//!   sphere mapped to the world. An affine map M stretches the area element at the point of
//!   unit local normal n by J = |det M| · |M⁻ᵀ n| (Nanson's formula), so the world area
//!   density is 1 / (4π r² J), converted to solid angle.

use std::f32::consts::PI;

use glam::{Mat3A, Vec2, Vec3A};
use prism_geometry::{Frame, Sphere, Transform};

use super::{area_to_solid_angle, ShapeSample};
use crate::light::warp::sample_uniform_sphere;
use crate::light::LightHit;

/// Relative band around r² within which a reference point counts as on the sphere (hit
/// points are within a few ulps, ~1e-6, of the surface).
const SURFACE_BAND: f32 = 1e-4;

#[derive(Clone, Debug, PartialEq)]
pub struct SphereEmitter {
    pub sphere: Sphere,
    pub to_world: Transform,
    /// World centre and radius when `to_world` is a similarity (cone sampling applies).
    similarity: Option<(Vec3A, f32)>,
    /// |det M| of the linear part.
    det_abs: f32,
    normal_matrix: Mat3A,
    area_m2: f64,
}

/// The uniform scale s of a linear map that is s × an orthogonal matrix, else `None`
/// (relative tolerance 1e-5).
fn similarity_scale(m: Mat3A) -> Option<f32> {
    let c = [m.x_axis, m.y_axis, m.z_axis].map(|v| v.as_dvec3());
    let s2 = (c[0].length_squared() + c[1].length_squared() + c[2].length_squared()) / 3.0;
    let tol = 1e-5 * s2;
    let orthogonal = (c[0].dot(c[1]).abs() < tol)
        && (c[0].dot(c[2]).abs() < tol)
        && (c[1].dot(c[2]).abs() < tol);
    let equal = c.iter().all(|v| (v.length_squared() - s2).abs() < tol);
    (orthogonal && equal && s2 > 0.0).then(|| s2.sqrt() as f32)
}

impl SphereEmitter {
    pub fn new(sphere: Sphere, to_world: Transform) -> Self {
        let linear = Mat3A::from_mat4(to_world.matrix());
        let similarity =
            similarity_scale(linear).map(|s| (to_world.point(Vec3A::ZERO), sphere.radius_m * s));
        let det_abs = linear.determinant().abs();
        let normal_matrix = to_world.normal_matrix();
        let r = f64::from(sphere.radius_m);
        let area_m2 = match similarity {
            Some((_, radius)) => 4.0 * std::f64::consts::PI * f64::from(radius).powi(2),
            None => r * r * area_stretch_integral(det_abs, normal_matrix),
        };
        Self {
            sphere,
            to_world,
            similarity,
            det_abs,
            normal_matrix,
            area_m2,
        }
    }

    pub fn area_m2(&self) -> f64 {
        self.area_m2
    }

    /// World centre and radius, m, when placed by a similarity (else an ellipsoid: `None`).
    pub fn world_centre_and_radius_m(&self) -> Option<(Vec3A, f32)> {
        self.similarity
    }

    /// World centre and radius of a sphere seen from outside at `reference` (cone
    /// sampling applies), else `None`.
    ///
    /// Points on the surface itself (within `SURFACE_BAND` of r², where rounding puts hit
    /// points on either side) count as inside: from a point of the sphere the subtended
    /// cone degenerates to the point itself, while area sampling stays well-behaved there
    /// (for two points of a sphere cos θ · cos θ' / d² = 1/(4r²)) and sees the whole
    /// interior that a path inside a closed emitter needs. pbrt-v4 gets the same effect by
    /// offsetting the reference point towards the centre.
    #[inline]
    fn cone_from(&self, reference: Vec3A) -> Option<(Vec3A, f32)> {
        let (c, r) = self.similarity?;
        ((reference - c).length_squared() > r * r * (1.0 + SURFACE_BAND)).then_some((c, r))
    }

    /// 1 − cos θ_max and sin θ_max for a sphere of radius r at distance² d2 (> r²).
    #[inline]
    fn cone(r: f32, d2: f32) -> (f32, f32) {
        let sin2_max = (r * r / d2).min(1.0);
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        (sin2_max / (1.0 + cos_max), sin2_max.sqrt())
    }

    #[inline]
    pub fn sample(&self, reference: Vec3A, u: Vec2) -> Option<ShapeSample> {
        if let Some((c, r)) = self.cone_from(reference) {
            let to_center = c - reference;
            let d2 = to_center.length_squared();
            let (omc_max, sin_max) = Self::cone(r, d2);
            // θ within the cone (pbrt-v4 §6.2.4), in the precise 1 − cos form.
            let omc = u.x * omc_max;
            let cos_theta = 1.0 - omc;
            let sin2_theta = omc * (2.0 - omc);
            // α: angle at the centre between the reference point and the sampled point.
            let cos_alpha = sin2_theta / sin_max
                + cos_theta * (1.0 - sin2_theta / (sin_max * sin_max)).max(0.0).sqrt();
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
            let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
            let w = Vec3A::new(sin_alpha * cos_phi, sin_alpha * sin_phi, cos_alpha);
            let frame = Frame::from_z(to_center / d2.sqrt());
            let n = frame.from_local(-w).normalize();
            return Some(ShapeSample {
                p: c + r * n,
                n,
                pdf: 1.0 / (2.0 * PI * omc_max),
            });
        }
        let n_local = sample_uniform_sphere(u);
        let p = self.to_world.point(n_local * self.sphere.radius_m);
        let (n, pdf_area) = self.area_density(n_local)?;
        Some(ShapeSample {
            p,
            n,
            pdf: area_to_solid_angle(pdf_area, reference, p, n),
        })
    }

    /// A point uniform on the local sphere mapped to the world (`sample_le`): world
    /// position, unit normal and world area density (Nanson's stretch).
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> Option<(Vec3A, Vec3A, f32)> {
        let n_local = sample_uniform_sphere(u);
        let p = self.to_world.point(n_local * self.sphere.radius_m);
        let (n, pdf_area) = self.area_density(n_local)?;
        Some((p, n, pdf_area))
    }

    /// Area density of `sample_area` at the world point `p` of the sphere.
    #[inline]
    pub fn pdf_area(&self, p: Vec3A) -> f32 {
        let n_local = self.to_world.inverse_point(p).normalize_or_zero();
        self.area_density(n_local)
            .map_or(0.0, |(_, pdf_area)| pdf_area)
    }

    /// World unit normal and world area density at the point of unit local normal
    /// `n_local` under uniform area sampling of the local sphere.
    #[inline]
    fn area_density(&self, n_local: Vec3A) -> Option<(Vec3A, f32)> {
        let nw = self.normal_matrix * n_local;
        let len = nw.length();
        let r = self.sphere.radius_m;
        let stretch = self.det_abs * len;
        if !(len > 0.0 && stretch > 0.0) {
            return None;
        }
        Some((nw / len, 1.0 / (4.0 * PI * r * r * stretch)))
    }

    #[inline]
    pub fn pdf(&self, reference: Vec3A, hit: &LightHit) -> f32 {
        if let Some((c, r)) = self.cone_from(reference) {
            let (omc_max, _) = Self::cone(r, (c - reference).length_squared());
            return 1.0 / (2.0 * PI * omc_max);
        }
        let n_local = self.to_world.inverse_point(hit.p).normalize_or_zero();
        match self.area_density(n_local) {
            Some((n, pdf_area)) => area_to_solid_angle(pdf_area, reference, hit.p, n),
            None => 0.0,
        }
    }
}

/// ∫_{S²} |det M| · |M⁻ᵀ n| dω: the area of the image of the unit sphere (an ellipsoid's
/// area has no closed form). Midpoint rule in (z, φ), which is uniform in area on the
/// sphere (Archimedes); the integrand is smooth, so 512 × 1024 cells give ~1e-6 relative.
fn area_stretch_integral(det_abs: f32, normal_matrix: Mat3A) -> f64 {
    let (nz, nphi) = (512usize, 1024usize);
    let nm = glam::DMat3::from_cols(
        normal_matrix.x_axis.as_dvec3(),
        normal_matrix.y_axis.as_dvec3(),
        normal_matrix.z_axis.as_dvec3(),
    );
    let mut sum = 0.0;
    for i in 0..nz {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / nz as f64;
        let r = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
            let n = glam::DVec3::new(r * phi.cos(), r * phi.sin(), z);
            sum += (nm * n).length();
        }
    }
    f64::from(det_abs) * sum * 4.0 * std::f64::consts::PI / (nz * nphi) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoid_area_matches_the_closed_form_of_a_spheroid() {
        // Prolate spheroid a = b = 1, c = 2: A = 2πa² (1 + c/(a e) asin e), e² = 1 − a²/c².
        let t = Transform::scale(Vec3A::new(1.0, 1.0, 2.0)).unwrap();
        let s = SphereEmitter::new(Sphere { radius_m: 1.0 }, t);
        let e = (1.0f64 - 0.25).sqrt();
        let exact = 2.0 * std::f64::consts::PI * (1.0 + 2.0 / e * e.asin());
        assert!(
            (s.area_m2() - exact).abs() < 1e-5 * exact,
            "{}",
            s.area_m2()
        );
        let u = SphereEmitter::new(
            Sphere { radius_m: 0.5 },
            Transform::scale(Vec3A::splat(3.0)).unwrap(),
        );
        assert!((u.area_m2() - 4.0 * std::f64::consts::PI * 2.25).abs() < 1e-9);
    }
}
