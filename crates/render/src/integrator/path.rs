//! The spectral path tracer: unidirectional path tracing with next-event estimation and
//! multiple importance sampling (Veach 1997, ch. 9; pbrt-v4 §13.4 `PathIntegrator`),
//! Russian roulette (Arvo & Kirk 1990) and hero-wavelength transport (Wilkie et al. 2014):
//! four wavelengths travel together; a dispersive interface keeps only the hero.
//!
//! `max_depth` counts scattering events: 1 is direct lighting only (pbrt-v4 convention;
//! Mitsuba 3's `max_depth` is one more, since it counts the camera segment).
//!
//! Sample dimensions: `integrator::dimensions` (one `VertexDimensions` block per vertex).
//! The loop walks `ScatterVertex`es with a `PathState`, so surface and medium vertices take
//! the same steps.

use glam::{Vec2, Vec3A};
use prism_geometry::{Ray, RayDifferential, SurfaceInteraction};
use prism_scene::{FluorescenceLanes, MisHeuristic};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::dimensions::ReradiationDimensions;
use super::fluorescent_vertex;
use super::lane_wavelengths::LaneWavelengths;
use super::path_state::{PathOrigin, PathState};
use super::scatter_vertex::{ScatterVertex, SurfaceVertex};
use crate::bsdf::TransportMode;
use crate::light::{LightHit, LightSampleContext};
use crate::sampler::SampleStream;
use crate::scene_build::RenderScene;
use crate::spectrum_cache::{SpectrumCache, TransportWavelengths};

/// Parameters of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTracer {
    /// Most scattering events (≥ 1; 1 = direct lighting only).
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering events.
    pub rr_depth: u32,
    pub mis: MisHeuristic,
    /// What the lanes do at a fluorescent vertex (integrator/fluorescent_vertex.rs).
    pub fluorescence_lanes: FluorescenceLanes,
    /// Spectral MIS of distance samples in media (`medium_transport`).
    pub spectral_mis: bool,
}

impl Default for PathTracer {
    /// The scene format's defaults: max depth 8, roulette from depth 3, power heuristic.
    fn default() -> Self {
        Self {
            max_depth: 8,
            rr_depth: 3,
            mis: MisHeuristic::Power,
            fluorescence_lanes: FluorescenceLanes::All,
            spectral_mis: true,
        }
    }
}

/// Per-sample counters the driver sums into `RenderStats`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathCounters {
    /// Extension and shadow rays (the camera ray is counted by the driver).
    pub rays: u64,
    /// Scattering events.
    pub bounces: u64,
    /// Paths ended by Russian roulette.
    pub roulette_terminations: u64,
    /// Light-sample or emission contributions that were NaN or infinite (dropped).
    pub non_finite_contributions: u64,
    /// Medium boundaries met from a medium other than the one they declare on that side
    /// (scenes with media: overlapping or inconsistent `interior_medium`/`exterior_medium`).
    pub medium_mismatches: u64,
}

/// What one camera path returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathResult {
    /// Radiance arriving at the camera along the ray, W·m⁻²·sr⁻¹·nm⁻¹ per lane.
    pub radiance: SampledSpectrum,
    /// The first surface hit, when there is one (what the film's surface AOVs record).
    pub first_hit: Option<FirstHit>,
    /// Radiance a neutral white Lambertian (R = 1) would reflect towards the camera at the
    /// first hit (direct light by light sampling plus the path's indirect estimate), for
    /// scene-based white balance; `None` when the first hit is specular or there is none.
    pub illumination: Option<SampledSpectrum>,
}

/// What the film's surface AOVs need of a path's first hit: a few fields instead of the
/// whole `SurfaceInteraction` (≈ 250 bytes, copied into the result of every camera sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstHit {
    /// Distance along the camera ray, metres.
    pub t: f32,
    /// Shading normal (world, unit), after normal or bump mapping.
    pub n_shading: Vec3A,
    pub material_id: u32,
}

