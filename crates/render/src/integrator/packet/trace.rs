//! The packet tracer's loop over one film tile: `N` lanes, each following one camera path
//! of the tile with the scalar tracer's steps (`integrator::path::PathTracer::trace`, whose
//! comments explain them), and the two ray queries of each step — the extension ray and
//! the shadow ray — done for all lanes at once.

// Lanes index several arrays at once: `for l in 0..N` is the clearest form.
#![allow(clippy::needless_range_loop)]

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::Ray;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::intersect::{closest, occluded, RayLanes};
use super::{Kernel, PacketScene};
use crate::film::xyz::XyzWeights;
use crate::film::FilmTile;
use crate::film::SurfaceAov;
use crate::integrator::path::{mis_weight, FirstHit, PathCounters, PathTracer};
use crate::light::{LightHit, LightSampleContext};
use crate::material::Material;
use crate::sampler::{PixelSampler, SampleStream};
use crate::sampling::sample_cosine_hemisphere;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;

/// What the driver passes in and sums up: one tile's work.
pub(crate) struct TileJob<'a> {
    pub scene: &'a RenderScene,
    pub packet: &'a PacketScene,
    pub tracer: &'a PathTracer,
    pub sampler: &'a PixelSampler,
    /// Camera samples per pixel of the tile (from the `SamplePlan`).
    pub camera_samples: &'a dyn Fn(UVec2) -> u32,
    pub first_sample: u32,
    pub uses_lens: bool,
    pub want_illumination: bool,
}

/// Per-tile totals, as the driver's scalar loop counts them.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TileCounts {
    /// Camera rays generated.
    pub camera_rays: u64,
    pub samples: u64,
    pub non_finite_samples: u64,
}

/// A next-event estimate waiting for its shadow ray.
#[derive(Clone, Copy, Debug)]
struct PendingLight {
    /// β·f·L·w / p, with β and the first bounce's throughput as they were at the vertex
    /// (the path has moved on by the time the shadow ray is answered).
    contribution: SampledSpectrum,
    /// `contribution` over the first bounce's throughput, when the indirect light at the
    /// first hit is being recorded (illumination AOV).
    incident: Option<SampledSpectrum>,
    /// What a white Lambertian would receive (illumination AOV, depth 1 only).
    white: SampledSpectrum,
    record_white: bool,
}

/// One lane's camera sample and path state (the locals of the scalar `trace`).
#[derive(Clone, Copy, Debug)]
struct Lane {
    pixel: UVec2,
    film_point: Vec2,
    filter_weight: f32,
    stream: SampleStream,
    wavelengths: SampledWavelengths,
    radiance: SampledSpectrum,
    beta: SampledSpectrum,
    first_bounce_beta: Option<SampledSpectrum>,
    incident_after_first: SampledSpectrum,
    illumination_direct: Option<SampledSpectrum>,
    first_hit: Option<FirstHit>,
    direction: Vec3A,
    depth: u32,
    specular_bounce: bool,
    prev_ctx: LightSampleContext,
    prev_bsdf_pdf: f32,
    le_cache: SpectrumCache,
    reflectance_cache: SpectrumCache,
    pending: Option<PendingLight>,
    /// The path ends once its pending light sample is resolved.
    ends: bool,
}

