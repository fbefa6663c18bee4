//! Scene camera description → runtime `Camera`.
//!
//! Field-of-view conventions: `PinholeCamera::new` takes the horizontal fov. A scene fov
//! given along another axis is converted through the image-plane half-extents, which scale
//! with the film sides: tan(h/2) = tan(v/2) · W/H for a vertical fov and
//! tan(h/2) = tan(d/2) · W/√(W² + H²) for a diagonal one (pbrt-v4 §5.2.2 defines its fov
//! along the shorter axis by the same relation).

use glam::UVec2;
use prism_scene::{CameraKind, FisheyeFit, FovAxis};

use super::error::SceneBuildError;
use super::transform::to_geometry_transform;
use crate::camera::{
    ApertureSpec, Camera, CameraFrame, FisheyeCamera, FisheyeCoverage, FisheyeProjection,
    FocalSpec, OrthographicCamera, PinholeCamera, SphericalCamera, ThinLensCamera,
};

/// The horizontal fov (rad) equivalent to `fov_rad` measured along `axis` on a film of
/// `resolution` pixels.
pub fn horizontal_fov_rad(fov_rad: f64, axis: FovAxis, resolution: UVec2) -> f64 {
    let (w, h) = (f64::from(resolution.x), f64::from(resolution.y));
    let ratio = match axis {
        FovAxis::Horizontal => return fov_rad,
        FovAxis::Vertical => w / h,
        FovAxis::Diagonal => w / (w * w + h * h).sqrt(),
    };
    2.0 * ((0.5 * fov_rad).tan() * ratio).atan()
}

/// Builds the camera of `camera` for a film of `resolution` whose samples reach
/// `film_margin_px` outside it (the filter radius; `CameraFrame::film_margin_px`).
pub fn build_camera(
    file: &std::path::Path,
    camera: &prism_scene::Camera,
    resolution: UVec2,
    film_margin_px: f32,
) -> Result<Camera, SceneBuildError> {
    let err = |place: &str, message: String| SceneBuildError::new(file, place, message);
    let to_world = to_geometry_transform(&camera.transform.matrix).ok_or_else(|| {
        err(
            "camera.transform",
            "the camera transform is not invertible in single precision".into(),
        )
    })?;
    let frame = CameraFrame::new(to_world, resolution)
        .map_err(|e| err("film.resolution", e.to_string()))?
        .with_film_margin_px(film_margin_px);
    let built = match &camera.kind {
        CameraKind::Pinhole { fov_rad, fov_axis } => {
            let h = horizontal_fov_rad(*fov_rad, *fov_axis, resolution);
            PinholeCamera::new(frame, h as f32).map(Camera::Pinhole)
        }
        CameraKind::ThinLens {
            focal_length_m,
            sensor_width_m,
            aperture_radius_m,
            f_number,
            focus_distance_m,
            ..
        } => {
            let aperture = match f_number {
                Some(n) => ApertureSpec::FNumber(*n as f32),
                None => ApertureSpec::RadiusM(*aperture_radius_m as f32),
            };
            ThinLensCamera::new(
                frame,
                FocalSpec::FocalLengthMm((focal_length_m * 1e3) as f32),
                aperture,
                *focus_distance_m as f32,
                (sensor_width_m * 1e3) as f32,
            )
            .map(Camera::ThinLens)
        }
        CameraKind::Fisheye {
            projection,
            fov_rad,
            fit,
        } => {
            let projection = match projection {
                prism_scene::FisheyeProjection::Equidistant => FisheyeProjection::Equidistant,
                prism_scene::FisheyeProjection::Equisolid => FisheyeProjection::Equisolid,
                prism_scene::FisheyeProjection::Orthographic => FisheyeProjection::Orthographic,
                prism_scene::FisheyeProjection::Stereographic => FisheyeProjection::Stereographic,
            };
            let coverage = match fit {
                FisheyeFit::Circular => FisheyeCoverage::Circular,
                FisheyeFit::Cropped => FisheyeCoverage::Cropped,
            };
            FisheyeCamera::new(frame, projection, coverage, *fov_rad as f32).map(Camera::Fisheye)
        }
        CameraKind::Orthographic { width_m } => {
            OrthographicCamera::new(frame, *width_m as f32).map(Camera::Orthographic)
        }
        CameraKind::Spherical => SphericalCamera::new(frame).map(Camera::Spherical),
    };
    built.map_err(|e| err("camera", e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertical_and_diagonal_fov_convert_through_the_film_aspect() {
        let res = UVec2::new(400, 200);
        let v = 40f64.to_radians();
        let h = horizontal_fov_rad(v, FovAxis::Vertical, res);
        assert!(((0.5 * h).tan() - 2.0 * (0.5 * v).tan()).abs() < 1e-12);
        let d = 70f64.to_radians();
        let h = horizontal_fov_rad(d, FovAxis::Diagonal, res);
        let diag = (400f64.powi(2) + 200f64.powi(2)).sqrt();
        assert!(((0.5 * h).tan() - (0.5 * d).tan() * 400.0 / diag).abs() < 1e-12);
        assert_eq!(horizontal_fov_rad(d, FovAxis::Horizontal, res), d);
    }
}
