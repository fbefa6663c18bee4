//! Ray differentials for hits that the camera ray's own differential does not reach (after
//! a scattering event): pbrt-v4's approximation (§10.1.2 `CameraBase::Approximate_dp_dxy`)
//! treats the hit as if seen directly from the camera, with the camera's per-pixel spread
//! of ray origins and directions, scaled by the pixel's sample count. This keeps texture
//! filtering at indirect hits proportional to how large the surface appears in the image,
//! which is what pbrt-v4 does in place of tracking differentials through rough bounces.

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::{Frame, Ray, RayDifferential};

use crate::camera::Camera;

/// The camera's per-pixel spread, measured once at the film centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFootprint {
    /// Origin of the centre pixel's ray, m.
    pub origin: Vec3A,
    /// Direction of the centre pixel's ray (used when the camera has no angular spread:
    /// orthographic).
    pub direction: Vec3A,
    /// Angle between neighbouring pixels' rays, radians (small-angle: |Δω|).
    pub direction_spread: f32,
    /// Distance between neighbouring pixels' ray origins, m.
    pub position_spread_m: f32,
}

impl CameraFootprint {
    /// The footprint of `camera` at the centre of a `resolution` film; `None` when the
    /// camera has no ray there.
    pub fn from_camera(camera: &Camera, resolution: UVec2) -> Option<Self> {
        let centre = Vec2::new(resolution.x as f32, resolution.y as f32) * 0.5;
        let rd = camera.generate_ray(centre, Vec2::splat(0.5))?;
        let (o, d) = (rd.ray.origin, rd.ray.direction);
        Some(Self {
            origin: o,
            direction: d,
            direction_spread: (rd.rx_direction - d)
                .length()
                .max((rd.ry_direction - d).length()),
            position_spread_m: (rd.rx_origin - o).length().max((rd.ry_origin - o).length()),
        })
    }

    /// A ray differential towards `p` whose offset rays spread like the camera's, times
    /// `scale` (max(1/8, 1/√spp), pbrt-v4).
    pub fn approximate(&self, p: Vec3A, scale: f32) -> RayDifferential {
        let w = if self.direction_spread > 0.0 {
            (p - self.origin).try_normalize().unwrap_or(self.direction)
        } else {
            self.direction
        };
        let origin = if self.direction_spread > 0.0 {
            self.origin
        } else {
            // Orthographic: the ray through p runs along the view direction.
            p - w * (p - self.origin).dot(w)
        };
        let frame = Frame::from_z(w);
        let (dp, dd) = (
            scale * self.position_spread_m,
            scale * self.direction_spread,
        );
        RayDifferential {
            ray: Ray::infinite(origin, w),
            rx_origin: origin + dp * frame.x,
            rx_direction: (w + dd * frame.x).normalize(),
            ry_origin: origin + dp * frame.y,
            ry_direction: (w + dd * frame.y).normalize(),
        }
    }
}
