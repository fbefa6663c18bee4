//! Sampling a rectangle uniformly in the solid angle it subtends (Ureña, Fajardo & King
//! 2013, "An Area-Preserving Parametrization for Spherical Rectangles", EGSR; pbrt-v4
//! `SampleSphericalRectangle`). Uniform area sampling has density d²/(A cos θ_light) per
//! steradian, which swings by orders of magnitude over a light seen from close by (its near
//! edge against its far one); this density is 1/Ω everywhere, so only the receiver's cosine
//! and visibility are left to vary. Computed in f64: the solid angle is a sum of four angles
//! less 2π, which loses f32's digits as Ω falls.

use glam::{DVec3, Vec2, Vec3A};

use crate::sampling::{bilinear_pdf, sample_bilinear};

/// A rectangle given by a corner and two orthogonal edges, world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphericalRectangle {
    corner: DVec3,
    x_axis: DVec3,
    y_axis: DVec3,
    normal: DVec3,
    width_m: f64,
    height_m: f64,
}

/// The rectangle in the frame of a reference point (Ureña et al. §3): its edges' offsets
/// x0 < x1, y0 < y1 and its plane at z0 ≤ 0, and what sampling needs of the four angles.
struct View {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    /// The frame's z: the normal, flipped to point away from the rectangle.
    z_axis: DVec3,
    b0: f64,
    b1: f64,
    /// 2π − γ2 − γ3.
    k: f64,
    solid_angle_sr: f64,
}

impl SphericalRectangle {
    /// `None` unless both edges have a length and are orthogonal to 10⁻⁵ (a sheared
    /// parallelogram is not a spherical rectangle).
    pub fn new(corner: Vec3A, edge_x: Vec3A, edge_y: Vec3A) -> Option<Self> {
        let (ex, ey) = (edge_x.as_dvec3(), edge_y.as_dvec3());
        let (width_m, height_m) = (ex.length(), ey.length());
        if !(width_m > 0.0 && height_m > 0.0 && width_m.is_finite() && height_m.is_finite()) {
            return None;
        }
        let (x_axis, y_axis) = (ex / width_m, ey / height_m);
        if x_axis.dot(y_axis).abs() > 1e-5 {
            return None;
        }
        Some(Self {
            corner: corner.as_dvec3(),
            x_axis,
            y_axis,
            normal: x_axis.cross(y_axis).normalize(),
            width_m,
            height_m,
        })
    }

    fn view(&self, reference: Vec3A) -> View {
        let d = self.corner - reference.as_dvec3();
        let (x0, y0) = (d.dot(self.x_axis), d.dot(self.y_axis));
        let (mut z0, mut z_axis) = (d.dot(self.normal), self.normal);
        if z0 > 0.0 {
            z0 = -z0;
            z_axis = -z_axis;
        }
        let (x1, y1) = (x0 + self.width_m, y0 + self.height_m);
        local_view(x0, x1, y0, y1, z0, z_axis)
    }

    /// The solid angle (sr) the rectangle subtends from `reference`; NaN where the
    /// reference point lies in its plane (nothing to sample there).
    #[cfg(test)]
    pub fn solid_angle_sr(&self, reference: Vec3A) -> f64 {
        self.view(reference).solid_angle_sr
    }

    /// The receiver's cosine towards each corner, (x0, y0), (x1, y0), (x0, y1), (x1, y1),
    /// at least 0.01 (pbrt-v4 `BilinearPatch::Sample`): the weights of the bilinear warp
    /// that makes the solid-angle sample roughly follow cos θ at the receiver.
    fn corner_cosines(&self, reference: Vec3A, normal: Vec3A) -> [f32; 4] {
        let (r, n) = (reference.as_dvec3(), normal.as_dvec3());
        let (ex, ey) = (self.x_axis * self.width_m, self.y_axis * self.height_m);
        [
            self.corner,
            self.corner + ex,
            self.corner + ey,
            self.corner + ex + ey,
        ]
        .map(|c| n.dot((c - r).normalize()).abs().max(0.01) as f32)
    }

    /// `sample` with `u` first warped by the bilinear density of the receiver's corner
    /// cosines (pbrt-v4 `BilinearPatch::Sample` for rectangles), for a receiver with unit
    /// normal `normal` (zero: no warp, a point in a medium): (point, density sr⁻¹).
    pub fn sample_cosine_warped(
        &self,
        reference: Vec3A,
        normal: Vec3A,
        u: Vec2,
    ) -> Option<(Vec3A, f64)> {
        if normal == Vec3A::ZERO {
            return self.sample(reference, u).map(|(p, omega)| (p, 1.0 / omega));
        }
        let w = self.corner_cosines(reference, normal);
        let warped = sample_bilinear(u, w);
        let (p, omega) = self.sample(reference, warped)?;
        Some((p, f64::from(bilinear_pdf(warped, w)) / omega))
    }

