//! Fisheye camera with the four classical radially symmetric projections (Kannala & Brandt
//! 2006, "A generic camera model and calibration method for conventional, wide-angle, and
//! fish-eye lenses", IEEE TPAMI 28(8), eqs. 1–4). θ is the angle between the ray and the
//! optical axis (−Z), r the distance of its image from the film centre, f the focal length
//! (here in pixels):
//!
//! | projection     | r(θ)          | largest field of view (2 θ_max)         |
//! |----------------|---------------|-----------------------------------------|
//! | equidistant    | f θ           | 360° (θ_max = π, the whole sphere)      |
//! | equisolid      | 2 f sin(θ/2)  | 360°                                    |
//! | orthographic   | f sin θ       | 180° (r(θ) turns back beyond 90°)       |
//! | stereographic  | 2 f tan(θ/2)  | below 360° (r → ∞ as θ → π)             |
//!
//! f follows from the field of view and the image-circle radius R: f = R / (r(θ_max)/f).
//! `FisheyeCoverage::Circular` inscribes the image circle in the film's shorter side
//! (R = min(W, H)/2; film points outside it have no ray); `FisheyeCoverage::Cropped` makes
//! the image circle the film diagonal (R = √(W² + H²)/2, "full-frame" fisheye; the field of
//! view is then measured along the diagonal and every film point has a ray). The ray's
//! azimuth about the axis is the film point's azimuth about the centre.
//!
//! Importance. In polar film coordinates dA_film = r dr dφ and on the sphere dω = sin θ dθ dφ,
//! so the lens maps solid angle to film area by
//!
//!   dω/dA_film = sin θ / (r(θ) r'(θ))   (sr per px²),
//!
//! i.e. dA_film/dω = f² J(θ) with J = θ/sin θ (equidistant), 1 (equisolid: equal-area),
//! cos θ (orthographic), 1/cos⁴(θ/2) (stereographic); J(0) = 1 for all four. Every film
//! point with a ray being equally important, W_e |cos θ| = f² J(θ) / A with A the film area
//! that has rays (π R² for circular coverage, W H for cropped), so ∫ W_e |cos θ| dω = 1
//! (pbrt-v3 §16.1.1's normalisation with a point lens of area 1). For a field of view over
//! 180° W_e grows as 1/|cos θ| towards θ = 90° (W_e |cos θ| stays finite); exactly there it
//! is `None`. `generate_ray`'s direction density is pdf_dir = f² J(θ) / (W H).

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraImportance, CameraModel, CameraRay};
use crate::error::InvalidParameter;

/// How far (rad) past the field of view's edge a direction may lie and still count as on
/// it for the importance: a few ulps of θ ≤ π, the round-off of a world-space round trip.
const EDGE_TOLERANCE_RAD: f32 = 1e-5;

/// Radial mapping θ → r/f of a fisheye lens (Kannala & Brandt 2006).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FisheyeProjection {
    /// r = f θ.
    Equidistant,
    /// r = 2 f sin(θ/2) (equal-area).
    Equisolid,
    /// r = f sin θ.
    Orthographic,
    /// r = 2 f tan(θ/2) (conformal).
    Stereographic,
}

impl FisheyeProjection {
    pub const ALL: [FisheyeProjection; 4] = [
        FisheyeProjection::Equidistant,
        FisheyeProjection::Equisolid,
        FisheyeProjection::Orthographic,
        FisheyeProjection::Stereographic,
    ];

    /// r/f at off-axis angle `theta_rad`.
    #[inline]
    pub fn radius_over_focal(self, theta_rad: f32) -> f32 {
        match self {
            FisheyeProjection::Equidistant => theta_rad,
            FisheyeProjection::Equisolid => 2.0 * (0.5 * theta_rad).sin(),
            FisheyeProjection::Orthographic => theta_rad.sin(),
            FisheyeProjection::Stereographic => 2.0 * (0.5 * theta_rad).tan(),
        }
    }

