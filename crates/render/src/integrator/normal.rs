//! The `normal` integrator: the world-space shading normal n of the first hit, mapped to
//! colour as RGB = n·½ + ½ (the usual normal-map encoding; misses: 0). The raw normal goes
//! to the `normal` AOV.

use glam::DVec3;
use prism_geometry::SurfaceInteraction;

use crate::film::xyz::rec709_to_xyz;

#[inline]
pub(super) fn shade(hit: &SurfaceInteraction) -> DVec3 {
    let c = hit.n_shading * 0.5 + 0.5;
    rec709_to_xyz([c.x, c.y, c.z])
}
