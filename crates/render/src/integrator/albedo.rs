//! The `albedo` integrator: the first hit's material albedo as linear Rec.709 RGB (see
//! `scene_build::albedo` for how a material's albedo is defined; misses: 0).

use glam::DVec3;
use prism_geometry::SurfaceInteraction;

use crate::film::xyz::rec709_to_xyz;
use crate::scene_build::RenderScene;

#[inline]
pub(super) fn shade(scene: &RenderScene, hit: &SurfaceInteraction) -> DVec3 {
    rec709_to_xyz(scene.albedo(hit.material_id))
}
