//! Thin-lens camera with depth of field (pbrt-v4 §5.2.3 "The thin lens model and depth of
//! field"), with a physical sensor.
//!
//! Geometry: a thin lens of focal length f at the camera origin, a sensor of width s behind
//! it at the image distance v of the focus plane, 1/f = 1/v + 1/d_f (Gaussian lens
//! equation), so v = f d_f / (d_f − f). A film point at offset (x, y) px from the centre is
//! the sensor point (−x, −y)·s/W (the image is inverted); its chief ray through the lens
//! centre meets the focus plane z = −d_f at (x, y)·d_f/f_px with f_px = v W / s. Every ray
//! from that film point passes through that focus-plane point, so a camera ray starts at a
//! point L on the aperture disk and heads there (pbrt-v4 `PerspectiveCamera`).
//!
//! The field of view therefore narrows slightly when focusing close (the sensor moves back
//! from f to v, "unit focusing"); a point at depth d ≠ d_f images to a disk of diameter
//! c = 2A · f |d − d_f| / (d (d_f − f)) on the sensor with A = f/(2N) the aperture radius —
//! the textbook circle of confusion, which the tests check.

use glam::{Vec2, Vec3A};

use super::{perspective, CameraFrame, CameraImportance, CameraModel, CameraRay};
use crate::error::{positive, InvalidParameter};
use crate::sampling::sample_uniform_disk_concentric;

const CONTEXT: &str = "thin-lens camera";

/// Default sensor width: full frame, 36 mm.
pub const DEFAULT_SENSOR_WIDTH_MM: f32 = 36.0;

/// How the lens's focal length is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FocalSpec {
    /// Focal length in millimetres.
    FocalLengthMm(f32),
    /// Horizontal field of view (rad) at infinity focus on the given sensor width:
    /// f = (s/2) / tan(fov/2).
    FovRad(f32),
}

/// How the aperture is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ApertureSpec {
    /// f-number N: aperture diameter = f / N.
    FNumber(f32),
    /// Aperture radius in metres (0 gives a pinhole).
    RadiusM(f32),
}

/// A thin lens focused at `focus_distance_m` in front of a sensor `sensor_width_mm` wide.
#[derive(Clone, Debug, PartialEq)]
pub struct ThinLensCamera {
    frame: CameraFrame,
    focal_length_m: f32,
    aperture_radius_m: f32,
    focus_distance_m: f32,
    sensor_width_m: f32,
    /// v = f d_f / (d_f − f).
    image_distance_m: f32,
    /// v·W/s: the sensor-to-lens distance in pixels.
    focal_px: f32,
}

impl ThinLensCamera {
    /// `focal`: focal length (mm, > 0) or horizontal fov at infinity focus (rad, in (0, π));
    /// `aperture`: f-number (> 0) or radius (m, ≥ 0); `focus_distance_m` > focal length;
    /// `sensor_width_mm` > 0 (`DEFAULT_SENSOR_WIDTH_MM` = 36 for full frame).
    pub fn new(
        frame: CameraFrame,
        focal: FocalSpec,
        aperture: ApertureSpec,
        focus_distance_m: f32,
        sensor_width_mm: f32,
    ) -> Result<Self, InvalidParameter> {
        let sensor_width_m = 1e-3 * positive(CONTEXT, "sensor_width_mm", sensor_width_mm)?;
        let focal_length_m = match focal {
            FocalSpec::FocalLengthMm(f_mm) => 1e-3 * positive(CONTEXT, "focal_length_mm", f_mm)?,
            FocalSpec::FovRad(fov) => {
                if !(fov.is_finite() && fov > 0.0 && fov < std::f32::consts::PI) {
                    return Err(InvalidParameter::new(
                        CONTEXT,
                        "fov_rad",
                        fov,
                        "(0, π) rad across the sensor width",
                    ));
                }
                0.5 * sensor_width_m / (0.5 * fov).tan()
            }
        };
        let aperture_radius_m = match aperture {
            ApertureSpec::FNumber(n) => 0.5 * focal_length_m / positive(CONTEXT, "f_number", n)?,
            ApertureSpec::RadiusM(r) => {
                if !(r.is_finite() && r >= 0.0) {
                    return Err(InvalidParameter::new(
                        CONTEXT,
                        "aperture_radius_m",
                        r,
                        "a finite number ≥ 0",
                    ));
                }
                r
            }
        };
        if !(focus_distance_m.is_finite() && focus_distance_m > focal_length_m) {
            return Err(InvalidParameter::new(
                CONTEXT,
                "focus_distance_m",
                focus_distance_m,
                format!(
                    "finite and greater than the focal length ({} m): a thin lens forms no \
                     real image of nearer points",
                    focal_length_m
                ),
            ));
        }
        let image_distance_m =
            focal_length_m * focus_distance_m / (focus_distance_m - focal_length_m);
        let focal_px = image_distance_m * frame.size_px().x / sensor_width_m;
        Ok(Self {
            frame,
            focal_length_m,
            aperture_radius_m,
            focus_distance_m,
            sensor_width_m,
            image_distance_m,
            focal_px,
        })
    }

    pub fn focal_length_m(&self) -> f32 {
        self.focal_length_m
    }

    pub fn aperture_radius_m(&self) -> f32 {
        self.aperture_radius_m
    }

    pub fn focus_distance_m(&self) -> f32 {
        self.focus_distance_m
    }

    pub fn sensor_width_m(&self) -> f32 {
        self.sensor_width_m
    }

