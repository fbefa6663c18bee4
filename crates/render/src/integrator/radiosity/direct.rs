//! The solution's direct light from the lights that are not patches (point, spot,
//! goniometric and directional lights): irradiance per band with shadows, by the same
//! light sampling and shadow rays as the path tracer's next-event estimation.

use glam::{Vec2, Vec3A};
use prism_radiosity::DirectIrradiance;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

use super::patches::{BANDS, BAND_WIDTH_NM, FIRST_BAND_NM};
use crate::integrator::{PathCounters, PathTracer};
use crate::light::LightSampleContext;
use crate::scene_build::RenderScene;

/// Wavelengths per band averaged (a band's mean of a spiky lamp spectrum).
const POINTS_PER_BAND: usize = 4;

pub struct DeltaLights<'a> {
    scene: &'a RenderScene,
    /// Indices of the delta lights in the scene's light set.
    lights: Vec<u32>,
    /// The band wavelengths in groups of the four lanes.
    wavelength_sets: Vec<SampledWavelengths>,
}

impl<'a> DeltaLights<'a> {
    pub fn new(scene: &'a RenderScene) -> Self {
        let lights = (0..scene.lights.len() as u32)
            .filter(|&l| scene.lights.light(l).is_delta())
            .collect();
        let all: Vec<f32> = (0..BANDS * POINTS_PER_BAND)
            .map(|i| {
                let (band, k) = (i / POINTS_PER_BAND, i % POINTS_PER_BAND);
                (FIRST_BAND_NM
                    + BAND_WIDTH_NM * (band as f64 + (k as f64 + 0.5) / POINTS_PER_BAND as f64))
                    as f32
            })
            .collect();
        let wavelength_sets = all
            .chunks(N_SPECTRUM_SAMPLES)
            .map(|c| {
                let mut lambda = [0.0; N_SPECTRUM_SAMPLES];
                lambda.copy_from_slice(c);
                SampledWavelengths::new(lambda, SampledSpectrum::splat(1.0))
            })
            .collect();
        Self {
            scene,
            lights,
            wavelength_sets,
        }
    }
}

impl DirectIrradiance for DeltaLights<'_> {
    fn irradiance(&self, p: Vec3A, n: Vec3A, out: &mut [f32]) {
        let ctx = LightSampleContext { p, n };
        let tracer = PathTracer::default();
        let mut counters = PathCounters::default();
        for &l in &self.lights {
            let light = self.scene.lights.light(l);
            let u = Vec2::splat(0.5);
            let Some(first) = light.sample_li(&ctx, u, &self.wavelength_sets[0]) else {
                continue;
            };
            let cos = first.wi.dot(n);
            if cos <= 0.0 || first.pdf <= 0.0 {
                continue;
            }
            // One shadow ray serves every wavelength (no medium, glazing or mask: refused).
            let t = tracer.transmittance(
                self.scene,
                p,
                &first,
                &self.wavelength_sets[0],
                &mut counters,
            );
            if t.is_black() {
                continue;
            }
            for (set, wavelengths) in self.wavelength_sets.iter().enumerate() {
                let Some(ls) = light.sample_li(&ctx, u, wavelengths) else {
                    continue;
                };
                for lane in 0..N_SPECTRUM_SAMPLES {
                    let band = (set * N_SPECTRUM_SAMPLES + lane) / POINTS_PER_BAND;
                    out[band] += ls.radiance[lane] * cos / ls.pdf / POINTS_PER_BAND as f32;
                }
            }
        }
    }
}
