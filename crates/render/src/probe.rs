//! Render's implementation of prism-bandwidth's `ShadingProbe` (Bagher et al. 2013,
//! eqs. 4, 5, 9): at a G-buffer hit, sampled light directions with the incident radiance,
//! BSDF·cos, distance and the light's and material's bandwidths, so the predictor never
//! depends on render.
//!
//! Values are luminance-like Y in the output normalisation (prism-bandwidth's probe docs),
//! estimated from one set of hero wavelengths per sample. Occlusion is ignored, as in
//! Bagher's eq. 1, unless `trace_visibility` (then blocked samples carry no light in
//! L̂, eq. 9 and the colour noise; docs/bandwidth.md). `sample_indirect` adds one-bounce
//! indirect estimates (beyond the paper).
//!
//! Bandwidths (cycles per metre / per radian): each light's `Light::bandwidth`
//! (light/bandwidth.rs), except where the probe is given eq. 7's maps
//! (`with_bandwidth_tables`): environment maps answer per direction, area lights per point
//! of the emitter (`light/area_bandwidth.rs`); the material's ρ from its lobe
//! (`Bxdf::angular_bandwidth_cycles_per_rad`) or its table.
//!
//! The samples alternate between the path tracer's two strategies, light sampling and BSDF
//! sampling, and each sample's pdf is the mixture's (½ p_light + ½ p_bsdf), so eq. 9's
//! χᵢ²/pᵢ is the variance of the estimator the render runs (a glossy lobe that light
//! sampling rarely hits shows its variance through the BSDF samples). A BSDF sample that
//! meets an area light (occlusion counts here) or escapes to the infinite lights is one
//! sample per emitter. At a Dirac-only lobe (a mirror, smooth glass) every sample is a
//! BSDF sample, a delta: one direction, no shading variance, the bandwidth of the light it
//! sees. Delta lights and Dirac lobes report pdf 0 and fold their selection probability
//! into their weight.

use glam::{UVec2, Vec3A};
use prism_bandwidth::{
    Bandwidth, GBufferHit, IndirectEstimate, LightSample, MaterialBandwidth, PixelClass,
    SeenSurface, ShadingProbe, SurfacePoint, Visibility,
};
use prism_geometry::{Frame, Ray, SurfaceInteraction};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use prism_scene::MisHeuristic;

use crate::bsdf::{Bsdf, Bxdf, TransportMode};
use crate::bsdf_angular_table::MaterialAngularBandwidth;
use crate::bsdf_table_cache::AngularTableCache;
use crate::integrator::{mis_weight, Integrator};
use crate::light::area_bandwidth::AreaLightBandwidth;
use crate::light::environment_bandwidth::EnvironmentBandwidth;
use crate::light::{Light, LightHit, LightSampleContext};
use crate::sampler::{PixelSampler, SamplerKind};
use crate::scene_build::RenderScene;
use crate::texture::{TextureBandwidth, TextureContext};
use prism_spectrum::XyzWeights;

/// Sample indices of the indirect estimates (`sample_indirect`), apart from the light
/// samples' 0..n_b.
const INDIRECT_STREAM_OFFSET: u32 = 1 << 30;

/// A `ShadingProbe` over a built scene.
pub struct RenderProbe<'a> {
    pub scene: &'a RenderScene,
    pub seed: u64,
    /// Per light (the scene's order): eq. 7's map where one is built, else `None`.
    pub light_maps: Vec<Option<LightBandwidthMap>>,
    /// Per material (`material_id` order): its angular bandwidth table; empty: each lobe's
    /// closed form.
    pub material_tables: Vec<MaterialAngularBandwidth>,
    /// Trace the light samples' shadow rays (`Visibility`; the paper ignores visibility).
    pub trace_visibility: bool,
    /// Per material (`material_id` order): its shading textures' bandwidths (the texture
    /// term t); empty: t = 0.
    pub texture_bandwidths: Vec<Vec<TextureBandwidth>>,
    /// The scene's estimator, whose per-camera-sample variance the probe measures.
    pub estimator: ProbedEstimator,
}

/// Dirac vertices the indirect estimate follows at most past the first bounce (glass: two
/// refractions per sphere; mirrors facing each other would go on).
const MAX_SPECULAR_CHAIN: u32 = 8;

/// What the probe imitates of the scene's estimator: its MIS heuristic between the light and
/// the BSDF sample of a hit, and how many path vertices it follows (`max_depth`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProbedEstimator {
    pub mis: MisHeuristic,
    /// The estimator's longest path in scattering vertices (the camera ray's hit is 1).
    pub max_depth: u32,
}

impl ProbedEstimator {
    /// The scene's integrator's; the ones without a heuristic of their own take the path
    /// tracer's default (power).
    pub fn of(integrator: &Integrator) -> Self {
        let (mis, max_depth) = match integrator {
            Integrator::Path(path) => (path.mis, path.max_depth),
            Integrator::Bdpt(bdpt) => (bdpt.mis, bdpt.max_depth),
            Integrator::Light(light) => (MisHeuristic::Power, light.max_depth),
            Integrator::Photon(photon) => (MisHeuristic::Power, photon.max_depth),
            Integrator::Radiosity(_) => (MisHeuristic::Power, u32::MAX),
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => (MisHeuristic::Power, 0),
        };
        Self { mis, max_depth }
    }

    /// Whether the estimator carries light beyond the first bounce.
    pub fn carries_indirect(&self) -> bool {
        self.max_depth > 1
    }
}

impl<'a> RenderProbe<'a> {
    /// A probe with each light's single bandwidth (`Light::bandwidth`).
    pub fn new(scene: &'a RenderScene, seed: u64) -> Self {
        Self {
            scene,
            seed,
            light_maps: Vec::new(),
            material_tables: Vec::new(),
            trace_visibility: false,
            texture_bandwidths: Vec::new(),
            estimator: ProbedEstimator::of(&scene.integrator),
        }
    }

    /// The same probe with eq. 7's per-direction map for every environment light, the
    /// angular bandwidth table of every material the scene's shapes use (others get a
    /// constant) and the bandwidths of those materials' textures, what the predictor runs
    /// with.
    pub fn with_bandwidth_tables(self) -> Result<Self, String> {
        self.with_bandwidth_tables_cached(None)
    }

