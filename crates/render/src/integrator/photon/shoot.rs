//! Photon tracing for one pass (Jensen 1996 §2.1; pbrt-v4 `SPPMIntegrator`'s photon pass):
//! each photon starts at a source chosen by power — a light, from `Light::sample_le`
//! (infinite lights from a disc over the scene's bounds), with flux
//! β = Le·|cos θ|/(pmf·p_pos·p_dir·N) for N photons, or an emissive medium
//! (`medium_sources`) — and walks the scene at the pass's wavelengths (a dispersive surface keeps
//! only the hero, as in `path`):
//!
//! - a photon that reaches a non-specular surface after one or more specular bounces and
//!   nothing else (L S⁺ D) is stored in the caustic map, once, and ends there;
//! - every real scattering in a medium stores a volume photon (before the photon scatters
//!   on), up to `max_depth` scattering events;
//! - without media a photon ends at its first non-specular surface (nothing later could be
//!   stored); with media it goes on by BSDF sampling (importance transport) and roulette
//!   (pbrt-v4 SPPM: survival by the throughput's ratio to what it was).
//!
//! Photons are traced in parallel in chunks, each from its own generator seeded by (seed,
//! pass, photon index), and concatenated in chunk order: the maps do not depend on the
//! number of threads.

use glam::Vec2;
use prism_geometry::Ray;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;

use super::medium_flight::{medium_at_start, photon_flight, Flight};
use super::medium_sources::{PhotonSources, Source};
use super::photon_map::Photon;
use crate::bsdf::TransportMode;
use crate::integrator::lane_wavelengths::LaneWavelengths;
use crate::integrator::medium_transport::MediumRng;
use crate::integrator::scatter_vertex::{MediumVertex, ScatterVertex, SurfaceVertex};
use crate::light::warp::sample_uniform_sphere;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// Photons per parallel chunk.
const CHUNK: u32 = 1024;

/// The photons of one pass.
#[derive(Default)]
pub struct ShotPhotons {
    pub caustic: Vec<Photon>,
    pub volume: Vec<Photon>,
    /// Rays traced.
    pub rays: u64,
}

/// SplitMix64's finaliser: the seed of photon `index` of pass `iteration`.
pub fn mix_seed(seed: u64, iteration: u32, index: u64) -> u64 {
    let mut z = seed
        ^ u64::from(iteration).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Traces `count` photons of pass `iteration` at `wavelengths` from `sources` with gather
/// radius `radius_m` (stored in each photon), paths of at most `max_depth` scattering
/// events.
#[allow(clippy::too_many_arguments)]
pub fn shoot(
    scene: &RenderScene,
    sources: &PhotonSources,
    wavelengths: &SampledWavelengths,
    count: u32,
    seed: u64,
    iteration: u32,
    max_depth: u32,
    radius_m: f32,
) -> ShotPhotons {
    let chunks = count.div_ceil(CHUNK);
    let parts: Vec<ShotPhotons> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut out = ShotPhotons::default();
            let start = c * CHUNK;
            let end = (start + CHUNK).min(count);
            for i in start..end {
                let mut rng = MediumRng::new(mix_seed(seed, iteration, u64::from(i)));
                trace_photon(
                    scene,
                    wavelengths,
                    count,
                    max_depth,
                    radius_m,
                    sources,
                    &mut rng,
                    &mut out,
                );
            }
            out
        })
        .collect();
    let mut all = ShotPhotons {
        caustic: Vec::with_capacity(parts.iter().map(|p| p.caustic.len()).sum()),
        volume: Vec::with_capacity(parts.iter().map(|p| p.volume.len()).sum()),
        rays: 0,
    };
    for p in parts {
        all.caustic.extend_from_slice(&p.caustic);
        all.volume.extend_from_slice(&p.volume);
        all.rays += p.rays;
    }
    all
}

fn u2(rng: &mut MediumRng) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// The flux a photon deposits: β/⟨r_u⟩ (spectral MIS of its distance samples; the hero's
/// r_u alone once lanes 1–3 have ended, as `path`), with lanes 1–3 zeroed then.
#[allow(clippy::too_many_arguments)]
fn stored(
    p: glam::Vec3A,
    direction: glam::Vec3A,
    beta: SampledSpectrum,
    r_u: SampledSpectrum,
    lanes: &LaneWavelengths,
    depth: u32,
    radius_m: f32,
    medium: Option<u32>,
) -> Photon {
    Photon {
        p: p.to_array(),
        direction: direction.to_array(),
        beta: (beta * (1.0 / average_r(r_u, lanes))).values,
        radius_m,
        depth: depth.min(255) as u8,
        hero_only: lanes.sensor().secondary_terminated(),
        medium: medium.map_or(u16::MAX, |m| m.min(u32::from(u16::MAX - 1)) as u16),
    }
}

