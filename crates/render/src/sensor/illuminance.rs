//! One Monte Carlo sample of the illuminance at a point, E = ∫_{H²(n)} L_i(ω) cos θ dω in lux.
//!
//! Two strategies, combined by multiple importance sampling (Veach 1997, ch. 9) exactly as
//! the path tracer combines light and BSDF sampling at a vertex — the sensor is a
//! vertex whose "BSDF" is the cosine (a white Lambertian receiver scaled by π):
//!
//! - next-event estimation: a light chosen in proportion to power, a direction from its
//!   `sample_li`, a shadow ray; weight L cos θ / p_light · w_light;
//! - a cosine-weighted direction (pdf cos θ / π) whose incoming radiance is the path
//!   tracer's (`PathTracer::radiance_from`, which MIS-weights the emission the ray meets
//!   against light sampling from this point and carries on through every bounce); weight
//!   L · π.
//!
//! Any light works, infinite ones (sky, environment, sun) included. Wavelengths are hero
//! wavelengths (Wilkie et al. 2014) drawn from the visible-range pdf; the spectral
//! irradiance becomes lux with the CIE 1931 ȳ and K_m = 683.002 lm/W
//! (`film::xyz` normalisation × `cd_m2_per_unit`).

use std::f32::consts::{FRAC_1_PI, PI};

use glam::Vec3A;
use prism_geometry::{Frame, Ray};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::SensorTracer;
use crate::film::xyz::{cd_m2_per_unit, xyz_of_sample};
use crate::integrator::{mis_weight, LaneWavelengths, PathCounters, PathOrigin, SolutionGather};
use crate::light::LightSampleContext;
use crate::sampler::SampleStream;
use crate::sampling::sample_cosine_hemisphere;
use crate::scene_build::RenderScene;

/// One illuminance sample in lux at `p` (metres, world) for a receiver facing `n` (unit),
/// with `light_samples` light samples here and at every path vertex. Draws 1 (wavelength)
/// + 2 (direction) + 3 per light sample dimensions, then the path's.
#[allow(clippy::too_many_arguments)]
pub fn sample_illuminance_lx(
    sensor_tracer: &SensorTracer,
    scene: &RenderScene,
    p: Vec3A,
    n: Vec3A,
    light_samples: u32,
    stream: &mut SampleStream,
    counters: &mut PathCounters,
) -> f64 {
    let tracer = &sensor_tracer.path;
    let gather = sensor_tracer
        .gather
        .as_deref()
        .map(|g| g as &dyn SolutionGather);
    let mut wavelengths = LaneWavelengths::new(SampledWavelengths::sample_visible(stream.get_1d()));
    let u_dir = stream.get_2d();
    let ctx = LightSampleContext { p, n };
    let lights = &scene.lights;
    let mut e = SampledSpectrum::splat(0.0);
    let n_light = light_samples.max(1);

    // Next-event estimation: `n_light` light samples, the choice stratified over the
    // selection CDF (see `PathTracer::radiance_from`), averaged. The choice is the path
    // tracer's at a shading point (`sample_at`): the cosine ray below weighs the emission
    // it meets against that choice's probabilities (`PathTracer::emission_weight`).
    for k in 0..n_light {
        let u_choice = ((k as f32 + stream.get_1d()) / n_light as f32).min(1.0 - f32::EPSILON);
        let u_light = stream.get_2d();
        let Some((l, pmf)) = lights.sample_at(&ctx, u_choice) else {
            continue;
        };
        if let Some(ls) = lights
            .light(l)
            .sample_li(&ctx, u_light, wavelengths.transport())
        {
            let cos = ls.wi.dot(n);
            if cos > 0.0 && ls.pdf > 0.0 && !ls.radiance.is_black() {
                counters.rays += 1;
                let t = tracer.transmittance(scene, p, &ls, wavelengths.transport(), counters);
                if !t.is_black() {
                    let light_pdf = pmf * ls.pdf;
                    let w = if ls.delta {
                        1.0
                    } else {
                        mis_weight(tracer.mis, light_pdf, cos * FRAC_1_PI)
                    };
                    let c = ls.radiance * t * (cos * w / (light_pdf * n_light as f32));
                    if c.has_non_finite() {
                        counters.non_finite_contributions += 1;
                    } else {
                        e += c;
                    }
                }
            }
        }
    }

    // A cosine-weighted direction and the radiance arriving along it.
    let local = sample_cosine_hemisphere(u_dir);
    let pdf = local.z * FRAC_1_PI;
    if pdf > 0.0 {
        let wi = Frame::from_z(n).from_local(local).normalize();
        let ray = Ray::spawn(p, wi);
        counters.rays += 1;
        let r = tracer.radiance_from(
            scene,
            &ray,
            Some(PathOrigin {
                ctx,
                direction_pdf: pdf,
            }),
            &mut wavelengths,
            stream,
            n_light,
            false,
            counters,
            gather,
        );
        // cos θ / pdf = π.
        e += r.radiance * PI;
    }
    if e.has_non_finite() {
        counters.non_finite_contributions += 1;
        return 0.0;
    }
    xyz_of_sample(e, wavelengths.sensor()).y * cd_m2_per_unit()
}
