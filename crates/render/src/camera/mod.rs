//! Cameras: pinhole, thin lens, fisheye (four projections), orthographic and spherical
//! (equirectangular). `Camera` is an enum dispatched by `match` (docs/architecture.md, "Deliberate choices").
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
//!
//! **The camera contract** (what light tracing and BDPT ask of a camera: pbrt-v3 §16.1.1
//! "Sampling cameras", pbrt-v4 `Camera::We`/`PDF_We`/`SampleWi`, Veach 1997 ch. 10). Every
//! model implements [`CameraModel`] in camera space, with no default methods (a new model
//! must state every answer); `Camera` forwards each method by exhaustive `match` and adds
//! the world transform.
//! - `generate_ray` / `project`: film point (+ lens sample) → ray; world point → film point
//!   (the chief ray). `project_with_jacobian` adds ∂film/∂world (px/m) for footprints.
//! - `importance(ray)`: W_e(p, ω) (m⁻² sr⁻¹) of a ray leaving lens point p, and its film
//!   point. Normalised so that ∫_lens ∫ W_e |cos θ| dω dA(p) = 1, θ measured from
//!   `forward()` (the lens normal), over the directions that reach the film region with
//!   rays, of area A_imp = `importance_area_px2` (W H, or π R² for a circular fisheye); a
//!   point lens (`is_delta_position`) counts as area 1. Equivalently
//!   W_e |cos θ| = (dA_film/dω) / (A_imp A_lens): every film point with a ray weighs alike.
//! - `pdf_we(ray)`: (pdf_pos per m², pdf_dir per sr) with which `generate_ray` makes that
//!   ray from a film point uniform over all W × H px and a lens sample uniform in [0, 1)²:
//!   pdf_pos = 1/A_lens, pdf_dir = W_e |cos θ| A_lens · A_imp/(W H).
//! - `sample_wi(p, u)`: a lens point for a connection from scene point p, with W_e towards
//!   p, the film point and the solid-angle density at p, dist² / (|cos θ_lens| A_lens).
//! - `importance_support()`: a user-facing `Err` for the orthographic and spherical
//!   cameras, whose importance methods answer `None`.
//!
//! Importance is computed in camera space, so it assumes a rigid camera-to-world transform.

// Closed sets are matched exhaustively here: a new camera or projection must be handled
// everywhere, not fall into a catch-all arm.
#![deny(clippy::wildcard_enum_match_arm)]

mod fisheye;
mod frame;
mod orthographic;
mod perspective;
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
pub type CameraRay = (Vec3A, Vec3A);

/// The importance a ray leaving the camera carries and where it meets the film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraImportance {
    /// W_e (m⁻² sr⁻¹), normalised as in the module docs.
    pub importance: f32,
    /// The film point (px) whose camera ray this is.
    pub film_point_px: Vec2,
}

/// A lens point chosen for a connection from a scene point (pbrt-v4 `CameraWiSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraWiSample {
    /// Unit, world space, from the reference point towards `p_lens_m`.
    pub wi: Vec3A,
    /// The lens point (world, m).
    pub p_lens_m: Vec3A,
    pub distance_m: f32,
    /// Solid-angle density at the reference point: dist² / (|cos θ_lens| · A_lens).
    pub pdf_per_sr: f32,
    /// W_e at `p_lens_m` in direction −`wi`.
    pub importance: f32,
    pub film_point_px: Vec2,
    /// The camera's forward axis (world, unit), the lens normal.
    pub n_lens: Vec3A,
}

/// What every camera model answers, in camera space (`Camera` adds the world transform).
/// No default methods: a new model must state each answer. Directions are unit vectors.
pub trait CameraModel {
    fn frame(&self) -> &CameraFrame;

