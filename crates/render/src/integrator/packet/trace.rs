//! The packet tracer's loop over one film tile: `N` lanes, each following one camera path
//! of the tile with the scalar tracer's steps (`integrator::path::PathTracer::trace`, whose
//! comments explain them). The paths' state is a structure of arrays (`Paths`), so that
//! each step — the two ray queries, the vertex's bookkeeping, the light choice, the
//! shading, the light sample's resolution — is one pass over the lanes that LLVM turns
//! into vector code; what only some paths meet (an emitter hit, an escape to infinite
//! lights, a light the scalar `Light` code samples, a material past the reflectance slots)
//! runs lane by lane inside those passes. The samplers' draws are passes too: independent
//! values and Sobol points for all lanes at once (`sampler::StreamLanes`).

// Lanes index several arrays at once: `for l in 0..N` is the clearest form.
#![allow(clippy::needless_range_loop)]

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::Ray;
use prism_spectrum::WavelengthDensity;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::intersect::{closest, occluded, RayLanes};
use super::shade::{select, shade, VertexIn, VertexOut, LIGHT_GIVEN, LIGHT_NONE, LIGHT_RECTANGLE};
use super::{PacketScene, RectangleLight, LIGHT_SLOTS, REFLECTANCE_SLOTS};
use crate::film::FilmTile;
use crate::film::SurfaceAov;
use crate::integrator::dimensions::{
    VertexDimensions, CAMERA_SAMPLE_DIMENSIONS, FILM_DIMENSION, LENS_DIMENSION,
    WAVELENGTH_DIMENSION,
};
use crate::integrator::path::{add_contribution, FirstHit, PathCounters, PathTracer};
use crate::light::{LightHit, LightSampleContext};
use crate::material::{Material, SurfaceMaterial};
use crate::sampler::{PixelSampler, SampleStream, SamplerKind, StreamLanes};
use crate::scene_build::RenderScene;
use crate::spectrum_cache::SpectrumCache;
use prism_spectrum::XyzWeights;

/// What the driver passes in and sums up: one tile's work.
pub(crate) struct TileJob<'a> {
    pub scene: &'a RenderScene,
    pub packet: &'a PacketScene,
    pub tracer: &'a PathTracer,
    pub sampler: &'a PixelSampler,
    /// Camera samples per pixel of the tile (from the `SamplePlan`).
    pub camera_samples: &'a dyn Fn(UVec2) -> u32,
    /// Index of each pixel's first sample in this pass.
    pub first_sample: &'a dyn Fn(UVec2) -> u32,
    pub uses_lens: bool,
    pub want_illumination: bool,
    /// The tile's (`FilmTile::wavelength_density`).
    pub wavelength_density: WavelengthDensity,
}

/// Per-tile totals, as the driver's scalar loop counts them.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TileCounts {
    /// Camera rays generated.
    pub camera_rays: u64,
    pub samples: u64,
    pub non_finite_samples: u64,
}