    /// [`Self::with_bandwidth_tables`] with the BSDF tables read from (or written to)
    /// `cache` (`bsdf_table_cache.rs`).
    pub fn with_bandwidth_tables_cached(
        mut self,
        cache: Option<&AngularTableCache>,
    ) -> Result<Self, String> {
        let mut used = vec![false; self.scene.materials.len()];
        for inst in self.scene.geometry.instances() {
            let id = inst.material.map_or(used.len() - 1, |m| m as usize);
            if let Some(u) = used.get_mut(id) {
                *u = true;
            }
        }
        // Per material the shapes use: its angular table and its textures' bandwidths.
        let per_material: Vec<(MaterialAngularBandwidth, Vec<TextureBandwidth>)> = self
            .scene
            .materials
            .iter()
            .zip(&used)
            .map(|(m, &used)| {
                if !used {
                    return Ok((MaterialAngularBandwidth::Constant(0.0), Vec::new()));
                }
                let textures = m
                    .shading_textures()
                    .into_iter()
                    .map(TextureBandwidth::new)
                    .collect::<Result<Vec<_>, _>>()?;
                let table = match cache {
                    Some(cache) => cache.table(m)?.0,
                    None => MaterialAngularBandwidth::build(m),
                };
                Ok((table, textures))
            })
            .collect::<Result<_, String>>()?;
        (self.material_tables, self.texture_bandwidths) = per_material.into_iter().unzip();
        self.light_maps =
            self.scene
                .lights
                .lights()
                .iter()
                .map(|l| match l {
                    Light::Environment(e) => EnvironmentBandwidth::new(e)
                        .map(|m| Some(LightBandwidthMap::Environment(m))),
                    Light::Area(a) => {
                        AreaLightBandwidth::new(a).map(|m| m.map(LightBandwidthMap::Area))
                    }
                    Light::Point(_)
                    | Light::Spot(_)
                    | Light::Directional(_)
                    | Light::Sky(_)
                    | Light::Daylight(_)
                    | Light::Goniometric(_) => Ok(None),
                })
                .collect::<Result<_, _>>()?;
        Ok(self)
    }

    /// The shading textures of material `material_id` (`material_id` past the list: the
    /// last, as `RenderScene::material` reads it); `None` before the tables are built.
    fn textures_of(&self, material_id: u32) -> Option<&Vec<TextureBandwidth>> {
        let index = (material_id as usize).min(self.texture_bandwidths.len().saturating_sub(1));
        self.texture_bandwidths.get(index)
    }

    /// t at the hit `si` of material `material_id`: the largest of its shading textures'
    /// bandwidths there (texture/bandwidth.rs), cycles/m; 0 without textures.
    pub(crate) fn texture_bandwidth_at(&self, material_id: u32, si: &SurfaceInteraction) -> f32 {
        let Some(textures) = self.textures_of(material_id) else {
            return 0.0;
        };
        let ctx = TextureContext::from_interaction(si);
        textures
            .iter()
            .map(|t| t.cycles_per_m(&ctx))
            .fold(0.0, f32::max)
    }

    /// What the G-buffer pass asks of the material at `hit`, from one BSDF (which reads the
    /// hit's textures), judged at the middle of the visible range: whether it scatters only
    /// in Dirac directions there (a mirror, smooth glass), and ρ_p for pooling V̂ and L̂
    /// (`prism_bandwidth::model_variance`): the directional albedo's Y seen from the eye
    /// where the material has a texture (which scales the pixel's light by its texel), else
    /// 1 (the whole surface shares one scale).
    pub(crate) fn hit_material(&self, hit: &GBufferHit) -> HitMaterial {
        let si = hit_interaction(hit);
        let wavelengths = SampledWavelengths::sample_visible(0.5);
        let bsdf = self
            .scene
            .material(hit.material_id())
            .bsdf(&si, &wavelengths);
        let textured = self
            .textures_of(hit.material_id())
            .is_some_and(|t| !t.is_empty());
        let texture_scale = if textured {
            let frame = Frame::from_zx(si.n_shading, si.dpdu);
            let albedo = bsdf.albedo(
                frame.to_local(hit.view_direction()),
                TransportMode::Radiance,
            );
            let y = reflectance_y(albedo, &XyzWeights::new(&wavelengths));
            if y.is_finite() {
                y.max(0.0)
            } else {
                0.0
            }
        } else {
            1.0
        };
        HitMaterial {
            dirac: bsdf.is_specular(),
            texture_scale,
        }
    }

    /// ρ and t of the material `material_id` for light from `wi_local` seen from
    /// `wo_local`, with the hit's texture term `texture_cycles_per_m`.
    fn material_bandwidth_at(
        &self,
        material_id: u32,
        bsdf: &Bsdf,
        wi_local: Vec3A,
        wo_local: Vec3A,
        texture_cycles_per_m: f32,
    ) -> MaterialBandwidth {
        let closed_form = MaterialBandwidth {
            texture_cycles_per_m,
            ..material_bandwidth(bsdf)
        };
        // `NO_MATERIAL` (and any id past the end) is the default material, the last.
        let index = (material_id as usize).min(self.material_tables.len().saturating_sub(1));
        match self.material_tables.get(index) {
            Some(table) => MaterialBandwidth {
                angular_cycles_per_rad: table.at(
                    wi_local,
                    wo_local,
                    closed_form.angular_cycles_per_rad,
                ),
                ..closed_form
            },
            None => closed_form,
        }
    }

