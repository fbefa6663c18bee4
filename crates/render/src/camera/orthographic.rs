//! Orthographic camera: parallel rays along −Z from the film plane (pbrt-v4 §5.2.1).

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraImportance, CameraModel, CameraRay};
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

    pub fn film_width_m(&self) -> f32 {
        self.film_width_m
    }

    pub fn pixel_size_m(&self) -> f32 {
        self.pixel_size_m
    }
}

/// No importance: every ray is parallel to the axis, so W_e would be a Dirac delta in
/// direction, which neither a light subpath hitting the film plane nor `sample_wi` can meet
/// with nonzero probability (pbrt-v4's `OrthographicCamera` has none either).
impl CameraModel for OrthographicCamera {
    fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    fn camera_ray(&self, film_point_px: Vec2, _lens_sample: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px) * self.pixel_size_m;
        Some((Vec3A::new(o.x, o.y, 0.0), Vec3A::NEG_Z))
    }

    fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
        (p.z < 0.0).then(|| {
            self.frame
                .film_from_offset_up_px(Vec2::new(p.x, p.y) / self.pixel_size_m)
        })
    }

    fn project_jacobian_camera_space(&self, p_m: Vec3A) -> Option<[Vec3A; 2]> {
        let s = 1.0 / self.pixel_size_m;
        (p_m.z < 0.0).then_some([Vec3A::new(s, 0.0, 0.0), Vec3A::new(0.0, -s, 0.0)])
    }

    fn importance_support(&self) -> Result<(), String> {
        Err(
            "the orthographic camera has no importance function: light tracing and BDPT \
             cannot connect to it; use path"
                .to_owned(),
        )
    }

    fn is_delta_position(&self) -> bool {
        false
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
