//! The camera side of the photon integrators: paths as `path` traces them (next-event
//! estimation with MIS, BSDF sampling, roulette), with two photon estimates and the
//! bookkeeping that keeps them from counting light twice:
//!
//! - **Media** (Jarosz et al. 2008): a camera path never scatters in a medium. Each of
//!   its segments through one adds the beam radiance estimate (`beam`) and carries on
//!   with the segment's transmittance; the volume photons stand for all light scattered
//!   in media, whatever its path before.
//! - **Surfaces** (Jensen 1996): at the first non-specular camera vertex D the caustic map
//!   (photons of L S⁺ D paths) is gathered; direct light comes from light sampling as in
//!   `path`, and the rest of the indirect light from the continued path — except emission
//!   that the path meets after D through specular vertices only (D S⁺ L): that is what the
//!   caustic map gave, so it is skipped.
//!
//! Every photon estimate obeys `max_depth`: a photon that scattered k times (a medium
//! photon counts its own scattering) joins a camera path after d of its scattering events
//! only if d + k ≤ max_depth (d + 1 + k at a surface, which scatters once more).

use glam::Vec3A;
use prism_geometry::{Ray, RayDifferential};
use prism_spectrum::WavelengthDensity;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::medium_flight::{segment_transmittance, shadow_transmittance, Transmittance};
use super::photon_map::{Photon, PhotonTree};
use crate::bsdf::TransportMode;
use crate::integrator::camera_sample::CameraSample;
use crate::integrator::dimensions::MediumDimensions;
use crate::integrator::lane_wavelengths::LaneWavelengths;
use crate::integrator::medium_transport::MediumRng;
use crate::integrator::path_state::PathState;
use crate::integrator::scatter_vertex::{ScatterVertex, SurfaceVertex, VertexLightSample};
use crate::integrator::{mis_weight, FirstHit, PathCounters, PathTracer};
use crate::light::LightHit;
use crate::sampler::SampleStream;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// One pass's photons.
#[derive(Clone, Debug, Default)]
pub struct PhotonMaps {
    /// Photons of L S⁺ D paths, on surfaces.
    pub caustic: PhotonTree,
    /// Photons at real scatterings in media.
    pub volume: PhotonTree,
}

/// A camera path's sum, split so that photons whose secondary lanes ended can be weighted
/// once the path's own lanes are known (`finish`).
#[derive(Clone, Copy, Debug)]
struct Radiance {
    all_lanes: SampledSpectrum,
    /// From hero-only photons: lane 0 alone, to be counted ×4 unless the path's own
    /// secondary lanes ended too (the film then applies that factor).
    hero_photons: SampledSpectrum,
}

impl Radiance {
    fn add(&mut self, c: SampledSpectrum, counters: &mut PathCounters) {
        if c.has_non_finite() {
            counters.non_finite_contributions += 1;
        } else {
            self.all_lanes += c;
        }
    }

    fn add_photon(&mut self, ph: &Photon, c: SampledSpectrum, counters: &mut PathCounters) {
        if c.has_non_finite() {
            counters.non_finite_contributions += 1;
        } else if ph.hero_only {
            self.hero_photons += c;
        } else {
            self.all_lanes += c;
        }
    }

    fn finish(&self, lanes: &LaneWavelengths) -> SampledSpectrum {
        if lanes.sensor().secondary_terminated() {
            self.all_lanes + self.hero_photons
        } else {
            self.all_lanes + self.hero_photons * 4.0
        }
    }
}

/// How a camera path gathers the caustic map, and what its gather found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CausticGather {
    /// `Some(R)`: the photons within R of the visible point, kernel 1/(π R²) — the pixel's
    /// radius of stochastic progressive photon mapping (`sppm`); `None`: every photon whose
    /// own sphere holds the point, kernel 1/(π rp²).
    pub radius_m: Option<f32>,
    /// Photons found within the radius that the path's depth admits (the M of the pixel's
    /// update), whatever their contribution: photons from behind the surface count too,
    /// as in pbrt-v4's SPPM.
    pub found: u32,
    /// Only count: the path adds nothing and ends at its gather (a replayed pass, whose
    /// statistics are wanted but not its image). Everything up to the gather — the stream,
    /// the throughput that roulette and the media read — is as in a rendered pass, so the
    /// count is the rendered pass's.
    pub count_only: bool,
}