/// Renders every camera sample of `tile` (pixels in order, samples in order) with the
/// kernels of the packet scene's ISA (`PacketScene::simd`); adds the path counters to
/// `counters`.
pub(crate) fn render_tile(
    job: &TileJob,
    tile: &mut FilmTile,
    counters: &mut PathCounters,
) -> TileCounts {
    #[cfg(target_arch = "x86_64")]
    {
        let simd = job.packet.simd;
        if simd.avx512() {
            // SAFETY: a `Simd` allows AVX-512 F/DQ/VL/BW (with AVX2 and FMA) only on a CPU
            // that has them.
            return unsafe { render_tile_avx512(job, tile, counters) };
        }
        if simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
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
}

impl SampleQueue {
    /// The next (pixel, sample index), pixels in order and each one's samples in order.
    fn next(
        &mut self,
        camera_samples: &dyn Fn(UVec2) -> u32,
        first_sample: &dyn Fn(UVec2) -> u32,
    ) -> Option<(UVec2, u32)> {
        while self.next_sample >= self.end_sample {
            let &pixel = self.pixels.get(self.next_pixel)?;
            self.next_pixel += 1;
            self.next_sample = first_sample(pixel);
            self.end_sample = self.next_sample.saturating_add(camera_samples(pixel));
        }
        let s = self.next_sample;
        self.next_sample += 1;
        Some((self.pixels[self.next_pixel - 1], s))
    }
}

/// A lane's camera sample and what only a path's start, its end and the rarer events
/// touch (the hot path state is in `Paths`).
#[derive(Clone, Copy, Debug)]
struct LaneSample {
    pixel: UVec2,
    film_point: Vec2,
    filter_weight: f32,
    wavelengths: SampledWavelengths,
    first_hit: Option<FirstHit>,
    le_cache: SpectrumCache,
    reflectance_cache: SpectrumCache,
}

/// The path state of every lane, structure of arrays (the locals of the scalar `trace`):
/// each step of the loop is one pass over the lanes. Every field is 4 bytes per lane and
/// the flags live apart (`PathFlags`): LLVM proves arrays of one stride in one object
/// independent, while mixed strides would need run-time overlap checks, too many of which
/// make it leave a loop scalar.
struct Paths<const N: usize> {
    depth: [u32; N],
    /// The stream's next dimension (`SampleStream::reserve`, kept here for all lanes).
    dimension: [u32; N],
    /// `PacketScene::reflectances` and `PacketScene::light_radiances` at the path's
    /// wavelengths.
    reflectance: [[[f32; N]; 4]; REFLECTANCE_SLOTS],
    light_le: [[[f32; N]; 4]; LIGHT_SLOTS],
    radiance: [[f32; N]; 4],
    beta: [[f32; N]; 4],
    /// β after the first bounce divided by a white Lambertian's (illumination AOV), where
    /// `PathFlags::has_first_beta`.
    first_beta: [[f32; N]; 4],
    incident_after_first: [[f32; N]; 4],
    illumination_direct: [[f32; N]; 4],
    prev_p: [[f32; N]; 3],
    prev_n: [[f32; N]; 3],
    prev_bsdf_pdf: [f32; N],
    /// Geometric normal of the current vertex (for the next emission hit's MIS).
    n_geometric: [[f32; N]; 3],
    /// A light sample waiting for its shadow ray, as `path::add_contribution`'s terms at
    /// the vertex's throughputs (the path has moved on when the ray is answered): β·direct
    /// and its part of the incident light after the first bounce; and what a white
    /// Lambertian would receive.
    pending_c: [[f32; N]; 4],
    pending_incident: [[f32; N]; 4],
    pending_white: [[f32; N]; 4],
}

/// The paths' flags (see `Paths`).
struct PathFlags<const N: usize> {
    /// The lane follows a path (its `LaneSample` is set).
    live: [bool; N],
    /// The path ends once its pending light sample is resolved.
    ends: [bool; N],
    has_first_beta: [bool; N],
    has_illumination: [bool; N],
    specular_bounce: [bool; N],
    /// A light sample waits for its shadow ray; whether its incident part counts; whether
    /// β·direct is non-finite.
    pending: [bool; N],
    pending_counts_incident: [bool; N],
    pending_non_finite: [bool; N],
}

#[inline(always)]
fn spectrum_at<const N: usize>(a: &[[f32; N]; 4], l: usize) -> SampledSpectrum {
    SampledSpectrum::new([a[0][l], a[1][l], a[2][l], a[3][l]])
}

#[inline(always)]
fn set_spectrum<const N: usize>(a: &mut [[f32; N]; 4], l: usize, s: SampledSpectrum) {
    for k in 0..4 {
        a[k][l] = s[k];
    }
}

#[inline(always)]
fn vec_at<const N: usize>(a: &[[f32; N]; 3], l: usize) -> Vec3A {
    Vec3A::new(a[0][l], a[1][l], a[2][l])
}

impl<const N: usize> Paths<N> {
    fn new() -> Self {
        let z = [0.0f32; N];
        Self {
            depth: [0; N],
            dimension: [0; N],
            reflectance: [[z; 4]; REFLECTANCE_SLOTS],
            light_le: [[z; 4]; LIGHT_SLOTS],
            radiance: [z; 4],
            beta: [z; 4],
            first_beta: [z; 4],
            incident_after_first: [z; 4],
            illumination_direct: [z; 4],
            prev_p: [z; 3],
            prev_n: [z; 3],
            prev_bsdf_pdf: z,
            n_geometric: [z; 3],
            pending_c: [z; 4],
            pending_incident: [z; 4],
            pending_white: [z; 4],
        }
    }

    /// Adds β·x to lane `l`'s radiance (`path::add_contribution`).
    #[inline(always)]
    fn add(
        &mut self,
        flags: &PathFlags<N>,
        l: usize,
        x: SampledSpectrum,
        count_incident: bool,
        counters: &mut PathCounters,
    ) {
        let mut radiance = spectrum_at(&self.radiance, l);
        let mut incident = spectrum_at(&self.incident_after_first, l);
        let first = flags.has_first_beta[l].then(|| spectrum_at(&self.first_beta, l));
        let beta = spectrum_at(&self.beta, l);
        add_contribution(
            &mut radiance,
            &mut incident,
            &first,
            beta,
            x,
            count_incident,
            counters,
        );
        set_spectrum(&mut self.radiance, l, radiance);
        set_spectrum(&mut self.incident_after_first, l, incident);
    }

    /// The previous vertex of lane `l` (for the MIS weight of an emission hit).
    #[inline(always)]
    fn prev_ctx(&self, l: usize) -> LightSampleContext {
        LightSampleContext {
            p: vec_at(&self.prev_p, l),
            n: vec_at(&self.prev_n, l),
        }
    }
}

impl<const N: usize> PathFlags<N> {
    fn new() -> Self {
        Self {
            live: [false; N],
            ends: [false; N],
            has_first_beta: [false; N],
            has_illumination: [false; N],
            specular_bounce: [false; N],
            pending: [false; N],
            pending_counts_incident: [false; N],
            pending_non_finite: [false; N],
        }
    }
}

/// Reflectance slot of a lane whose material has none (`LeafShading::reflectance_slot`).
const NO_SLOT: u8 = u8::MAX;

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
    };
    // Separate locals, not one struct: LLVM keeps each one its own object (see `Paths`).
    let mut samples: [Option<LaneSample>; N] = [None; N];
    let mut paths = Paths::<N>::new();
    let mut flags = PathFlags::<N>::new();
    let mut rays = RayLanes::<N>::idle();
    let mut shadow = RayLanes::<N>::idle();
    let mut vertex = VertexIn::<N>::new();
    let mut shaded = VertexOut::<N>::new();
    let mut variates = Variates::<N>::new();
    let mut starts = Starts::<N>::new();
    // The light whose rectangle fields lane l of `vertex` holds.
    let mut rectangle_in_lane = [u32::MAX; N];
    let mut queue_empty = false;
    loop {
        // Fill idle lanes with the tile's next camera samples.
        for l in 0..N {
            while !flags.live[l] && !queue_empty {
                match starts.next(job, tile, &mut queue) {
                    Some(start) => {
                        let Some(ray) = start_lane(job, tile, &start, &mut counts, &mut samples[l])
                        else {
                            continue;
                        };
                        start_path(&mut paths, &mut flags, &mut variates, l, &start, ray.origin);
                        rays.set(l, ray.origin, ray.direction, ray.t_min, ray.t_max);
                    }
                    None => queue_empty = true,
                }
            }
        }
        if !flags.live.iter().any(|&live| live) {
            break;
        }
        let (hit_t, hit_leaf) = closest(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &rays,
        );
        begin_vertices(
            job,
            &mut paths,
            &mut flags,
            &mut samples,
            &rays,
            &hit_t,
            &hit_leaf,
            &mut vertex,
            &mut variates,
            counters,
        );
        draw_variates(job, &mut variates, &vertex, &samples);
        choose_lights(
            job,
            &paths,
            &mut samples,
            &mut vertex,
            &variates,
            &mut rectangle_in_lane,
        );
        shade(&vertex, job.tracer.mis, &mut shaded);
        end_vertices(
            job,
            &mut paths,
            &mut flags,
            &vertex,
            &shaded,
            &mut rays,
            &mut shadow,
            counters,
        );
        let blocked = occluded(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &shadow,
        );
        resolve_light_samples(job, &mut paths, &mut flags, &blocked, counters);
        for l in 0..N {
            if flags.ends[l] {
                flags.live[l] = false;
                flags.ends[l] = false;
                finish_lane(job, tile, &paths, &flags, &mut samples[l], l, &mut counts);
            }
        }
    }
    counts
}