/// ⟨r_u⟩ over the live lanes.
fn average_r(r_u: SampledSpectrum, lanes: &LaneWavelengths) -> f32 {
    if lanes.sensor().secondary_terminated() {
        r_u[0]
    } else {
        r_u.average()
    }
}

/// A photon as it leaves its source.
struct PhotonStart {
    beta: SampledSpectrum,
    ray: Ray,
    medium: Option<u32>,
    depth: u32,
}

/// A photon from a source chosen by power: a light's `sample_le` (flux
/// Le·|cos θ|/(pmf·p_pos·p_dir·N)), or a point of an emissive medium (`medium_sources`).
fn start_photon(
    scene: &RenderScene,
    sources: &PhotonSources,
    wavelengths: &SampledWavelengths,
    count: u32,
    rng: &mut MediumRng,
    out: &mut ShotPhotons,
) -> Option<PhotonStart> {
    let lights = &scene.lights;
    let media = scene.media.as_ref();
    match sources.choose(rng.uniform()) {
        Source::Lights { group_pmf, u_light } => {
            let (l, light_pmf) = lights.sample(u_light)?;
            let pmf = group_pmf * light_pmf;
            let light = lights.light(l);
            let (u_pos, u_dir) = (u2(rng), u2(rng));
            let le = light.sample_le(lights.scene_sphere(), u_pos, u_dir, wavelengths)?;
            if le.pdf_pos <= 0.0 || le.pdf_dir <= 0.0 || le.radiance.is_black() {
                return None;
            }
            let cos = if le.n == glam::Vec3A::ZERO {
                1.0
            } else {
                le.n.dot(le.ray.direction).abs()
            };
            let beta = le.radiance * (cos / (pmf * le.pdf_pos * le.pdf_dir * count as f32));
            let medium = media.and_then(|m| {
                out.rays += 1;
                medium_at_start(scene, m, &le.ray)
            });
            Some(PhotonStart {
                beta,
                ray: le.ray,
                medium,
                depth: 0,
            })
        }
        Source::Medium { index, pmf } => {
            let media = media?;
            let source = &sources.media[index];
            let p = sources.point_in_box(index, [rng.uniform(), rng.uniform(), rng.uniform()]);
            let ray = Ray::infinite(p, sample_uniform_sphere(u2(rng)));
            out.rays += 1;
            if medium_at_start(scene, media, &ray) != Some(source.medium) {
                return None;
            }
            let medium = media.medium(source.medium);
            let density = medium.density(p);
            if density <= 0.0 {
                return None;
            }
            let optics = medium.optics().at(wavelengths);
            let scale =
                density * source.volume_m3 * 4.0 * std::f32::consts::PI / (pmf * count as f32);
            Some(PhotonStart {
                beta: optics.sigma_a * optics.emission * scale,
                ray,
                medium: Some(source.medium),
                depth: 1,
            })
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn trace_photon(
    scene: &RenderScene,
    wavelengths: &SampledWavelengths,
    count: u32,
    max_depth: u32,
    radius_m: f32,
    sources: &PhotonSources,
    rng: &mut MediumRng,
    out: &mut ShotPhotons,
) {
    let media = scene.media.as_ref();
    let mut lanes = LaneWavelengths::new(*wavelengths);
    let Some(start) = start_photon(scene, sources, wavelengths, count, rng, out) else {
        return;
    };
    let (mut beta, mut ray, mut medium) = (start.beta, start.ray, start.medium);
    let mut r_u = SampledSpectrum::splat(1.0);
    // Scattering events so far (an emitting medium's emission counts as one: `path` adds
    // medium emission only at depth < max_depth); a specular bounce was met and nothing
    // non-specular.
    let mut depth = start.depth;
    if depth >= max_depth {
        return;
    }
    let mut caustic_chain = true;
    let mut had_specular = false;
    let mut null_events = 0u32;
    let mut reflectance_cache = SpectrumCache::new();
    loop {
        out.rays += 1;
        let hit = scene.geometry.intersect(&ray);
        if let (Some(media), Some(m)) = (media, medium) {
            let med = media.medium(m);
            let optics = med.optics().at(lanes.transport());
            let segment = Ray::new(
                ray.origin,
                ray.direction,
                0.0,
                hit.map_or(f32::INFINITY, |h| h.t),
            );
            match photon_flight(med, &optics, &segment, &mut beta, &mut r_u, rng) {
                Flight::Passed => {}
                Flight::Absorbed => return,
                Flight::Scattered(p) => {
                    depth += 1;
                    if beta.is_black() {
                        return;
                    }
                    out.volume.push(stored(
                        p,
                        ray.direction,
                        beta,
                        r_u,
                        &lanes,
                        depth,
                        radius_m,
                        Some(m),
                    ));
                    if depth >= max_depth {
                        return;
                    }
                    caustic_chain = false;
                    let vertex = ScatterVertex::Medium(MediumVertex {
                        p,
                        wo: -ray.direction,
                        phase: &med.optics().phase,
                    });
                    let Some(ps) = vertex.sample(0.0, u2(rng), TransportMode::Importance) else {
                        return;
                    };
                    beta *= ps.weight;
                    ray = Ray::infinite(p, ps.wi);
                    continue;
                }
            }
        }
        let Some(hit) = hit else {
            return;
        };
        let mut si = scene.geometry.shading_interaction(&ray, &hit);
        if let Some(media) = media {
            if media.is_interface(si.material_id) {
                medium =
                    media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
                null_events += 1;
                if null_events > crate::integrator::MAX_NULL_EVENTS {
                    return;
                }
                continue;
            }
        }
        let material = scene.material(si.material_id);
        if scene.has_masks {
            let opacity = material.opacity_at(&si);
            if opacity < 1.0 && rng.uniform() >= opacity {
                if let Some(media) = media {
                    medium =
                        media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                }
                ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
                null_events += 1;
                if null_events > crate::integrator::MAX_NULL_EVENTS {
                    return;
                }
                continue;
            }
        }
        let shading_maps = material.has_shading_maps();
        if shading_maps {
            material.apply_shading_maps(&mut si);
        }
        if scene.has_dispersion
            && material.is_dispersive()
            && !lanes.sensor().secondary_terminated()
        {
            lanes.terminate_secondary();
            for lane in 1..4 {
                beta[lane] = 0.0;
            }
        }
        let bsdf = material.bsdf_cached(si.material_id, &si, &lanes, &mut reflectance_cache);
        let vertex =
            ScatterVertex::Surface(SurfaceVertex::new(&si, &bsdf, ray.direction, shading_maps));
        if !vertex.is_specular() {
            if caustic_chain && had_specular && depth < max_depth {
                out.caustic.push(stored(
                    si.p,
                    ray.direction,
                    beta,
                    r_u,
                    &lanes,
                    depth,
                    radius_m,
                    None,
                ));
            }
            caustic_chain = false;
            if media.is_none() {
                return;
            }
        }
        if depth >= max_depth {
            return;
        }
        let Some(bs) = vertex.sample(rng.uniform(), u2(rng), TransportMode::Importance) else {
            return;
        };
        if bs.weight.is_black() || bs.weight.has_non_finite() {
            return;
        }
        let glazing_pass = bs.transmission
            && scene.has_glazing
            && material.thin_glazing(lanes.transport()).is_some();
        if glazing_pass {
            null_events += 1;
            if null_events > crate::integrator::MAX_NULL_EVENTS {
                return;
            }
        } else {
            depth += 1;
            if bs.specular {
                had_specular = true;
            }
        }
        let r = average_r(r_u, &lanes);
        let before = beta.max_component() / r;
        let after = beta * bs.weight;
        // Roulette by the throughput's ratio (pbrt-v4 SPPM): a photon keeps its flux.
        let q = (1.0 - after.max_component() / r / before.max(1e-30)).max(0.0);
        if q > 0.0 {
            if rng.uniform() < q {
                return;
            }
            beta = after * (1.0 / (1.0 - q));
        } else {
            beta = after;
        }
        let wi = bs.wi.normalize();
        if let Some(media) = media {
            medium = media.after_surface(medium, hit.instance_id, wi, si.n_geometric);
        }
        ray = Ray::spawn_off_surface(vertex.p(), si.n_geometric, wi);
    }
}
