//! Subpath generation for bidirectional methods (pbrt-v3 §16.3.2 `GenerateCameraSubpath`,
//! `GenerateLightSubpath`, `RandomWalk`): one random walk for both directions, radiance
//! from the camera and importance from the lights, recording each vertex's forward density
//! and, once the next direction is sampled, its predecessor's reverse density.
//!
//! Opacity-mask pass-throughs and straight transmission through thin glazing are null
//! events (as in the path tracer): no vertex, densities unchanged; connections account for
//! those surfaces exactly (`PathTracer::segment_transmittance`), so every strategy sees the
//! same path and the MIS weights stay consistent.

use glam::Vec3A;
use prism_geometry::Ray;

use super::vertex::{infinite_light_density, BdptVertex, Subpath, SurfaceScatter};
use crate::bsdf::TransportMode;
use crate::integrator::dimensions::LightStartDimensions;
use crate::integrator::path_state::PathState;
use crate::integrator::PathCounters;
use crate::light::NO_LIGHT;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// Extends `path` (whose last vertex emitted `ray`) by a random walk of at most
/// `max_vertices` more vertices; `pdf_dir` is the solid-angle density of `ray`'s direction
/// at the last vertex and `path_state.beta` the throughput along it. Returns the vertices
/// added.
#[allow(clippy::too_many_arguments)]
pub fn random_walk<'s>(
    scene: &'s RenderScene,
    mut ray: Ray,
    pdf_dir: f32,
    max_vertices: u32,
    mode: TransportMode,
    rr_depth: u32,
    path_state: &mut PathState,
    path: &mut Subpath<'s>,
    counters: &mut PathCounters,
) -> u32 {
    if max_vertices == 0 {
        return 0;
    }
    let mut added = 0u32;
    let mut pdf_fwd = pdf_dir;
    let mut reflectance_cache = SpectrumCache::new();
    loop {
        if path_state.beta.is_black() {
            break;
        }
        counters.rays += 1;
        let Some(hit) = scene.geometry.intersect(&ray) else {
            // Camera paths that escape end on the infinite lights (a vertex at infinity,
            // its density per unit solid angle).
            if mode == TransportMode::Radiance && !scene.lights.infinite_lights().is_empty() {
                let far = ray.origin + ray.direction;
                path.vertices.push(BdptVertex::infinite_light(
                    None,
                    far,
                    path_state.beta,
                    pdf_fwd,
                ));
                added += 1;
            }
            break;
        };
        let mut si = scene.geometry.shading_interaction(&ray, &hit);
        scene.set_texture_differentials(&mut si, None, 1.0);
        let material = scene.material(si.material_id);
        let dims = path_state.next_vertex_dimensions();
        let opacity = if scene.has_masks {
            material.opacity_at(&si)
        } else {
            1.0
        };
        if opacity < 1.0 && path_state.stream.get_1d_at(dims.mask()) >= opacity {
            if !path_state.null_event() {
                break;
            }
            ray = Ray::spawn(si.p, ray.direction);
            continue;
        }
        let shading_maps = material.has_shading_maps();
        if shading_maps {
            material.apply_shading_maps(&mut si);
        }
        if scene.has_dispersion && material.is_dispersive() {
            path_state.wavelengths.terminate_secondary();
        }
        let bsdf = material.bsdf_cached(
            si.material_id,
            &si,
            &path_state.wavelengths,
            &mut reflectance_cache,
        );
        let emitter = scene
            .lights
            .area_light_of_instance(hit.instance_id)
            .unwrap_or(NO_LIGHT);
        let prev_index = path.len() - 1;
        path.push_surface(
            SurfaceScatter::new(si, bsdf, ray.direction, shading_maps),
            emitter,
            path_state.beta,
        );
        let index = path.len() - 1;
        let vertex = path.vertices[index];
        path.vertices[index].pdf_fwd = path.vertices[prev_index].convert_density(pdf_fwd, &vertex);
        added += 1;
        path_state.depth += 1;
        if added >= max_vertices {
            break;
        }
        counters.bounces += 1;
        // Sample the next direction at the new vertex, and the reverse density (sampling
        // −ωo from ωi there), borrowing its scattering data in place.
        let (bs, weight, pdf_rev) = {
            let scatter = &path.surfaces[path.surfaces.len() - 1];
            let v = scatter.scatter_vertex();
            let u_lobe = path_state.stream.get_1d_at(dims.lobe());
            let u = path_state.stream.get_2d_at(dims.bsdf());
            let Some(bs) = v.sample(u_lobe, u, mode) else {
                break;
            };
            let correction =
                super::vertex::shading_normal_correction(&scatter.si, scatter.wo, bs.wi, mode);
            let pdf_rev = if bs.specular {
                0.0
            } else {
                scatter
                    .seen_from(bs.wi.normalize())
                    .pdf_toward(-ray.direction, mode)
            };
            (bs, bs.weight * correction, pdf_rev)
        };
        let glazing_pass = bs.transmission
            && scene.has_glazing
            && material
                .thin_glazing(path_state.wavelengths.transport())
                .is_some();
        if weight.is_black() || weight.has_non_finite() {
            if weight.has_non_finite() {
                counters.non_finite_contributions += 1;
            }
            break;
        }
        path_state.beta *= weight;
        if glazing_pass {
            // Straight through the pane: not a vertex (see the module docs).
            path.pop();
            added -= 1;
            path_state.depth -= 1;
            counters.bounces -= 1;
            if !path_state.null_event() {
                break;
            }
            ray = Ray::spawn(si.p, ray.direction);
            continue;
        }
        let wi = bs.wi.normalize();
        if bs.specular {
            path.vertices[index].delta = true;
            pdf_fwd = 0.0;
        } else {
            pdf_fwd = bs.pdf;
        }
        let prev = path.vertices[prev_index];
        path.vertices[prev_index].pdf_rev = path.vertices[index].convert_density(pdf_rev, &prev);
        ray = Ray::spawn(si.p, wi);
        let stream = path_state.stream;
        if path_state.roulette(rr_depth, || stream.get_1d_at(dims.roulette())) {
            counters.roulette_terminations += 1;
            break;
        }
    }
    added
}

