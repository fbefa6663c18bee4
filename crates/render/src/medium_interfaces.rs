//! The predictor's rays cross medium `interface` surfaces as the render's rays do: an
//! interface scatters nothing and is not a bounce (docs/media.md), so the G-buffer's centre
//! hit, the probe's shadow rays and its BSDF and indirect samples look past it. Without
//! this a fog box around a scene (scenes/cornell-box-fog.json) was every pixel's "surface"
//! and blocked every shadow ray: the predictor saw nothing and planned uniformly.

use prism_geometry::{Hit, Ray};

use crate::integrator::MAX_NULL_EVENTS;
use crate::scene_build::RenderScene;

/// The first hit along `ray` on a surface that is not a medium `interface` (interfaces
/// scatter nothing: the render's rays cross them), with t in `ray`'s own parameter; `None`
/// past [`MAX_NULL_EVENTS`] crossings, where the render's paths end too (a ray caught
/// between coincident boundaries would loop).
pub(crate) fn first_surface(scene: &RenderScene, ray: &Ray) -> Option<Hit> {
    let Some(media) = scene.media.as_ref() else {
        return scene.geometry.intersect(ray);
    };
    let mut rest = *ray;
    for _ in 0..MAX_NULL_EVENTS {
        let hit = scene.geometry.intersect(&rest)?;
        let si = scene.geometry.interaction(&rest, &hit);
        if !media.is_interface(si.material_id) {
            return Some(hit);
        }
        rest.t_min = hit.t * (1.0 + 1e-5) + 1e-5;
    }
    None
}
