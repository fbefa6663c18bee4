//! Orthographic camera: parallel rays along −Z from the film plane (pbrt-v4 §5.2.1).

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraRay};
use crate::error::{positive, InvalidParameter};

/// Parallel projection; the film spans `film_width_m` metres across its width (square
/// pixels), centred on the camera position, and rays start on the plane z = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct OrthographicCamera {
    frame: CameraFrame,
    film_width_m: f32,
    /// Pixel pitch in metres.
    pixel_size_m: f32,
}

impl OrthographicCamera {
    /// `film_width_m` > 0: width of the imaged region in metres.
    pub fn new(frame: CameraFrame, film_width_m: f32) -> Result<Self, InvalidParameter> {
        positive("orthographic camera", "film_width_m", film_width_m)?;
        Ok(Self {
            frame,
            film_width_m,
            pixel_size_m: film_width_m / frame.size_px().x,
        })
    }

    pub fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    pub fn film_width_m(&self) -> f32 {
        self.film_width_m
    }

    pub fn pixel_size_m(&self) -> f32 {
        self.pixel_size_m
    }

    pub(crate) fn camera_ray(&self, film_point_px: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px) * self.pixel_size_m;
        Some((Vec3A::new(o.x, o.y, 0.0), Vec3A::NEG_Z))
    }

    pub(crate) fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        (p.z < 0.0).then(|| {
            self.frame
                .film_from_offset_up_px(Vec2::new(p.x, p.y) / self.pixel_size_m)
        })
    }
}