/// A camera sample's first draws: its stream, film point, wavelengths and camera ray.
#[derive(Clone, Copy, Debug)]
struct Start {
    pixel: UVec2,
    stream: SampleStream,
    film_point: Vec2,
    filter_weight: f32,
    wavelengths: SampledWavelengths,
    /// `PacketScene::reflectances` and `PacketScene::light_radiances` at the sample's
    /// wavelengths.
    reflectance: [SampledSpectrum; REFLECTANCE_SLOTS],
    light_le: [SampledSpectrum; LIGHT_SLOTS],
    /// The camera ray (`Camera::generate_ray_only`), `None` where the film point has none.
    ray: Option<Ray>,
}

/// The tile's next camera samples, their first draws made `N` at a time (the scalar
/// driver's order of dimensions: filter 2, lens 2, wavelength 1), so that the wavelengths
/// are sampled and the camera rays made in vector loops
/// (`WavelengthDensity::sample_many`, `Camera::generate_rays_only_many`).
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
            let mut film_points = [Vec2::ZERO; N];
            let mut lens_samples = [Vec2::ZERO; N];
            let zero = SampledSpectrum::splat(0.0);
            // The streams first, then their film, lens and wavelength draws for all lanes
            // at once (`StreamLanes`, the values of `get_2d`, `get_2d_at` and `get_1d`).
            let mut lanes = StreamLanes::<N>::new();
            let mut taken = [(UVec2::ZERO, None); N];
            let mut count = 0;
            while count < N {
                let Some((pixel, s)) = queue.next(job.camera_samples, job.first_sample) else {
                    break;
                };
                let mut stream = job.sampler.stream(pixel, s);
                lanes.set(count, &stream);
                stream.reserve(CAMERA_SAMPLE_DIMENSIONS);
                taken[count] = (pixel, Some(stream));
                count += 1;
            }
            let (film_x, film_y) = lanes.get_2d_at(&[FILM_DIMENSION; N]);
            let (lens_x, lens_y) = if job.uses_lens {
                lanes.get_2d_at(&[LENS_DIMENSION; N])
            } else {
                ([0.0; N], [0.0; N])
            };
            let wavelength_u = lanes.get_1d_at(&[WAVELENGTH_DIMENSION; N]);
            for (k, &(pixel, stream)) in taken[..count].iter().enumerate() {
                let Some(stream) = stream else { continue };
                let (film_point, filter_weight) =
                    tile.sample_film_point(pixel, Vec2::new(film_x[k], film_y[k]));
                u[k] = wavelength_u[k];
                (film_points[k], lens_samples[k]) = (film_point, Vec2::new(lens_x[k], lens_y[k]));
                self.ready.push(Start {
                    pixel,
                    stream,
                    film_point,
                    filter_weight,
                    wavelengths: SampledWavelengths::new([0.0; 4], zero),
                    reflectance: [zero; REFLECTANCE_SLOTS],
                    light_le: [zero; LIGHT_SLOTS],
                    ray: None,
                });
            }
            let camera = &job.scene.camera;
            let rays = camera.generate_rays_only_many(&film_points, &lens_samples);
            for (start, ray) in self.ready.iter_mut().zip(rays) {
                start.ray = ray;
            }
            let wavelengths = job.wavelength_density.sample_many(&u);
            for (start, wl) in self.ready.iter_mut().zip(wavelengths) {
                start.wavelengths = wl;
            }
            for (slot, spectrum) in job.packet.reflectances.iter().enumerate() {
                let values = spectrum.eval_many(&wavelengths);
                for (start, v) in self.ready.iter_mut().zip(values) {
                    start.reflectance[slot] = v;
                }
            }
            for (slot, spectrum) in job.packet.light_radiances.iter().enumerate() {
                let values = spectrum.eval_many(&wavelengths);
                for (start, v) in self.ready.iter_mut().zip(values) {
                    start.light_le[slot] = v;
                }
            }
        }
        let start = self.ready.get(self.next).copied()?;
        self.next += 1;
        Some(start)
    }
}

