//! Rays and ray differentials (pbrt-v4 §3.6 "Rays", §3.6.1 "Ray differentials").

use glam::Vec3A;

/// Relative offset used by [`Ray::spawn`]: t_min is this many units of the origin's largest
/// coordinate magnitude (plus one, so points near the world origin still get an offset).
/// Chosen ~170 ulps of f32 at the origin's magnitude, enough to step off the surface a ray
/// leaves without the error-bound bookkeeping of pbrt-v4 §6.8.6.
pub const SPAWN_T_MIN_REL: f32 = 2.0e-5;

/// A ray `origin + t·direction` for `t` in `(t_min, t_max)`. `direction` need not be unit
/// length (object-space rays under a scaling transform are not); `t` is in units of
/// `direction`, so it is a distance in metres only when `direction` is normalised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3A,
    pub direction: Vec3A,
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    /// A ray with explicit parameter interval.
    pub fn new(origin: Vec3A, direction: Vec3A, t_min: f32, t_max: f32) -> Self {
        Self {
            origin,
            direction,
            t_min,
            t_max,
        }
    }

    /// A ray over `(0, ∞)`, for camera rays that start off any surface.
    pub fn infinite(origin: Vec3A, direction: Vec3A) -> Self {
        Self::new(origin, direction, 0.0, f32::INFINITY)
    }

    /// A ray leaving a surface point: `t_min` is offset so the surface it leaves is not hit
    /// again (the origin stays on the surface; the offset scales with the coordinates' magnitude).
    pub fn spawn(origin: Vec3A, direction: Vec3A) -> Self {
        Self::new(
            origin,
            direction,
            spawn_t_min(origin, direction),
            f32::INFINITY,
        )
    }

    /// A ray leaving a surface point through or off the surface: the origin moves off the
    /// surface along the normal `n` (to the side `direction` goes to) and `t_min` is 0
    /// (pbrt-v4 `OffsetRayOrigin`). Unlike `spawn`, whose `t_min` skips the first
    /// 2·10⁻⁵·(1 + |p|∞) of the ray, this still finds a surface the ray meets right away:
    /// an adjacent face of a box entered next to its edge, which a path tracking media must
    /// not miss (it would leave the box still marked as inside).
    pub fn spawn_off_surface(origin: Vec3A, n: Vec3A, direction: Vec3A) -> Self {
        let offset = SPAWN_T_MIN_REL * (1.0 + origin.abs().max_element());
        let side = if n.dot(direction) >= 0.0 { 1.0 } else { -1.0 };
        Self::new(origin + n * (offset * side), direction, 0.0, f32::INFINITY)
    }

    /// A shadow ray from `from` to `to`, stopping short of `to` by the same relative offset.
    pub fn spawn_to(from: Vec3A, to: Vec3A) -> Self {
        let d = to - from;
        let eps = spawn_t_min(from, d).max(spawn_t_min(to, d));
        Self::new(from, d, eps, 1.0 - eps)
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + t * self.direction
    }
}

fn spawn_t_min(origin: Vec3A, direction: Vec3A) -> f32 {
    let len = direction.length();
    if len > 0.0 {
        SPAWN_T_MIN_REL * (1.0 + origin.abs().max_element()) / len
    } else {
        0.0
    }
}

/// A ray with offset rays for one pixel step in x and in y (pbrt-v4 `RayDifferential`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDifferential {
    pub ray: Ray,
    /// Origin of the ray one pixel over in x.
    pub rx_origin: Vec3A,
    /// Direction of the ray one pixel over in x.
    pub rx_direction: Vec3A,
    /// Origin of the ray one pixel over in y.
    pub ry_origin: Vec3A,
    /// Direction of the ray one pixel over in y.
    pub ry_direction: Vec3A,
}

impl RayDifferential {
    /// Scale the offsets, e.g. by 1/√spp when several samples share a pixel
    /// (pbrt-v4 `RayDifferential::ScaleDifferentials`).
    pub fn scale_differentials(&mut self, s: f32) {
        let o = self.ray.origin;
        let d = self.ray.direction;
        self.rx_origin = o + (self.rx_origin - o) * s;
        self.ry_origin = o + (self.ry_origin - o) * s;
        self.rx_direction = d + (self.rx_direction - d) * s;
        self.ry_direction = d + (self.ry_direction - d) * s;
    }
}
