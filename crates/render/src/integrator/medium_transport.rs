//! `path` in scenes with participating media: null-scattering volumetric path tracing
//! (Miller, Georgiev & Jarosz 2019, "A null-scattering path integral formulation of light
//! transport"), as pbrt-v4's `VolPathIntegrator` (§14.2) does it:
//!
//! - **Delta tracking** against a majorant σ_maj ≥ σt: free-flight distances sampled at
//!   the hero wavelength (lane 0); each collision is absorption, real scattering or a null
//!   event with probabilities σa/σ_maj, σs/σ_maj, σn/σ_maj (hero values). A homogeneous
//!   medium's majorant is σt; a grid's is its 16³ majorant cells × σt, walked by 3-D DDA.
//! - **Spectral MIS**: the other three lanes were sampled with the hero's pdfs. The path
//!   carries pbrt-v4's rescaled path probabilities r_u (unidirectional strategy) and r_l
//!   (light strategy), per lane, relative to the hero's pdf; a contribution is divided by
//!   their lane average, the one-sample balance heuristic over the four wavelengths and
//!   the two strategies (dividing by the hero's pdf alone made Mitsuba 2's `volpath`
//!   noisy in chromatic media, mitsuba2 #323). `spectral_mis: false` divides by the hero's
//!   alone (a debug switch), as does every contribution once the secondary lanes have
//!   ended (`spectral_mis_now`).
//! - **Next-event estimation** from surface and medium vertices; shadow rays estimate
//!   transmittance by ratio tracking and cross `interface` surfaces (and masks and thin
//!   panes, as in vacuum); any other surface blocks them.
//! - **Interfaces** (`material: interface`) scatter nothing: crossing one changes the
//!   ray's medium and is not a bounce (pbrt-v3 #69).
//! - **Emissive media** add σa·Le at every collision (pbrt-v4).
//! - **Fluorescent media** (a `Fluorophore`, issue 21): at each collision, with
//!   probability q = c_max/(σ_maj + c_max) the path continues as the fluorescent source
//!   (isotropic, each lane's λi drawn ∝ M(·, λo) at its transport wavelength, weight
//!   M/(σ_maj·q·p), the lane's transport moved to λi), else as usual with weight 1/(1 − q).
//!   q and the majorant (`OpticsAtLanes::fluorescent_majorant`) are the same for every
//!   lane, so no lane's source or null continuation is out of the hero's reach. Fluorescent
//!   surfaces scatter as in vacuum (`fluorescent_vertex`).
//!
//! Light and BSDF sampling are weighted by the balance heuristic here (it is what the
//! rescaled probabilities express), whatever `mis` says.
//!
//! Sample dimensions: every segment reserves a `MediumDimensions` block, then each vertex
//! (surface or medium) its `VertexDimensions` block, and a surface vertex in a scene with
//! re-radiation its `ReradiationDimensions`. A fluorophore's choices draw from the
//! segment's generator. Scenes without media never come here.

use glam::{Vec2, Vec3A};
use prism_geometry::{Ray, RayDifferential};
use prism_scene::FluorescenceLanes;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

use super::dimensions::{MediumDimensions, ReradiationDimensions};
use super::fluorescent_vertex;
use super::lane_wavelengths::LaneWavelengths;
use super::path::{FirstHit, PathCounters, PathResult, PathTracer};
use super::path_state::{PathOrigin, PathState};
use super::scatter_vertex::{MediumVertex, ScatterVertex, SurfaceVertex, VertexLightSample};
use crate::bsdf::TransportMode;
use crate::light::LightHit;
use crate::medium::{Fluorophore, Medium, OpticsAtLanes, PhaseFunction};
use crate::sampler::SampleStream;
use crate::scene_build::media::MediaScene;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// SplitMix64 (Steele, Lea & Flood 2014): the variates of one segment's collisions and
/// shadow rays, seeded per (sample, dimension).
#[derive(Clone, Copy, Debug)]
pub struct MediumRng(u64);

impl MediumRng {
    #[inline]
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Uniform in [0, 1), 24 bits.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
    }
}

/// What a medium is at a collision: σa, σs (density-scaled) and Le.
#[derive(Clone, Copy, Debug)]
pub struct Collision {
    pub p: Vec3A,
    pub sigma_a: SampledSpectrum,
    pub sigma_s: SampledSpectrum,
    pub emission: SampledSpectrum,
    pub sigma_maj: SampledSpectrum,
    /// The density at `p` (1 in a homogeneous medium).
    pub density: f32,
    /// Majorant transmittance since the previous collision (or the segment's start).
    pub t_maj: SampledSpectrum,
}

