//! Pose and film resolution shared by every camera model.

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::Transform;

use crate::error::InvalidParameter;

/// The camera-to-world transform and the film resolution in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    /// Maps camera space (−Z forward, +X right, +Y up) to world space.
    pub camera_to_world: Transform,
    /// Film width and height in pixels.
    pub resolution: UVec2,
    /// How far (px) outside the film camera samples' film points reach: the pixel filter's
    /// radius (a sample is the pixel centre plus a filter offset). Importance and its
    /// densities (`CameraModel::importance_camera_space`, `pdf_we_camera_space`) are
    /// defined over the film grown by it, so a light-path connection landing just outside
    /// still reaches the border pixels' filters, as camera samples do. 0 by default.
    pub film_margin_px: f32,
}

const CONTEXT: &str = "camera";

impl CameraFrame {
    /// A frame from an explicit transform. The resolution must be at least 1 × 1.
    pub fn new(camera_to_world: Transform, resolution: UVec2) -> Result<Self, InvalidParameter> {
        if resolution.x == 0 || resolution.y == 0 {
            return Err(InvalidParameter::new(
                CONTEXT,
                "resolution",
                format!("{}×{}", resolution.x, resolution.y),
                "width and height ≥ 1 pixel",
            ));
        }
        Ok(Self {
            camera_to_world,
            resolution,
            film_margin_px: 0.0,
        })
    }

    /// The same frame with camera samples reaching `margin_px` outside the film (the
    /// filter's radius).
    pub fn with_film_margin_px(mut self, margin_px: f32) -> Self {
        self.film_margin_px = margin_px.max(0.0);
        self
    }

    /// True when `film_point_px` lies on the film grown by `film_margin_px`: where camera
    /// samples' film points lie, so where importance is defined.
    pub fn reaches(&self, film_point_px: Vec2) -> bool {
        let s = self.size_px();
        let m = self.film_margin_px;
        film_point_px.x >= -m
            && film_point_px.y >= -m
            && film_point_px.x < s.x + m
            && film_point_px.y < s.y + m
    }

    /// A viewer at `eye_m` looking at `target_m`, `up` giving the image's up direction
    /// (`Transform::look_at`).
    pub fn look_at(
        eye_m: Vec3A,
        target_m: Vec3A,
        up: Vec3A,
        resolution: UVec2,
    ) -> Result<Self, InvalidParameter> {
        let finite = eye_m.is_finite() && target_m.is_finite() && up.is_finite();
        let transform = finite
            .then(|| Transform::look_at(eye_m, target_m, up))
            .flatten()
            .ok_or_else(|| {
                InvalidParameter::new(
                    CONTEXT,
                    "eye_m/target_m/up",
                    format!("eye {eye_m}, target {target_m}, up {up}"),
                    "finite vectors, eye ≠ target, up not parallel to target − eye",
                )
            })?;
        Self::new(transform, resolution)
    }

    /// Film size in pixels as floats.
    #[inline]
    pub fn size_px(&self) -> Vec2 {
        self.resolution.as_vec2()
    }

    /// The film centre in pixels.
    #[inline]
    pub fn centre_px(&self) -> Vec2 {
        0.5 * self.size_px()
    }

    /// Whether a continuous film point lies on the film, [0, W) × [0, H).
    #[inline]
    pub fn contains(&self, film_point_px: Vec2) -> bool {
        let s = self.size_px();
        film_point_px.x >= 0.0
            && film_point_px.y >= 0.0
            && film_point_px.x < s.x
            && film_point_px.y < s.y
    }

    /// Film offset from the centre with y flipped to point up: (x − W/2, H/2 − y) px.
    #[inline]
    pub(crate) fn offset_up_px(&self, film_point_px: Vec2) -> Vec2 {
        let c = self.centre_px();
        Vec2::new(film_point_px.x - c.x, c.y - film_point_px.y)
    }

    /// Inverse of `offset_up_px`.
    #[inline]
    pub(crate) fn film_from_offset_up_px(&self, offset_up_px: Vec2) -> Vec2 {
        let c = self.centre_px();
        Vec2::new(c.x + offset_up_px.x, c.y - offset_up_px.y)
    }
}