/// Whether this CPU runs the 16-lane AVX-512 kernels.
pub(crate) fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512bw")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Renders every camera sample of `tile` (pixels in order, samples in order) with the
/// widest kernels this CPU runs; adds the path counters to `counters`.
pub(crate) fn render_tile(
    job: &TileJob,
    tile: &mut FilmTile,
    counters: &mut PathCounters,
) -> TileCounts {
    #[cfg(target_arch = "x86_64")]
    {
        let kernel = job.packet.kernel;
        if kernel == Kernel::Auto && has_avx512() {
            // SAFETY: the CPU reports AVX-512 F/DQ/VL/BW (`has_avx512`).
            return unsafe { render_tile_avx512(job, tile, counters) };
        }
        if matches!(kernel, Kernel::Auto | Kernel::Avx2) && has_avx2() {
            // SAFETY: the CPU reports AVX2 and FMA (`has_avx2`).
            return unsafe { render_tile_avx2(job, tile, counters) };
        }
    }
    render_tile_lanes::<8>(job, tile, counters)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw,avx2,fma")]
unsafe fn render_tile_avx512(
    job: &TileJob,
    tile: &mut FilmTile,
    counters: &mut PathCounters,
) -> TileCounts {
    render_tile_lanes::<16>(job, tile, counters)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn render_tile_avx2(
    job: &TileJob,
    tile: &mut FilmTile,
    counters: &mut PathCounters,
) -> TileCounts {
    render_tile_lanes::<8>(job, tile, counters)
}

/// The tile's camera samples in the scalar driver's order.
struct SampleQueue {
    pixels: Vec<UVec2>,
    next_pixel: usize,
    next_sample: u32,
    end_sample: u32,
    first_sample: u32,
}

impl SampleQueue {
    /// The next (pixel, sample index), pixels in order and each one's samples in order.
    fn next(&mut self, camera_samples: &dyn Fn(UVec2) -> u32) -> Option<(UVec2, u32)> {
        while self.next_sample >= self.end_sample {
            let &pixel = self.pixels.get(self.next_pixel)?;
            self.next_pixel += 1;
            self.next_sample = self.first_sample;
            self.end_sample = self.first_sample.saturating_add(camera_samples(pixel));
        }
        let s = self.next_sample;
        self.next_sample += 1;
        Some((self.pixels[self.next_pixel - 1], s))
    }
}

#[inline(always)]
fn render_tile_lanes<const N: usize>(
    job: &TileJob,
    tile: &mut FilmTile,
    counters: &mut PathCounters,
) -> TileCounts {
    let packet = job.packet;
    let mut counts = TileCounts::default();
    let mut queue = SampleQueue {
        pixels: tile.bounds().pixels().collect(),
        next_pixel: 0,
        next_sample: 0,
        end_sample: 0,
        first_sample: job.first_sample,
    };
    let mut lanes: [Option<Lane>; N] = [None; N];
    let mut rays = RayLanes::<N>::idle();
    let mut shadow = RayLanes::<N>::idle();
    let mut queue_empty = false;
    loop {
        // Fill idle lanes with the tile's next camera samples.
        for l in 0..N {
            while lanes[l].is_none() && !queue_empty {
                match queue.next(job.camera_samples) {
                    Some((pixel, s)) => {
                        if let Some((lane, ray)) = start_lane(job, tile, pixel, s, &mut counts) {
                            rays.set(l, ray.origin, ray.direction, ray.t_min, ray.t_max);
                            lanes[l] = Some(lane);
                        }
                    }
                    None => queue_empty = true,
                }
            }
        }
        if lanes.iter().all(Option::is_none) {
            break;
        }
        let (hit_t, hit_leaf) = closest(&packet.triangles, &packet.parallelograms, &rays);
        for l in 0..N {
            shadow.clear(l);
            let Some(lane) = &mut lanes[l] else {
                continue;
            };
            let origin = Vec3A::new(rays.o[0][l], rays.o[1][l], rays.o[2][l]);
            let next = scatter(
                job,
                lane,
                origin,
                hit_t[l],
                hit_leaf[l],
                &mut shadow,
                l,
                counters,
            );
            match next {
                Some(ray) => rays.set(l, ray.origin, ray.direction, ray.t_min, ray.t_max),
                None => {
                    lane.ends = true;
                    rays.clear(l);
                }
            }
        }
        let blocked = occluded(&packet.triangles, &packet.parallelograms, &shadow);
        for l in 0..N {
            let Some(lane) = &mut lanes[l] else {
                continue;
            };
            if let Some(p) = lane.pending.take() {
                if !blocked[l] {
                    // The scalar tracer's `add` of the light sample, with the vertex's β.
                    if p.contribution.has_non_finite() {
                        counters.non_finite_contributions += 1;
                    } else {
                        lane.radiance += p.contribution;
                        if let Some(incident) = p.incident {
                            lane.incident_after_first += incident;
                        }
                    }
                    if p.record_white {
                        lane.illumination_direct = Some(p.white);
                    }
                }
            }
            if lane.ends {
                finish_lane(job, tile, lane, &mut counts);
                lanes[l] = None;
            }
        }
    }
    counts
}

/// Draws the camera sample's film point, lens and wavelengths and its camera ray (the
/// scalar driver's order of dimensions); a sample without a ray goes to the film at once.
#[inline(always)]
fn start_lane(
    job: &TileJob,
    tile: &mut FilmTile,
    pixel: UVec2,
    s: u32,
    counts: &mut TileCounts,
) -> Option<(Lane, Ray)> {
    let mut stream = job.sampler.stream(pixel, s);
    let (film_point, filter_weight) = tile.sample_film_point(pixel, stream.get_2d());
    let lens_dimension = stream.reserve(2);
    let lens = if job.uses_lens {
        stream.get_2d_at(lens_dimension)
    } else {
        Vec2::ZERO
    };
    let wavelengths = SampledWavelengths::sample_visible(stream.get_1d());
    let zero = SampledSpectrum::splat(0.0);
    let mut lane = Lane {
        pixel,
        film_point,
        filter_weight,
        stream,
        wavelengths,
        radiance: zero,
        beta: SampledSpectrum::splat(1.0),
        first_bounce_beta: None,
        incident_after_first: zero,
        illumination_direct: None,
        first_hit: None,
        direction: Vec3A::ZERO,
        depth: 0,
        specular_bounce: true,
        prev_ctx: LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::ZERO,
        },
        prev_bsdf_pdf: 0.0,
        le_cache: SpectrumCache::new(),
        reflectance_cache: SpectrumCache::new(),
        pending: None,
        ends: false,
    };
    match job.scene.camera.generate_ray_only(film_point, lens) {
        Some(ray) => {
            counts.camera_rays += 1;
            lane.prev_ctx.p = ray.origin;
            lane.direction = ray.direction;
            Some((lane, ray))
        }
        None => {
            // No camera ray: a black sample with no AOV (the scalar driver's `None` arm).
            finish_lane(job, tile, &mut lane, counts);
            None
        }
    }
}

/// Adds β·x to the lane's radiance unless it is NaN/∞ (the scalar tracer's `add`).
#[inline(always)]
fn add(lane: &mut Lane, x: SampledSpectrum, count_incident: bool, counters: &mut PathCounters) {
    let c = lane.beta * x;
    if c.has_non_finite() {
        counters.non_finite_contributions += 1;
        return;
    }
    lane.radiance += c;
    if let (Some(b1), true) = (lane.first_bounce_beta, count_incident) {
        lane.incident_after_first += c.safe_div(b1);
    }
}

/// One path vertex after the closest-hit query: emission, next-event estimation (its
/// shadow ray into `shadow`, its contribution left pending), BSDF sampling and roulette.
/// Returns the next ray, or `None` when the path ends after the pending light sample.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn scatter<const N: usize>(
    job: &TileJob,
    lane: &mut Lane,
    origin: Vec3A,
    hit_t: f32,
    hit_leaf: u32,
    shadow: &mut RayLanes<N>,
    l: usize,
    counters: &mut PathCounters,
) -> Option<Ray> {
    let scene = job.scene;
    let tracer = job.tracer;
    let lights = &scene.lights;
    let direction = lane.direction;
    let wavelengths = lane.wavelengths;
    let Some(leaf) = job.packet.leaves.get(hit_leaf as usize) else {
        // Escaped: infinite lights.
        for &li in lights.infinite_lights() {
            let light = lights.light(li);
            let le = light.infinite_radiance(direction, &wavelengths);
            if le.is_black() {
                continue;
            }
            let w = if lane.specular_bounce {
                1.0
            } else {
                let light_pdf = lights.pmf(li) * light.pdf_li(&lane.prev_ctx, direction, None);
                mis_weight(tracer.mis, lane.prev_bsdf_pdf, light_pdf)
            };
            let count = lane.depth >= 2;
            add(lane, le * w, count, counters);
        }
        return None;
    };
    let p = origin + hit_t * direction;
    if lane.first_hit.is_none() {
        lane.first_hit = Some(FirstHit {
            t: hit_t,
            n_shading: leaf.n_shading,
            material_id: leaf.material_id,
        });
    }
    let dims = lane.stream.reserve(8);
    let (d_light_choice, d_light, d_bsdf, d_roulette) = (dims + 1, dims + 2, dims + 5, dims + 7);

    if let Some(li) = leaf.light {
        let light = lights.light(li);
        let light_hit = LightHit {
            p,
            n: leaf.n_geometric,
            uv: leaf.uv,
            distance_m: hit_t,
        };
        let le = light.emitted_radiance_cached(
            li,
            &light_hit,
            -direction,
            &wavelengths,
            &mut lane.le_cache,
        );
        if !le.is_black() {
            let w = if lane.specular_bounce {
                1.0
            } else {
                let light_pdf =
                    lights.pmf(li) * light.pdf_li(&lane.prev_ctx, direction, Some(&light_hit));
                mis_weight(tracer.mis, lane.prev_bsdf_pdf, light_pdf)
            };
            let count = lane.depth >= 2;
            add(lane, le * w, count, counters);
        }
    }
    if lane.depth == tracer.max_depth {
        return None;
    }
    lane.depth += 1;
    counters.bounces += 1;

    let Material::Lambert { reflectance } = scene.material(leaf.material_id) else {
        unreachable!("PacketScene::new admits constant Lambertian materials only");
    };
    let constant = reflectance
        .constant()
        .expect("PacketScene::new admits constant reflectances only");
    let f_lambert = lane
        .reflectance_cache
        .get(leaf.material_id, constant, &wavelengths)
        * std::f32::consts::FRAC_1_PI;
    let frame = leaf.frame;
    let wo_local = frame.to_local(-direction);
    let ctx = LightSampleContext {
        p,
        n: leaf.n_geometric,
    };

    // Next-event estimation (one light sample: `PacketScene` runs plans of one per hit).
    let record_white = job.want_illumination && lane.depth == 1;
    if !lights.is_empty() {
        let uc = lane
            .stream
            .get_1d_at(d_light_choice)
            .min(1.0 - f32::EPSILON);
        let ul = lane.stream.get_2d_at(d_light);
        if record_white {
            lane.illumination_direct = Some(SampledSpectrum::splat(0.0));
        }
        if let Some((li, pmf)) = lights.sample(uc) {
            let light = lights.light(li);
            if let Some(ls) = light.sample_li_cached(li, &ctx, ul, &wavelengths, &mut lane.le_cache)
            {
                if ls.pdf > 0.0 && !ls.radiance.is_black() {
                    let wi_local = frame.to_local(ls.wi);
                    let upper = wo_local.z > 0.0 && wi_local.z > 0.0;
                    let f = if upper {
                        f_lambert
                    } else {
                        SampledSpectrum::splat(0.0)
                    } * wi_local.z.abs();
                    let white_cos = if record_white {
                        wi_local.z.max(0.0) * std::f32::consts::FRAC_1_PI
                    } else {
                        0.0
                    };
                    if !(f.is_black() && white_cos <= 0.0) {
                        counters.rays += 1;
                        let shadow_ray = if ls.distance_m.is_finite() {
                            Ray::spawn_to(p, ls.p_light)
                        } else {
                            Ray::spawn(p, ls.wi)
                        };
                        shadow.set(
                            l,
                            shadow_ray.origin,
                            shadow_ray.direction,
                            shadow_ray.t_min,
                            shadow_ray.t_max,
                        );
                        let light_pdf = pmf * ls.pdf;
                        let w = if ls.delta {
                            1.0
                        } else {
                            let bsdf_pdf = if upper {
                                wi_local.z * std::f32::consts::FRAC_1_PI
                            } else {
                                0.0
                            };
                            mis_weight(tracer.mis, light_pdf, bsdf_pdf)
                        };
                        let contribution = lane.beta * (f * ls.radiance * (w / light_pdf));
                        lane.pending = Some(PendingLight {
                            contribution,
                            incident: lane.first_bounce_beta.map(|b1| contribution.safe_div(b1)),
                            white: ls.radiance * (white_cos / light_pdf),
                            record_white,
                        });
                    }
                }
            }
        }
    }

    // Continue by cosine-weighted sampling of the Lambertian lobe (`Lambert::sample`).
    if wo_local.z <= 0.0 {
        return None;
    }
    let wi = sample_cosine_hemisphere(lane.stream.get_2d_at(d_bsdf));
    let pdf = if wi.z > 0.0 {
        wi.z * std::f32::consts::FRAC_1_PI
    } else {
        0.0
    };
    if wi.z <= 0.0 || pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    let weight = f_lambert * (wi.z.abs() / pdf);
    let wi_world = frame.from_local(wi);
    if weight.is_black() || weight.has_non_finite() {
        if weight.has_non_finite() {
            counters.non_finite_contributions += 1;
        }
        return None;
    }
    lane.beta *= weight;
    if lane.depth == 1 && job.want_illumination {
        let white_weight = wi.z.max(0.0) * std::f32::consts::FRAC_1_PI / pdf;
        lane.first_bounce_beta = if white_weight <= 0.0 {
            None
        } else {
            Some(weight * (1.0 / white_weight.max(1e-20)))
        };
    }
    lane.specular_bounce = false;
    lane.prev_bsdf_pdf = pdf;
    lane.prev_ctx = ctx;
    let ray = Ray::spawn(p, wi_world.normalize());
    lane.direction = ray.direction;
    counters.rays += 1;

    if lane.depth >= tracer.rr_depth {
        let q = (1.0 - lane.beta.max_component()).max(0.0);
        if lane.stream.get_1d_at(d_roulette) < q {
            counters.roulette_terminations += 1;
            return None;
        }
        lane.beta *= 1.0 / (1.0 - q);
    }
    Some(ray)
}

/// The camera sample's value into the film (the scalar driver's steps after `radiance`).
#[inline(always)]
fn finish_lane(job: &TileJob, tile: &mut FilmTile, lane: &mut Lane, counts: &mut TileCounts) {
    let xyz_weights = XyzWeights::new(&lane.wavelengths);
    let illumination = lane.illumination_direct.map(|d| {
        if lane.first_bounce_beta.is_some() {
            d + lane.incident_after_first
        } else {
            d
        }
    });
    if let Some(white) = illumination {
        tile.add_illumination_with(lane.pixel, white, &xyz_weights);
    }
    let aov = lane.first_hit.map(|h| SurfaceAov {
        depth_m: h.t,
        normal: h.n_shading,
        albedo_rgb: job.scene.albedo(h.material_id),
    });
    if lane.radiance.has_non_finite() {
        counts.non_finite_samples += 1;
    }
    tile.add_sample_with(
        lane.pixel,
        lane.film_point,
        lane.radiance,
        &lane.wavelengths,
        &xyz_weights,
        lane.filter_weight,
        aov.as_ref(),
    );
    counts.samples += 1;
}
