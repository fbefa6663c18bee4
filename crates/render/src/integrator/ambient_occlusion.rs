//! The `ambient_occlusion` integrator (pbrt-v4 source, `AOIntegrator` in src/pbrt/cpu/integrators.cpp; Zhukov et al. 1998
//! "obscurances"): the cosine-weighted visible fraction of the hemisphere about the first
//! hit's shading normal,
//!
//!   A(p) = (1/π) ∫_{H²(n)} V(p, ω) cos θ dω,
//!
//! with V = 0 when a ray from p towards ω hits anything within `max_distance_m` (default:
//! unbounded) and 1 otherwise. Directions are drawn with density cos θ/π, so each sample's
//! estimate is V itself, and a camera sample's value is the mean of `samples` of them. It is
//! written as a flat spectrum, so Y is the visible fraction (misses: 0).
//!
//! The shading normal is flipped to the side the camera ray arrives from, so one-sided
//! shapes seen from behind (a rectangle's back) get occlusion of the side that is visible.
//! Occlusion rays start at the hit with the geometry crate's t_min offset (`Ray::spawn`)
//! and stop at `max_distance_m` (their directions are unit, so t is in metres).

use glam::DVec3;
use prism_geometry::{Frame, Geometry, Ray, SurfaceInteraction};

use crate::film::xyz::flat_spectrum_xyz;
use crate::sampler::SampleStream;
use crate::sampling::sample_cosine_hemisphere;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    /// Occluders farther than this do not count (m; `f32::INFINITY`: unbounded).
    pub max_distance_m: f32,
    /// Occlusion rays per camera sample (≥ 1).
    pub samples: u32,
}

impl AmbientOcclusion {
    /// `max_distance_m` > 0 (may be +∞), `samples` ≥ 1.
    pub fn new(max_distance_m: f32, samples: u32) -> Result<Self, String> {
        // NaN fails this test too.
        if max_distance_m.is_nan() || max_distance_m <= 0.0 {
            return Err(format!(
                "ambient occlusion: `max_distance_m` = {max_distance_m} must be > 0"
            ));
        }
        if samples == 0 {
            return Err("ambient occlusion: `samples` must be at least 1".into());
        }
        Ok(Self {
            max_distance_m,
            samples,
        })
    }

    /// The visible fraction at `hit` (in [0, 1]), from `samples` occlusion rays drawn from
    /// `stream`; adds the rays traced to `rays`.
    #[inline]
    pub fn visibility(
        &self,
        geometry: &Geometry,
        incoming: &Ray,
        hit: &SurfaceInteraction,
        stream: &mut SampleStream,
        rays: &mut u64,
    ) -> f64 {
        let mut n = hit.n_shading;
        if n.dot(incoming.direction) > 0.0 {
            n = -n;
        }
        let frame = Frame::from_z(n);
        let mut visible = 0u32;
        for _ in 0..self.samples {
            let w = frame.from_local(sample_cosine_hemisphere(stream.get_2d()));
            let mut shadow = Ray::spawn(hit.p, w);
            shadow.t_max = self.max_distance_m;
            if !geometry.occluded(&shadow) {
                visible += 1;
            }
        }
        *rays += u64::from(self.samples);
        f64::from(visible) / f64::from(self.samples)
    }

    #[inline]
    pub(super) fn shade(
        &self,
        geometry: &Geometry,
        incoming: &Ray,
        hit: &SurfaceInteraction,
        stream: &mut SampleStream,
        rays: &mut u64,
    ) -> DVec3 {
        self.visibility(geometry, incoming, hit, stream, rays) * flat_spectrum_xyz()
    }
}