/// The camera subpath of a camera ray with `pdf_dir` (the camera's directional density of
/// it): the camera vertex, then a walk of at most `max_depth + 1` vertices.
#[allow(clippy::too_many_arguments)]
pub fn camera_subpath<'s>(
    scene: &'s RenderScene,
    ray: &Ray,
    pdf_dir: f32,
    max_depth: u32,
    rr_depth: u32,
    path_state: &mut PathState,
    path: &mut Subpath<'s>,
    counters: &mut PathCounters,
) {
    path.clear();
    path.vertices.push(BdptVertex::camera(
        ray.origin,
        scene.camera.forward(),
        path_state.beta,
    ));
    random_walk(
        scene,
        *ray,
        pdf_dir,
        max_depth + 1,
        TransportMode::Radiance,
        rr_depth,
        path_state,
        path,
        counters,
    );
}

/// A light subpath: a light chosen in proportion to power, an emission sampled from it
/// (`Light::sample_le`), then a walk of at most `max_vertices` vertices. Empty when the
/// scene has no light or the emission sample fails.
#[allow(clippy::too_many_arguments)]
pub fn light_subpath<'s>(
    scene: &'s RenderScene,
    start: LightStartDimensions,
    max_vertices: u32,
    rr_depth: u32,
    path_state: &mut PathState,
    path: &mut Subpath<'s>,
    counters: &mut PathCounters,
) {
    path.clear();
    let lights = &scene.lights;
    let u_choice = path_state.stream.get_1d_at(start.light_choice());
    let Some((l, pmf)) = lights.sample(u_choice) else {
        return;
    };
    let light = lights.light(l);
    let u_pos = path_state.stream.get_2d_at(start.position());
    let u_dir = path_state.stream.get_2d_at(start.direction());
    let sphere = lights.scene_sphere();
    let Some(le) = light.sample_le(sphere, u_pos, u_dir, path_state.wavelengths.transport()) else {
        return;
    };
    if le.pdf_pos <= 0.0 || le.pdf_dir <= 0.0 || le.radiance.is_black() {
        return;
    }
    let infinite = light.is_infinite();
    let vertex0 = if infinite {
        BdptVertex::infinite_light(Some(l), le.ray.origin, le.radiance, le.pdf_pos * pmf)
    } else {
        BdptVertex::light(l, le.ray.origin, le.n, le.radiance, le.pdf_pos * pmf)
    };
    path.vertices.push(vertex0);
    let cos = if le.n == Vec3A::ZERO {
        1.0
    } else {
        le.n.dot(le.ray.direction).abs()
    };
    path_state.beta = le.radiance * (cos / (pmf * le.pdf_pos * le.pdf_dir));
    let added = random_walk(
        scene,
        le.ray,
        le.pdf_dir,
        max_vertices,
        TransportMode::Importance,
        rr_depth,
        path_state,
        path,
        counters,
    );
    // Infinite lights: the first vertex's density is the scene disk's, per unit area at
    // the first hit; the light vertex's own is the directional density (pbrt-v3 §16.3.2).
    if infinite {
        if added > 0 {
            let first = &mut path.vertices[1];
            first.pdf_fwd = le.pdf_pos;
            if first.is_on_surface() {
                first.pdf_fwd *= first.n_geometric.dot(le.ray.direction).abs();
            }
        }
        path.vertices[0].pdf_fwd = infinite_light_density(lights, le.ray.direction);
    }
}