    /// The camera-space ray through `film_point_px` leaving the aperture point of
    /// `lens_sample` ∈ [0, 1)² (ignored by point-like models); `None` where the film point
    /// has no ray.
    fn camera_ray(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<CameraRay>;

    /// The film point (px, possibly off the film) imaging camera-space point `p_m`; `None`
    /// behind the camera or outside the field of view.
    fn project_camera_space(&self, p_m: Vec3A) -> Option<Vec2>;

    /// The rows ∂(film x px)/∂p and ∂(film y px)/∂p of `project_camera_space` at `p_m`;
    /// `None` where it has none or the map is singular there.
    fn project_jacobian_camera_space(&self, p_m: Vec3A) -> Option<[Vec3A; 2]>;

    /// `Ok` when the model has an importance function, else a user-facing reason.
    fn importance_support(&self) -> Result<(), String>;

    /// Whether the lens is a single point (pbrt-v4 `IsDeltaPosition`).
    fn is_delta_position(&self) -> bool;

    /// Film area (px²) over which W_e integrates to one: the part of the film with rays.
    fn importance_area_px2(&self) -> f32;

    /// A lens point (camera space) for `u_lens` ∈ [0, 1)² and its density per m² (1 for a
    /// point-like lens); `None` without importance.
    fn sample_lens_point(&self, u_lens: Vec2) -> Option<(Vec3A, f32)>;

    /// W_e of the ray leaving lens point `lens_point_m` in `direction`, and its film point;
    /// `None` where the ray reaches no film point with a ray.
    fn importance_camera_space(
        &self,
        lens_point_m: Vec3A,
        direction: Vec3A,
    ) -> Option<CameraImportance>;

    /// (pdf_pos per m², pdf_dir per sr) of `camera_ray` producing this ray (module docs).
    fn pdf_we_camera_space(&self, lens_point_m: Vec3A, direction: Vec3A) -> Option<(f32, f32)>;
}

/// `match` over every variant with the same body (no catch-all arm: a new variant is a
/// compile error until it is listed).
macro_rules! each_camera {
    ($camera:expr, $c:ident => $body:expr) => {
        match $camera {
            Camera::Pinhole($c) => $body,
            Camera::ThinLens($c) => $body,
            Camera::Fisheye($c) => $body,
            Camera::Orthographic($c) => $body,
            Camera::Spherical($c) => $body,
        }
    };
}

impl Camera {
    pub fn frame(&self) -> &CameraFrame {
        each_camera!(self, c => c.frame())
    }

    /// The world-space ray (unit direction, `t` in metres, over (0, ∞)) through
    /// `film_point_px`, with differentials one pixel over in x and y. `lens_sample` ∈ [0, 1)²
    /// picks the point on the aperture (thin lens only; the others ignore it). `None` where
    /// the film point has no ray: outside a circular fisheye's image circle.
    pub fn generate_ray(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<RayDifferential> {
        each_camera!(self, c => {
            differential(c.frame(), film_point_px, |p| c.camera_ray(p, lens_sample))
        })
    }

    /// The ray of `generate_ray` alone (the same bits), without its differentials: for
    /// renders that never read them (no texture needs a footprint), two camera rays fewer
    /// per sample.
    #[inline]
    pub fn generate_ray_only(&self, film_point_px: Vec2, lens_sample: Vec2) -> Option<Ray> {
        let (o, d) = each_camera!(self, c => c.camera_ray(film_point_px, lens_sample))?;
        let t = &self.frame().camera_to_world;
        Some(Ray::infinite(t.point(o), t.vector(d).normalize()))
    }

    /// `generate_ray_only` for `N` film points at once, the same rays: the pinhole
    /// camera's in one vector loop (`PinholeCamera::world_rays_many`), the others' one by
    /// one. Fast path only: the packet tracer's camera rays.
    #[inline(always)]
    pub(crate) fn generate_rays_only_many<const N: usize>(
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
            Camera::ThinLens(_)
            | Camera::Fisheye(_)
            | Camera::Orthographic(_)
            | Camera::Spherical(_) => {
                std::array::from_fn(|k| self.generate_ray_only(film_points_px[k], lens_samples[k]))
            }
        }
    }

    /// Whether `generate_ray` reads its lens sample (the thin lens only): the driver
    /// computes those two dimensions only then.
    pub fn uses_lens_sample(&self) -> bool {
        match self {
            Camera::ThinLens(_) => true,
            Camera::Pinhole(_)
            | Camera::Fisheye(_)
            | Camera::Orthographic(_)
            | Camera::Spherical(_) => false,
        }
    }

    /// The film point (px) at which `world_point_m` is imaged: the inverse of
    /// `generate_ray` (for the thin lens, through the lens centre: the chief ray). `None`
    /// when the point is behind the camera, outside the field of view or off the film.
    pub fn project(&self, world_point_m: Vec3A) -> Option<Vec2> {
        let p = self.frame().camera_to_world.inverse_point(world_point_m);
        let film = each_camera!(self, c => c.project_camera_space(p))?;
        self.frame().contains(film).then_some(film)
    }

    /// `project` and its Jacobian: the film point and the rows ∂(film x px)/∂x and
    /// ∂(film y px)/∂x with respect to the world point (px per m; the footprint a world
    /// patch covers on the film). `None` where `project` is, and where the map is singular
    /// (the poles of the spherical camera).
    pub fn project_with_jacobian(&self, world_point_m: Vec3A) -> Option<(Vec2, [Vec3A; 2])> {
        let t = &self.frame().camera_to_world;
        let p = t.inverse_point(world_point_m);
        // `project`'s arithmetic, so the same film point.
        let film = each_camera!(self, c => c.project_camera_space(p))?;
        if !self.frame().contains(film) {
            return None;
        }
        let rows = each_camera!(self, c => c.project_jacobian_camera_space(p))?;
        // ∂film/∂x = (∂film/∂p)·M⁻¹ for p = M⁻¹x: each row maps by (M⁻¹)ᵀ, the normal matrix.
        Some((film, rows.map(|r| t.normal(r))))
    }