    /// What a pixel whose centre hit is a Dirac surface shows: its centre ray followed
    /// through the chain of Dirac vertices (each time the lobe the BSDF picks at u = ½ for
    /// the middle of the visible range: the reflection where it outweighs the refraction)
    /// to the first other surface, or out to the background. `None` where the hit is not
    /// Dirac (`hit_material`) or the chain is longer than [`MAX_SPECULAR_CHAIN`].
    pub(crate) fn seen_through_dirac(&self, hit: &GBufferHit) -> Option<SeenSurface> {
        let wavelengths = SampledWavelengths::sample_visible(0.5);
        let mut si = hit_interaction(hit);
        let mut wo = hit.view_direction();
        let mut bsdf = self.scene.material(si.material_id).bsdf(&si, &wavelengths);
        if !bsdf.is_specular() {
            return None;
        }
        for _ in 0..MAX_SPECULAR_CHAIN {
            let frame = Frame::from_zx(si.n_shading, si.dpdu);
            let bs = bsdf.sample(
                frame.to_local(wo),
                0.5,
                glam::Vec2::splat(0.5),
                TransportMode::Radiance,
            )?;
            let ray = Ray::spawn(si.p, frame.from_local(bs.wi));
            let Some(next) = crate::medium_interfaces::first_surface(self.scene, &ray) else {
                return Some(SeenSurface {
                    class: PixelClass::Background,
                    surface: None,
                });
            };
            si = self.scene.geometry.shading_interaction(&ray, &next);
            wo = -ray.direction.normalize();
            bsdf = self.scene.material(si.material_id).bsdf(&si, &wavelengths);
            let emitter = self
                .scene
                .lights
                .area_light_of_instance(next.instance_id)
                .is_some();
            if !bsdf.is_specular() || emitter {
                return Some(SeenSurface {
                    class: PixelClass::Material(si.material_id),
                    surface: Some(SurfacePoint {
                        position_m: si.p,
                        normal: facing_normal(si.n_shading, wo).normalize(),
                    }),
                });
            }
        }
        None
    }

    /// ν_l of light `index` towards `wi`, met at `at_m` on the light when it has a
    /// position (area lights): (the light field's bandwidth there, `LightSample::
    /// light_bandwidth`; the emitter's, `LightSample::emitter_bandwidth`). The two differ
    /// only for an area light with eq. 7's map, whose emitter bandwidth is its size (the
    /// closed form): a penumbra spans the whole emitter, not the detail at the point.
    pub(crate) fn light_bandwidths_towards(
        &self,
        index: usize,
        wi: Vec3A,
        at_m: Option<Vec3A>,
    ) -> (Bandwidth, Bandwidth) {
        let light = &self.scene.lights.lights()[index];
        match (light, self.light_maps.get(index).and_then(Option::as_ref)) {
            (Light::Environment(e), Some(LightBandwidthMap::Environment(map))) => {
                let b = Bandwidth {
                    spatial_cycles_per_m: 0.0,
                    angular_cycles_per_rad: map.at(e, wi),
                };
                (b, b)
            }
            (Light::Area(_), Some(LightBandwidthMap::Area(map))) => {
                let size = light.bandwidth();
                let at_point = match at_m.and_then(|p| map.at(p, wi)) {
                    Some(spatial_cycles_per_m) => Bandwidth {
                        spatial_cycles_per_m,
                        ..size
                    },
                    None => size,
                };
                (at_point, size)
            }
            (_, Some(LightBandwidthMap::Environment(_) | LightBandwidthMap::Area(_)) | None) => {
                (light.bandwidth(), light.bandwidth())
            }
        }
    }
}

/// Eq. 7's per-point map of a light (`RenderProbe::light_maps`).
#[derive(Clone, Debug)]
pub enum LightBandwidthMap {
    /// ν_a per direction (`light/environment_bandwidth.rs`).
    Environment(EnvironmentBandwidth),
    /// ν_s per point of the emitter (`light/area_bandwidth.rs`).
    Area(AreaLightBandwidth),
}

/// ν_l of a light (see the module docs; the choices live in `light/bandwidth.rs`).
pub fn light_bandwidth(light: &Light) -> Bandwidth {
    light.bandwidth()
}

/// ρ of a BSDF (see the module docs): each lobe's `Bxdf::angular_bandwidth_cycles_per_rad`;
/// t = 0 (the probe adds the hit's texture term, `RenderProbe::texture_bandwidth_at`).
pub fn material_bandwidth(bsdf: &Bsdf) -> MaterialBandwidth {
    MaterialBandwidth {
        angular_cycles_per_rad: bsdf.lobe.angular_bandwidth_cycles_per_rad(),
        texture_cycles_per_m: 0.0,
    }
}

/// The ȳ-weighted mean of a BSDF value over the lanes (a white Lambertian gives 1/π).
pub(crate) fn reflectance_y(f: SampledSpectrum, weights: &XyzWeights) -> f32 {
    let ones = weights.y(SampledSpectrum::splat(1.0)) as f32;
    if ones > 0.0 {
        weights.y(f) as f32 / ones
    } else {
        0.0
    }
}

/// The variance of the hero-wavelength XYZ estimate of `weight` over its lanes (X, Y, Z
/// summed): each lane alone is an unbiased single-wavelength estimate, the hero estimate is
/// their mean, so its variance is the lanes' sample variance / 4. Spiky spectra (F11,
/// narrow LEDs) give much, flat ones none.
pub(crate) fn lane_variance(weight: SampledSpectrum, weights: &XyzWeights) -> f32 {
    let n = prism_spectrum::N_SPECTRUM_SAMPLES;
    let per_lane: [glam::DVec3; prism_spectrum::N_SPECTRUM_SAMPLES] =
        std::array::from_fn(|j| weights.lane(weight, j) * n as f64);
    let mean = per_lane.iter().copied().sum::<glam::DVec3>() / n as f64;
    let sum_sq: f64 = per_lane.iter().map(|x| (*x - mean).length_squared()).sum();
    let variance = sum_sq / ((n - 1) * n) as f64;
    if variance.is_finite() {
        variance as f32
    } else {
        0.0
    }
}

/// One BSDF sample from `wo_local`: its weight f·|cos θ|/pdf and local direction, or
/// `None` where it failed or has no density.
fn scatter(
    bsdf: &Bsdf,
    wo_local: Vec3A,
    stream: &mut crate::sampler::SampleStream,
) -> Option<(SampledSpectrum, Vec3A)> {
    let bs = bsdf.sample(
        wo_local,
        stream.get_1d(),
        stream.get_2d(),
        TransportMode::Radiance,
    )?;
    if bs.pdf.is_nan() || bs.pdf <= 0.0 {
        return None;
    }
    Some((bs.f * (bs.wi.z.abs() / bs.pdf), bs.wi))
}

/// The shading normal `n` turned to the side `towards` lies on (the side a viewer sees).
pub(crate) fn facing_normal(n: Vec3A, towards: Vec3A) -> Vec3A {
    if n.dot(towards) < 0.0 {
        -n
    } else {
        n
    }
}