/// Whether the camera path left its first non-specular vertex by a non-Dirac lobe and has
/// met specular vertices only since (at least one): emission it meets now, on a surface or
/// in a medium, is light of L S⁺ D paths, which the caustic map gave.
#[inline]
fn after_specular_chain(after_first_diffuse: bool, specular_chain: bool, count: u32) -> bool {
    after_first_diffuse && specular_chain && count > 0
}

/// A pass's camera ray, with its differentials (scaled for the pixel's samples) where
/// the scene filters textures: the camera path's first hits are filtered over the ray's
/// footprint, as `path`'s (later hits over the camera footprint approximation).
pub struct CameraRay {
    pub ray: Ray,
    pub differential: Option<RayDifferential>,
}

/// The camera ray of sample `cs`; differentials only where textures read them (the ray
/// itself has the same bits either way).
pub fn camera_ray(scene: &RenderScene, cs: &CameraSample, scale: f32) -> Option<CameraRay> {
    if scene.texture_footprint.is_none() {
        let ray = scene.camera.generate_ray_only(cs.film_point, cs.lens)?;
        return Some(CameraRay {
            ray,
            differential: None,
        });
    }
    let mut differential = scene.camera.generate_ray(cs.film_point, cs.lens)?;
    differential.scale_differentials(scale);
    Some(CameraRay {
        ray: differential.ray,
        differential: Some(differential),
    })
}

/// The camera-path tracer of a pass.
pub struct CameraPaths<'a> {
    pub tracer: PathTracer,
    pub maps: &'a PhotonMaps,
}