/// pbrt-v4 `SampleT_maj`: walks `ray` (unit direction) from `ray.t_min` to `ray.t_max`
/// through `medium`, sampling collisions against the majorant at the hero lane (the first
/// distance from `u`, the rest from `rng`), and calls `callback` at each; it returns false
/// to stop. Returns the majorant transmittance from the last collision to the end (1 when
/// stopped).
pub fn sample_t_maj(
    medium: &Medium,
    optics: &OpticsAtLanes,
    ray: &Ray,
    mut u: f32,
    rng: &mut MediumRng,
    mut callback: impl FnMut(&Collision, &mut MediumRng) -> bool,
) -> SampledSpectrum {
    let mut t_maj = SampledSpectrum::splat(1.0);
    for stretch in medium.stretches(ray) {
        let sigma_maj = optics.sigma_maj * stretch.density_bound;
        let span = |a: f32, b: f32| {
            let dt = b - a;
            if dt.is_finite() {
                dt
            } else {
                f32::MAX
            }
        };
        if sigma_maj[0] <= 0.0 {
            // No collisions at the hero wavelength: other lanes get their transmittance.
            t_maj *= (sigma_maj * -span(stretch.t_min, stretch.t_max)).exp();
            continue;
        }
        let mut t_min = stretch.t_min;
        loop {
            let t = t_min - (1.0 - u).ln() / sigma_maj[0];
            u = rng.uniform();
            if t < stretch.t_max {
                t_maj *= (sigma_maj * -(t - t_min)).exp();
                let p = ray.origin + ray.direction * t;
                let density = medium.density(p);
                let c = Collision {
                    p,
                    sigma_a: optics.sigma_a * density,
                    sigma_s: optics.sigma_s * density,
                    emission: optics.emission,
                    sigma_maj,
                    density,
                    t_maj,
                };
                if !callback(&c, rng) {
                    return SampledSpectrum::splat(1.0);
                }
                t_maj = SampledSpectrum::splat(1.0);
                t_min = t;
            } else {
                t_maj *= (sigma_maj * -span(t_min, stretch.t_max)).exp();
                break;
            }
        }
    }
    t_maj
}

/// Adds contribution `c` unless it is NaN/∞ (then counts it).
#[inline]
fn add(radiance: &mut SampledSpectrum, c: SampledSpectrum, counters: &mut PathCounters) {
    if c.has_non_finite() {
        counters.non_finite_contributions += 1;
    } else {
        *radiance += c;
    }
}

/// The lane average of rescaled probabilities `r` (the hero's alone without spectral MIS).
#[inline]
fn average(r: SampledSpectrum, spectral_mis: bool) -> f32 {
    if spectral_mis {
        r.average()
    } else {
        r[0]
    }
}

/// Transmittance and rescaled probabilities of a shadow ray (pbrt-v4 `SampleLd`'s loop).
#[derive(Clone, Copy, Debug)]
struct ShadowTransmittance {
    t_ray: SampledSpectrum,
    r_u: SampledSpectrum,
    r_l: SampledSpectrum,
}

/// What one collision did to the path.
enum SegmentEnd {
    /// The segment reached its end (a surface or escape).
    Passed,
    /// Absorbed, or its weight vanished: the path ends.
    Terminated,
    /// Real scattering at this point.
    Scattered(Vec3A),
    /// The fluorophore re-emits here: the lanes' new transport wavelengths (`None`: the
    /// lane carries nothing on).
    Fluoresced(Vec3A, [Option<f32>; N_SPECTRUM_SAMPLES]),
}

/// Per-lane weights of re-emission by fluorophore `f` (density `density`) at a collision,
/// times the source's isotropic phase over its pdf (1), and the lanes' excitation
/// wavelengths: each lane draws λi ∝ M(·, λo) at its own transport wavelength λo (`u`
/// rotated per lane, as at fluorescent surfaces), weight M(λi, λo)·density/p(λi). `Hero`
/// keeps only the hero lane when any lane shifts.
fn fluoresce(
    f: &Fluorophore,
    lanes: &LaneWavelengths,
    density: f32,
    u: f32,
    mode: FluorescenceLanes,
) -> (SampledSpectrum, [Option<f32>; N_SPECTRUM_SAMPLES]) {
    let mut weight = SampledSpectrum::splat(0.0);
    let mut shifted = [None; N_SPECTRUM_SAMPLES];
    let live = lanes.sensor().pdf();
    let lambda_out = lanes.transport().lambda();
    for lane in 0..N_SPECTRUM_SAMPLES {
        if live[lane] == 0.0 {
            continue;
        }
        let u_lane = fluorescent_vertex::rotated(u, lane);
        let Some((lambda_in_nm, pdf)) = f.matrix.sample_excitation(lambda_out[lane], u_lane) else {
            continue;
        };
        if pdf > 0.0 {
            weight[lane] = f.matrix.eval(lambda_in_nm, lambda_out[lane]) * density / pdf;
            shifted[lane] = Some(lambda_in_nm);
        }
    }
    match mode {
        FluorescenceLanes::All => {}
        FluorescenceLanes::Hero => {
            if shifted.iter().any(Option::is_some) {
                for lane in 1..N_SPECTRUM_SAMPLES {
                    weight[lane] = 0.0;
                }
            }
        }
    }
    (weight, shifted)
}

