//! Pinhole (perspective) camera (pbrt-v4 §5.2.2 "The perspective camera" with a zero lens
//! radius).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraRay};
use crate::error::InvalidParameter;

/// A perspective projection through a point. `fov_rad` spans the film **width**.
#[derive(Clone, Debug, PartialEq)]
pub struct PinholeCamera {
    frame: CameraFrame,
    fov_rad: f32,
    /// Distance of the image plane in pixels: (W/2) / tan(fov/2).
    focal_px: f32,
}

impl PinholeCamera {
    /// `fov_rad`: horizontal field of view, in (0, π).
    pub fn new(frame: CameraFrame, fov_rad: f32) -> Result<Self, InvalidParameter> {
        if !(fov_rad.is_finite() && fov_rad > 0.0 && fov_rad < PI) {
            return Err(InvalidParameter::new(
                "pinhole camera",
                "fov_rad",
                fov_rad,
                "(0, π) rad, i.e. (0°, 180°), across the film width",
            ));
        }
        let focal_px = 0.5 * frame.size_px().x / (0.5 * fov_rad).tan();
        Ok(Self {
            frame,
            fov_rad,
            focal_px,
        })
    }

    pub fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    pub fn fov_rad(&self) -> f32 {
        self.fov_rad
    }

    /// Image-plane distance in pixels.
    pub fn focal_px(&self) -> f32 {
        self.focal_px
    }

    pub(crate) fn camera_ray(&self, film_point_px: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px);
        let d = Vec3A::new(o.x, o.y, -self.focal_px).normalize();
        Some((Vec3A::ZERO, d))
    }

    pub(crate) fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        (p.z < 0.0).then(|| {
            let s = self.focal_px / -p.z;
            self.frame
                .film_from_offset_up_px(Vec2::new(p.x * s, p.y * s))
        })
    }
}