/// Camera sample `start`'s record for lane `slot` and its camera ray; a sample without a
/// ray goes to the film at once and leaves the lane idle (`None`).
#[inline(always)]
fn start_lane(
    job: &TileJob,
    tile: &mut FilmTile,
    start: &Start,
    counts: &mut TileCounts,
    slot: &mut Option<LaneSample>,
) -> Option<Ray> {
    let lane_sample = LaneSample {
        pixel: start.pixel,
        film_point: start.film_point,
        filter_weight: start.filter_weight,
        wavelengths: start.wavelengths,
        first_hit: None,
        le_cache: SpectrumCache::new(),
        reflectance_cache: SpectrumCache::new(),
    };
    match start.ray {
        Some(ray) => {
            counts.camera_rays += 1;
            *slot = Some(lane_sample);
            Some(ray)
        }
        None => {
            // No camera ray: a black sample with no AOV (the scalar driver's `None` arm).
            let black = SampledSpectrum::splat(0.0);
            write_sample(job, tile, &lane_sample, black, None, counts);
            None
        }
    }
}

/// Lane `l` starts the path of `start` from the camera ray's origin.
#[inline(always)]
fn start_path<const N: usize>(
    paths: &mut Paths<N>,
    flags: &mut PathFlags<N>,
    variates: &mut Variates<N>,
    l: usize,
    start: &Start,
    origin: Vec3A,
) {
    flags.live[l] = true;
    flags.ends[l] = false;
    flags.has_first_beta[l] = false;
    flags.has_illumination[l] = false;
    flags.specular_bounce[l] = true;
    flags.pending[l] = false;
    paths.depth[l] = 0;
    paths.dimension[l] = start.stream.dimension();
    variates.hashed[l] = start.stream.kind() == SamplerKind::Independent;
    variates.lanes.set(l, &start.stream);
    for (slot, r) in start.reflectance.iter().enumerate() {
        set_spectrum(&mut paths.reflectance[slot], l, *r);
    }
    for (slot, le) in start.light_le.iter().enumerate() {
        set_spectrum(&mut paths.light_le[slot], l, *le);
    }
    for k in 0..4 {
        paths.radiance[k][l] = 0.0;
        paths.beta[k][l] = 1.0;
        paths.incident_after_first[k][l] = 0.0;
    }
    for a in 0..3 {
        paths.prev_p[a][l] = origin[a];
        paths.prev_n[a][l] = 0.0;
    }
    paths.prev_bsdf_pdf[l] = 0.0;
}

/// The dimension offset of each entry of `Variates::u` within a vertex's block
/// (`dimensions::VertexDimensions`).
const VARIATE_OFFSETS: [u32; 6] = [
    VertexDimensions::LIGHT_CHOICE,
    VertexDimensions::LIGHT,
    VertexDimensions::LIGHT + 1,
    VertexDimensions::BSDF,
    VertexDimensions::BSDF + 1,
    VertexDimensions::ROULETTE,
];

/// The variates of one vertex per lane: light choice, light position (2), BSDF direction
/// (2), roulette — the values `SampleStream::get_1d_at` gives at those dimensions.
struct Variates<const N: usize> {
    first_dimension: [u32; N],
    /// Independent stream: `u` is its hashes alone (`StreamLanes::independent_1d_at`);
    /// else the stream's Sobol or independent values (`StreamLanes::get_1d_at`).
    hashed: [bool; N],
    /// Every lane's stream.
    lanes: StreamLanes<N>,
    u: [[f32; N]; 6],
}

impl<const N: usize> Variates<N> {
    fn new() -> Self {
        Self {
            first_dimension: [0; N],
            hashed: [false; N],
            lanes: StreamLanes::new(),
            u: [[0.0; N]; 6],
        }
    }
}

/// The vertex's variates (after `begin_vertices`): the independent sampler's values
/// (`independent::value`, SplitMix64) for all lanes at once — a loop over lanes of 64-bit
/// multiplies, vector code with AVX-512 — then those of other streams (Sobol), again for all
/// lanes at once (`StreamLanes`); each part only where some lane needs it. The
/// light choice's is skipped where a scene has one light (never read), the roulette's
/// where no lane has reached `rr_depth` (read only there).
#[inline(always)]
fn draw_variates<const N: usize>(
    job: &TileJob,
    v: &mut Variates<N>,
    vertex: &VertexIn<N>,
    samples: &[Option<LaneSample>; N],
) {
    let mut roulette = false;
    for l in 0..N {
        roulette |= vertex.active[l] & vertex.roulette[l];
    }
    let needed = [job.scene.lights.len() > 1, true, true, true, true, roulette];
    let any_hashed = v.hashed.contains(&true);
    for (k, &offset) in VARIATE_OFFSETS.iter().enumerate() {
        if !(needed[k] && any_hashed) {
            continue;
        }
        v.u[k] = v
            .lanes
            .independent_1d_at(&std::array::from_fn(|l| v.first_dimension[l] + offset));
    }
    // Other streams (Sobol): all lanes at once (`StreamLanes`), the same values as each
    // stream's `get_1d_at`/`get_2d_at`; lanes that hashed above keep theirs.
    let mut drawn = [false; N];
    for l in 0..N {
        drawn[l] = vertex.active[l] & !v.hashed[l] & samples[l].is_some();
    }
    if !drawn.contains(&true) {
        return;
    }
    let at = |offset: u32| -> [u32; N] { std::array::from_fn(|l| v.first_dimension[l] + offset) };
    let put = |k: usize, values: [f32; N], u: &mut [[f32; N]; 6]| {
        for l in 0..N {
            if drawn[l] {
                u[k][l] = values[l];
            }
        }
    };
    if needed[0] {
        put(
            0,
            v.lanes.get_1d_at(&at(VertexDimensions::LIGHT_CHOICE)),
            &mut v.u,
        );
    }
    let (x, y) = v.lanes.get_2d_at(&at(VertexDimensions::LIGHT));
    put(1, x, &mut v.u);
    put(2, y, &mut v.u);
    let (x, y) = v.lanes.get_2d_at(&at(VertexDimensions::BSDF));
    put(3, x, &mut v.u);
    put(4, y, &mut v.u);
    if needed[5] {
        put(
            5,
            v.lanes.get_1d_at(&at(VertexDimensions::ROULETTE)),
            &mut v.u,
        );
    }
}