impl PathTracer {
    /// `trace` in a scene with media (see the module docs); the arguments as there.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn trace_volumetric(
        &self,
        scene: &RenderScene,
        media: &MediaScene,
        camera_ray: &Ray,
        origin: Option<PathOrigin>,
        camera_differential: Option<&RayDifferential>,
        differential_scale: f32,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        counters: &mut PathCounters,
    ) -> PathResult {
        let mode = self.fluorescence_lanes;
        let lights = &scene.lights;
        let mut current_differential = camera_differential.copied();
        let mut radiance = SampledSpectrum::splat(0.0);
        let mut path = PathState::new(camera_ray.origin, origin, *stream, *wavelengths);
        let mut r_u = SampledSpectrum::splat(1.0);
        // A path sampled at a non-specular origin weights the emission it meets against
        // the caller's light samples from there.
        let mut r_l = SampledSpectrum::splat(origin.map_or(1.0, |o| 1.0 / o.direction_pdf));
        let mut medium = if origin.is_none() {
            media.camera
        } else {
            media.world
        };
        let mut first_hit: Option<FirstHit> = None;
        let mut ray = *camera_ray;
        let n_light = light_samples.max(1);
        let mut le_cache = SpectrumCache::new();
        let mut reflectance_cache = SpectrumCache::new();
        // The phase function of re-emission by a medium's fluorophore.
        let isotropic = PhaseFunction::Isotropic;

        loop {
            let spectral = self.spectral_mis_now(&path.wavelengths);
            let hit = scene.geometry.intersect(&ray);
            let md = MediumDimensions::reserve(&mut path.stream);
            let mut rng = MediumRng::new(path.stream.seed_at(md.generator()));
            if let Some(m) = medium {
                let med = media.medium(m);
                let optics = med
                    .optics()
                    .at(path.wavelengths.transport())
                    .fluorescent_majorant(path.depth < self.max_depth);
                let segment = Ray::new(
                    ray.origin,
                    ray.direction,
                    0.0,
                    hit.map_or(f32::INFINITY, |h| h.t),
                );
                let mut end = SegmentEnd::Passed;
                let (mut beta, max_depth) = (path.beta, self.max_depth);
                let mut depth = path.depth;
                let fluorophore = med.optics().fluorescence.as_ref();
                let lanes = &path.wavelengths;
                let u0 = path.stream.get_1d_at(md.distance());
                let t_maj = sample_t_maj(med, &optics, &segment, u0, &mut rng, |c, rng| {
                    // Emission (pbrt-v4: σa·Le, weighted over the lanes' distance pdfs).
                    if depth < max_depth && !c.emission.is_black() {
                        let pdf = c.sigma_maj[0] * c.t_maj[0];
                        let beta_e = beta * c.t_maj / pdf;
                        let r_e = r_u * c.sigma_maj * c.t_maj / pdf;
                        if !r_e.is_black() {
                            add(
                                &mut radiance,
                                beta_e * c.sigma_a * c.emission / average(r_e, spectral),
                                counters,
                            );
                        }
                    }
                    // A fluorophore's source term, chosen with probability q (one value for
                    // all lanes, so their MIS ratios keep it out); the rest of the collision
                    // estimator is weighted by 1/(1 − q).
                    if let (Some(f), true) = (fluorophore, depth < max_depth) {
                        let c_max = optics.sigma_fl.max_component() * c.density;
                        // (c_max > 0 implies the shared majorant: depth only grows here.)
                        if c_max > 0.0 {
                            let q = c_max / (c.sigma_maj[0] + c_max);
                            if rng.uniform() < q {
                                depth += 1;
                                let (w, shifted) =
                                    fluoresce(f, lanes, c.density, rng.uniform(), mode);
                                let pdf = c.t_maj[0] * c.sigma_maj[0] * q;
                                beta *= c.t_maj * w / pdf;
                                r_u *= c.t_maj * c.sigma_maj * q / pdf;
                                end = if beta.is_black() || r_u.is_black() {
                                    SegmentEnd::Terminated
                                } else {
                                    SegmentEnd::Fluoresced(c.p, shifted)
                                };
                                return false;
                            }
                            beta *= 1.0 / (1.0 - q);
                            r_l *= 1.0 / (1.0 - q);
                        }
                    }
                    let p_absorb = c.sigma_a[0] / c.sigma_maj[0];
                    let p_scatter = c.sigma_s[0] / c.sigma_maj[0];
                    let u_mode = rng.uniform();
                    if u_mode < p_absorb {
                        end = SegmentEnd::Terminated;
                        return false;
                    }
                    if u_mode < p_absorb + p_scatter {
                        if depth >= max_depth {
                            end = SegmentEnd::Terminated;
                            return false;
                        }
                        depth += 1;
                        let pdf = c.t_maj[0] * c.sigma_s[0];
                        beta *= c.t_maj * c.sigma_s / pdf;
                        r_u *= c.t_maj * c.sigma_s / pdf;
                        end = if beta.is_black() || r_u.is_black() {
                            SegmentEnd::Terminated
                        } else {
                            SegmentEnd::Scattered(c.p)
                        };
                        return false;
                    }
                    // Null collision.
                    let sigma_n = (c.sigma_maj - c.sigma_a - c.sigma_s).clamp_zero();
                    let pdf = c.t_maj[0] * sigma_n[0];
                    if pdf <= 0.0 {
                        beta = SampledSpectrum::splat(0.0);
                    } else {
                        beta *= c.t_maj * sigma_n / pdf;
                        r_u *= c.t_maj * sigma_n / pdf;
                        r_l *= c.t_maj * c.sigma_maj / pdf;
                    }
                    if beta.is_black() || r_u.is_black() {
                        end = SegmentEnd::Terminated;
                        return false;
                    }
                    true
                });
                path.beta = beta;
                let scattered = match end {
                    SegmentEnd::Terminated => break,
                    SegmentEnd::Scattered(p) => Some((p, &med.optics().phase)),
                    SegmentEnd::Fluoresced(p, shifted) => {
                        for (lane, lambda_in_nm) in shifted.iter().enumerate() {
                            if let Some(lambda_in_nm) = lambda_in_nm {
                                path.wavelengths.shift_transport(lane, *lambda_in_nm);
                            }
                        }
                        if mode == FluorescenceLanes::Hero && shifted.iter().any(Option::is_some) {
                            path.wavelengths.terminate_secondary();
                        }
                        Some((p, &isotropic))
                    }
                    SegmentEnd::Passed => {
                        let scale = t_maj / t_maj[0];
                        path.beta *= scale;
                        r_u *= scale;
                        r_l *= scale;
                        if path.beta.is_black() || path.beta.has_non_finite() {
                            break;
                        }
                        None
                    }
                };
                if let Some((p, phase)) = scattered {
                    path.depth = depth;
                    counters.bounces += 1;
                    let vertex = ScatterVertex::Medium(MediumVertex {
                        p,
                        wo: -ray.direction,
                        phase,
                    });
                    let dims = path.next_vertex_dimensions();
                    if !lights.is_empty() {
                        let direct = self.sample_lights_volumetric(
                            scene,
                            media,
                            &vertex,
                            medium,
                            None,
                            &dims,
                            n_light,
                            &mut path,
                            r_u,
                            &mut rng,
                            &mut le_cache,
                            counters,
                        );
                        add(&mut radiance, path.beta * direct, counters);
                    }
                    let Some(ps) = vertex.sample(
                        0.0,
                        path.stream.get_2d_at(dims.bsdf()),
                        TransportMode::Radiance,
                    ) else {
                        break;
                    };
                    path.beta *= ps.weight;
                    r_l = r_u / ps.pdf;
                    path.scattered(vertex.light_context(), &ps);
                    ray = Ray::infinite(p, ps.wi);
                    current_differential = None;
                    counters.rays += 1;
                    let spectral = self.spectral_mis_now(&path.wavelengths);
                    if self.volumetric_roulette(&mut path, r_u, dims.roulette(), spectral) {
                        counters.roulette_terminations += 1;
                        break;
                    }
                    continue;
                }
            }

            let Some(hit) = hit else {
                // Escaped: infinite lights.
                for &l in lights.infinite_lights() {
                    let le = lights
                        .light(l)
                        .infinite_radiance(ray.direction, path.wavelengths.transport());
                    if le.is_black() {
                        continue;
                    }
                    let c = if path.specular_bounce {
                        path.beta * le / average(r_u, spectral)
                    } else {
                        let p_l = lights.pmf_at(&path.prev_ctx, l)
                            * lights.light(l).pdf_li(&path.prev_ctx, ray.direction, None);
                        path.beta * le / average(r_u + r_l * p_l, spectral)
                    };
                    add(&mut radiance, c, counters);
                }
                break;
            };
            let mut si = scene.geometry.shading_interaction(&ray, &hit);
            // The boundary's own word for the side the ray arrives from.
            if media.arrives_mismatched(medium, hit.instance_id, ray.direction, si.n_geometric) {
                counters.medium_mismatches += 1;
            }
            // A medium boundary that scatters nothing: cross it, not a bounce.
            if media.is_interface(si.material_id) {
                medium =
                    media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
                if !path.null_event() {
                    break;
                }
                continue;
            }
            scene.set_texture_differentials(
                &mut si,
                current_differential.as_ref(),
                differential_scale,
            );
            let material = scene.material(si.material_id);
            let dims = path.next_vertex_dimensions();
            let reradiation_dims = scene
                .has_reradiation
                .then(|| ReradiationDimensions::reserve(&mut path.stream));
            let opacity = if scene.has_masks {
                material.opacity_at(&si)
            } else {
                1.0
            };
            if opacity < 1.0 && path.stream.get_1d_at(dims.mask()) >= opacity {
                medium =
                    media.after_surface(medium, hit.instance_id, ray.direction, si.n_geometric);
                if !path.null_event() {
                    break;
                }
                ray = Ray::spawn_off_surface(si.p, si.n_geometric, ray.direction);
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
            if let Some(l) = lights.area_light_of_instance(hit.instance_id) {
                let light_hit = LightHit {
                    p: si.p,
                    n: si.n_geometric,
                    uv: si.uv,
                    distance_m: hit.t,
                };
                let light = lights.light(l);
                let le = light.emitted_radiance_cached(
                    lights.emission_key(l),
                    &light_hit,
                    -ray.direction,
                    &path.wavelengths,
                    &mut le_cache,
                );
                if !le.is_black() {
                    let c = if path.specular_bounce {
                        path.beta * le / average(r_u, spectral)
                    } else {
                        let p_l = lights.pmf_at(&path.prev_ctx, l)
                            * light.pdf_li(&path.prev_ctx, ray.direction, Some(&light_hit));
                        path.beta * le / average(r_u + r_l * p_l, spectral)
                    };
                    add(&mut radiance, c, counters);
                }
            }
            if path.depth == self.max_depth {
                break;
            }
            path.depth += 1;
            counters.bounces += 1;
            if scene.has_dispersion && material.is_dispersive() {
                path.wavelengths.terminate_secondary();
            }
            let mut bsdf = material.bsdf_cached(
                si.material_id,
                &si,
                &path.wavelengths,
                &mut reflectance_cache,
            );
            // A fluorescent surface (fluorescent_vertex.rs), as in vacuum.
            if let (Some(d), Some(f)) = (reradiation_dims, material.fluorescent()) {
                let lanes = &mut path.wavelengths;
                fluorescent_vertex::scatter(mode, f, &mut bsdf, lanes, &path.stream, d);
            }
            let vertex =
                ScatterVertex::Surface(SurfaceVertex::new(&si, &bsdf, ray.direction, shading_maps));
            if !vertex.is_specular() && !lights.is_empty() {
                let direct = self.sample_lights_volumetric(
                    scene,
                    media,
                    &vertex,
                    medium,
                    Some(hit.instance_id),
                    &dims,
                    n_light,
                    &mut path,
                    r_u,
                    &mut rng,
                    &mut le_cache,
                    counters,
                );
                add(&mut radiance, path.beta * direct, counters);
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
                r_l = r_u / bs.pdf;
                path.scattered(vertex.light_context(), &bs);
            }
            let wi = bs.wi.normalize();
            medium = media.after_surface(medium, hit.instance_id, wi, si.n_geometric);
            ray = Ray::spawn_off_surface(vertex.p(), si.n_geometric, wi);
            current_differential = None;
            counters.rays += 1;
            let spectral = self.spectral_mis_now(&path.wavelengths);
            if self.volumetric_roulette(&mut path, r_u, dims.roulette(), spectral) {
                counters.roulette_terminations += 1;
                break;
            }
        }
        *stream = path.stream;
        *wavelengths = path.wavelengths;
        PathResult {
            radiance,
            first_hit,
            // The white-Lambertian illumination AOV is not estimated in media.
            illumination: None,
        }
    }

    /// Spectral MIS while every lane lives. Once the secondary lanes end (a dispersive
    /// surface, or re-emission under `fluorescence_lanes: hero`) only the hero's estimate
    /// is kept, counted four times by its quartered pdf, so it must divide by the hero's
    /// own pdf: averaging in the dead lanes' pdfs biased it (+23 % in the fluorophore slab).
    #[inline]
    fn spectral_mis_now(&self, lanes: &LaneWavelengths) -> bool {
        self.spectral_mis && !lanes.sensor().secondary_terminated()
    }

    /// Russian roulette on β/⟨r_u⟩ (pbrt-v4 `VolPathIntegrator`), from `rr_depth` on.
    fn volumetric_roulette(
        &self,
        path: &mut PathState,
        r_u: SampledSpectrum,
        dimension: u32,
        spectral: bool,
    ) -> bool {
        if path.depth < self.rr_depth {
            return false;
        }
        let rr_beta = path.beta * path.eta_scale / average(r_u, spectral);
        let q = (1.0 - rr_beta.max_component()).max(0.0);
        if q <= 0.0 {
            return false;
        }
        if path.stream.get_1d_at(dimension) < q {
            return true;
        }
        path.beta *= 1.0 / (1.0 - q);
        false
    }

    /// The light samples of one vertex (the first from the vertex block, further ones
    /// drawn after it, stratified over the light choice as in vacuum), averaged; the
    /// result is multiplied by β by the caller. `instance` is the surface's instance (its
    /// shadow rays leave into the medium on their side), `None` at a medium vertex.
    #[allow(clippy::too_many_arguments)]
    fn sample_lights_volumetric(
        &self,
        scene: &RenderScene,
        media: &MediaScene,
        vertex: &ScatterVertex,
        medium: Option<u32>,
        instance: Option<u32>,
        dims: &super::dimensions::VertexDimensions,
        n_light: u32,
        path: &mut PathState,
        r_p: SampledSpectrum,
        rng: &mut MediumRng,
        le_cache: &mut SpectrumCache,
        counters: &mut PathCounters,
    ) -> SampledSpectrum {
        let mut direct = SampledSpectrum::splat(0.0);
        for k in 0..n_light {
            let (uc, ul) = if k == 0 {
                (
                    path.stream.get_1d_at(dims.light_choice()),
                    path.stream.get_2d_at(dims.light()),
                )
            } else {
                (path.stream.get_1d(), path.stream.get_2d())
            };
            let uc = ((k as f32 + uc) / n_light as f32).min(1.0 - f32::EPSILON);
            direct += self.sample_ld(
                scene,
                media,
                vertex,
                medium,
                instance,
                uc,
                ul,
                &path.wavelengths,
                path.depth < self.max_depth,
                r_p,
                rng,
                le_cache,
                counters,
            );
        }
        direct * (1.0 / n_light as f32)
    }

    /// pbrt-v4 `VolPathIntegrator::SampleLd`: one light sample at `vertex`, its
    /// transmittance by ratio tracking, weighted by the rescaled probabilities (`r_p`: the
    /// path's r_u). Without β.
    #[allow(clippy::too_many_arguments)]
    fn sample_ld(
        &self,
        scene: &RenderScene,
        media: &MediaScene,
        vertex: &ScatterVertex,
        medium: Option<u32>,
        instance: Option<u32>,
        u_choice: f32,
        u: Vec2,
        wavelengths: &LaneWavelengths,
        may_scatter: bool,
        r_p: SampledSpectrum,
        rng: &mut MediumRng,
        le_cache: &mut SpectrumCache,
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
        let scatter_pdf = vertex.pdf(&eval, TransportMode::Radiance);
        let start_medium = match instance {
            Some(id) => media.after_surface(medium, id, ls.wi, normal),
            None => medium,
        };
        counters.rays += 1;
        let Some(tr) = shadow_transmittance(
            scene,
            media,
            vertex.p(),
            &ls,
            start_medium,
            wavelengths.transport(),
            may_scatter,
            rng,
            counters,
        ) else {
            return zero;
        };
        let light_pdf = pmf * ls.pdf;
        let r_l = tr.r_l * r_p * light_pdf;
        let r_u = tr.r_u * r_p * scatter_pdf;
        let spectral = self.spectral_mis_now(wavelengths);
        let denom = if ls.delta {
            average(r_l, spectral)
        } else {
            average(r_l + r_u, spectral)
        };
        if denom <= 0.0 {
            return zero;
        }
        eval.f_cos * tr.t_ray * ls.radiance / denom
    }
}