/// The material at a G-buffer hit (`RenderProbe::hit_material`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HitMaterial {
    /// Dirac scattering only (a mirror, smooth glass).
    pub dirac: bool,
    /// ρ_p for pooling V̂ and L̂.
    pub texture_scale: f32,
}

fn hit_interaction(hit: &GBufferHit) -> SurfaceInteraction {
    let n = hit.normal();
    let frame = Frame::from_z(n);
    SurfaceInteraction {
        p: hit.position_m(),
        t: hit.depth_m(),
        n_geometric: n,
        n_shading: n,
        uv: hit.uv(),
        dpdu: frame.x,
        dpdv: frame.y,
        dndu: Vec3A::ZERO,
        dndv: Vec3A::ZERO,
        curvature: hit.curvature(),
        // The camera ray's footprint: texture lookups filter as the render's first hit does.
        differentials: hit.differentials(),
        primitive_id: 0,
        material_id: hit.material_id(),
        object_id: 0,
        instance_id: 0,
    }
}

/// One probe sample's strategy: the path tracer's two (light sampling and BSDF sampling),
/// drawn in turn so that eq. 9's pᵢ is the density of the estimator the render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ProbeStrategy {
    Light,
    Bsdf,
}

impl RenderProbe<'_> {
    /// Light sampling's solid-angle density towards `wi` (all lights, each with the pmf the
    /// render's light selection gives it at `ctx`).
    fn light_pdf(&self, ctx: &LightSampleContext, wi: Vec3A, hit: Option<(u32, &LightHit)>) -> f32 {
        let lights = &self.scene.lights;
        let mut pdf = 0.0;
        for (index, light) in lights.lights().iter().enumerate() {
            let light_hit = match hit {
                Some((l, h)) if l as usize == index => Some(h),
                Some(_) => None,
                None => None,
            };
            let on_this_light = light.is_infinite() || light_hit.is_some();
            if on_this_light && !light.is_delta() {
                pdf += lights.pmf_at(ctx, index as u32) * light.pdf_li(ctx, wi, light_hit);
            }
        }
        pdf
    }

    /// One BSDF-sampled direction from `si`, the first non-Dirac surface it meets and one
    /// light sample there with its shadow ray: the one-bounce indirect radiance estimate
    /// towards the eye, or `None` where it is zero. Where `si` itself is Dirac (glass,
    /// mirrors), the Dirac vertices on the way are followed as the estimator follows them,
    /// up to its `max_depth`, and light that such a chain meets (an emitter or the
    /// environment) counts: the direct samples stop at the first surface, so without this a
    /// glass sphere's pixel, whose every path enters the glass, was predicted dark and
    /// noiseless.
    fn one_bounce_indirect(
        &self,
        si: &SurfaceInteraction,
        frame: &Frame,
        wo_local: Vec3A,
        material: &crate::material::Material,
        wavelengths: &SampledWavelengths,
        stream: &mut crate::sampler::SampleStream,
    ) -> Option<SampledSpectrum> {
        let lights = &self.scene.lights;
        let bsdf = material.bsdf(si, wavelengths);
        let (mut throughput, wi) = scatter(&bsdf, wo_local, stream)?;
        let mut ray = Ray::spawn(si.p, frame.from_local(wi));
        // Chains only from a Dirac first hit (what a glass or mirror pixel shows). From a
        // rough surface a chain is a caustic that 16 BSDF samples find too rarely to rank
        // pixels by: following those took glossy-env's expected relMSE gain from 1.26 to
        // 1.18 (docs/bandwidth.md, test d).
        let max_vertex = if bsdf.is_specular() {
            self.estimator.max_depth.min(MAX_SPECULAR_CHAIN + 2)
        } else {
            2
        };
        // The vertex the ray leaves (the camera ray's hit is 1) and the Dirac vertices
        // passed since the first bounce.
        let mut vertex = 1;
        let mut dirac_vertices = 0;
        loop {
            let Some(hit) = crate::medium_interfaces::first_surface(self.scene, &ray) else {
                // The direct samples' BSDF sample already sees what the first bounce escapes
                // to; after a Dirac chain, the environment is the estimator's emission.
                if dirac_vertices == 0 {
                    return None;
                }
                let mut radiance = SampledSpectrum::splat(0.0);
                for &l in lights.infinite_lights() {
                    radiance += lights
                        .light(l)
                        .infinite_radiance(ray.direction.normalize(), wavelengths);
                }
                return Some(throughput * radiance);
            };
            let next = self.scene.geometry.shading_interaction(&ray, &hit);
            if let Some(l) = lights.area_light_of_instance(hit.instance_id) {
                if dirac_vertices == 0 {
                    return None;
                }
                let light_hit = LightHit {
                    p: next.p,
                    n: next.n_geometric,
                    uv: next.uv,
                    distance_m: hit.t,
                };
                let le = lights.light(l).emitted_radiance(
                    &light_hit,
                    -ray.direction.normalize(),
                    wavelengths,
                );
                return Some(throughput * le);
            }
            vertex += 1;
            let next_bsdf = self
                .scene
                .material(next.material_id)
                .bsdf(&next, wavelengths);
            let next_frame = Frame::from_zx(next.n_shading, next.dpdu);
            let wo_next = next_frame.to_local(-ray.direction.normalize());
            if next_bsdf.is_specular() {
                if vertex >= max_vertex {
                    return None;
                }
                let (weight, wi) = scatter(&next_bsdf, wo_next, stream)?;
                throughput *= weight;
                ray = Ray::spawn(next.p, next_frame.from_local(wi));
                dirac_vertices += 1;
                continue;
            }
            if vertex > self.estimator.max_depth {
                return None;
            }
            let ctx = LightSampleContext {
                p: next.p,
                n: next.n_geometric,
            };
            let (l, pmf) = lights.sample_at(&ctx, stream.get_1d())?;
            let ls = lights
                .light(l)
                .sample_li(&ctx, stream.get_2d(), wavelengths)?;
            let density = if ls.delta { pmf } else { pmf * ls.pdf };
            if density.is_nan()
                || density <= 0.0
                || self.shadow_ray(&next, &ls) != Visibility::Visible
            {
                return None;
            }
            let wi2 = next_frame.to_local(ls.wi);
            let f2 = next_bsdf.eval(wo_next, wi2, TransportMode::Radiance) * wi2.z.abs();
            return Some(throughput * f2 * ls.radiance * (1.0 / density));
        }
    }

    /// What the shadow ray of light sample `ls` from `si` meets.
    fn shadow_ray(&self, si: &SurfaceInteraction, ls: &crate::light::LightSample) -> Visibility {
        let (ray, metres_per_t) = if ls.distance_m.is_finite() {
            (
                Ray::spawn_to(si.p, ls.p_light),
                (ls.p_light - si.p).length(),
            )
        } else {
            (Ray::spawn(si.p, ls.wi), 1.0)
        };
        match crate::medium_interfaces::first_surface(self.scene, &ray) {
            None => Visibility::Visible,
            Some(hit) => Visibility::Blocked {
                blocker_distance_m: hit.t * metres_per_t,
            },
        }
    }

    /// What a BSDF-sampled direction from `si` meets: the area light it hits (occlusion
    /// by other surfaces counts here, as the render's BSDF samples see it), else every
    /// infinite light along it. `visit(light index, radiance, distance, its hit)` per
    /// emitter (a callback: this runs for every BSDF draw of the probe, without allocating).
    fn for_each_emitter_along(
        &self,
        si: &SurfaceInteraction,
        wi: Vec3A,
        wavelengths: &SampledWavelengths,
        mut visit: impl FnMut(u32, SampledSpectrum, f32, Option<LightHit>),
    ) {
        let lights = &self.scene.lights;
        let ray = Ray::spawn(si.p, wi);
        match crate::medium_interfaces::first_surface(self.scene, &ray) {
            Some(hit) => {
                let Some(l) = lights.area_light_of_instance(hit.instance_id) else {
                    return;
                };
                let hit_si = self.scene.geometry.shading_interaction(&ray, &hit);
                let light_hit = LightHit {
                    p: hit_si.p,
                    n: hit_si.n_geometric,
                    uv: hit_si.uv,
                    distance_m: hit.t,
                };
                let le = lights
                    .light(l)
                    .emitted_radiance(&light_hit, -wi, wavelengths);
                visit(l, le, hit.t, Some(light_hit));
            }
            None => {
                for &l in lights.infinite_lights() {
                    let le = lights.light(l).infinite_radiance(wi, wavelengths);
                    visit(l, le, f32::INFINITY, None);
                }
            }
        }
    }
}

