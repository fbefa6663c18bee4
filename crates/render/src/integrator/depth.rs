//! The `depth` integrator: the distance (m) from the camera ray's origin to the first hit,
//! written as a flat spectrum so Y = depth in metres (misses: 0).

use glam::DVec3;
use prism_geometry::SurfaceInteraction;

use crate::film::xyz::flat_spectrum_xyz;

/// Camera rays have unit directions, so the ray parameter is the distance in metres.
#[inline]
pub(super) fn shade(hit: &SurfaceInteraction) -> DVec3 {
    f64::from(hit.t) * flat_spectrum_xyz()
}