    /// The density (sr⁻¹) of `sample_cosine_warped` for the direction to `point`, a point
    /// of the rectangle: the bilinear density at the point's preimage — x from the share of
    /// the solid angle left of it, y from its h (Ureña et al.'s parametrization, inverted) —
    /// over Ω.
    pub fn pdf_cosine_warped(&self, reference: Vec3A, normal: Vec3A, point: Vec3A) -> Option<f64> {
        let v = self.view(reference);
        let omega = v.sampleable_solid_angle()?;
        if normal == Vec3A::ZERO {
            return Some(1.0 / omega);
        }
        let d = point.as_dvec3() - reference.as_dvec3();
        let xu = d.dot(self.x_axis).clamp(v.x0, v.x1);
        let yv = d.dot(self.y_axis).clamp(v.y0, v.y1);
        let left = local_view(v.x0, xu, v.y0, v.y1, v.z0, v.z_axis).solid_angle_sr;
        let ux = if left > 0.0 {
            (left / omega).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = (xu * xu + v.z0 * v.z0).sqrt();
        let h = |y: f64| y / (dist * dist + y * y).sqrt();
        let (h0, h1) = (h(v.y0), h(v.y1));
        let uy = if h1 > h0 {
            ((h(yv) - h0) / (h1 - h0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let w = self.corner_cosines(reference, normal);
        Some(f64::from(bilinear_pdf(Vec2::new(ux as f32, uy as f32), w)) / omega)
    }

    /// A point of the rectangle whose direction from `reference` is uniform in the solid
    /// angle for `u` uniform in [0, 1)² (Ureña et al. Algorithm 1), with that solid angle
    /// (sr); `None` where the solid angle is not positive and finite (`reference` in the
    /// rectangle's plane). The point's coordinates are clamped to the rectangle against
    /// rounding.
    pub fn sample(&self, reference: Vec3A, u: Vec2) -> Option<(Vec3A, f64)> {
        let v = self.view(reference);
        v.sampleable_solid_angle()?;
        let (su, sv) = (f64::from(u.x), f64::from(u.y));
        // The area of the part of the spherical rectangle left of x = xu is su·Ω: solve
        // for the cosine cu of the angle that edge makes (their eqs. 8–10).
        let au = su * v.solid_angle_sr + v.k;
        let (sin_au, cos_au) = au.sin_cos();
        let fu = (cos_au * v.b0 - v.b1) / sin_au;
        let cu = ((fu * fu + v.b0 * v.b0).sqrt().recip())
            .copysign(fu)
            .clamp(-1.0 + 1e-15, 1.0 - 1e-15);
        let xu = (-(cu * v.z0) / (1.0 - cu * cu).sqrt()).clamp(v.x0, v.x1);
        // Then y uniform in the solid angle along that line (their eqs. 11–12).
        let dist = (xu * xu + v.z0 * v.z0).sqrt();
        let h0 = v.y0 / (dist * dist + v.y0 * v.y0).sqrt();
        let h1 = v.y1 / (dist * dist + v.y1 * v.y1).sqrt();
        let hv = h0 + sv * (h1 - h0);
        let yv = if hv * hv < 1.0 - 1e-15 {
            (hv * dist / (1.0 - hv * hv).sqrt()).clamp(v.y0, v.y1)
        } else {
            v.y1
        };
        let p = reference.as_dvec3() + xu * self.x_axis + yv * self.y_axis + v.z0 * v.z_axis;
        Some((p.as_vec3a(), v.solid_angle_sr))
    }
}

impl View {
    /// The solid angle (sr) where it is positive and finite: not so for a reference point
    /// in the rectangle's plane, where nothing is sampled.
    fn sampleable_solid_angle(&self) -> Option<f64> {
        (self.solid_angle_sr > 0.0 && self.solid_angle_sr < f64::INFINITY)
            .then_some(self.solid_angle_sr)
    }
}

/// `View` of the rectangle [x0, x1] × [y0, y1] in the plane z = z0 ≤ 0 of a reference
/// point's frame.
fn local_view(x0: f64, x1: f64, y0: f64, y1: f64, z0: f64, z_axis: DVec3) -> View {
    // Unit normals of the planes through the reference point and each edge: the cross
    // products of consecutive corner vectors, in closed form.
    let n0 = DVec3::new(0.0, z0, -y0).normalize();
    let n1 = DVec3::new(-z0, 0.0, x1).normalize();
    let n2 = DVec3::new(0.0, -z0, y1).normalize();
    let n3 = DVec3::new(z0, 0.0, -x0).normalize();
    // The spherical rectangle's inner angles.
    let angle = |a: DVec3, b: DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
    let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
    let tau = std::f64::consts::TAU;
    View {
        x0,
        x1,
        y0,
        y1,
        z0,
        z_axis,
        b0: n0.z,
        b1: n2.z,
        k: tau - g2 - g3,
        solid_angle_sr: g0 + g1 + g2 + g3 - tau,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_square_at_height(h: f32) -> SphericalRectangle {
        // The square [0, 1]² in the plane z = h, normal +z.
        SphericalRectangle::new(Vec3A::new(0.0, 0.0, h), Vec3A::X, Vec3A::Y).unwrap()
    }

    /// Ω of an axis-aligned rectangle [x0, x1] × [y0, y1] at height h above the origin:
    /// Σ ± atan(xy / (h √(x² + y² + h²))) over its corners (the closed form for a corner
    /// rectangle, by inclusion–exclusion).
    fn solid_angle_closed_form(x: [f64; 2], y: [f64; 2], h: f64) -> f64 {
        let corner = |x: f64, y: f64| (x * y / (h * (x * x + y * y + h * h).sqrt())).atan();
        corner(x[1], y[1]) - corner(x[0], y[1]) - corner(x[1], y[0]) + corner(x[0], y[0])
    }

    #[test]
    fn solid_angle_matches_the_closed_form() {
        for (p, h) in [
            (Vec3A::new(0.5, 0.5, 0.0), 1.0),
            (Vec3A::new(-0.3, 0.2, 0.0), 0.05),
            (Vec3A::new(3.0, -2.0, 0.0), 0.5),
            (Vec3A::new(0.5, 0.5, 0.0), 1000.0),
        ] {
            let r = unit_square_at_height(h);
            let expected = solid_angle_closed_form(
                [-f64::from(p.x), 1.0 - f64::from(p.x)],
                [-f64::from(p.y), 1.0 - f64::from(p.y)],
                f64::from(h),
            );
            let got = r.solid_angle_sr(p);
            assert!(
                (got - expected).abs() <= 1e-9 * expected.max(1e-6),
                "{p} h {h}: {got} vs {expected}"
            );
            // From the other side the same.
            let below = Vec3A::new(p.x, p.y, 2.0 * h);
            assert!((r.solid_angle_sr(below) - expected).abs() <= 1e-9 * expected.max(1e-6));
        }
    }

    #[test]
    fn samples_lie_on_the_rectangle_and_are_uniform_in_solid_angle() {
        // A point close to the square's corner: uniform area sampling would crowd the
        // directions towards the far side. Split the square into 4 × 4 cells; each cell's
        // share of the samples must equal its share of the solid angle (closed form).
        let r = unit_square_at_height(0.2);
        let p = Vec3A::new(0.1, -0.1, 0.0);
        let total = r.solid_angle_sr(p);
        let n = 64u32;
        let mut counts = [[0u32; 4]; 4];
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (q, omega) = r.sample(p, u).unwrap();
                assert_eq!(omega, total);
                assert!((q.z - 0.2).abs() < 1e-6, "{q}");
                assert!((-1e-6..=1.0 + 1e-6).contains(&q.x) && (-1e-6..=1.0 + 1e-6).contains(&q.y));
                let cx = ((q.x * 4.0) as usize).min(3);
                let cy = ((q.y * 4.0) as usize).min(3);
                counts[cx][cy] += 1;
            }
        }
        for (cx, column) in counts.iter().enumerate() {
            for (cy, &count) in column.iter().enumerate() {
                let xs = [cx as f64 / 4.0 - 0.1, (cx + 1) as f64 / 4.0 - 0.1];
                let ys = [cy as f64 / 4.0 + 0.1, (cy + 1) as f64 / 4.0 + 0.1];
                let share = solid_angle_closed_form(xs, ys, 0.2) / total;
                let got = f64::from(count) / f64::from(n * n);
                // A stratified grid of 4096 points: within 1 % of the whole plus a cell's
                // edge effects.
                assert!(
                    (got - share).abs() < 0.01,
                    "cell ({cx}, {cy}): {got} vs {share}"
                );
            }
        }
    }

    #[test]
    fn sheared_or_degenerate_edges_are_refused() {
        assert!(
            SphericalRectangle::new(Vec3A::ZERO, Vec3A::X, Vec3A::new(0.5, 1.0, 0.0)).is_none()
        );
        assert!(SphericalRectangle::new(Vec3A::ZERO, Vec3A::ZERO, Vec3A::Y).is_none());
    }
}