/// What each lane's ray found, before the lanes are shaded together (the scalar tracer's
/// steps): the escape to infinite lights, the first-hit record, emission, the depth
/// limit, then the vertex's patch, reflectance, sample dimensions and flags into `vertex`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn begin_vertices<const N: usize>(
    job: &TileJob,
    paths: &mut Paths<N>,
    flags: &mut PathFlags<N>,
    samples: &mut [Option<LaneSample>; N],
    rays: &RayLanes<N>,
    hit_t: &[f32; N],
    hit_leaf: &[u32; N],
    vertex: &mut VertexIn<N>,
    variates: &mut Variates<N>,
    counters: &mut PathCounters,
) {
    let scene = job.scene;
    let tracer = job.tracer;
    let lights = &scene.lights;
    let leaves = &job.packet.leaves;
    // Locals, so that the vector passes below read no flag of an object they write.
    let mut active = [false; N];
    let mut slot = [NO_SLOT; N];
    let mut material = [0u32; N];
    // Lane by lane: the events only some lanes meet, and the patch's constants.
    for l in 0..N {
        let (true, Some(sample)) = (flags.live[l], &mut samples[l]) else {
            continue;
        };
        let direction = vec_at(&rays.d, l);
        let Some(leaf) = leaves.get(hit_leaf[l] as usize) else {
            escape(job, paths, flags, sample, l, direction, counters);
            flags.ends[l] = true;
            continue;
        };
        if paths.depth[l] == 0 {
            sample.first_hit = Some(FirstHit {
                t: hit_t[l],
                n_shading: leaf.n_shading,
                material_id: leaf.material_id,
            });
        }
        if let Some(li) = leaf.light {
            // The same bits as `shade`'s hit point.
            let o = vec_at(&rays.o, l);
            let t = hit_t[l];
            let light_hit = LightHit {
                p: Vec3A::new(
                    o.x + t * direction.x,
                    o.y + t * direction.y,
                    o.z + t * direction.z,
                ),
                n: leaf.n_geometric,
                uv: leaf.uv,
                distance_m: t,
            };
            let hit = (li, &light_hit, direction);
            emission(job, paths, flags, sample, l, hit, counters);
        }
        if paths.depth[l] == tracer.max_depth {
            flags.ends[l] = true;
            continue;
        }
        active[l] = true;
        let frame = leaf.frame;
        for a in 0..3 {
            vertex.fx[a][l] = frame.x[a];
            vertex.fy[a][l] = frame.y[a];
            vertex.fz[a][l] = frame.z[a];
            paths.n_geometric[a][l] = leaf.n_geometric[a];
        }
        slot[l] = leaf.reflectance_slot.map_or(NO_SLOT, |s| s as u8);
        material[l] = leaf.material_id;
    }
    // All lanes at once: depth, sample dimensions, the ray, β and R(λ)/π; at the first
    // bounce the illumination AOV's direct part starts.
    let want_white = job.want_illumination && !lights.is_empty();
    let mut bounces = 0u32;
    for l in 0..N {
        let depth = paths.depth[l] + active[l] as u32;
        paths.depth[l] = depth;
        let clear_white = active[l] && want_white && depth == 1;
        bounces += active[l] as u32;
        variates.first_dimension[l] = paths.dimension[l];
        paths.dimension[l] += if active[l] {
            VertexDimensions::COUNT
        } else {
            0
        };
        vertex.t[l] = hit_t[l];
        for a in 0..3 {
            vertex.o[a][l] = rays.o[a][l];
            vertex.d[a][l] = rays.d[a][l];
        }
        for k in 0..4 {
            vertex.beta[k][l] = paths.beta[k][l];
            let mut r = 0.0;
            for s in 0..REFLECTANCE_SLOTS {
                r = select(slot[l] == s as u8, paths.reflectance[s][k][l], r);
            }
            vertex.f_lambert[k][l] = r * std::f32::consts::FRAC_1_PI;
            let d = paths.illumination_direct[k][l];
            paths.illumination_direct[k][l] = select(clear_white, 0.0, d);
        }
    }
    counters.bounces += bounces as u64;
    // The vertex's flags.
    for l in 0..N {
        let depth = paths.depth[l];
        vertex.active[l] = active[l];
        vertex.roulette[l] = depth >= tracer.rr_depth;
        let record_white = job.want_illumination && depth == 1;
        vertex.record_white[l] = record_white;
        vertex.light_kind[l] = LIGHT_NONE;
        flags.has_illumination[l] |= active[l] && record_white && want_white;
    }
    // Lane by lane again where needed: reflectances past the slots.
    let mut slotless = false;
    for l in 0..N {
        slotless |= active[l] & (slot[l] == NO_SLOT);
    }
    if !slotless {
        return;
    }
    for l in 0..N {
        let (true, Some(sample)) = (active[l], &mut samples[l]) else {
            continue;
        };
        if slot[l] == NO_SLOT {
            let Material::Surface(SurfaceMaterial::Lambert { reflectance }) =
                scene.material(material[l])
            else {
                unreachable!("PacketScene::new admits constant Lambertian materials only");
            };
            let constant = reflectance
                .constant()
                .expect("PacketScene::new admits constant reflectances only");
            let r = sample
                .reflectance_cache
                .get(material[l], constant, &sample.wavelengths);
            set_spectrum(&mut vertex.f_lambert, l, r * std::f32::consts::FRAC_1_PI);
        }
    }
}