impl CameraPaths<'_> {
    /// Radiance along `camera_ray` (its differentials scaled by `differential_scale`);
    /// the first surface hit for the film's AOVs.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        scene: &RenderScene,
        camera_ray: &CameraRay,
        differential_scale: f32,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        gather: &mut CausticGather,
        counters: &mut PathCounters,
    ) -> (SampledSpectrum, Option<FirstHit>) {
        let max_depth = self.tracer.max_depth;
        let lights = &scene.lights;
        let media = scene.media.as_ref();
        let mut sum = Radiance {
            all_lanes: SampledSpectrum::splat(0.0),
            hero_photons: SampledSpectrum::splat(0.0),
        };
        let mut path = PathState::new(camera_ray.ray.origin, None, *stream, *wavelengths);
        let mut current_differential = camera_ray.differential;
        let mut medium = media.and_then(|m| m.camera);
        let mut first_hit = None;
        let mut ray = camera_ray.ray;
        let mut le_cache = SpectrumCache::new();
        let mut reflectance_cache = SpectrumCache::new();
        let mut steps = Vec::new();
        // The first non-specular vertex is behind, the path left it by a non-Dirac lobe,
        // and since then it met only specular vertices (at least one): emission met now is
        // what the caustic map gave (its gather evaluates the non-Dirac lobes only, so a
        // Dirac lobe of a mixed BSDF at that vertex stays the path's).
        let mut after_first_diffuse = false;
        let mut specular_chain = false;
        let mut chain_specular_count = 0u32;
        loop {
            let hit = scene.geometry.intersect(&ray);
            let mut rng = None;
            if let Some(media) = media {
                let md = MediumDimensions::reserve(&mut path.stream);
                let mut r = MediumRng::new(path.stream.seed_at(md.generator()));
                if let Some(m) = medium {
                    let med = media.medium(m);
                    let optics = med.optics().at(path.wavelengths.transport());
                    let t_end = hit.map_or(f32::INFINITY, |h| h.t);
                    let segment = Ray::new(ray.origin, ray.direction, 0.0, t_end);
                    let crossed = segment_transmittance(med, &optics, &segment, &mut steps, &mut r);
                    if path.depth < max_depth && !gather.count_only {
                        self.beam(
                            &segment,
                            m,
                            &med.optics().phase,
                            &crossed.transmittance,
                            path.beta,
                            max_depth - path.depth,
                            &mut sum,
                            counters,
                        );
                        // The medium's own emission, as `path` takes it at its collisions
                        // (depth < max_depth), unless the caustic map holds it (D S⁺ then
                        // the medium: photons that emissive media shoot).
                        if !after_specular_chain(
                            after_first_diffuse,
                            specular_chain,
                            chain_specular_count,
                        ) {
                            sum.add(path.beta * crossed.emitted, counters);
                        }
                    }
                    path.beta *= crossed.end;
                    if path.beta.is_black() {
                        break;
                    }
                }
                rng = Some(r);
            }
            let skip_emission =
                after_specular_chain(after_first_diffuse, specular_chain, chain_specular_count)
                    || gather.count_only;
            let Some(hit) = hit else {
                if !skip_emission {
                    let (d, prev) = (ray.direction, &path.prev_ctx);
                    let beta = path.beta;
                    self.tracer.escape_terms(
                        scene,
                        path.specular_bounce,
                        prev,
                        path.prev_pdf,
                        d,
                        path.wavelengths.transport(),
                        |x| sum.add(beta * x, counters),
                    );
                }
                break;
            };
            let mut si = scene.geometry.shading_interaction(&ray, &hit);
            scene.set_texture_differentials(
                &mut si,
                current_differential.as_ref(),
                differential_scale,
            );
            if let Some(media) = media {
                // The boundary's own word for the side the ray arrives from (as `path`).
                if media.arrives_mismatched(medium, hit.instance_id, ray.direction, si.n_geometric)
                {
                    counters.medium_mismatches += 1;
                }
                if media.is_interface(si.material_id) {
                    medium =
                        media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                    ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
                    if !path.null_event() {
                        break;
                    }
                    continue;
                }
            }
            let material = scene.material(si.material_id);
            let dims = path.next_vertex_dimensions();
            let opacity = if scene.has_masks {
                material.opacity_at(&si)
            } else {
                1.0
            };
            if opacity < 1.0 && path.stream.get_1d_at(dims.mask()) >= opacity {
                if let Some(media) = media {
                    medium =
                        media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                }
                ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
                if !path.null_event() {
                    break;
                }
                continue;
            }
            let shading_maps = material.has_shading_maps();
            if shading_maps {
                material.apply_shading_maps(&mut si);
            }
            if first_hit.is_none() {
                first_hit = Some(FirstHit {
                    t: si.t,
                    n_shading: si.n_shading,
                    material_id: si.material_id,
                });
            }
            if let (Some(l), false) = (
                lights.area_light_of_instance(hit.instance_id),
                skip_emission,
            ) {
                let light_hit = LightHit {
                    p: si.p,
                    n: si.n_geometric,
                    uv: si.uv,
                    distance_m: hit.t,
                };
                if let Some(x) = self.tracer.emission_term(
                    scene,
                    l,
                    &light_hit,
                    path.specular_bounce,
                    &path.prev_ctx,
                    path.prev_pdf,
                    ray.direction,
                    &path.wavelengths,
                    &mut le_cache,
                ) {
                    sum.add(path.beta * x, counters);
                }
            }
            if path.depth == max_depth {
                break;
            }
            path.depth += 1;
            counters.bounces += 1;
            if scene.has_dispersion && material.is_dispersive() {
                path.wavelengths.terminate_secondary();
            }
            let bsdf = material.bsdf_cached(
                si.material_id,
                &si,
                &path.wavelengths,
                &mut reflectance_cache,
            );
            let vertex =
                ScatterVertex::Surface(SurfaceVertex::new(&si, &bsdf, ray.direction, shading_maps));
            let mut gathered_here = false;
            if vertex.is_specular() {
                if after_first_diffuse {
                    chain_specular_count += 1;
                }
            } else {
                if after_first_diffuse {
                    specular_chain = false;
                } else {
                    after_first_diffuse = true;
                    specular_chain = true;
                    gathered_here = true;
                    self.gather_caustics(
                        &vertex,
                        si.p,
                        path.beta,
                        max_depth - path.depth,
                        gather,
                        &mut sum,
                        counters,
                    );
                    if gather.count_only {
                        break;
                    }
                }
                if !lights.is_empty() {
                    let (uc, ul) = (
                        path.stream.get_1d_at(dims.light_choice()),
                        path.stream.get_2d_at(dims.light()),
                    );
                    let direct = self.sample_light(
                        scene,
                        &vertex,
                        medium,
                        hit.instance_id,
                        uc,
                        ul,
                        &path.wavelengths,
                        &mut le_cache,
                        rng.as_mut(),
                        counters,
                    );
                    sum.add(path.beta * direct, counters);
                }
            }
            let (u_lobe, u_bsdf) = (
                path.stream.get_1d_at(dims.lobe()),
                path.stream.get_2d_at(dims.bsdf()),
            );
            let Some(bs) = vertex.sample(u_lobe, u_bsdf, TransportMode::Radiance) else {
                break;
            };
            if bs.weight.is_black() || bs.weight.has_non_finite() {
                if bs.weight.has_non_finite() {
                    counters.non_finite_contributions += 1;
                }
                break;
            }
            if gathered_here && bs.specular {
                specular_chain = false;
            }
            path.beta *= bs.weight;
            let glazing_pass = bs.transmission
                && scene.has_glazing
                && material
                    .thin_glazing(path.wavelengths.transport())
                    .is_some();
            if glazing_pass {
                path.depth -= 1;
                counters.bounces -= 1;
                if !path.null_event() {
                    break;
                }
            } else {
                path.scattered(vertex.light_context(), &bs);
            }
            let wi = bs.wi.normalize();
            if let Some(media) = media {
                medium = media.after_surface(medium, hit.instance_id, wi, si.n_geometric);
            }
            ray = Ray::spawn_off_surface(vertex.p(), si.n_geometric, wi);
            current_differential = None;
            counters.rays += 1;
            let stream = path.stream;
            if path.roulette(self.tracer.rr_depth, || stream.get_1d_at(dims.roulette())) {
                counters.roulette_terminations += 1;
                break;
            }
        }
        *stream = path.stream;
        *wavelengths = path.wavelengths;
        (sum.finish(&path.wavelengths), first_hit)
    }

    /// Jensen 1996 eq. 9 at a surface vertex: Σ f(ωo, ωp) ΔΦp / (π r²) over the caustic
    /// photons within r of `p` (f without the cosine: the photons' flux is already per
    /// projected area), of at most `depth_left` scattering events. r is the pixel's radius
    /// when `gather` has one (Hachisuka & Jensen 2009), else each photon's own.
    #[allow(clippy::too_many_arguments)]
    fn gather_caustics(
        &self,
        vertex: &ScatterVertex,
        p: Vec3A,
        beta: SampledSpectrum,
        depth_left: u32,
        gather: &mut CausticGather,
        sum: &mut Radiance,
        counters: &mut PathCounters,
    ) {
        let mut add = |ph: &Photon, radius_m: f32| {
            if u32::from(ph.depth) > depth_left {
                return;
            }
            gather.found += 1;
            if gather.count_only {
                return;
            }
            let Some(eval) = vertex.eval(-ph.direction(), TransportMode::Radiance) else {
                return;
            };
            let cos = eval.wi_local.z.abs();
            if cos <= 0.0 || eval.f_cos.is_black() {
                return;
            }
            let kernel = 1.0 / (std::f32::consts::PI * radius_m * radius_m);
            let c = beta * eval.f_cos * ph.beta() * (kernel / cos);
            sum.add_photon(ph, c, counters);
        };
        match gather.radius_m {
            Some(r) => self.maps.caustic.for_each_within(p, r, |ph| add(ph, r)),
            None => self
                .maps
                .caustic
                .for_each_containing(p, |ph| add(ph, ph.radius_m)),
        }
    }

    /// Jarosz et al. 2008 eq. 13, the beam radiance estimate along `segment` in medium
    /// `m`: Σ K(dp) · T(tp) · p(ωo, ωp) · ΔΦp over the volume photons whose disc of radius
    /// rp (perpendicular to the ray, K = 1/(π rp²)) the segment crosses, of at most
    /// `depth_left` scattering events. The photons were deposited at real scattering
    /// events, with density ∝ σs along their flights, so σs is in their flux.
    #[allow(clippy::too_many_arguments)]
    fn beam(
        &self,
        segment: &Ray,
        m: u32,
        phase: &crate::medium::PhaseFunction,
        profile: &Transmittance,
        beta: SampledSpectrum,
        depth_left: u32,
        sum: &mut Radiance,
        counters: &mut PathCounters,
    ) {
        let wo = -segment.direction;
        self.maps.volume.for_each_crossed(
            segment.origin,
            segment.direction,
            segment.t_min,
            segment.t_max,
            |ph, t| {
                if u32::from(ph.depth) > depth_left || u32::from(ph.medium) != m {
                    return;
                }
                let kernel = 1.0 / (std::f32::consts::PI * ph.radius_m * ph.radius_m);
                let p = phase.eval(wo, -ph.direction());
                let c = beta * profile.at(t) * ph.beta() * (p * kernel);
                sum.add_photon(ph, c, counters);
            },
        );
    }

    /// One light sample at surface vertex `vertex`, MIS-weighted against BSDF sampling
    /// (`path`'s `mis`), its shadow ray through the media on its way. Without β.
    #[allow(clippy::too_many_arguments)]
    fn sample_light(
        &self,
        scene: &RenderScene,
        vertex: &ScatterVertex,
        medium: Option<u32>,
        instance: u32,
        u_choice: f32,
        u: glam::Vec2,
        wavelengths: &LaneWavelengths,
        le_cache: &mut SpectrumCache,
        rng: Option<&mut MediumRng>,
        counters: &mut PathCounters,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::splat(0.0);
        let Some(VertexLightSample {
            sample: ls,
            pmf,
            eval,
            normal,
        }) = vertex.sample_light(scene, u_choice, u, wavelengths, le_cache)
        else {
            return zero;
        };
        counters.rays += 1;
        let transmittance = match (scene.media.as_ref(), rng) {
            (Some(media), Some(rng)) => {
                let start = media.after_surface(medium, instance, ls.wi, normal);
                shadow_transmittance(
                    scene,
                    media,
                    vertex.p(),
                    &ls,
                    start,
                    wavelengths.transport(),
                    rng,
                    counters,
                )
            }
            _ => {
                self.tracer
                    .transmittance(scene, vertex.p(), &ls, wavelengths.transport(), counters)
            }
        };
        if transmittance.is_black() {
            return zero;
        }
        let light_pdf = pmf * ls.pdf;
        let w = if ls.delta {
            1.0
        } else {
            let bsdf_pdf = vertex.pdf(&eval, TransportMode::Radiance);
            mis_weight(self.tracer.mis, light_pdf, bsdf_pdf)
        };
        eval.f_cos * ls.radiance * transmittance * (w / light_pdf)
    }
}

/// The pass's wavelengths: one set for every photon and camera path of pass
/// `iteration` (pbrt-v4 SPPM samples one `SampledWavelengths` per iteration), its hero
/// from a hash of (seed, pass), drawn from `density` (the film's).
pub fn pass_wavelengths(
    seed: u64,
    iteration: u32,
    density: WavelengthDensity,
) -> SampledWavelengths {
    let h = super::shoot::mix_seed(seed ^ 0x5741_5645_4C45_4E47, iteration, u64::MAX);
    let u = (h >> 40) as f32 * (1.0 / (1u32 << 24) as f32);
    density.sample(u)
}