/// Transmittance from `p` to the light sample `ls` leaving in `medium` (`may_scatter`: the
/// path may scatter again, `OpticsAtLanes::fluorescent_majorant`): ratio tracking
/// through each medium on the way (pbrt-v4 `SampleLd`), across `interface` surfaces,
/// masks' holes and thin panes; `None` where something opaque blocks it or the estimate
/// is 0.
#[allow(clippy::too_many_arguments)]
fn shadow_transmittance(
    scene: &RenderScene,
    media: &MediaScene,
    mut p: Vec3A,
    ls: &crate::light::LightSample,
    mut medium: Option<u32>,
    wavelengths: &SampledWavelengths,
    may_scatter: bool,
    rng: &mut MediumRng,
    counters: &mut PathCounters,
) -> Option<ShadowTransmittance> {
    let mut tr = ShadowTransmittance {
        t_ray: SampledSpectrum::splat(1.0),
        r_u: SampledSpectrum::splat(1.0),
        r_l: SampledSpectrum::splat(1.0),
    };
    for _ in 0..256 {
        let shadow = if ls.distance_m.is_finite() {
            Ray::spawn_to(p, ls.p_light)
        } else {
            Ray::spawn(p, ls.wi)
        };
        let hit = scene.geometry.intersect(&shadow);
        let through = match &hit {
            None => None,
            Some(h) => {
                let si = scene.geometry.shading_interaction(&shadow, h);
                let material = scene.material(si.material_id);
                let opacity = material.opacity_at(&si);
                let mut through = SampledSpectrum::splat(1.0 - opacity);
                if let Some(pane) = material.thin_glazing(wavelengths) {
                    let cos = ls.wi.dot(si.n_shading).abs();
                    through += pane.transmittance(cos) * opacity;
                }
                if through.is_black() {
                    return None;
                }
                Some((si.p, si.n_geometric, h.instance_id, h.t, through))
            }
        };
        if let Some(m) = medium {
            // The segment in metres along a unit direction.
            let length = shadow.direction.length();
            let t_end = through.as_ref().map_or(shadow.t_max, |t| t.3);
            let segment = Ray::new(
                shadow.origin,
                shadow.direction / length,
                shadow.t_min * length,
                t_end * length,
            );
            let med = media.medium(m);
            // The majorant of the path's own next segment, so both strategies of the MIS
            // weigh the same null collisions.
            let optics = med
                .optics()
                .at(wavelengths)
                .fluorescent_majorant(may_scatter);
            let u = rng.uniform();
            let t_maj = sample_t_maj(med, &optics, &segment, u, rng, |c, rng| {
                let sigma_n = (c.sigma_maj - c.sigma_a - c.sigma_s).clamp_zero();
                let pdf = c.t_maj[0] * c.sigma_maj[0];
                tr.t_ray *= c.t_maj * sigma_n / pdf;
                tr.r_l *= c.t_maj * c.sigma_maj / pdf;
                tr.r_u *= c.t_maj * sigma_n / pdf;
                // Roulette on a small transmittance estimate (pbrt-v4: below 0.05,
                // survive with probability 1/4).
                let estimate = tr.t_ray / (tr.r_l + tr.r_u).average();
                if estimate.max_component() < 0.05 {
                    if rng.uniform() < 0.75 {
                        tr.t_ray = SampledSpectrum::splat(0.0);
                    } else {
                        tr.t_ray *= 4.0;
                    }
                }
                !tr.t_ray.is_black()
            });
            let scale = t_maj / t_maj[0];
            tr.t_ray *= scale;
            tr.r_l *= scale;
            tr.r_u *= scale;
        }
        if tr.t_ray.is_black() || tr.t_ray.has_non_finite() {
            return None;
        }
        let Some((p_hit, n, instance, _, through)) = through else {
            return Some(tr);
        };
        tr.t_ray *= through;
        medium = media.after_surface(medium, instance, ls.wi, n);
        p = p_hit;
        counters.rays += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::{HomogeneousMedium, MediumOptics, PhaseFunction};
    use prism_spectrum::Spectrum;

    fn homogeneous(sigma_t: f32) -> Medium {
        Medium::Homogeneous(HomogeneousMedium {
            optics: MediumOptics {
                sigma_a: Spectrum::constant(0.0),
                sigma_s: Spectrum::constant(sigma_t),
                emission: None,
                phase: PhaseFunction::Isotropic,
                fluorescence: None,
            },
        })
    }

    /// Issue 20 test 4: through a density ramp, delta tracking (the fraction of walks with
    /// no real collision) and ratio tracking (the mean of Π σn/σ_maj) both estimate the
    /// exact transmittance e^(−σ ∫ density), the integral by the trapezoid rule over voxel
    /// centres with the edge values held; 4 standard errors.
    #[test]
    fn delta_and_ratio_tracking_agree_with_the_exact_transmittance() {
        use crate::medium::{DensityGrid, GridMedium};
        let ramp = [0.2f32, 0.6, 1.0, 1.4, 0.3];
        let grid = DensityGrid::new(
            [1, 1, 5],
            glam::Vec3::new(-1.0, -1.0, 0.0),
            glam::Vec3::new(1.0, 1.0, 1.0),
            ramp.to_vec(),
        )
        .unwrap();
        let sigma = 1.5f32;
        let medium = Medium::Grid(GridMedium {
            optics: MediumOptics {
                sigma_a: Spectrum::constant(sigma),
                sigma_s: Spectrum::constant(0.0),
                emission: None,
                phase: PhaseFunction::Isotropic,
                fluorescence: None,
            },
            density: grid,
        });
        let h = 1.0 / ramp.len() as f64;
        let integral = h
            * (0.5 * f64::from(ramp[0])
                + ramp
                    .windows(2)
                    .map(|w| 0.5 * f64::from(w[0] + w[1]))
                    .sum::<f64>()
                + 0.5 * f64::from(ramp[ramp.len() - 1]));
        let exact = (-f64::from(sigma) * integral).exp();
        let w = SampledWavelengths::sample_visible(0.5);
        let optics = medium.optics().at(&w);
        // Along +z through the box, from below it to above it, off the grid's centre.
        let ray = Ray::new(Vec3A::new(0.3, -0.2, -0.5), Vec3A::Z, 0.0, 2.0);
        let n = 200_000;
        let mut rng = MediumRng::new(99);
        let (mut passed, mut ratio_sum, mut ratio_sq) = (0u32, 0.0f64, 0.0f64);
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let mut absorbed = false;
            sample_t_maj(&medium, &optics, &ray, u, &mut rng, |c, rng| {
                if rng.uniform() < c.sigma_a[0] / c.sigma_maj[0] {
                    absorbed = true;
                    return false;
                }
                true
            });
            if !absorbed {
                passed += 1;
            }
            let mut t_ray = 1.0f64;
            let u = rng.uniform();
            // The rest of the way after the last collision weighs T_maj/T_maj[0] = 1 (every
            // lane is the hero's here).
            sample_t_maj(&medium, &optics, &ray, u, &mut rng, |c, _| {
                let sigma_n = (c.sigma_maj[0] - c.sigma_a[0] - c.sigma_s[0]).max(0.0);
                t_ray *= f64::from(sigma_n / c.sigma_maj[0]);
                true
            });
            ratio_sum += t_ray;
            ratio_sq += t_ray * t_ray;
        }
        let p = f64::from(passed) / n as f64;
        let se_delta = (p * (1.0 - p) / n as f64).sqrt();
        let ratio = ratio_sum / n as f64;
        let se_ratio = ((ratio_sq / n as f64 - ratio * ratio) / n as f64).sqrt();
        assert!(
            (p - exact).abs() < 4.0 * se_delta,
            "delta tracking {p} ± {se_delta}, exact {exact}"
        );
        assert!(
            (ratio - exact).abs() < 4.0 * se_ratio,
            "ratio tracking {ratio} ± {se_ratio}, exact {exact}"
        );
    }

    /// The first collision's distance is exponential with rate σt: its mean is 1/σt.
    #[test]
    fn free_flights_are_exponential() {
        let medium = homogeneous(2.5);
        let w = SampledWavelengths::sample_visible(0.5);
        let optics = medium.optics().at(&w);
        let ray = Ray::infinite(Vec3A::ZERO, Vec3A::X);
        let n = 100_000;
        let mut rng = MediumRng::new(7);
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let mut first = 0.0;
            sample_t_maj(&medium, &optics, &ray, u, &mut rng, |c, _| {
                first = c.p.x;
                false
            });
            sum += first as f64;
        }
        let mean = sum / n as f64;
        assert!(
            (mean - 0.4).abs() < 2e-3,
            "mean free path {mean}, expected 0.4"
        );
    }
}
