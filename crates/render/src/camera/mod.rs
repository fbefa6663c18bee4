//! Cameras: pinhole, thin lens, fisheye (four projections), orthographic and spherical
//! (equirectangular). `Camera` is an enum dispatched by `match` (DESIGN.md "Core types").
//!
//! Every model works in camera space (−Z forward, +X right, +Y up) and maps continuous film
//! points in pixels (origin at the top-left corner, y down; see the crate docs) to rays;
//! `CameraFrame` carries the camera-to-world transform and the film resolution. Each model
//! also has the inverse map `project` (world point → film point), which the tests use and
//! light tracing will.
//!
//! Ray differentials follow pbrt-v4 (§5.1.1 "Camera interface", `GenerateRayDifferential`):
//! the offset rays are the rays of the film points one pixel over in +x and +y with the same
//! lens sample. Where that neighbour has no ray (beyond a circular fisheye's image circle)
//! the neighbour on the other side is reflected through the centre ray.

mod fisheye;
mod frame;
mod orthographic;
mod pinhole;
mod spherical;
mod thin_lens;

pub use fisheye::{FisheyeCamera, FisheyeCoverage, FisheyeProjection};
pub use frame::CameraFrame;
pub use orthographic::OrthographicCamera;
pub use pinhole::PinholeCamera;
pub use spherical::SphericalCamera;
pub use thin_lens::{ApertureSpec, FocalSpec, ThinLensCamera, DEFAULT_SENSOR_WIDTH_MM};

use glam::{Vec2, Vec3A};
use prism_geometry::{Ray, RayDifferential};

/// A camera model with its pose and film resolution.
#[derive(Clone, Debug, PartialEq)]
pub enum Camera {
    Pinhole(PinholeCamera),
    ThinLens(ThinLensCamera),
    Fisheye(FisheyeCamera),
    Orthographic(OrthographicCamera),
    Spherical(SphericalCamera),
}

/// A ray in camera space: origin (m) and unit direction.
pub(crate) type CameraRay = (Vec3A, Vec3A);

impl Camera {
    pub fn frame(&self) -> &CameraFrame {
        match self {
            Camera::Pinhole(c) => c.frame(),
            Camera::ThinLens(c) => c.frame(),
            Camera::Fisheye(c) => c.frame(),
            Camera::Orthographic(c) => c.frame(),
            Camera::Spherical(c) => c.frame(),
        }
    }

    /// The world-space ray (unit direction, `t` in metres, over (0, ∞)) through
    /// `film_point_px`, with differentials one pixel over in x and y. `lens_sample` ∈ [0, 1)²
    /// picks the point on the aperture (thin lens only; the others ignore it). `None` where
    /// the film point has no ray: outside a circular fisheye's image circle.
    pub fn generate_ray(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<RayDifferential> {
        match self {
            Camera::Pinhole(c) => differential(c.frame(), film_point_px, |p| c.camera_ray(p)),
            Camera::ThinLens(c) => {
                differential(c.frame(), film_point_px, |p| c.camera_ray(p, lens_sample))
            }
            Camera::Fisheye(c) => differential(c.frame(), film_point_px, |p| c.camera_ray(p)),
            Camera::Orthographic(c) => differential(c.frame(), film_point_px, |p| c.camera_ray(p)),
            Camera::Spherical(c) => differential(c.frame(), film_point_px, |p| c.camera_ray(p)),
        }
    }

    /// The ray of `generate_ray` alone (the same bits), without its differentials: for
    /// renders that never read them (no texture needs a footprint), two camera rays fewer
    /// per sample.
    #[inline]
    pub fn generate_ray_only(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<Ray> {
        let (o, d) = match self {
            Camera::Pinhole(c) => c.camera_ray(film_point_px),
            Camera::ThinLens(c) => c.camera_ray(film_point_px, lens_sample),
            Camera::Fisheye(c) => c.camera_ray(film_point_px),
            Camera::Orthographic(c) => c.camera_ray(film_point_px),
            Camera::Spherical(c) => c.camera_ray(film_point_px),
        }?;
        let t = &self.frame().camera_to_world;
        Some(Ray::infinite(t.point(o), t.vector(d).normalize()))
    }

    /// `generate_ray_only` for `N` film points at once, the same rays: the pinhole
    /// camera's in one vector loop (`PinholeCamera::world_rays_many`), the others' one by
    /// one.
    #[inline(always)]
    pub fn generate_rays_only_many<const N: usize>(
        &self,
        film_points_px: &[Vec2; N],
        lens_samples: &[Vec2; N],
    ) -> [Option<Ray>; N] {
        match self {
            Camera::Pinhole(c) => {
                let (origin, d) = c.world_rays_many(film_points_px);
                std::array::from_fn(|k| {
                    Some(Ray::infinite(origin, Vec3A::new(d[0][k], d[1][k], d[2][k])))
                })
            }
            _ => {
                std::array::from_fn(|k| self.generate_ray_only(film_points_px[k], lens_samples[k]))
            }
        }
    }

    /// Whether `generate_ray` reads its lens sample (the thin lens only): the driver
    /// computes those two dimensions only then.
    pub fn uses_lens_sample(&self) -> bool {
        matches!(self, Camera::ThinLens(_))
    }

    /// The film point (px) at which `world_point_m` is imaged: the inverse of
    /// `generate_ray` (for the thin lens, through the lens centre: the chief ray). `None`
    /// when the point is behind the camera, outside the field of view or off the film.
    pub fn project(&self, world_point_m: Vec3A) -> Option<Vec2> {
        let p = self.frame().camera_to_world.inverse_point(world_point_m);
        let film = match self {
            Camera::Pinhole(c) => c.project_camera_space(p),
            Camera::ThinLens(c) => c.project_camera_space(p),
            Camera::Fisheye(c) => c.project_camera_space(p),
            Camera::Orthographic(c) => c.project_camera_space(p),
            Camera::Spherical(c) => c.project_camera_space(p),
        }?;
        self.frame().contains(film).then_some(film)
    }
}

/// Builds the world-space ray differential from a camera-space ray function.
fn differential(
    frame: &CameraFrame,
    film_point_px: Vec2,
    ray: impl Fn(Vec2) -> Option<CameraRay>,
) -> Option<RayDifferential> {
    let (o, d) = ray(film_point_px)?;
    let neighbour = |step: Vec2| -> CameraRay {
        if let Some(r) = ray(film_point_px + step) {
            r
        } else if let Some((o2, d2)) = ray(film_point_px - step) {
            (2.0 * o - o2, (2.0 * d - d2).normalize_or(d))
        } else {
            (o, d)
        }
    };
    let (ox, dx) = neighbour(Vec2::X);
    let (oy, dy) = neighbour(Vec2::Y);
    let t = &frame.camera_to_world;
    Some(RayDifferential {
        ray: Ray::infinite(t.point(o), t.vector(d).normalize()),
        rx_origin: t.point(ox),
        rx_direction: t.vector(dx).normalize(),
        ry_origin: t.point(oy),
        ry_direction: t.vector(dy).normalize(),
    })
}