    /// θ from r/f (inverse of `radius_over_focal` on [0, θ limit]); arguments beyond the
    /// projection's range are clamped to it.
    #[inline]
    pub fn theta_rad(self, radius_over_focal: f32) -> f32 {
        let rho = radius_over_focal.max(0.0);
        match self {
            FisheyeProjection::Equidistant => rho.min(PI),
            FisheyeProjection::Equisolid => 2.0 * (0.5 * rho).min(1.0).asin(),
            FisheyeProjection::Orthographic => rho.min(1.0).asin(),
            FisheyeProjection::Stereographic => 2.0 * (0.5 * rho).atan(),
        }
    }

    /// d(r/f)/dθ at `theta_rad`.
    #[inline]
    pub fn radius_over_focal_derivative(self, theta_rad: f32) -> f32 {
        match self {
            FisheyeProjection::Equidistant => 1.0,
            FisheyeProjection::Equisolid => (0.5 * theta_rad).cos(),
            FisheyeProjection::Orthographic => theta_rad.cos(),
            FisheyeProjection::Stereographic => {
                let c = (0.5 * theta_rad).cos();
                1.0 / (c * c)
            }
        }
    }

    /// Film area per solid angle in units of f²: J(θ) = r(θ) r'(θ) / (f² sin θ), so
    /// dA_film/dω = f² J(θ) (module docs); closed forms, finite at θ = 0 where J = 1.
    #[inline]
    pub fn area_per_solid_angle_over_focal2(self, theta_rad: f32) -> f32 {
        match self {
            FisheyeProjection::Equidistant => {
                if theta_rad > 0.0 {
                    // |sin|: sin of the f32 nearest π is a tiny negative number.
                    theta_rad / theta_rad.sin().abs()
                } else {
                    1.0
                }
            }
            FisheyeProjection::Equisolid => 1.0,
            // cos of the f32 nearest π/2 is a tiny negative number.
            FisheyeProjection::Orthographic => theta_rad.cos().max(0.0),
            FisheyeProjection::Stereographic => {
                let c = (0.5 * theta_rad).cos();
                let c2 = c * c;
                1.0 / (c2 * c2)
            }
        }
    }

    /// The largest field of view (full angle, rad) and whether it is itself allowed.
    pub fn max_fov_rad(self) -> (f32, bool) {
        match self {
            FisheyeProjection::Equidistant | FisheyeProjection::Equisolid => (TAU, true),
            FisheyeProjection::Orthographic => (PI, true),
            FisheyeProjection::Stereographic => (TAU, false),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            FisheyeProjection::Equidistant => "equidistant",
            FisheyeProjection::Equisolid => "equisolid",
            FisheyeProjection::Orthographic => "orthographic",
            FisheyeProjection::Stereographic => "stereographic",
        }
    }
}

/// Where the image circle lies on the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FisheyeCoverage {
    /// The image circle is inscribed in the shorter film side; the fov spans its diameter.
    Circular,
    /// The image circle passes through the film corners; the fov spans the diagonal.
    Cropped,
}

/// A fisheye camera.
#[derive(Clone, Debug, PartialEq)]
pub struct FisheyeCamera {
    frame: CameraFrame,
    projection: FisheyeProjection,
    coverage: FisheyeCoverage,
    fov_rad: f32,
    image_circle_radius_px: f32,
    focal_px: f32,
}

