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
use super::shade::{shade, VertexIn, VertexOut, LIGHT_GIVEN, LIGHT_NONE, LIGHT_RECTANGLE};
use super::{Kernel, PacketScene, REFLECTANCE_SLOTS};
use crate::cpu::{has_avx2, has_avx512};
use crate::film::xyz::XyzWeights;
use crate::film::FilmTile;
use crate::film::SurfaceAov;
use crate::integrator::path::{add_contribution, FirstHit, PathCounters, PathTracer};
use crate::light::{LightHit, LightSampleContext};
use crate::material::Material;
use crate::sampler::hash::u32_to_unit_f32;
use crate::sampler::independent;
use crate::sampler::{PixelSampler, SampleStream};
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

/// A next-event estimate waiting for its shadow ray, with the path's throughputs as they
/// were at the vertex (the path has moved on by the time the shadow ray is answered).
#[derive(Clone, Copy, Debug)]
struct PendingLight {
    /// f·L·w / p, added as β·direct (`path::add_contribution`).
    direct: SampledSpectrum,
    beta: SampledSpectrum,
    first_bounce_beta: Option<SampledSpectrum>,
    /// What a white Lambertian would receive (illumination AOV, depth 1 only).
    white: SampledSpectrum,
}

/// One lane's camera sample and path state (the locals of the scalar `trace`).
#[derive(Clone, Copy, Debug)]
struct Lane {
    pixel: UVec2,
    film_point: Vec2,
    filter_weight: f32,
    stream: SampleStream,
    wavelengths: SampledWavelengths,
    /// `PacketScene::reflectances` at the path's wavelengths.
    reflectance: [SampledSpectrum; REFLECTANCE_SLOTS],
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
    /// Geometric normal of the current vertex (for the next emission hit's MIS).
    n_geometric: Vec3A,
    pending: Option<PendingLight>,
    /// The path ends once its pending light sample is resolved.
    ends: bool,
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
    let mut vertex = VertexIn::<N>::new();
    let mut shaded = VertexOut::<N>::new();
    let mut variates = Variates::<N>::new();
    let mut starts = Starts::<N>::new();
    let mut queue_empty = false;
    loop {
        // Fill idle lanes with the tile's next camera samples.
        for l in 0..N {
            while lanes[l].is_none() && !queue_empty {
                match starts.next(job, tile, &mut queue) {
                    Some(start) => {
                        if let Some(ray) = start_lane(job, tile, start, &mut counts, &mut lanes[l])
                        {
                            rays.set(l, ray.origin, ray.direction, ray.t_min, ray.t_max);
                        }
                    }
                    None => queue_empty = true,
                }
            }
        }
        if lanes.iter().all(Option::is_none) {
            break;
        }
        let (hit_t, hit_leaf) = closest(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &rays,
        );
        for l in 0..N {
            shadow.clear(l);
            vertex.active[l] = false;
            if let Some(lane) = &mut lanes[l] {
                let origin = Vec3A::new(rays.o[0][l], rays.o[1][l], rays.o[2][l]);
                if !begin_vertex(
                    job,
                    lane,
                    origin,
                    hit_t[l],
                    hit_leaf[l],
                    &mut vertex,
                    &mut variates,
                    l,
                    counters,
                ) {
                    lane.ends = true;
                    rays.clear(l);
                }
            }
        }
        draw_variates(&mut variates);
        for l in 0..N {
            if let (Some(lane), true) = (&mut lanes[l], vertex.active[l]) {
                choose_light(job, lane, &mut vertex, &variates, l);
            }
        }
        shade(&vertex, job.tracer.mis, &mut shaded);
        for l in 0..N {
            let Some(lane) = &mut lanes[l] else {
                continue;
            };
            if !vertex.active[l] {
                continue;
            }
            match end_vertex(job, lane, &shaded, &mut shadow, l, counters) {
                Some((origin, direction, t_min)) => {
                    rays.set(l, origin, direction, t_min, f32::INFINITY)
                }
                None => {
                    lane.ends = true;
                    rays.clear(l);
                }
            }
        }
        let blocked = occluded(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &shadow,
        );
        for l in 0..N {
            let Some(lane) = &mut lanes[l] else {
                continue;
            };
            if let Some(p) = lane.pending.take() {
                if !blocked[l] {
                    add_contribution(
                        &mut lane.radiance,
                        &mut lane.incident_after_first,
                        &p.first_bounce_beta,
                        p.beta,
                        p.direct,
                        true,
                        counters,
                    );
                    // The vertex's depth: it changes only at the next vertex.
                    if job.want_illumination && lane.depth == 1 {
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

/// A camera sample's first draws: its stream, film point, lens variate and wavelengths.
#[derive(Clone, Copy, Debug)]
struct Start {
    pixel: UVec2,
    stream: SampleStream,
    film_point: Vec2,
    filter_weight: f32,
    lens: Vec2,
    wavelengths: SampledWavelengths,
    /// `PacketScene::reflectances` at the sample's wavelengths.
    reflectance: [SampledSpectrum; REFLECTANCE_SLOTS],
}

/// The tile's next camera samples, their first draws made `N` at a time (the scalar
/// driver's order of dimensions: filter 2, lens 2, wavelength 1), so that the wavelengths
/// are sampled in one vector loop (`SampledWavelengths::sample_visible_many`).
struct Starts<const N: usize> {
    ready: Vec<Start>,
    next: usize,
}

impl<const N: usize> Starts<N> {
    fn new() -> Self {
        Self {
            ready: Vec::with_capacity(N),
            next: 0,
        }
    }

    #[inline(always)]
    fn next(&mut self, job: &TileJob, tile: &FilmTile, queue: &mut SampleQueue) -> Option<Start> {
        if self.next == self.ready.len() {
            self.ready.clear();
            self.next = 0;
            let mut u = [0.5f32; N];
            while self.ready.len() < N {
                let Some((pixel, s)) = queue.next(job.camera_samples) else {
                    break;
                };
                let mut stream = job.sampler.stream(pixel, s);
                let (film_point, filter_weight) = tile.sample_film_point(pixel, stream.get_2d());
                let lens_dimension = stream.reserve(2);
                let lens = if job.uses_lens {
                    stream.get_2d_at(lens_dimension)
                } else {
                    Vec2::ZERO
                };
                u[self.ready.len()] = stream.get_1d();
                self.ready.push(Start {
                    pixel,
                    stream,
                    film_point,
                    filter_weight,
                    lens,
                    wavelengths: SampledWavelengths::new([0.0; 4], SampledSpectrum::splat(0.0)),
                    reflectance: [SampledSpectrum::splat(0.0); REFLECTANCE_SLOTS],
                });
            }
            let wavelengths = SampledWavelengths::sample_visible_many(&u);
            for (start, wl) in self.ready.iter_mut().zip(wavelengths) {
                start.wavelengths = wl;
            }
            for (slot, spectrum) in job.packet.reflectances.iter().enumerate() {
                let values = spectrum.eval_many(&wavelengths);
                for (start, v) in self.ready.iter_mut().zip(values) {
                    start.reflectance[slot] = v;
                }
            }
        }
        let start = self.ready.get(self.next).copied()?;
        self.next += 1;
        Some(start)
    }
}

/// Puts camera sample `start` into lane `slot` and returns its camera ray; a sample
/// without a ray goes to the film at once and leaves the slot empty. (Written in place: a
/// `Lane` is ≈ 500 bytes, and returning it by value cost two copies per camera sample.)
#[inline(always)]
fn start_lane(
    job: &TileJob,
    tile: &mut FilmTile,
    start: Start,
    counts: &mut TileCounts,
    slot: &mut Option<Lane>,
) -> Option<Ray> {
    let zero = SampledSpectrum::splat(0.0);
    let lane = slot.insert(Lane {
        pixel: start.pixel,
        film_point: start.film_point,
        filter_weight: start.filter_weight,
        stream: start.stream,
        wavelengths: start.wavelengths,
        reflectance: start.reflectance,
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
        n_geometric: Vec3A::ZERO,
        pending: None,
        ends: false,
    });
    match job
        .scene
        .camera
        .generate_ray_only(start.film_point, start.lens)
    {
        Some(ray) => {
            counts.camera_rays += 1;
            lane.prev_ctx.p = ray.origin;
            lane.direction = ray.direction;
            Some(ray)
        }
        None => {
            // No camera ray: a black sample with no AOV (the scalar driver's `None` arm).
            finish_lane(job, tile, lane, counts);
            *slot = None;
            None
        }
    }
}

/// Adds β·x to the lane's radiance (`path::add_contribution`).
#[inline(always)]
fn add(lane: &mut Lane, x: SampledSpectrum, count_incident: bool, counters: &mut PathCounters) {
    add_contribution(
        &mut lane.radiance,
        &mut lane.incident_after_first,
        &lane.first_bounce_beta,
        lane.beta,
        x,
        count_incident,
        counters,
    );
}

/// Offsets of a vertex's variates in its 8 reserved dimensions (`integrator::path` module
/// docs: mask 0, light choice 1, light position 2–3, lobe 4, direction 5–6, roulette 7).
const DIM_LIGHT_CHOICE: u32 = 1;
const DIM_LIGHT: u32 = 2;
const DIM_BSDF: u32 = 5;
const DIM_ROULETTE: u32 = 7;
/// The dimension offset of each entry of `Variates::u`.
const VARIATE_OFFSETS: [u32; 6] = [
    DIM_LIGHT_CHOICE,
    DIM_LIGHT,
    DIM_LIGHT + 1,
    DIM_BSDF,
    DIM_BSDF + 1,
    DIM_ROULETTE,
];

/// The variates of one vertex per lane: light choice, light position (2), BSDF direction
/// (2), roulette — the values `SampleStream::get_1d_at` gives at those dimensions.
struct Variates<const N: usize> {
    key: [u64; N],
    first_dimension: [u32; N],
    /// Independent stream: `u` is hashed from `key` by `draw_variates`; else drawn already.
    hashed: [bool; N],
    u: [[f32; N]; 6],
}

impl<const N: usize> Variates<N> {
    fn new() -> Self {
        Self {
            key: [0; N],
            first_dimension: [0; N],
            hashed: [false; N],
            u: [[0.0; N]; 6],
        }
    }
}

/// The independent sampler's values (`independent::value`, SplitMix64) for every hashed
/// lane at once: a loop over lanes of 64-bit multiplies, vector code with AVX-512.
#[inline(always)]
fn draw_variates<const N: usize>(v: &mut Variates<N>) {
    for (k, &offset) in VARIATE_OFFSETS.iter().enumerate() {
        for l in 0..N {
            let bits = independent::value(v.key[l], v.first_dimension[l] + offset);
            let u = u32_to_unit_f32(bits);
            v.u[k][l] = if v.hashed[l] { u } else { v.u[k][l] };
        }
    }
}

/// A vertex's light choice and, for lights that are not rectangles, its light sample by
/// the scalar `Light` code (after `draw_variates`).
#[inline(always)]
fn choose_light<const N: usize>(
    job: &TileJob,
    lane: &mut Lane,
    vertex: &mut VertexIn<N>,
    variates: &Variates<N>,
    l: usize,
) {
    let lights = &job.scene.lights;
    let u = &variates.u;
    for (k, row) in [(3, 0), (4, 1)] {
        vertex.u_bsdf[row][l] = u[k][l];
    }
    vertex.u_roulette[l] = if vertex.roulette[l] { u[5][l] } else { 1.0 };
    if lights.is_empty() {
        return;
    }
    let wavelengths = lane.wavelengths;
    let uc = u[0][l].min(1.0 - f32::EPSILON);
    let ul = glam::Vec2::new(u[1][l], u[2][l]);
    let Some((li, pmf)) = lights.sample(uc) else {
        return;
    };
    vertex.pmf[l] = pmf;
    vertex.u_light[0][l] = ul.x;
    vertex.u_light[1][l] = ul.y;
    match &job.packet.lights[li as usize] {
        Some(rect) => {
            let le = lane.le_cache.get(li, &rect.radiance, &wavelengths);
            for k in 0..4 {
                vertex.le[k][l] = le[k];
            }
            for a in 0..3 {
                vertex.rx[a][l] = rect.axes[0][a];
                vertex.ry[a][l] = rect.axes[1][a];
                vertex.rz[a][l] = rect.axes[2][a];
                vertex.rt[a][l] = rect.axes[3][a];
                vertex.rn[a][l] = rect.normal[a];
            }
            vertex.half_w[l] = rect.half_width_m;
            vertex.half_h[l] = rect.half_height_m;
            vertex.inv_area[l] = rect.inv_area_m2;
            vertex.two_sided[l] = rect.two_sided;
            vertex.light_kind[l] = LIGHT_RECTANGLE;
        }
        None => {
            let (o, d, t) = (vertex.o, vertex.d, vertex.t[l]);
            // The same bits as `shade`'s hit point.
            let p = Vec3A::new(
                o[0][l] + t * d[0][l],
                o[1][l] + t * d[1][l],
                o[2][l] + t * d[2][l],
            );
            let ctx = LightSampleContext {
                p,
                n: lane.n_geometric,
            };
            let light = lights.light(li);
            if let Some(ls) = light.sample_li_cached(li, &ctx, ul, &wavelengths, &mut lane.le_cache)
            {
                for k in 0..4 {
                    vertex.le[k][l] = ls.radiance[k];
                }
                for a in 0..3 {
                    vertex.given_p[a][l] = ls.p_light[a];
                    vertex.given_wi[a][l] = ls.wi[a];
                }
                vertex.given_pdf[l] = ls.pdf;
                vertex.given_distance[l] = ls.distance_m;
                vertex.given_delta[l] = ls.delta;
                vertex.light_kind[l] = LIGHT_GIVEN;
            }
        }
    }
}

/// A vertex's scalar part before the lanes are shaded together: the escape to infinite
/// lights, the first-hit record, emission, the depth limit, the vertex's sample dimensions,
/// the material's and light's spectra and the light choice (as the scalar tracer). Fills
/// lane `l` of `vertex`; `false` when the path ends here.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn begin_vertex<const N: usize>(
    job: &TileJob,
    lane: &mut Lane,
    origin: Vec3A,
    hit_t: f32,
    hit_leaf: u32,
    vertex: &mut VertexIn<N>,
    variates: &mut Variates<N>,
    l: usize,
    counters: &mut PathCounters,
) -> bool {
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
            let w = tracer.emission_weight(
                scene,
                li,
                lane.specular_bounce,
                &lane.prev_ctx,
                lane.prev_bsdf_pdf,
                direction,
                None,
            );
            let count = lane.depth >= 2;
            add(lane, le * w, count, counters);
        }
        return false;
    };
    // The same bits as `shade`'s hit point.
    let p = Vec3A::new(
        origin.x + hit_t * direction.x,
        origin.y + hit_t * direction.y,
        origin.z + hit_t * direction.z,
    );
    if lane.first_hit.is_none() {
        lane.first_hit = Some(FirstHit {
            t: hit_t,
            n_shading: leaf.n_shading,
            material_id: leaf.material_id,
        });
    }
    let dims = lane.stream.reserve(8);
    let (d_light_choice, d_light, d_bsdf, d_roulette) = (
        dims + DIM_LIGHT_CHOICE,
        dims + DIM_LIGHT,
        dims + DIM_BSDF,
        dims + DIM_ROULETTE,
    );

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
            let w = tracer.emission_weight(
                scene,
                li,
                lane.specular_bounce,
                &lane.prev_ctx,
                lane.prev_bsdf_pdf,
                direction,
                Some(&light_hit),
            );
            let count = lane.depth >= 2;
            add(lane, le * w, count, counters);
        }
    }
    if lane.depth == tracer.max_depth {
        return false;
    }
    lane.depth += 1;
    counters.bounces += 1;
    lane.n_geometric = leaf.n_geometric;

    let Material::Lambert { reflectance } = scene.material(leaf.material_id) else {
        unreachable!("PacketScene::new admits constant Lambertian materials only");
    };
    let constant = reflectance
        .constant()
        .expect("PacketScene::new admits constant reflectances only");
    let reflectance = match leaf.reflectance_slot {
        Some(slot) => lane.reflectance[slot],
        None => lane
            .reflectance_cache
            .get(leaf.material_id, constant, &wavelengths),
    };
    let f_lambert = reflectance * std::f32::consts::FRAC_1_PI;
    let frame = leaf.frame;
    for a in 0..3 {
        vertex.o[a][l] = origin[a];
        vertex.d[a][l] = direction[a];
        vertex.fx[a][l] = frame.x[a];
        vertex.fy[a][l] = frame.y[a];
        vertex.fz[a][l] = frame.z[a];
    }
    vertex.t[l] = hit_t;
    for k in 0..4 {
        vertex.beta[k][l] = lane.beta[k];
        vertex.f_lambert[k][l] = f_lambert[k];
    }
    vertex.roulette[l] = lane.depth >= tracer.rr_depth;
    let record_white = job.want_illumination && lane.depth == 1;
    vertex.record_white[l] = record_white;
    vertex.light_kind[l] = LIGHT_NONE;
    if !lights.is_empty() && record_white {
        lane.illumination_direct = Some(SampledSpectrum::splat(0.0));
    }
    // The vertex's variates: hashed for all lanes at once (`draw_variates`) for
    // independent streams, here for the others.
    variates.first_dimension[l] = dims;
    match lane.stream.independent_key() {
        Some(key) => {
            variates.key[l] = key;
            variates.hashed[l] = true;
        }
        None => {
            variates.hashed[l] = false;
            let u = &mut variates.u;
            u[0][l] = lane.stream.get_1d_at(d_light_choice);
            let ul = lane.stream.get_2d_at(d_light);
            (u[1][l], u[2][l]) = (ul.x, ul.y);
            let ub = lane.stream.get_2d_at(d_bsdf);
            (u[3][l], u[4][l]) = (ub.x, ub.y);
            u[5][l] = lane.stream.get_1d_at(d_roulette);
        }
    }
    vertex.active[l] = true;
    true
}

/// A vertex's scalar part after the lanes were shaded: its shadow ray and pending light
/// contribution, the path's new state, statistics. The next ray (origin, unit direction,
/// t_min), or `None` when the path ends after the pending light sample.
#[inline(always)]
fn end_vertex<const N: usize>(
    job: &TileJob,
    lane: &mut Lane,
    out: &VertexOut<N>,
    shadow: &mut RayLanes<N>,
    l: usize,
    counters: &mut PathCounters,
) -> Option<(Vec3A, Vec3A, f32)> {
    let p = Vec3A::new(out.p[0][l], out.p[1][l], out.p[2][l]);
    let spectrum = |a: &[[f32; N]; 4]| SampledSpectrum::from([a[0][l], a[1][l], a[2][l], a[3][l]]);
    if out.has_shadow[l] {
        counters.rays += 1;
        let d = Vec3A::new(out.shadow_d[0][l], out.shadow_d[1][l], out.shadow_d[2][l]);
        shadow.set(l, p, d, out.shadow_t_min[l], out.shadow_t_max[l]);
        lane.pending = Some(PendingLight {
            direct: spectrum(&out.direct),
            beta: lane.beta,
            first_bounce_beta: lane.first_bounce_beta,
            white: spectrum(&out.white),
        });
    }
    if out.weight_non_finite[l] {
        counters.non_finite_contributions += 1;
    }
    let goes_on = out.continues[l] || out.killed_by_roulette[l];
    if !goes_on {
        return None;
    }
    if lane.depth == 1 && job.want_illumination {
        let white_weight = out.wi_z[l].max(0.0) * std::f32::consts::FRAC_1_PI / out.pdf[l];
        lane.first_bounce_beta = if white_weight <= 0.0 {
            None
        } else {
            Some(spectrum(&out.weight) * (1.0 / white_weight.max(1e-20)))
        };
    }
    lane.specular_bounce = false;
    lane.prev_bsdf_pdf = out.pdf[l];
    lane.prev_ctx = LightSampleContext {
        p,
        n: lane.n_geometric,
    };
    counters.rays += 1;
    if out.killed_by_roulette[l] {
        counters.roulette_terminations += 1;
        return None;
    }
    lane.beta = spectrum(&out.beta);
    let direction = Vec3A::new(out.next_d[0][l], out.next_d[1][l], out.next_d[2][l]);
    lane.direction = direction;
    Some((p, direction, out.next_t_min[l]))
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