/// Multiple importance sampling weight of a strategy with pdf `a` against one with pdf `b`
/// (Veach 1997, eqs. 9.12–9.13; one sample per strategy).
#[inline]
pub fn mis_weight(heuristic: MisHeuristic, a: f32, b: f32) -> f32 {
    match heuristic {
        MisHeuristic::Balance => {
            if a + b > 0.0 {
                a / (a + b)
            } else {
                0.0
            }
        }
        MisHeuristic::Power => {
            let (a2, b2) = (a * a, b * b);
            if a2 + b2 > 0.0 {
                a2 / (a2 + b2)
            } else {
                0.0
            }
        }
    }
}

/// A view-independent solution a final gather ends on: the radiance a surface point
/// reflects towards `wo` (emission excluded).
pub trait SolutionGather: Sync {
    /// The reflected radiance at `si`; with `seen_from_m`, `None` when the solution does
    /// not resolve it from that distance (a piecewise-constant element seen from closer
    /// than its size misses the variation across it, e.g. the corner where a wall meets
    /// the floor), so that the gather path continues instead.
    fn reflected_radiance(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
        seen_from_m: Option<f32>,
    ) -> Option<SampledSpectrum>;

    /// The solution's light that a camera path's gather vertex `vertex` (at `si`, seen
    /// from `wo`) reflects by an interpolated gather, and the receiver it used; `None`
    /// where it does not serve the vertex (the path then reads `reflected_radiance` at its
    /// next hit for all sources).
    fn interpolated_reflection(
        &self,
        _scene: &RenderScene,
        _si: &SurfaceInteraction,
        _wo: Vec3A,
        _vertex: &ScatterVertex,
        _wavelengths: &SampledWavelengths,
    ) -> Option<(SampledSpectrum, u32)> {
        None
    }

    /// Whether the gather ray's hit `si` (seen from `wo`) is a source that `receiver`'s
    /// interpolation left out (its gathering list): only those hits read the solution.
    fn hits_listed_source(&self, _receiver: u32, _si: &SurfaceInteraction, _wo: Vec3A) -> bool {
        true
    }
}

/// Most vertices a final gather path adds after its gather depth for hits too close for
/// the solution (`SolutionGather::reflected_radiance`'s `seen_from_m`).
pub const MAX_GATHER_EXTRA_BOUNCES: u32 = 2;

/// Adds β·x to `radiance` unless it is NaN/∞ (then counts it: one bad contribution cannot
/// poison a pixel, and the stats say so). `count_incident`: also part of the indirect light
/// at the first hit, `incident` (divided by the first bounce's throughput `first`; not
/// emission met right after the first bounce — the white Lambertian's direct light comes
/// from light sampling alone). The scalar and the packet tracer both add through here.
#[inline(always)]
pub(crate) fn add_contribution(
    radiance: &mut SampledSpectrum,
    incident: &mut SampledSpectrum,
    first: &Option<SampledSpectrum>,
    beta: SampledSpectrum,
    x: SampledSpectrum,
    count_incident: bool,
    counters: &mut PathCounters,
) {
    let c = beta * x;
    if c.has_non_finite() {
        counters.non_finite_contributions += 1;
        return;
    }
    *radiance += c;
    if let (Some(b1), true) = (first, count_incident) {
        *incident += c.safe_div(*b1);
    }
}