    /// The camera's forward axis (world, unit): the lens normal.
    pub fn forward(&self) -> Vec3A {
        self.frame()
            .camera_to_world
            .vector(Vec3A::NEG_Z)
            .normalize()
    }

    /// `Ok` when light tracing and BDPT can connect to this camera; otherwise a message
    /// for the user saying why not and what to use instead.
    pub fn importance_support(&self) -> Result<(), String> {
        each_camera!(self, c => c.importance_support())
    }

    /// Whether the camera's lens is a single point (pinhole, fisheye; a thin lens with a
    /// zero aperture): then no path can hit it and only `sample_wi` connects to it.
    pub fn is_delta_position(&self) -> bool {
        each_camera!(self, c => c.is_delta_position())
    }

    /// The film area (px²) over which W_e integrates to one: W·H, or the image circle's area
    /// for a circular fisheye; 0 for cameras without importance.
    pub fn importance_area_px2(&self) -> f32 {
        each_camera!(self, c => c.importance_area_px2())
    }

    /// W_e (pbrt-v4 `Camera::We`) of a world-space ray leaving the camera (origin on the
    /// lens, not checked) and the film point it comes from; `None` when the ray reaches no
    /// film point with a ray, or the camera has no importance.
    pub fn importance(&self, ray: &Ray) -> Option<CameraImportance> {
        let (o, d) = self.ray_to_camera(ray)?;
        each_camera!(self, c => c.importance_camera_space(o, d))
    }

    /// (pdf_pos per m² of lens, pdf_dir per sr) with which `generate_ray` produces `ray`
    /// from a film point uniform over the whole W × H film and a lens sample uniform in
    /// [0, 1)² (pbrt-v4 `Camera::PDF_We`); pdf_pos is 1 for point-like cameras. `None` where
    /// `importance` is.
    pub fn pdf_we(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (o, d) = self.ray_to_camera(ray)?;
        each_camera!(self, c => c.pdf_we_camera_space(o, d))
    }

    /// A lens point for a connection from `reference_p_m` (pbrt-v4 `Camera::SampleWi`):
    /// uniform over the aperture for the thin lens (`u_lens` ∈ [0, 1)², the lens mapping of
    /// `generate_ray`), the camera position otherwise. `None` when that lens point does not
    /// image the reference point onto the film, or the camera has no importance.
    pub fn sample_wi(&self, reference_p_m: Vec3A, u_lens: Vec2) -> Option<CameraWiSample> {
        let (lens_cam, pdf_area) = each_camera!(self, c => c.sample_lens_point(u_lens))?;
        let t = &self.frame().camera_to_world;
        let p_lens_m = t.point(lens_cam);
        let to_lens = p_lens_m - reference_p_m;
        let distance_m = to_lens.length();
        if !(distance_m > 0.0 && distance_m.is_finite()) {
            return None;
        }
        let wi = to_lens / distance_m;
        let direction = self.direction_to_camera(-wi)?;
        let imp = each_camera!(self, c => c.importance_camera_space(lens_cam, direction))?;
        let n_lens = self.forward();
        let cos_lens = n_lens.dot(wi).abs();
        // pbrt-v4 `PerspectiveCamera::SampleWi`: area density → solid angle (dist²/|cos|).
        let pdf_per_sr = distance_m * distance_m * pdf_area / cos_lens;
        pdf_per_sr.is_finite().then_some(CameraWiSample {
            wi,
            p_lens_m,
            distance_m,
            pdf_per_sr,
            importance: imp.importance,
            film_point_px: imp.film_point_px,
            n_lens,
        })
    }

    /// A world ray in camera space: its origin and unit direction.
    fn ray_to_camera(&self, ray: &Ray) -> Option<CameraRay> {
        let d = self.direction_to_camera(ray.direction)?;
        let o = self.frame().camera_to_world.inverse_point(ray.origin);
        o.is_finite().then_some((o, d))
    }

    /// A world direction as a unit camera-space one; `None` for zero or non-finite ones.
    fn direction_to_camera(&self, direction: Vec3A) -> Option<Vec3A> {
        let d = self.frame().camera_to_world.inverse_vector(direction);
        let length = d.length();
        (length > 0.0 && length.is_finite()).then(|| d / length)
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

#[cfg(test)]
mod tests;