/// A lane's ray escaped: the infinite lights it sees (`PathTracer::escape_terms`).
#[inline(always)]
fn escape<const N: usize>(
    job: &TileJob,
    paths: &mut Paths<N>,
    flags: &PathFlags<N>,
    sample: &LaneSample,
    l: usize,
    direction: Vec3A,
    counters: &mut PathCounters,
) {
    let (specular, prev, pdf) = (
        flags.specular_bounce[l],
        paths.prev_ctx(l),
        paths.prev_bsdf_pdf[l],
    );
    let count = paths.depth[l] >= 2;
    let wavelengths = &sample.wavelengths;
    job.tracer.escape_terms(
        job.scene,
        specular,
        &prev,
        pdf,
        direction,
        wavelengths,
        |x| paths.add(flags, l, x, count, counters),
    );
}

/// A lane's ray hit emitter `hit.0` at `hit.1` along `hit.2`: its radiance, MIS-weighted
/// against the light sample (`PathTracer::emission_term`).
#[inline(always)]
fn emission<const N: usize>(
    job: &TileJob,
    paths: &mut Paths<N>,
    flags: &PathFlags<N>,
    sample: &mut LaneSample,
    l: usize,
    (li, light_hit, direction): (u32, &LightHit, Vec3A),
    counters: &mut PathCounters,
) {
    if let Some(x) = job.tracer.emission_term(
        job.scene,
        li,
        light_hit,
        flags.specular_bounce[l],
        &paths.prev_ctx(l),
        paths.prev_bsdf_pdf[l],
        direction,
        &sample.wavelengths,
        &mut sample.le_cache,
    ) {
        let count = paths.depth[l] >= 2;
        paths.add(flags, l, x, count, counters);
    }
}

/// Rectangle emitter `rect`'s fields into lane `l` of `vertex`.
#[inline(always)]
fn put_rectangle<const N: usize>(vertex: &mut VertexIn<N>, l: usize, rect: &RectangleLight) {
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
}

/// Lights with at most this many entries are picked for all lanes in one vector pass.
const VECTOR_LIGHT_CHOICE_MAX: usize = 16;

/// Each vertex's light choice (`LightSet::sample_at`), the chosen
/// rectangle's fields and L(λ), or a light sample by the scalar `Light` code for other
/// lights (after `draw_variates`). `rectangle_in_lane[l]` names the light whose fields lane `l` of
/// `vertex` already holds.
#[inline(always)]
fn choose_lights<const N: usize>(
    job: &TileJob,
    paths: &Paths<N>,
    samples: &mut [Option<LaneSample>; N],
    vertex: &mut VertexIn<N>,
    variates: &Variates<N>,
    rectangle_in_lane: &mut [u32; N],
) {
    let u = &variates.u;
    let rr_depth = job.tracer.rr_depth;
    for l in 0..N {
        vertex.u_bsdf[0][l] = u[3][l];
        vertex.u_bsdf[1][l] = u[4][l];
        // `vertex.roulette`, from the depth: this pass writes no flag of `vertex`.
        vertex.u_roulette[l] = select(paths.depth[l] >= rr_depth, u[5][l], 1.0);
        vertex.u_light[0][l] = u[1][l];
        vertex.u_light[1][l] = u[2][l];
    }
    let lights = &job.scene.lights;
    if lights.is_empty() {
        return;
    }
    // Many lights: each lane descends the light BVH at its own hit point and geometric
    // normal, as the scalar tracer's `LightSet::sample_at` does, the lanes' descents side
    // by side (`LightBvh::sample_lanes`: the same picks).
    if let Some(bvh) = lights.light_bvh() {
        let points: [Vec3A; N] = std::array::from_fn(|l| hit_point(vertex, l));
        let normals: [Vec3A; N] = std::array::from_fn(|l| vec_at(&paths.n_geometric, l));
        let active: [bool; N] = std::array::from_fn(|l| vertex.active[l] && samples[l].is_some());
        let picks = bvh.sample_lanes(&points, &normals, &u[0], &active);
        for (l, pick) in picks.into_iter().enumerate() {
            let (Some((li, p)), Some(sample)) = (pick, &mut samples[l]) else {
                continue;
            };
            vertex.pmf[l] = p;
            take_light(job, paths, vertex, sample, l, li, u, rectangle_in_lane);
        }
        return;
    }
    let table = lights.shading_table();
    let cdf = table.cdf_slice();
    let order = table.order_slice();
    let pmf = table.pmf_slice();
    // One rectangle emitter with its radiance slot (a Cornell box, a room with one
    // lamp): every lane picks it (`LightSet::sample_at` of one light) — its fields are
    // written into the lanes once, its L(λ) and pmf for all lanes in vector passes.
    if let ([Some(rect)], [p]) = (job.packet.lights.as_slice(), pmf) {
        if let (Some(0), true) = (rect.radiance_slot, *p > 0.0) {
            if rectangle_in_lane[0] != 0 {
                for l in 0..N {
                    rectangle_in_lane[l] = 0;
                    put_rectangle(vertex, l, rect);
                }
            }
            for l in 0..N {
                vertex.pmf[l] = *p;
                for k in 0..4 {
                    vertex.le[k][l] = paths.light_le[0][k][l];
                }
            }
            for l in 0..N {
                vertex.light_kind[l] = if vertex.active[l] {
                    LIGHT_RECTANGLE
                } else {
                    LIGHT_NONE
                };
            }
            // Lanes near the emitter sample it in solid angle, by the scalar code.
            if let Some(sampling) = &rect.solid_angle {
                let near = sampling.in_range_lanes(&hit_points(vertex));
                if near.contains(&true) {
                    for l in 0..N {
                        if !(near[l] && vertex.active[l]) {
                            continue;
                        }
                        vertex.light_kind[l] = LIGHT_NONE;
                        if let Some(sample) = &mut samples[l] {
                            sample_light_scalar(job, paths, vertex, sample, l, 0, u);
                        }
                    }
                }
            }
            return;
        }
    }
    // `SelectionTable::sample`: the first light whose running sum exceeds u, i.e. the
    // number of sums ≤ u (they never decrease).
    let mut chosen = [0u32; N];
    let last = cdf.len() as u32 - 1;
    if cdf.len() <= VECTOR_LIGHT_CHOICE_MAX {
        for l in 0..N {
            let uc = u[0][l].min(1.0 - f32::EPSILON);
            let mut below = 0u32;
            for &c in cdf {
                below += (c <= uc) as u32;
            }
            chosen[l] = order[below.min(last) as usize];
        }
    } else {
        for l in 0..N {
            let uc = u[0][l].min(1.0 - f32::EPSILON);
            chosen[l] = table.sample(uc).map_or(0, |(i, _)| i);
        }
    }
    for l in 0..N {
        let (true, Some(sample)) = (vertex.active[l], &mut samples[l]) else {
            continue;
        };
        let li = chosen[l];
        let p = pmf[li as usize];
        // `SelectionTable::sample` picks no light where p is not > 0.
        if p.is_nan() || p <= 0.0 {
            continue;
        }
        vertex.pmf[l] = p;
        take_light(job, paths, vertex, sample, l, li, u, rectangle_in_lane);
    }
}

