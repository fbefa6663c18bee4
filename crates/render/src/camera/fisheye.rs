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

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraRay};
use crate::error::InvalidParameter;

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

    pub fn frame(&self) -> &CameraFrame {
        &self.frame
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

    pub(crate) fn camera_ray(&self, film_point_px: Vec2) -> Option<CameraRay> {
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

    pub(crate) fn project_camera_space(&self, p: Vec3A) -> Option<Vec2> {
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
}