impl PathTracer {
    /// Radiance along `camera_ray` (unit direction) at `wavelengths` (which a dispersive
    /// hit may reduce to the hero); `light_samples` light samples per scattering event.
    /// Without ray differentials: texture lookups use the camera footprint approximation
    /// at every hit (see `radiance_with_differentials`).
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        scene: &RenderScene,
        camera_ray: &Ray,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        want_illumination: bool,
        counters: &mut PathCounters,
    ) -> PathResult {
        self.trace(
            scene,
            camera_ray,
            None,
            None,
            1.0,
            wavelengths,
            stream,
            light_samples,
            want_illumination,
            counters,
            None,
        )
    }

    /// As `radiance`, with the camera ray's differential (already scaled for the pixel's
    /// sample count, pbrt-v4 `ScaleDifferentials`) for texture filtering at the first hit
    /// and behind opacity masks; hits after a scattering event use the camera footprint
    /// (`RenderScene::texture_footprint`) scaled by `differential_scale` (pbrt-v4 §10.1.2
    /// `Camera::Approximate_dp_dxy`).
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_with_differentials(
        &self,
        scene: &RenderScene,
        camera_ray: &Ray,
        camera_differential: Option<&RayDifferential>,
        differential_scale: f32,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        want_illumination: bool,
        counters: &mut PathCounters,
    ) -> PathResult {
        self.trace(
            scene,
            camera_ray,
            None,
            camera_differential,
            differential_scale,
            wavelengths,
            stream,
            light_samples,
            want_illumination,
            counters,
            None,
        )
    }

    /// Radiance arriving at `ray.origin` along `ray` when the ray was sampled at a
    /// non-specular point `origin` (an illuminance sensor): emission met by the ray is then
    /// MIS-weighted against light sampling from `origin` (whose light samples the caller
    /// takes), instead of counted in full as for a camera ray. `None` is a camera ray.
    /// Textures are filtered with the camera footprint approximation. With `gather`, the
    /// path ends at depth `max_depth` on the solution's reflected radiance.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_from(
        &self,
        scene: &RenderScene,
        camera_ray: &Ray,
        origin: Option<PathOrigin>,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        want_illumination: bool,
        counters: &mut PathCounters,
        gather: Option<&dyn SolutionGather>,
    ) -> PathResult {
        self.trace(
            scene,
            camera_ray,
            origin,
            None,
            1.0,
            wavelengths,
            stream,
            light_samples,
            want_illumination,
            counters,
            gather,
        )
    }

    /// `radiance` of a final gather (`radiosity`): the path ends at depth `max_depth` on
    /// `gather`'s reflected radiance instead of stopping there.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_gathered(
        &self,
        scene: &RenderScene,
        camera_ray: &Ray,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        want_illumination: bool,
        counters: &mut PathCounters,
        gather: &dyn SolutionGather,
    ) -> PathResult {
        self.trace(
            scene,
            camera_ray,
            None,
            None,
            1.0,
            wavelengths,
            stream,
            light_samples,
            want_illumination,
            counters,
            Some(gather),
        )
    }

    /// The path loop behind `radiance`, `radiance_with_differentials` and `radiance_from`.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        scene: &RenderScene,
        camera_ray: &Ray,
        origin: Option<PathOrigin>,
        camera_differential: Option<&RayDifferential>,
        differential_scale: f32,
        wavelengths: &mut LaneWavelengths,
        stream: &mut SampleStream,
        light_samples: u32,
        want_illumination: bool,
        counters: &mut PathCounters,
        gather: Option<&dyn SolutionGather>,
    ) -> PathResult {
        if let Some(media) = &scene.media {
            return self.trace_volumetric(
                scene,
                media,
                camera_ray,
                origin,
                camera_differential,
                differential_scale,
                wavelengths,
                stream,
                light_samples,
                counters,
            );
        }
        let mut current_differential = camera_differential.copied();
        let lights = &scene.lights;
        let mut radiance = SampledSpectrum::splat(0.0);
        let camera_path = origin.is_none();
        // The receiver element whose interpolated gather served the gather vertex.
        let mut interpolated_gather: Option<u32> = None;
        let mut path = PathState::new(camera_ray.origin, origin, *stream, *wavelengths);
        // Indirect light arriving at the first hit, for the illumination AOV: contributions
        // after the first bounce divided by the first bounce's throughput factor.
        let mut first_bounce_beta: Option<SampledSpectrum> = None;
        let mut incident_after_first = SampledSpectrum::splat(0.0);
        let mut illumination_direct: Option<SampledSpectrum> = None;
        let mut first_hit: Option<FirstHit> = None;
        let mut ray = *camera_ray;
        let n_light = light_samples.max(1);
        // The lights' spectra at this path's wavelengths (their values never change along
        // the path; `terminate_secondary` only zeroes pdfs).
        let mut le_cache = SpectrumCache::new();
        // Constant reflectances at this path's wavelengths, by material id.
        let mut reflectance_cache = SpectrumCache::new();

        let add = add_contribution;

        loop {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                // Escaped: infinite lights.
                let (d, prev) = (ray.direction, &path.prev_ctx);
                self.escape_terms(
                    scene,
                    path.specular_bounce,
                    prev,
                    path.prev_pdf,
                    d,
                    path.wavelengths.transport(),
                    |x| {
                        add(
                            &mut radiance,
                            &mut incident_after_first,
                            &first_bounce_beta,
                            path.beta,
                            x,
                            path.depth >= 2,
                            counters,
                        )
                    },
                );
                break;
            };
            // No curvature: shading never reads it, nor does the film's G-buffer (depth,
            // normal, albedo); it cost ≈ 1 % of a Cornell box render at every first hit.
            let mut si = scene.geometry.shading_interaction(&ray, &hit);
            scene.set_texture_differentials(
                &mut si,
                current_differential.as_ref(),
                differential_scale,
            );
            let material = scene.material(si.material_id);
            // The vertex's block (`dimensions`): reserved in order, each computed only when
            // used — the same values as drawing all of them (`SampleStream::reserve`).
            let dims = path.next_vertex_dimensions();
            let reradiation_dims = scene
                .has_reradiation
                .then(|| ReradiationDimensions::reserve(&mut path.stream));

            // Opacity mask: pass straight through with probability 1 − α (only scenes with
            // masks: the per-hit material dispatch is not free).
            let opacity = if scene.has_masks {
                material.opacity_at(&si)
            } else {
                1.0
            };
            if opacity < 1.0 && path.stream.get_1d_at(dims.mask()) >= opacity {
                if !path.null_event() {
                    break;
                }
                ray = Ray::spawn(si.p, ray.direction);
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

            // Emission of a hit area light.
            if let Some(l) = lights.area_light_of_instance(hit.instance_id) {
                let light_hit = LightHit {
                    p: si.p,
                    n: si.n_geometric,
                    uv: si.uv,
                    distance_m: hit.t,
                };
                if let Some(x) = self.emission_term(
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
                    add(
                        &mut radiance,
                        &mut incident_after_first,
                        &first_bounce_beta,
                        path.beta,
                        x,
                        path.depth >= 2,
                        counters,
                    );
                }
            }
            if path.depth >= self.max_depth {
                // A final gather ends on the solution's reflected radiance (light that
                // bounced at least once before this vertex; emission was counted above),
                // unless the hit is too close for the solution's element there: then the
                // path goes on (up to MAX_GATHER_EXTRA_BOUNCES more vertices).
                let Some(g) = gather else {
                    break;
                };
                let extra = path.depth - self.max_depth;
                if let (Some(receiver), 0) = (interpolated_gather, extra) {
                    if !g.hits_listed_source(receiver, &si, -ray.direction) {
                        break;
                    }
                }
                let seen_from_m = (extra < MAX_GATHER_EXTRA_BOUNCES).then_some(hit.t);
                let transport = path.wavelengths.transport();
                if let Some(x) = g.reflected_radiance(&si, -ray.direction, transport, seen_from_m) {
                    add(
                        &mut radiance,
                        &mut incident_after_first,
                        &first_bounce_beta,
                        path.beta,
                        x,
                        path.depth >= 2,
                        counters,
                    );
                    break;
                }
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
            // Re-radiation (fluorescent_vertex.rs): asked only in scenes that have it.
            if let Some(d) = reradiation_dims {
                if let Some(f) = material.fluorescent() {
                    let lanes = &mut path.wavelengths;
                    let mode = self.fluorescence_lanes;
                    fluorescent_vertex::scatter(mode, f, &mut bsdf, lanes, &path.stream, d);
                }
            }
            let vertex =
                ScatterVertex::Surface(SurfaceVertex::new(&si, &bsdf, ray.direction, shading_maps));
            let ctx = vertex.light_context();
            // The interpolated gather serves a camera path's gather vertex for all but its
            // listed sources: the next hit reads the solution only on those.
            if let (Some(g), true) = (gather, camera_path && path.depth == self.max_depth) {
                if !vertex.is_specular() {
                    let transport = path.wavelengths.transport();
                    if let Some((x, receiver)) =
                        g.interpolated_reflection(scene, &si, -ray.direction, &vertex, transport)
                    {
                        add(
                            &mut radiance,
                            &mut incident_after_first,
                            &first_bounce_beta,
                            path.beta,
                            x,
                            path.depth >= 2,
                            counters,
                        );
                        interpolated_gather = Some(receiver);
                    }
                }
            }

            // Next-event estimation.
            if !vertex.is_specular() && !lights.is_empty() {
                let mut direct = SampledSpectrum::splat(0.0);
                let mut white = SampledSpectrum::splat(0.0);
                for k in 0..n_light {
                    let (uc, ul) = if k == 0 {
                        (
                            path.stream.get_1d_at(dims.light_choice()),
                            path.stream.get_2d_at(dims.light()),
                        )
                    } else {
                        (path.stream.get_1d(), path.stream.get_2d())
                    };
                    // Stratified light choice: sample k picks from the k-th of n equal
                    // slices of the selection CDF (each is still a sample of the same
                    // mixture, so the average stays unbiased; with n ≥ the number of
                    // equally bright lights every light gets its shadow ray).
                    let uc = ((k as f32 + uc) / n_light as f32).min(1.0 - f32::EPSILON);
                    let (d, w) = self.sample_light(
                        scene,
                        &vertex,
                        &ctx,
                        uc,
                        ul,
                        &path.wavelengths,
                        &mut le_cache,
                        want_illumination && path.depth == 1,
                        counters,
                    );
                    direct += d;
                    white += w;
                }
                let inv = 1.0 / n_light as f32;
                add(
                    &mut radiance,
                    &mut incident_after_first,
                    &first_bounce_beta,
                    path.beta,
                    direct * inv,
                    true,
                    counters,
                );
                if want_illumination && path.depth == 1 {
                    illumination_direct = Some(white * inv);
                }
            }

            // Continue the path by sampling the BSDF.
            let (u_lobe, u_bsdf) = (
                path.stream.get_1d_at(dims.lobe()),
                path.stream.get_2d_at(dims.bsdf()),
            );
            let Some(bs) = vertex.sample(u_lobe, u_bsdf, TransportMode::Radiance) else {
                break;
            };
            let weight = bs.weight;
            if weight.is_black() || weight.has_non_finite() {
                if weight.has_non_finite() {
                    counters.non_finite_contributions += 1;
                }
                break;
            }
            path.beta *= weight;
            if path.depth == 1 {
                if want_illumination && !bs.specular {
                    // White Lambertian weight of this direction: (cos/π)/pdf.
                    let white_weight =
                        bs.wi_local.z.max(0.0) * std::f32::consts::FRAC_1_PI / bs.pdf;
                    first_bounce_beta = Some(weight * (1.0 / white_weight.max(1e-20)));
                    if white_weight <= 0.0 {
                        first_bounce_beta = None;
                    }
                } else {
                    illumination_direct = None;
                }
            }
            // Straight through thin glazing: a null event (material/glazing.rs), so the MIS
            // state of the vertex before the pane stays and it is not a bounce.
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
                path.scattered(ctx, &bs);
            }
            ray = Ray::spawn(vertex.p(), bs.wi.normalize());
            current_differential = None;
            counters.rays += 1;

            let stream = path.stream;
            if path.roulette(self.rr_depth, || stream.get_1d_at(dims.roulette())) {
                counters.roulette_terminations += 1;
                break;
            }
        }
        *stream = path.stream;
        *wavelengths = path.wavelengths;
        let illumination = illumination_direct.map(|d| {
            if first_bounce_beta.is_some() {
                d + incident_after_first
            } else {
                d
            }
        });
        PathResult {
            radiance,
            first_hit,
            illumination,
        }
    }

    /// What a ray escaping along `direction` brings from the infinite lights: each light's
    /// radiance, MIS-weighted (`emission_weight`), handed to `add` one by one (each term
    /// gets its own non-finite check there). Both tracers' escape step.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn escape_terms(
        &self,
        scene: &RenderScene,
        specular_bounce: bool,
        prev_ctx: &LightSampleContext,
        prev_bsdf_pdf: f32,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
        mut add: impl FnMut(SampledSpectrum),
    ) {
        let lights = &scene.lights;
        for &l in lights.infinite_lights() {
            let le = lights.light(l).infinite_radiance(direction, wavelengths);
            if le.is_black() {
                continue;
            }
            let w = self.emission_weight(
                scene,
                l,
                specular_bounce,
                prev_ctx,
                prev_bsdf_pdf,
                direction,
                None,
            );
            add(le * w);
        }
    }

    /// The radiance area light `l` emits back along `direction` at `light_hit`,
    /// MIS-weighted (`emission_weight`); `None` where it is black. Both tracers' emission
    /// step.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn emission_term(
        &self,
        scene: &RenderScene,
        l: u32,
        light_hit: &LightHit,
        specular_bounce: bool,
        prev_ctx: &LightSampleContext,
        prev_bsdf_pdf: f32,
        direction: Vec3A,
        wavelengths: &impl TransportWavelengths,
        le_cache: &mut SpectrumCache,
    ) -> Option<SampledSpectrum> {
        let light = scene.lights.light(l);
        let key = scene.lights.emission_key(l);
        let le = light.emitted_radiance_cached(key, light_hit, -direction, wavelengths, le_cache);
        if le.is_black() {
            return None;
        }
        let w = self.emission_weight(
            scene,
            l,
            specular_bounce,
            prev_ctx,
            prev_bsdf_pdf,
            direction,
            Some(light_hit),
        );
        Some(le * w)
    }

    /// MIS weight of light `l`'s emission met by a ray along `direction` that BSDF sampling
    /// at `prev_ctx` produced with `prev_bsdf_pdf` (`hit`: where it met an area light; `None`
    /// for an infinite light): 1 after a specular bounce or from the camera.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn emission_weight(
        &self,
        scene: &RenderScene,
        l: u32,
        specular_bounce: bool,
        prev_ctx: &LightSampleContext,
        prev_bsdf_pdf: f32,
        direction: Vec3A,
        hit: Option<&LightHit>,
    ) -> f32 {
        if specular_bounce {
            return 1.0;
        }
        let lights = &scene.lights;
        let light_pdf =
            lights.pmf_at(prev_ctx, l) * lights.light(l).pdf_li(prev_ctx, direction, hit);
        mis_weight(self.mis, prev_bsdf_pdf, light_pdf)
    }

    /// One light sample at `vertex`, MIS-weighted against BSDF sampling: (contribution for
    /// the path, contribution a white Lambertian would get — for the illumination AOV).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn sample_light(
        &self,
        scene: &RenderScene,
        vertex: &ScatterVertex,
        ctx: &LightSampleContext,
        u_choice: f32,
        u: Vec2,
        wavelengths: &LaneWavelengths,
        le_cache: &mut SpectrumCache,
        want_white: bool,
        counters: &mut PathCounters,
    ) -> (SampledSpectrum, SampledSpectrum) {
        let zero = SampledSpectrum::splat(0.0);
        let lights = &scene.lights;
        let Some((l, pmf)) = lights.sample_at(ctx, u_choice) else {
            return (zero, zero);
        };
        let light = lights.light(l);
        let key = lights.emission_key(l);
        let Some(ls) = light.sample_li_cached(key, ctx, u, wavelengths, le_cache) else {
            return (zero, zero);
        };
        if ls.pdf <= 0.0 || ls.radiance.is_black() {
            return (zero, zero);
        }
        let Some(eval) = vertex.eval(ls.wi, TransportMode::Radiance) else {
            return (zero, zero);
        };
        let f = eval.f_cos;
        let white_cos = if want_white {
            eval.wi_local.z.max(0.0) * std::f32::consts::FRAC_1_PI
        } else {
            0.0
        };
        if f.is_black() && white_cos <= 0.0 {
            return (zero, zero);
        }
        counters.rays += 1;
        let transmittance =
            self.transmittance(scene, vertex.p(), &ls, wavelengths.transport(), counters);
        if transmittance.is_black() {
            return (zero, zero);
        }
        let light_pdf = pmf * ls.pdf;
        let w = if ls.delta {
            1.0
        } else {
            let bsdf_pdf = vertex.pdf(&eval, TransportMode::Radiance);
            mis_weight(self.mis, light_pdf, bsdf_pdf)
        };
        let arriving = ls.radiance * transmittance;
        let direct = f * arriving * (w / light_pdf);
        let white = arriving * (white_cos / light_pdf);
        (direct, white)
    }

    /// Fraction of light that reaches `p` from the light sample, per lane: 0 or 1, unless
    /// the scene has opacity masks or thin glazing (the plan's choices,
    /// `RenderScene::has_masks`/`has_glazing`): then each masked surface on the way
    /// multiplies by 1 − α and each pane by its straight-through transmittance
    /// (material/glazing.rs) — exact, no extra noise.
    #[inline]
    pub(crate) fn transmittance(
        &self,
        scene: &RenderScene,
        p: Vec3A,
        ls: &crate::light::LightSample,
        wavelengths: &SampledWavelengths,
        counters: &mut PathCounters,
    ) -> SampledSpectrum {
        let shadow = if ls.distance_m.is_finite() {
            Ray::spawn_to(p, ls.p_light)
        } else {
            Ray::spawn(p, ls.wi)
        };
        self.segment_transmittance(scene, shadow, ls.wi, wavelengths, counters)
    }

    /// `transmittance` along the segment `shadow` (its parameter interval bounds it);
    /// `direction` is its unit direction (panes' transmittance depends on the angle).
    #[inline]
    pub(crate) fn segment_transmittance(
        &self,
        scene: &RenderScene,
        mut shadow: Ray,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
        counters: &mut PathCounters,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::splat(0.0);
        if !scene.has_masks && !scene.has_glazing {
            return if scene.geometry.occluded(&shadow) {
                zero
            } else {
                SampledSpectrum::splat(1.0)
            };
        }
        let mut transmittance = SampledSpectrum::splat(1.0);
        let offset = shadow.t_min;
        for _ in 0..256 {
            let Some(hit) = scene.geometry.intersect(&shadow) else {
                return transmittance;
            };
            let si = scene.geometry.shading_interaction(&shadow, &hit);
            let material = scene.material(si.material_id);
            // What crosses this surface: the mask's holes (1 − α), plus what a pane lets
            // through straight of the light that meets it (α · T').
            let opacity = material.opacity_at(&si);
            let mut through = SampledSpectrum::splat(1.0 - opacity);
            if let Some(pane) = material.thin_glazing(wavelengths) {
                let cos = direction.dot(si.n_shading).abs();
                through += pane.transmittance(cos) * opacity;
            }
            transmittance *= through;
            if transmittance.is_black() {
                return zero;
            }
            counters.rays += 1;
            // Continue past the surface, keeping the same end point.
            shadow.t_min = hit.t * (1.0 + 1e-5) + offset;
        }
        zero
    }
}