/// Lane `l`'s light sample of the chosen light `li`: a rectangle emitter's fields and L(λ)
/// for the lanes' area sampling, or the scalar `Light` code's sample for other lights.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn take_light<const N: usize>(
    job: &TileJob,
    paths: &Paths<N>,
    vertex: &mut VertexIn<N>,
    sample: &mut LaneSample,
    l: usize,
    li: u32,
    u: &[[f32; N]; 6],
    rectangle_in_lane: &mut [u32; N],
) {
    match &job.packet.lights[li as usize] {
        Some(rect)
            if rect
                .solid_angle
                .is_none_or(|s| !s.in_range(hit_point(vertex, l))) =>
        {
            if rectangle_in_lane[l] != li {
                rectangle_in_lane[l] = li;
                put_rectangle(vertex, l, rect);
            }
            let le = match rect.radiance_slot {
                Some(s) => spectrum_at(&paths.light_le[s], l),
                None => sample.le_cache.get(
                    job.scene.lights.emission_key(li),
                    &rect.radiance,
                    &sample.wavelengths,
                ),
            };
            set_spectrum(&mut vertex.le, l, le);
            vertex.light_kind[l] = LIGHT_RECTANGLE;
        }
        // Other lights, and a rectangle near enough to sample in solid angle from here
        // (the scalar code also falls back to area sampling where it must).
        Some(_) | None => sample_light_scalar(job, paths, vertex, sample, l, li, u),
    }
}

/// Every lane's hit point, `hit_point`'s bits.
#[inline(always)]
fn hit_points<const N: usize>(vertex: &VertexIn<N>) -> [[f32; N]; 3] {
    std::array::from_fn(|a| std::array::from_fn(|l| vertex.o[a][l] + vertex.t[l] * vertex.d[a][l]))
}

/// The vertex's hit point in lane `l`: the same bits as `shade`'s.
#[inline(always)]
fn hit_point<const N: usize>(vertex: &VertexIn<N>, l: usize) -> Vec3A {
    let (o, d, t) = (vertex.o, vertex.d, vertex.t[l]);
    Vec3A::new(
        o[0][l] + t * d[0][l],
        o[1][l] + t * d[1][l],
        o[2][l] + t * d[2][l],
    )
}