impl FisheyeCamera {
    /// `fov_rad`: full angle across the image circle's diameter, in (0, limit] with the
    /// limit of the projection (see the module table).
    pub fn new(
        frame: CameraFrame,
        projection: FisheyeProjection,
        coverage: FisheyeCoverage,
        fov_rad: f32,
    ) -> Result<Self, InvalidParameter> {
        let (max, inclusive) = projection.max_fov_rad();
        let within = fov_rad.is_finite()
            && fov_rad > 0.0
            && (fov_rad < max || (inclusive && fov_rad == max));
        if !within {
            let valid = format!(
                "(0, {:.6}{} rad, i.e. (0°, {}°{}, for the {} projection",
                max,
                if inclusive { "]" } else { ")" },
                max.to_degrees().round(),
                if inclusive { "]" } else { ")" },
                projection.name()
            );
            return Err(InvalidParameter::new(
                "fisheye camera",
                "fov_rad",
                fov_rad,
                valid,
            ));
        }
        let size = frame.size_px();
        let image_circle_radius_px = match coverage {
            FisheyeCoverage::Circular => 0.5 * size.x.min(size.y),
            FisheyeCoverage::Cropped => 0.5 * size.length(),
        };
        let focal_px = image_circle_radius_px / projection.radius_over_focal(0.5 * fov_rad);
        Ok(Self {
            frame,
            projection,
            coverage,
            fov_rad,
            image_circle_radius_px,
            focal_px,
        })
    }

    pub fn projection(&self) -> FisheyeProjection {
        self.projection
    }

    pub fn coverage(&self) -> FisheyeCoverage {
        self.coverage
    }

    pub fn fov_rad(&self) -> f32 {
        self.fov_rad
    }

    pub fn image_circle_radius_px(&self) -> f32 {
        self.image_circle_radius_px
    }

    /// f in pixels (r = f · r(θ)/f).
    pub fn focal_px(&self) -> f32 {
        self.focal_px
    }

    /// θ and film point of unit camera-space `direction` where that point has a ray. As
    /// `camera_ray` clamps θ to the field of view, directions past its edge by no more than
    /// the round-off of the world transform (`EDGE_TOLERANCE_RAD`) belong to the edge, so
    /// every generated ray has importance.
    fn film_of_direction(&self, direction: Vec3A) -> Option<(f32, Vec2)> {
        let rho = Vec2::new(direction.x, direction.y).length();
        if rho == 0.0 && direction.z >= 0.0 {
            return None;
        }
        let half_fov = 0.5 * self.fov_rad;
        let theta = rho.atan2(-direction.z);
        if theta.is_nan() || theta > half_fov + EDGE_TOLERANCE_RAD {
            return None;
        }
        let theta = theta.min(half_fov);
        let r = self.focal_px * self.projection.radius_over_focal(theta);
        let azimuth = if rho > 0.0 {
            Vec2::new(direction.x, direction.y) / rho
        } else {
            Vec2::ZERO
        };
        let film = self.frame.film_from_offset_up_px(r * azimuth);
        self.frame.reaches(film).then_some((theta, film))
    }
}

