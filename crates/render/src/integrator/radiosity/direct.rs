//! The solution's direct light from the lights that are not patches: point, spot,
//! goniometric and directional lights (one shadow ray each) and skies and environment
//! maps (`SKY_DIRECTIONS` stratified directions, the same at every point so that the
//! estimate varies smoothly over a surface and the refinement sees shadows, not noise):
//! irradiance per band with shadows, by the same light sampling and shadow rays as the
//! path tracer's next-event estimation.

use glam::{Vec2, Vec3A};
use prism_radiosity::DirectIrradiance;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

use super::patches::PatchMap;
use crate::integrator::{PathCounters, PathTracer};
use crate::light::LightSampleContext;
use crate::scene_build::RenderScene;

/// Wavelengths per 25 nm averaged (a band's mean of a spiky lamp spectrum): 4 per band
/// of the default 25 nm, fewer (at least 1) in narrower bands.
const POINTS_PER_25_NM: f64 = 4.0;

/// Directions per point and sky (importance-sampled by the light, R2-stratified).
const SKY_DIRECTIONS: u32 = 64;

pub struct PointLikeAndSkyLights<'a> {
    scene: &'a RenderScene,
    /// Points of tiled carriers are lit above their tile's slab, of meshed spheres on the
    /// sphere.
    map: &'a PatchMap,
    /// Indices of the delta lights in the scene's light set.
    lights: Vec<u32>,
    /// Indices of the skies and environment maps.
    skies: Vec<u32>,
    /// The band wavelengths in groups of the four lanes (the last group padded with its
    /// last wavelength).
    wavelength_sets: Vec<SampledWavelengths>,
    /// Wavelengths per band (the first `points_per_band × bands` lanes are not padding).
    points_per_band: usize,
}

impl<'a> PointLikeAndSkyLights<'a> {
    pub fn new(scene: &'a RenderScene, map: &'a PatchMap) -> Self {
        let lights = (0..scene.lights.len() as u32)
            .filter(|&l| scene.lights.light(l).is_delta())
            .collect();
        let skies = scene.lights.infinite_lights().to_vec();
        let bands = map.bands;
        let points_per_band =
            ((POINTS_PER_25_NM * bands.width_nm / 25.0).round() as usize).clamp(1, 4);
        let all: Vec<f32> = (0..bands.count * points_per_band)
            .map(|i| {
                bands.point_nm(i / points_per_band, i % points_per_band, points_per_band) as f32
            })
            .collect();
        let wavelength_sets = all
            .chunks(N_SPECTRUM_SAMPLES)
            .map(|c| {
                let lambda = std::array::from_fn(|k| c[k.min(c.len() - 1)]);
                SampledWavelengths::new(lambda, SampledSpectrum::splat(1.0))
            })
            .collect();
        Self {
            scene,
            map,
            lights,
            skies,
            wavelength_sets,
            points_per_band,
        }
    }
}

impl DirectIrradiance for PointLikeAndSkyLights<'_> {
    fn irradiance(&self, p: Vec3A, n: Vec3A, out: &mut [f32]) {
        let ctx = self.context(p, n);
        self.for_each_sample(|l, u, weight| {
            self.add_direction(l, &ctx, u, weight, out);
        });
    }

    /// The same arrivals one by one, with the direction each comes from (a tiled
    /// carrier's points bin them).
    fn irradiance_by_direction(
        &self,
        p: Vec3A,
        n: Vec3A,
        bands: usize,
        add: &mut dyn FnMut(Vec3A, &[f32]),
    ) {
        let ctx = self.context(p, n);
        let mut one = vec![0.0f32; bands];
        self.for_each_sample(|l, u, weight| {
            one.fill(0.0);
            if let Some(wi) = self.add_direction(l, &ctx, u, weight, &mut one) {
                add(wi, &one);
            }
        });
    }
}

impl PointLikeAndSkyLights<'_> {
    /// The point `p` (normal `n`) where its rays start (`PatchMap::lift`).
    fn context(&self, p: Vec3A, n: Vec3A) -> LightSampleContext {
        LightSampleContext {
            p: self.map.lift(p, n).unwrap_or(p),
            n,
        }
    }

    /// Every light sample a point takes, as (light, sample, weight): one per delta light,
    /// `SKY_DIRECTIONS` per sky (the same stratified directions at every point).
    fn for_each_sample(&self, mut sample: impl FnMut(u32, Vec2, f32)) {
        for &l in &self.lights {
            sample(l, Vec2::splat(0.5), 1.0);
        }
        for &l in &self.skies {
            for k in 0..SKY_DIRECTIONS {
                let (a, b) = prism_radiosity::r2(k, 0);
                sample(l, Vec2::new(a, b), 1.0 / SKY_DIRECTIONS as f32);
            }
        }
    }
}

impl PointLikeAndSkyLights<'_> {
    /// Adds weight · L cos θ / pdf of light `l`'s sample `u` when it is above the surface
    /// and unshadowed (one shadow ray serves every wavelength: media, glazing and masks
    /// are refused); the direction towards the light when it added.
    fn add_direction(
        &self,
        l: u32,
        ctx: &LightSampleContext,
        u: Vec2,
        weight: f32,
        out: &mut [f32],
    ) -> Option<Vec3A> {
        let light = self.scene.lights.light(l);
        let first = light.sample_li(ctx, u, &self.wavelength_sets[0])?;
        let cos = first.wi.dot(ctx.n);
        if cos <= 0.0 || first.pdf.is_nan() || first.pdf <= 0.0 {
            return None;
        }
        let mut counters = PathCounters::default();
        let t = PathTracer::default().transmittance(
            self.scene,
            ctx.p,
            &first,
            &self.wavelength_sets[0],
            &mut counters,
        );
        if t.is_black() {
            return None;
        }
        self.add_sample(light, ctx, u, cos, weight, out);
        Some(first.wi)
    }

    /// Adds weight · L cos θ / pdf of `light`'s sample `u` at every band wavelength.
    fn add_sample(
        &self,
        light: &crate::light::Light,
        ctx: &LightSampleContext,
        u: Vec2,
        cos: f32,
        weight: f32,
        out: &mut [f32],
    ) {
        for (set, wavelengths) in self.wavelength_sets.iter().enumerate() {
            let Some(ls) = light.sample_li(ctx, u, wavelengths) else {
                continue;
            };
            if ls.pdf.is_nan() || ls.pdf <= 0.0 {
                continue;
            }
            let points = self.points_per_band;
            for lane in 0..N_SPECTRUM_SAMPLES {
                let band = (set * N_SPECTRUM_SAMPLES + lane) / points;
                if band < self.map.bands.count {
                    out[band] += weight * ls.radiance[lane] * cos / ls.pdf / points as f32;
                }
            }
        }
    }
}
