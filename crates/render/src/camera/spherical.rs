//! Spherical camera with the equirectangular (latitude–longitude) mapping, 360° × 180°
//! (pbrt-v4 §5.3 "Spherical camera", equirectangular variant; axes adapted to Y up).
//!
//! Film u = x/W maps to azimuth φ = 2π u − π, measured from −Z (forward) towards +X
//! (right); v = y/H maps to polar angle θ = π v from +Y (up). So the film centre looks
//! forward, the top row up and the left/right edges backwards:
//! d = (sin θ sin φ, cos θ, −sin θ cos φ).

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraImportance, CameraModel, CameraRay};
use crate::error::InvalidParameter;

/// Full-sphere equirectangular camera. Any resolution is accepted; pixels are square in
/// angle when W = 2H.
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalCamera {
    frame: CameraFrame,
}

impl SphericalCamera {
    pub fn new(frame: CameraFrame) -> Result<Self, InvalidParameter> {
        Ok(Self { frame })
    }

    /// The direction (camera space) of azimuth `phi_rad` and polar angle `theta_rad`.
    pub fn direction(phi_rad: f32, theta_rad: f32) -> Vec3A {
        let (sin_t, cos_t) = theta_rad.sin_cos();
        let (sin_p, cos_p) = phi_rad.sin_cos();
        Vec3A::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
    }

    /// (φ, θ) of the film point.
    pub fn angles_rad(&self, film_point_px: Vec2) -> (f32, f32) {
        let uv = film_point_px / self.frame.size_px();
        (TAU * uv.x - PI, PI * uv.y)
    }
}

/// No importance (not implemented: the renderer's light tracer and BDPT reject it).
impl CameraModel for SphericalCamera {
    fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    fn camera_ray(&self, film_point_px: Vec2, _lens_sample: Vec2) -> Option<CameraRay> {
        let (phi, theta) = self.angles_rad(film_point_px);
        Some((Vec3A::ZERO, Self::direction(phi, theta)))
    }

    fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        let len = p.length();
        if len == 0.0 || !len.is_finite() {
            return None;
        }
        let phi = p.x.atan2(-p.z);
        let theta = (p.y / len).clamp(-1.0, 1.0).acos();
        // φ = π (straight back) is the left edge, not one past the right edge; θ = π
        // (straight down) belongs to the last row.
        let mut uv = Vec2::new((phi + PI) / TAU, theta / PI);
        if uv.x >= 1.0 {
            uv.x -= 1.0;
        }
        let size = self.frame.size_px();
        let film = (uv * size).min(size - size * f32::EPSILON);
        Some(film)
    }

    /// film x = W (φ + π)/2π, film y = H θ/π with φ = atan2(x, −z), θ = acos(y/|p|):
    /// ∇φ = (−z, 0, x)/(x² + z²), ∇θ = −(e_y − y p/|p|²)/√(x² + z²). Singular at the poles
    /// (x = z = 0). The wrap at φ = ±π and the clamp onto the last row are ignored.
    fn project_jacobian_camera_space(&self, p_m: Vec3A) -> Option<[Vec3A; 2]> {
        let rho2 = p_m.x * p_m.x + p_m.z * p_m.z;
        (rho2 > 0.0).then(|| {
            let size = self.frame.size_px();
            let grad_phi = Vec3A::new(-p_m.z, 0.0, p_m.x) / rho2;
            let grad_theta = -(Vec3A::Y - p_m.y * p_m / p_m.length_squared()) / rho2.sqrt();
            [size.x / TAU * grad_phi, size.y / PI * grad_theta]
        })
    }

    fn importance_support(&self) -> Result<(), String> {
        Err(
            "the spherical camera has no importance function: light tracing and BDPT \
             cannot connect to it; use path"
                .to_owned(),
        )
    }

    fn is_delta_position(&self) -> bool {
        true
    }

    fn importance_area_px2(&self) -> f32 {
        0.0
    }

    fn sample_lens_point(&self, _u_lens: Vec2) -> Option<(Vec3A, f32)> {
        None
    }

    fn importance_camera_space(
        &self,
        _lens_point_m: Vec3A,
        _direction: Vec3A,
    ) -> Option<CameraImportance> {
        None
    }

    fn pdf_we_camera_space(&self, _lens_point_m: Vec3A, _direction: Vec3A) -> Option<(f32, f32)> {
        None
    }
}