impl CameraModel for FisheyeCamera {
    fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    fn camera_ray(&self, film_point_px: Vec2, _lens_sample: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px);
        let r = o.length();
        if r > self.image_circle_radius_px {
            return None;
        }
        let theta = self
            .projection
            .theta_rad(r / self.focal_px)
            .min(0.5 * self.fov_rad);
        let (sin_t, cos_t) = theta.sin_cos();
        let azimuth = if r > 0.0 { o / r } else { Vec2::ZERO };
        let d = Vec3A::new(sin_t * azimuth.x, sin_t * azimuth.y, -cos_t);
        Some((Vec3A::ZERO, d))
    }

    fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        let rho = Vec2::new(p.x, p.y).length();
        if rho == 0.0 && p.z >= 0.0 {
            // On the axis behind the camera (or the origin): no unique image point.
            return None;
        }
        let theta = rho.atan2(-p.z);
        if theta > 0.5 * self.fov_rad {
            return None;
        }
        let r = self.focal_px * self.projection.radius_over_focal(theta);
        let azimuth = if rho > 0.0 {
            Vec2::new(p.x, p.y) / rho
        } else {
            Vec2::ZERO
        };
        Some(self.frame.film_from_offset_up_px(r * azimuth))
    }

    /// Film offset o = f g(θ) u with u = (x, y)/ρ, θ = atan2(ρ, −z), ρ = |(x, y)|:
    /// ∇o = f g'(θ) u ∇θᵀ + f g(θ) ∇u, ∇θ = (−z ∇ρ + ρ e_z)/|p|², ∇ρ = (u, 0),
    /// ∇u = (I − u uᵀ)/ρ on x, y. On the axis (ρ = 0, in front) g ≈ θ ≈ ρ/(−z), so
    /// o ≈ f (x, y)/(−z).
    fn project_jacobian_camera_space(&self, p: Vec3A) -> Option<[Vec3A; 2]> {
        let rho = Vec2::new(p.x, p.y).length();
        let f = self.focal_px;
        if rho == 0.0 {
            return (p.z < 0.0).then(|| {
                let s = f / -p.z;
                [Vec3A::new(s, 0.0, 0.0), Vec3A::new(0.0, -s, 0.0)]
            });
        }
        let theta = rho.atan2(-p.z);
        if theta > 0.5 * self.fov_rad {
            return None;
        }
        let u = Vec2::new(p.x, p.y) / rho;
        let grad_theta =
            (-p.z * Vec3A::new(u.x, u.y, 0.0) + Vec3A::new(0.0, 0.0, rho)) / p.length_squared();
        let grad_r = f * self.projection.radius_over_focal_derivative(theta) * grad_theta;
        let r_over_rho = f * self.projection.radius_over_focal(theta) / rho;
        let grad_ox = u.x * grad_r + r_over_rho * Vec3A::new(1.0 - u.x * u.x, -u.x * u.y, 0.0);
        let grad_oy = u.y * grad_r + r_over_rho * Vec3A::new(-u.x * u.y, 1.0 - u.y * u.y, 0.0);
        // Film y runs down: film = centre + (o_x, −o_y).
        Some([grad_ox, -grad_oy])
    }

    fn importance_support(&self) -> Result<(), String> {
        Ok(())
    }

    fn is_delta_position(&self) -> bool {
        true
    }

    /// π R² for circular coverage (the image circle is inscribed in the film), W H for
    /// cropped (the film lies inside the image circle): exact.
    fn importance_area_px2(&self) -> f32 {
        let size = self.frame.size_px();
        match self.coverage {
            FisheyeCoverage::Circular => {
                PI * self.image_circle_radius_px * self.image_circle_radius_px
            }
            FisheyeCoverage::Cropped => size.x * size.y,
        }
    }

    fn sample_lens_point(&self, _u_lens: Vec2) -> Option<(Vec3A, f32)> {
        Some((Vec3A::ZERO, 1.0))
    }

    /// W_e = f² J(θ) / (A |cos θ|) (module docs).
    fn importance_camera_space(
        &self,
        _lens_point_m: Vec3A,
        direction: Vec3A,
    ) -> Option<CameraImportance> {
        let (theta, film_point_px) = self.film_of_direction(direction)?;
        let f2 = self.focal_px * self.focal_px;
        let importance = f2 * self.projection.area_per_solid_angle_over_focal2(theta)
            / (self.importance_area_px2() * direction.z.abs());
        (importance.is_finite() && importance > 0.0).then_some(CameraImportance {
            importance,
            film_point_px,
        })
    }

    /// (1, f² J(θ) / (W H)): film points uniform over W × H, of which those with rays map
    /// through dω/dA_film.
    fn pdf_we_camera_space(&self, _lens_point_m: Vec3A, direction: Vec3A) -> Option<(f32, f32)> {
        let (theta, _) = self.film_of_direction(direction)?;
        let size = self.frame.size_px();
        let pdf_dir =
            self.focal_px * self.focal_px * self.projection.area_per_solid_angle_over_focal2(theta)
                / (size.x * size.y);
        (pdf_dir.is_finite() && pdf_dir > 0.0).then_some((1.0, pdf_dir))
    }
}