/// Light `li`'s sample for lane `l` by the scalar `Light` code, as the lane's given sample
/// (`LIGHT_GIVEN`; the lane's kind is left as it is where the light gives none).
#[inline(always)]
fn sample_light_scalar<const N: usize>(
    job: &TileJob,
    paths: &Paths<N>,
    vertex: &mut VertexIn<N>,
    sample: &mut LaneSample,
    l: usize,
    li: u32,
    u: &[[f32; N]; 6],
) {
    let ctx = LightSampleContext {
        p: hit_point(vertex, l),
        n: vec_at(&paths.n_geometric, l),
    };
    let ul = Vec2::new(u[1][l], u[2][l]);
    let lights = &job.scene.lights;
    if let Some(ls) = lights.light(li).sample_li_cached(
        lights.emission_key(li),
        &ctx,
        ul,
        &sample.wavelengths,
        &mut sample.le_cache,
    ) {
        set_spectrum(&mut vertex.le, l, ls.radiance);
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

/// Each lane's vertex after shading, all lanes at once: its shadow ray and pending light
/// sample, the path's new state and next ray (or its end), statistics.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn end_vertices<const N: usize>(
    job: &TileJob,
    paths: &mut Paths<N>,
    flags: &mut PathFlags<N>,
    vertex: &VertexIn<N>,
    out: &VertexOut<N>,
    rays: &mut RayLanes<N>,
    shadow: &mut RayLanes<N>,
    counters: &mut PathCounters,
) {
    let want_illumination = job.want_illumination;
    let mut rays_traced = 0u32;
    let mut non_finite = 0u32;
    let mut roulette = 0u32;
    for l in 0..N {
        let has_shadow = out.has_shadow[l];
        let goes_on = out.continues[l] | out.killed_by_roulette[l];
        let continues = out.continues[l];
        let first = want_illumination & goes_on & (paths.depth[l] == 1);
        let white_weight = out.wi_z[l].max(0.0) * std::f32::consts::FRAC_1_PI / out.pdf[l];
        let scale = 1.0 / white_weight.max(1e-20);
        let had_first_beta = flags.has_first_beta[l];
        // `path::add_contribution`'s terms at this vertex's β.
        let mut c_non_finite = false;
        for k in 0..4 {
            let beta = paths.beta[k][l];
            let c = beta * out.direct[k][l];
            c_non_finite |= !c.is_finite();
            let b1 = paths.first_beta[k][l];
            paths.pending_c[k][l] = c;
            // `SampledSpectrum::safe_div`.
            paths.pending_incident[k][l] = select(b1 != 0.0, c / b1, 0.0);
            paths.pending_white[k][l] = out.white[k][l];
            paths.first_beta[k][l] = select(first, out.weight[k][l] * scale, b1);
            // Stores under a condition, not `select`s of two loads, which LLVM turns into a
            // load from a selected address that it cannot vectorise.
            if continues {
                paths.beta[k][l] = out.beta[k][l];
            }
        }
        flags.pending[l] = has_shadow;
        flags.pending_non_finite[l] = c_non_finite;
        flags.pending_counts_incident[l] = had_first_beta;
        // The scalar tracer keeps no first-bounce β where the weight is ≤ 0 (NaN keeps it).
        let keeps = white_weight > 0.0 || white_weight.is_nan();
        flags.has_first_beta[l] = (first & keeps) | (!first & had_first_beta);
        flags.specular_bounce[l] &= !goes_on;
        flags.ends[l] |= vertex.active[l] & !continues;
        if goes_on {
            paths.prev_bsdf_pdf[l] = out.pdf[l];
        }
        for a in 0..3 {
            let p = out.p[a][l];
            if goes_on {
                paths.prev_p[a][l] = p;
                paths.prev_n[a][l] = paths.n_geometric[a][l];
            }
            shadow.o[a][l] = p;
            shadow.d[a][l] = out.shadow_d[a][l];
            rays.o[a][l] = p;
            rays.d[a][l] = out.next_d[a][l];
        }
        shadow.t_min[l] = select(has_shadow, out.shadow_t_min[l], f32::INFINITY);
        shadow.t_max[l] = select(has_shadow, out.shadow_t_max[l], 0.0);
        rays.t_min[l] = select(continues, out.next_t_min[l], f32::INFINITY);
        rays.t_max[l] = select(continues, f32::INFINITY, 0.0);
        rays_traced += has_shadow as u32 + goes_on as u32;
        non_finite += out.weight_non_finite[l] as u32;
        roulette += out.killed_by_roulette[l] as u32;
    }
    counters.rays += rays_traced as u64;
    counters.non_finite_contributions += non_finite as u64;
    counters.roulette_terminations += roulette as u64;
}

/// The pending light samples whose shadow rays were not blocked, added as
/// `path::add_contribution` adds them, all lanes at once.
#[inline(always)]
fn resolve_light_samples<const N: usize>(
    job: &TileJob,
    paths: &mut Paths<N>,
    flags: &mut PathFlags<N>,
    blocked: &[bool; N],
    counters: &mut PathCounters,
) {
    let mut non_finite = 0u32;
    for l in 0..N {
        let unblocked = flags.pending[l] & !blocked[l];
        non_finite += (unblocked & flags.pending_non_finite[l]) as u32;
        let add = unblocked & !flags.pending_non_finite[l];
        let add_incident = add & flags.pending_counts_incident[l];
        // The vertex's depth: it changes only at the next vertex.
        let white = job.want_illumination & unblocked & (paths.depth[l] == 1);
        flags.has_illumination[l] |= white;
        flags.pending[l] = false;
        for k in 0..4 {
            let r = paths.radiance[k][l];
            paths.radiance[k][l] = select(add, r + paths.pending_c[k][l], r);
            let i = paths.incident_after_first[k][l];
            paths.incident_after_first[k][l] =
                select(add_incident, i + paths.pending_incident[k][l], i);
            if white {
                paths.illumination_direct[k][l] = paths.pending_white[k][l];
            }
        }
    }
    counters.non_finite_contributions += non_finite as u64;
}

/// Lane `l`'s camera sample into the film; the lane is idle after.
#[inline(always)]
fn finish_lane<const N: usize>(
    job: &TileJob,
    tile: &mut FilmTile,
    paths: &Paths<N>,
    flags: &PathFlags<N>,
    sample: &mut Option<LaneSample>,
    l: usize,
    counts: &mut TileCounts,
) {
    let Some(sample) = sample.take() else {
        return;
    };
    let illumination = flags.has_illumination[l].then(|| {
        let d = spectrum_at(&paths.illumination_direct, l);
        if flags.has_first_beta[l] {
            d + spectrum_at(&paths.incident_after_first, l)
        } else {
            d
        }
    });
    let radiance = spectrum_at(&paths.radiance, l);
    write_sample(job, tile, &sample, radiance, illumination, counts);
}

/// A camera sample's value into the film (the scalar driver's steps after `radiance`).
#[inline(always)]
fn write_sample(
    job: &TileJob,
    tile: &mut FilmTile,
    sample: &LaneSample,
    radiance: SampledSpectrum,
    illumination: Option<SampledSpectrum>,
    counts: &mut TileCounts,
) {
    let xyz_weights = XyzWeights::new(&sample.wavelengths);
    if let Some(white) = illumination {
        tile.add_illumination_with(sample.pixel, white, &xyz_weights);
    }
    let aov = sample.first_hit.map(|h| SurfaceAov {
        depth_m: h.t,
        normal: h.n_shading,
        albedo_rgb: job.scene.albedo(h.material_id),
    });
    if radiance.has_non_finite() {
        counts.non_finite_samples += 1;
    }
    tile.add_sample_with(
        sample.pixel,
        sample.film_point,
        radiance,
        &sample.wavelengths,
        &xyz_weights,
        sample.filter_weight,
        aov.as_ref(),
    );
    counts.samples += 1;
}
