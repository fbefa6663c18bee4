//! Pinhole (perspective) camera (pbrt-v4 §5.2.2 "The perspective camera" with a zero lens
//! radius).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use super::{perspective, CameraFrame, CameraImportance, CameraModel, CameraRay};
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

    pub fn fov_rad(&self) -> f32 {
        self.fov_rad
    }

    /// Image-plane distance in pixels.
    pub fn focal_px(&self) -> f32 {
        self.focal_px
    }

    /// `Camera::generate_ray_only` of `N` film points: the world origin and the unit
    /// directions (one array per axis). One loop over the points in plain f32
    /// arithmetic, which LLVM vectorises where the caller is compiled for it; the same
    /// operations in the same order as glam's `normalize` ((x² + y²) + z², then v / √)
    /// and `transform_vector3a` ((X·x + Y·y) + Z·z), so the same bits.
    #[inline(always)]
    pub(crate) fn world_rays_many<const N: usize>(
        &self,
        film_points_px: &[Vec2; N],
    ) -> (Vec3A, [[f32; N]; 3]) {
        let to_world = &self.frame.camera_to_world;
        let m = to_world.matrix();
        let (x_axis, y_axis, z_axis) = (m.x_axis, m.y_axis, m.z_axis);
        let centre = self.frame.centre_px();
        let z = -self.focal_px;
        let mut world = [[0.0f32; N]; 3];
        for k in 0..N {
            let p = film_points_px[k];
            // `CameraFrame::offset_up_px`.
            let (x, y) = (p.x - centre.x, centre.y - p.y);
            let len = ((x * x + y * y) + z * z).sqrt();
            let (x, y, z) = (x / len, y / len, z / len);
            let w = [0, 1, 2].map(|a| (x_axis[a] * x + y_axis[a] * y) + z_axis[a] * z);
            let len = ((w[0] * w[0] + w[1] * w[1]) + w[2] * w[2]).sqrt();
            for a in 0..3 {
                world[a][k] = w[a] / len;
            }
        }
        (to_world.point(Vec3A::ZERO), world)
    }
}

/// Importance with a point lens (area 1) and the image plane at any distance (pbrt-v4
/// `PerspectiveCamera` with lensRadius 0; `perspective` derives it).
impl CameraModel for PinholeCamera {
    fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    fn camera_ray(&self, film_point_px: Vec2, _lens_sample: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px);
        let d = Vec3A::new(o.x, o.y, -self.focal_px).normalize();
        Some((Vec3A::ZERO, d))
    }

    fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        (p.z < 0.0).then(|| {
            let s = self.focal_px / -p.z;
            self.frame
                .film_from_offset_up_px(Vec2::new(p.x * s, p.y * s))
        })
    }

    fn project_jacobian_camera_space(&self, p_m: Vec3A) -> Option<[Vec3A; 2]> {
        perspective::project_jacobian(self.focal_px, p_m)
    }

    fn importance_support(&self) -> Result<(), String> {
        Ok(())
    }

    fn is_delta_position(&self) -> bool {
        true
    }

    fn importance_area_px2(&self) -> f32 {
        let size = self.frame.size_px();
        size.x * size.y
    }

    fn sample_lens_point(&self, _u_lens: Vec2) -> Option<(Vec3A, f32)> {
        Some((Vec3A::ZERO, 1.0))
    }

    fn importance_camera_space(
        &self,
        _lens_point_m: Vec3A,
        direction: Vec3A,
    ) -> Option<CameraImportance> {
        perspective::importance(&self.frame, self.focal_px, 1.0, 1.0, Vec3A::ZERO, direction)
    }

    fn pdf_we_camera_space(&self, _lens_point_m: Vec3A, direction: Vec3A) -> Option<(f32, f32)> {
        perspective::pdf_we(&self.frame, self.focal_px, 1.0, 1.0, Vec3A::ZERO, direction)
    }
}