    /// Lens-to-sensor distance v = f d_f / (d_f − f).
    pub fn image_distance_m(&self) -> f32 {
        self.image_distance_m
    }

    /// Horizontal field of view as focused: 2 atan(s / 2v).
    pub fn fov_rad(&self) -> f32 {
        2.0 * (0.5 * self.sensor_width_m / self.image_distance_m).atan()
    }

    /// Diameter (m, on the sensor) of the circle of confusion of a point at depth
    /// `depth_m`: c = 2A · f |d − d_f| / (d (d_f − f)).
    pub fn circle_of_confusion_m(&self, depth_m: f32) -> f32 {
        let (f, df) = (self.focal_length_m, self.focus_distance_m);
        2.0 * self.aperture_radius_m * f * (depth_m - df).abs() / (depth_m * (df - f))
    }

    /// Diameter in pixels of the circle of confusion of the world point `world_point_m`
    /// (its depth along the optical axis; 0 behind the lens).
    pub fn circle_of_confusion_px(&self, world_point_m: Vec3A) -> f32 {
        let depth_m = -self.frame.camera_to_world.inverse_point(world_point_m).z;
        if depth_m <= 0.0 {
            return 0.0;
        }
        self.circle_of_confusion_m(depth_m) * self.px_per_sensor_m()
    }

    /// Diameter in pixels of the circle of confusion of a point at infinity (what a ray
    /// that leaves the scene shows): the limit of c for d → ∞, 2A·f/(d_f − f).
    pub fn circle_of_confusion_at_infinity_px(&self) -> f32 {
        let (f, df) = (self.focal_length_m, self.focus_distance_m);
        2.0 * self.aperture_radius_m * f / (df - f) * self.px_per_sensor_m()
    }

    /// Pixels per metre on the sensor.
    fn px_per_sensor_m(&self) -> f32 {
        self.frame.size_px().x / self.sensor_width_m
    }

    /// The aperture point (camera space, z = 0) of `lens_sample` ∈ [0, 1)².
    pub fn lens_point_m(&self, lens_sample: Vec2) -> Vec3A {
        let l = self.aperture_radius_m * sample_uniform_disk_concentric(lens_sample);
        Vec3A::new(l.x, l.y, 0.0)
    }

    /// Aperture area π r² (m²); 1 for a zero aperture, whose lens is a point (pbrt-v4
    /// `PerspectiveCamera::We`'s `lensArea`).
    pub fn lens_area_m2(&self) -> f32 {
        if self.aperture_radius_m > 0.0 {
            std::f32::consts::PI * self.aperture_radius_m * self.aperture_radius_m
        } else {
            1.0
        }
    }

    /// The film point (px) whose ray through the aperture point of `lens_sample` passes
    /// through `world_point_m`: the inverse of `generate_ray` at a fixed lens sample. Over
    /// all lens samples these points fill the image of the point (its circle of confusion).
    /// `None` behind the lens or off the film.
    pub fn project_through_lens(&self, world_point_m: Vec3A, lens_sample: Vec2) -> Option<Vec2> {
        let p = self.frame.camera_to_world.inverse_point(world_point_m);
        if p.z >= 0.0 {
            return None;
        }
        let lens = self.lens_point_m(lens_sample);
        let focus_point = lens + (p - lens) * (self.focus_distance_m / -p.z);
        let s = self.focal_px / self.focus_distance_m;
        let film = self
            .frame
            .film_from_offset_up_px(Vec2::new(focus_point.x * s, focus_point.y * s));
        self.frame.contains(film).then_some(film)
    }
}

/// Importance of pbrt-v4's thin lens, W_e = f_px² / (W H · A_lens · cos⁴θ) with the film at
/// the focus-plane scale (`perspective` derives it for our film parameterisation). The lens
/// point of `lens_sample` is `lens_point_m`'s concentric map, uniform over the aperture.
impl CameraModel for ThinLensCamera {
    fn frame(&self) -> &CameraFrame {
        &self.frame
    }

    fn camera_ray(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<CameraRay> {
        let o = self.frame.offset_up_px(film_point_px);
        let scale = self.focus_distance_m / self.focal_px;
        let focus_point = Vec3A::new(o.x * scale, o.y * scale, -self.focus_distance_m);
        let lens = self.lens_point_m(lens_sample);
        Some((lens, (focus_point - lens).normalize()))
    }

    /// Chief-ray projection (through the lens centre).
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
        self.aperture_radius_m == 0.0
    }

    fn importance_area_px2(&self) -> f32 {
        let size = self.frame.size_px();
        size.x * size.y
    }

    fn sample_lens_point(&self, u_lens: Vec2) -> Option<(Vec3A, f32)> {
        Some((self.lens_point_m(u_lens), 1.0 / self.lens_area_m2()))
    }

    fn importance_camera_space(
        &self,
        lens_point_m: Vec3A,
        direction: Vec3A,
    ) -> Option<CameraImportance> {
        perspective::importance(
            &self.frame,
            self.focal_px,
            self.focus_distance_m,
            self.lens_area_m2(),
            lens_point_m,
            direction,
        )
    }

    fn pdf_we_camera_space(&self, lens_point_m: Vec3A, direction: Vec3A) -> Option<(f32, f32)> {
        perspective::pdf_we(
            &self.frame,
            self.focal_px,
            self.focus_distance_m,
            self.lens_area_m2(),
            lens_point_m,
            direction,
        )
    }
}