impl ShadingProbe for RenderProbe<'_> {
    fn sample_lights(
        &self,
        pixel: UVec2,
        hit: &GBufferHit,
        count: u32,
        out: &mut Vec<LightSample>,
    ) -> u32 {
        out.clear();
        // The estimator takes a light and a BSDF sample per hit, the probe one of them per
        // draw in turn: two draws make a camera sample, one where the BSDF is Dirac only.
        let mut draws_per_camera_sample = 2;
        let lights = &self.scene.lights;
        if lights.is_empty() {
            return count.div_ceil(draws_per_camera_sample);
        }
        let mis = self.estimator.mis;
        let si = hit_interaction(hit);
        let material = self.scene.material(hit.material_id());
        let texture_t = self.texture_bandwidth_at(hit.material_id(), &si);
        let frame = Frame::from_zx(si.n_shading, si.dpdu);
        let wo_local = frame.to_local(hit.view_direction());
        let ctx = LightSampleContext {
            p: si.p,
            n: si.n_geometric,
        };
        let sampler = PixelSampler::with_kind(SamplerKind::Independent, self.seed);
        // The wavelengths, their CMF weights and the BSDF of the current camera sample.
        let mut camera_sample = None;
        for k in 0..count {
            let mut stream = sampler.stream(pixel, k);
            let u_wavelengths = stream.get_1d();
            // The estimator's light and BSDF samples of one camera sample share its
            // wavelengths, so draws 2j and 2j + 1 share them (and the BSDF built for them,
            // which reads the hit's textures) where a camera sample takes two draws.
            if k % draws_per_camera_sample == 0 {
                camera_sample = None;
            }
            let (wavelengths, xyz, bsdf) = &*camera_sample.get_or_insert_with(|| {
                let wavelengths = SampledWavelengths::sample_rgb_output(u_wavelengths);
                (
                    wavelengths,
                    XyzWeights::new(&wavelengths),
                    material.bsdf(&si, &wavelengths),
                )
            });
            let specular = bsdf.is_specular();
            if specular {
                draws_per_camera_sample = 1;
            }
            // A Dirac-only lobe: light sampling cannot reach it, BSDF sampling alone does.
            let strategy = if specular || k % 2 == 1 {
                ProbeStrategy::Bsdf
            } else {
                ProbeStrategy::Light
            };
            // The share of samples each strategy takes (the mixture's weights).
            let (light_share, bsdf_share) = if specular { (0.0, 1.0) } else { (0.5, 0.5) };
            match strategy {
                ProbeStrategy::Light => {
                    let Some((l, pmf)) = lights.sample_at(&ctx, stream.get_1d()) else {
                        continue;
                    };
                    let light = lights.light(l);
                    let Some(ls) = light.sample_li(&ctx, stream.get_2d(), wavelengths) else {
                        continue;
                    };
                    let wi_local = frame.to_local(ls.wi);
                    let cos = wi_local.z.abs();
                    let f = bsdf.eval(wo_local, wi_local, TransportMode::Radiance) * cos;
                    let mut radiance_y = xyz.y(ls.radiance) as f32;
                    // A delta light's direction has no BSDF density to weigh against.
                    let bsdf_pdf = if ls.delta {
                        0.0
                    } else {
                        bsdf.pdf(wo_local, wi_local, TransportMode::Radiance)
                    };
                    let pdf_per_sr = if ls.delta {
                        // One direction: the estimator's weight divides by the selection.
                        radiance_y /= light_share * pmf;
                        0.0
                    } else {
                        light_share * pmf * ls.pdf + bsdf_share * bsdf_pdf
                    };
                    let divisor = if ls.delta {
                        light_share * pmf
                    } else {
                        pdf_per_sr
                    };
                    let lanes = lane_variance(ls.radiance * f * (1.0 / divisor), xyz);
                    let bsdf_cos_per_sr = reflectance_y(f, xyz);
                    // A sample the BSDF does not scatter towards the eye (the light behind
                    // a reflector) lights nothing, blocked or not: its shadow ray, which
                    // meets the surface's own back, would fake a shadow edge.
                    // The estimator's light sample: its own density, its MIS weight against
                    // the BSDF sample (a delta light's has none, `radiance_y` holds
                    // E/(share·pmf), the estimator divides by the pmf only).
                    let estimator_y = if ls.delta {
                        bsdf_cos_per_sr * radiance_y * light_share
                    } else {
                        let light_pdf = pmf * ls.pdf;
                        bsdf_cos_per_sr * radiance_y * mis_weight(mis, light_pdf, bsdf_pdf)
                            / light_pdf
                    };
                    let visibility = if self.trace_visibility && bsdf_cos_per_sr > 0.0 {
                        self.shadow_ray(&si, &ls)
                    } else {
                        Visibility::Unknown
                    };
                    let (light_bandwidth, emitter_bandwidth) = self.light_bandwidths_towards(
                        l as usize,
                        ls.wi,
                        Some(si.p + ls.wi * ls.distance_m),
                    );
                    out.push(LightSample {
                        direction: ls.wi,
                        radiance_y,
                        pdf_per_sr,
                        bsdf_cos_per_sr,
                        cos_theta_i: cos,
                        distance_m: ls.distance_m,
                        light_bandwidth,
                        emitter_bandwidth,
                        light_index: l,
                        material_bandwidth: self.material_bandwidth_at(
                            hit.material_id(),
                            bsdf,
                            wi_local,
                            wo_local,
                            texture_t,
                        ),
                        lane_variance: lanes,
                        visibility,
                        estimator_y,
                        draw: k / draws_per_camera_sample,
                    });
                }
                ProbeStrategy::Bsdf => {
                    let Some(bs) = bsdf.sample(
                        wo_local,
                        stream.get_1d(),
                        stream.get_2d(),
                        TransportMode::Radiance,
                    ) else {
                        continue;
                    };
                    if bs.pdf.is_nan() || bs.pdf <= 0.0 {
                        continue;
                    }
                    let cos = bs.wi.z.abs();
                    let wi = frame.from_local(bs.wi);
                    self.for_each_emitter_along(
                        &si,
                        wi,
                        wavelengths,
                        |l, le, distance_m, light_hit| {
                            let radiance_y = xyz.y(le) as f32;
                            if radiance_y.is_nan() || radiance_y <= 0.0 {
                                return;
                            }
                            let light_pdf = if bs.specular {
                                0.0
                            } else {
                                self.light_pdf(&ctx, wi, light_hit.as_ref().map(|h| (l, h)))
                            };
                            let (pdf_per_sr, bsdf_cos_per_sr) = if bs.specular {
                                // A Dirac lobe: one direction, weight f cos / (share · P(lobe)).
                                (
                                    0.0,
                                    reflectance_y(bs.f * (cos / (bsdf_share * bs.pdf)), xyz),
                                )
                            } else {
                                (
                                    bsdf_share * bs.pdf + light_share * light_pdf,
                                    reflectance_y(bs.f * cos, xyz),
                                )
                            };
                            let divisor = if bs.specular {
                                bsdf_share * bs.pdf
                            } else {
                                pdf_per_sr
                            };
                            let lanes = lane_variance(le * bs.f * (cos / divisor), xyz);
                            // The estimator's BSDF sample: a Dirac lobe's has no MIS.
                            let estimator_y = if bs.specular {
                                radiance_y * reflectance_y(bs.f * (cos / bs.pdf), xyz)
                            } else {
                                radiance_y * bsdf_cos_per_sr * mis_weight(mis, bs.pdf, light_pdf)
                                    / bs.pdf
                            };
                            let (light_bandwidth, emitter_bandwidth) = self
                                .light_bandwidths_towards(
                                    l as usize,
                                    wi,
                                    light_hit.as_ref().map(|h| h.p),
                                );
                            out.push(LightSample {
                                direction: wi,
                                radiance_y,
                                pdf_per_sr,
                                bsdf_cos_per_sr,
                                cos_theta_i: cos,
                                distance_m,
                                light_bandwidth,
                                emitter_bandwidth,
                                light_index: l,
                                material_bandwidth: self.material_bandwidth_at(
                                    hit.material_id(),
                                    bsdf,
                                    bs.wi,
                                    wo_local,
                                    texture_t,
                                ),
                                lane_variance: lanes,
                                visibility: Visibility::Unknown,
                                estimator_y,
                                draw: k / draws_per_camera_sample,
                            });
                        },
                    );
                }
            }
        }
        count.div_ceil(draws_per_camera_sample)
    }

    fn sample_indirect(
        &self,
        pixel: UVec2,
        hit: &GBufferHit,
        count: u32,
        out: &mut Vec<IndirectEstimate>,
    ) {
        out.clear();
        if self.scene.lights.is_empty() {
            out.resize(count as usize, IndirectEstimate::default());
            return;
        }
        let si = hit_interaction(hit);
        let material = self.scene.material(hit.material_id());
        let frame = Frame::from_zx(si.n_shading, si.dpdu);
        let wo_local = frame.to_local(hit.view_direction());
        let sampler = PixelSampler::with_kind(SamplerKind::Independent, self.seed);
        for k in 0..count {
            // Streams apart from `sample_lights`' (indices 0..count).
            let mut stream = sampler.stream(pixel, INDIRECT_STREAM_OFFSET + k);
            let wavelengths = SampledWavelengths::sample_rgb_output(stream.get_1d());
            out.push(
                self.one_bounce_indirect(
                    &si,
                    &frame,
                    wo_local,
                    material,
                    &wavelengths,
                    &mut stream,
                )
                .map_or(IndirectEstimate::default(), |l| {
                    let xyz = XyzWeights::new(&wavelengths);
                    IndirectEstimate {
                        radiance_y: xyz.y(l) as f32,
                        lane_variance: lane_variance(l, &xyz),
                    }
                }),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_geometry::Curvature;
    use prism_scene::parse_scene_str;

    #[test]
    fn probe_at_a_lambertian_hit_under_a_point_light_gives_i_over_d2_and_one_over_pi() {
        let json = r#"{"materials": {"white": {"type": "lambert", "reflectance": 1.0}},
            "shapes": [{"type": "sphere", "material": "white"}],
            "lights": [{"type": "point", "position_m": [0, 3, 0], "spectrum": 1.0, "scale": 2.0}]}"#;
        let scene = RenderScene::build(&parse_scene_str(json, "t.json").unwrap(), None).unwrap();
        let probe = RenderProbe::new(&scene, 1);
        let hit = top_of_the_unit_sphere();
        let mut out = Vec::new();
        probe.sample_lights(UVec2::new(3, 4), &hit, 64, &mut out);
        // Every other sample is a BSDF sample, which never finds a point light.
        assert_eq!(out.len(), 32);
        let values: Vec<f64> = out.iter().map(|s| f64::from(s.radiance_y)).collect();
        let mean_radiance = values.iter().sum::<f64>() / 32.0;
        let sd = (values
            .iter()
            .map(|v| (v - mean_radiance).powi(2))
            .sum::<f64>()
            / 31.0)
            .sqrt();
        // I/d² = 2/4 at the hit, divided by the light strategy's share ½ (the sample's
        // weight in the mixture); Y of a flat spectrum is exact in expectation: 5 standard
        // errors of the hero-wavelength estimate.
        assert!(
            (mean_radiance - 1.0).abs() < 5.0 * sd / 32f64.sqrt(),
            "{mean_radiance} (sd {sd})"
        );
        for s in &out {
            assert!(s.is_delta());
            assert!((s.bsdf_cos_per_sr - 1.0 / std::f32::consts::PI).abs() < 1e-4);
            assert!((s.distance_m - 2.0).abs() < 1e-5);
            assert_eq!(s.material_bandwidth.angular_cycles_per_rad, 0.0);
            assert_eq!(s.light_bandwidth, Bandwidth::POINT_LIGHT);
        }
        // Deterministic per pixel.
        let mut again = Vec::new();
        probe.sample_lights(UVec2::new(3, 4), &hit, 64, &mut again);
        assert_eq!(out, again);
    }

    /// The G-buffer hit at the top of the unit sphere (material 0), seen from 2 m above.
    fn top_of_the_unit_sphere() -> GBufferHit {
        GBufferHit::new(
            Vec3A::new(0.0, 1.0, 0.0),
            2.0,
            Vec3A::Y,
            Curvature::default(),
            Vec3A::Y,
            0,
        )
        .unwrap()
    }

    /// A white Lambertian unit sphere under a 0.5 m square lamp 3 m above its centre.
    fn sphere_under_a_lamp() -> RenderScene {
        let json = r#"{"materials": {"white": {"type": "lambert", "reflectance": 0.8},
                "black": {"type": "lambert", "reflectance": 0.0}},
            "shapes": [{"type": "sphere", "material": "white"},
                {"type": "rectangle", "name": "lamp", "size_m": [0.5, 0.5], "material": "black",
                 "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}},
                               {"translate": [0, 3, 0]}]}],
            "lights": [{"type": "area", "shape": "lamp", "spectrum": 1.0}]}"#;
        RenderScene::build(&parse_scene_str(json, "t.json").unwrap(), None).unwrap()
    }

    /// Shadow rays only where the BSDF scatters the light towards the eye: under a lamp, the
    /// bottom of a sphere sees the lamp from behind, and its shadow rays, which would meet
    /// the sphere itself, are not traced (they faked a shadow edge along the terminator).
    /// The samples that are traced carry the lamp's size, 1/√A, for the penumbra.
    #[test]
    fn shadow_rays_are_traced_only_for_samples_that_light_the_hit() {
        let scene = sphere_under_a_lamp();
        let mut probe = RenderProbe::new(&scene, 1);
        probe.trace_visibility = true;
        let hit_facing = |y: f32| {
            GBufferHit::new(
                Vec3A::new(0.0, y, 0.0),
                2.0,
                Vec3A::new(0.0, y, 0.0),
                Curvature::default(),
                Vec3A::new(0.0, y, 0.0),
                0,
            )
            .unwrap()
        };
        let mut out = Vec::new();
        probe.sample_lights(UVec2::ZERO, &hit_facing(-1.0), 32, &mut out);
        assert!(!out.is_empty());
        assert!(out
            .iter()
            .all(|s| s.bsdf_cos_per_sr == 0.0 && s.visibility == Visibility::Unknown));
        probe.sample_lights(UVec2::ZERO, &hit_facing(1.0), 32, &mut out);
        let lit: Vec<_> = out
            .iter()
            .filter(|s| s.visibility == Visibility::Visible)
            .collect();
        assert!(!lit.is_empty());
        for s in lit {
            assert!((s.emitter_bandwidth.spatial_cycles_per_m - 2.0).abs() < 1e-5);
        }
    }

    /// A draw pairs a light and a BSDF sample as the path tracer does, each MIS-weighted:
    /// the draws' mean is the reflected radiance, as the one-sample mixture's mean is (5
    /// standard errors), and under a small lamp their variance is a fraction of the
    /// mixture's, whose BSDF half finds the lamp rarely and whose light half counts double.
    #[test]
    fn draws_pair_a_light_and_a_bsdf_sample_with_the_estimators_weights() {
        let scene = sphere_under_a_lamp();
        let probe = RenderProbe::new(&scene, 5);
        assert_eq!(probe.estimator.mis, MisHeuristic::Power);
        let hit = top_of_the_unit_sphere();
        let mut out = Vec::new();
        let n = 8192u32;
        let draws = probe.sample_lights(UVec2::ZERO, &hit, n, &mut out);
        assert_eq!(draws, n / 2);
        let mut draw_values = vec![0.0f64; draws as usize];
        for s in &out {
            draw_values[s.draw as usize] += f64::from(s.estimator_y);
        }
        let mut mixture = vec![0.0f64; n as usize];
        for (slot, s) in mixture.iter_mut().zip(&out) {
            *slot = f64::from(s.weight_y());
        }
        let mean_sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
            (m, var)
        };
        let (draw_mean, draw_var) = mean_sd(&draw_values);
        let (mix_mean, mix_var) = mean_sd(&mixture);
        let se = (draw_var / f64::from(draws) + mix_var / f64::from(n)).sqrt();
        assert!(draw_mean > 0.0);
        assert!(
            (draw_mean - mix_mean).abs() < 5.0 * se,
            "{draw_mean} vs {mix_mean} (s.e. {se})"
        );
        assert!(draw_var < 0.25 * mix_var, "{draw_var} vs {mix_var}");
    }

    /// One bounce of indirect light inside a Lambertian sphere (albedo a, radius R) around a
    /// point light of intensity I at its centre: every wall point leaves L_o = a I/(π R²),
    /// so the indirect radiance at the wall is a·L_o = a² I/(π R²) (0.159 for a = ½, I = 2,
    /// R = 1), within 5 standard errors.
    #[test]
    fn indirect_estimates_inside_a_lambertian_sphere_match_the_closed_form() {
        let json = r#"{"materials": {"grey": {"type": "lambert", "reflectance": 0.5},
                "inside": {"type": "two_sided", "material": "grey"}},
            "shapes": [{"type": "sphere", "radius_m": 1.0, "material": "inside"}],
            "lights": [{"type": "point", "position_m": [0, 0, 0], "spectrum": 1.0, "scale": 2.0}]}"#;
        let scene = RenderScene::build(&parse_scene_str(json, "t.json").unwrap(), None).unwrap();
        let probe = RenderProbe::new(&scene, 7);
        let hit = GBufferHit::new(
            Vec3A::new(0.0, -1.0, 0.0),
            0.5,
            Vec3A::Y,
            Curvature::default(),
            Vec3A::Y,
            1,
        )
        .unwrap();
        let n = 4096;
        let mut out = Vec::new();
        probe.sample_indirect(UVec2::new(1, 2), &hit, n, &mut out);
        assert_eq!(out.len(), n as usize);
        let values: Vec<f64> = out.iter().map(|v| f64::from(v.radiance_y)).collect();
        let mean = values.iter().sum::<f64>() / f64::from(n);
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f64::from(n - 1)).sqrt();
        let expected = 0.25 * 2.0 / std::f64::consts::PI;
        assert!(
            (mean - expected).abs() < 5.0 * sd / f64::from(n).sqrt(),
            "{mean} vs {expected} (sd {sd})"
        );
        let mut again = Vec::new();
        probe.sample_indirect(UVec2::new(1, 2), &hit, n, &mut again);
        assert_eq!(out, again);
    }

    /// Light through a Dirac chain: a smooth glass sphere (η 1.5) under a uniform sky of
    /// radiance 1 (over the whole sphere), hit at its top from above. The direct samples
    /// see only the Fresnel reflection (F(0) = 0.04); every refracted path leaves the glass
    /// again, after any number of internal reflections, to the sky, so the indirect
    /// estimate's mean is 1 − F(0) = 0.96 (radiance invariance), within 5 standard errors.
    /// Before the chain was followed it was 0: the refracted ray meets the sphere's inside,
    /// a Dirac surface, where no light sample can be taken.
    #[test]
    fn indirect_estimates_follow_dirac_chains_through_glass() {
        let json = r#"{"materials": {"glass": {"type": "dielectric", "ior": 1.5}},
            "integrator": {"type": "path", "max_depth": 12},
            "shapes": [{"type": "sphere", "radius_m": 1.0, "material": "glass"}],
            "lights": [{"type": "sky", "spectrum": 1.0}]}"#;
        let scene = RenderScene::build(&parse_scene_str(json, "t.json").unwrap(), None).unwrap();
        let probe = RenderProbe::new(&scene, 5);
        let hit = top_of_the_unit_sphere();
        let n = 4096;
        let mut out = Vec::new();
        probe.sample_indirect(UVec2::new(2, 2), &hit, n, &mut out);
        let values: Vec<f64> = out.iter().map(|v| f64::from(v.radiance_y)).collect();
        let mean = values.iter().sum::<f64>() / f64::from(n);
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f64::from(n - 1)).sqrt();
        let expected = 1.0 - 0.04;
        assert!(
            (mean - expected).abs() < 5.0 * sd / f64::from(n).sqrt(),
            "{mean} vs {expected} (sd {sd})"
        );
        // The estimator's depth bounds the chain: with max_depth 1 nothing is indirect, and
        // the predictor takes no indirect samples (`ProbedEstimator::carries_indirect`).
        assert!(probe.estimator.carries_indirect());
    }

    /// The mixture's weights are an unbiased estimate of the reflected radiance: a
    /// Lambertian plane (a = 0.6) under a uniform sky of radiance 1 reflects 0.6; a glossy
    /// aluminium lobe reflects its directional albedo (between 0.3 and 1).
    #[test]
    fn mixture_weights_estimate_the_reflected_radiance() {
        for (material, expected) in [
            (r#"{"type": "lambert", "reflectance": 0.6}"#, Some(0.6)),
            (
                r#"{"type": "conductor", "metal": "Al", "roughness": 0.2}"#,
                None,
            ),
        ] {
            let json = format!(
                r#"{{"materials": {{"m": {material}}},
                "shapes": [{{"type": "rectangle", "size_m": [1, 1], "material": "m"}}],
                "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
            );
            let scene =
                RenderScene::build(&parse_scene_str(&json, "t.json").unwrap(), None).unwrap();
            let probe = RenderProbe::new(&scene, 7);
            let view = Vec3A::new(0.3, 0.0, 1.0).normalize();
            let hit =
                GBufferHit::new(Vec3A::ZERO, 2.0, Vec3A::Z, Curvature::default(), view, 0).unwrap();
            let n = 4096u32;
            let mut out = Vec::new();
            let (mut sum, mut sum_sq) = (0.0, 0.0);
            for pixel in 0..n / 16 {
                probe.sample_lights(UVec2::new(pixel, 0), &hit, 16, &mut out);
                // The probe alternates strategies; each sample's weight is the mixture's.
                for s in &out {
                    let w = f64::from(s.weight_y());
                    sum += w;
                    sum_sq += w * w;
                }
            }
            // All samples of both strategies together (n of them) estimate the integral.
            let mean = sum / f64::from(n);
            let sd = (sum_sq / f64::from(n) - mean * mean).max(0.0).sqrt();
            let tolerance = 4.0 * sd / f64::from(n).sqrt() + 1e-3;
            match expected {
                Some(e) => assert!((mean - e).abs() < tolerance, "{material}: {mean} vs {e}"),
                None => assert!(mean > 0.3 && mean < 1.0, "{material}: {mean}"),
            }
        }
    }
}
