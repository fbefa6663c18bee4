//! Shared helpers of the emitter tests: scenes from JSON, the hit a ray finds on an area
//! light (what the path tracer passes to `pdf_li`), chi-square runs of `sample_li` against
//! `pdf_li`, photometric sums over wavelength and Monte Carlo means with standard errors.

use std::path::Path;

use glam::{Vec2, Vec3A};
use prism_geometry::{Geometry, Ray};
use prism_spectrum::constants::K_M_PHOTOPIC_LM_PER_W;
use prism_spectrum::data::cmfs;
use prism_spectrum::{Observer, SampledSpectrum, SampledWavelengths};

use super::{Light, LightHit, LightSampleContext, LightSet};
use crate::scene_build::{build_geometry_with_instances, SceneBuildError};
use prism_testkit::chi2::{chi2_test_adaptive, Chi2Config, Chi2Result};

/// Geometry and lights of a scene given as JSON, as if it were the file `dir/scene.json`.
pub fn build_scene(dir: &Path, json: &str) -> Result<(Geometry, LightSet), SceneBuildError> {
    let scene = prism_scene::parse_scene_str(json, dir.join("scene.json"))
        .unwrap_or_else(|e| panic!("test scene does not parse: {e}"));
    let (geometry, ranges) = build_geometry_with_instances(&scene)?;
    let lights = LightSet::build_with_instances(&scene, &geometry, &ranges)?;
    Ok((geometry, lights))
}

/// The error message of a scene that must fail to build.
pub fn build_error(dir: &Path, json: &str) -> String {
    match build_scene(dir, json) {
        Ok(_) => panic!("expected the scene to fail: {json}"),
        Err(e) => e.to_string(),
    }
}

/// The first hit along `w` from `p`, as the `LightHit` of the area light it carries.
pub fn area_hit(
    geometry: &Geometry,
    lights: &LightSet,
    p: Vec3A,
    w: Vec3A,
) -> Option<(u32, LightHit)> {
    let ray = Ray::new(p, w, 0.0, f32::INFINITY);
    let hit = geometry.intersect(&ray)?;
    let light = lights.area_light_of_instance(hit.instance_id)?;
    let si = geometry.interaction(&ray, &hit);
    Some((
        light,
        LightHit {
            p: si.p,
            n: si.n_geometric,
            uv: si.uv,
            distance_m: hit.t,
        },
    ))
}

/// χ² of light `index`'s `sample_li` at `ctx` against its `pdf_li`, finding area hits
/// through `geometry` as the integrator does.
pub fn chi2_light(
    config: &Chi2Config,
    geometry: &Geometry,
    lights: &LightSet,
    index: u32,
    ctx: LightSampleContext,
) -> Chi2Result {
    let light = lights.light(index);
    let wl = SampledWavelengths::sample_uniform(0.5);
    chi2_test_adaptive(
        config,
        |_, u| {
            let s = light.sample_li(&ctx, u, &wl)?;
            assert!(
                s.pdf > 0.0 && s.pdf.is_finite() && !s.radiance.has_non_finite(),
                "{s:?}"
            );
            (!s.delta).then_some(s.wi)
        },
        |w| {
            if matches!(light, Light::Area(_)) {
                match area_hit(geometry, lights, ctx.p, w) {
                    Some((l, hit)) if l == index => f64::from(light.pdf_li(&ctx, w, Some(&hit))),
                    _ => 0.0,
                }
            } else {
                f64::from(light.pdf_li(&ctx, w, None))
            }
        },
    )
}

/// K_m Σ f(λ) ȳ(λ) Δλ over 360–830 nm at 1 nm, with `f` evaluated four wavelengths at a
/// time: the photometric value of a spectral quantity that `f` returns.
pub fn photometric_sum(mut f: impl FnMut(&SampledWavelengths) -> SampledSpectrum) -> f64 {
    let y = &cmfs(Observer::Cie1931).y_bar;
    let mut sum = 0.0;
    let mut wl = 360usize;
    while wl <= 830 {
        let lambda = std::array::from_fn(|i| (wl + i).min(830) as f32);
        let values = f(&SampledWavelengths::new(
            lambda,
            SampledSpectrum::splat(1.0),
        ));
        for (i, v) in values.to_array().iter().enumerate() {
            if wl + i <= 830 {
                sum += f64::from(*v) * y.eval((wl + i) as f64);
            }
        }
        wl += 4;
    }
    K_M_PHOTOPIC_LM_PER_W * sum
}

/// Mean and standard error of `n` values of `f(u₁, u₂)` with fixed-seed variates.
pub fn mean_and_standard_error(n: usize, seed: u64, mut f: impl FnMut(Vec2) -> f64) -> (f64, f64) {
    let mut rng = prism_testkit::chi2::SplitMix64(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let v = f(Vec2::new(rng.next_f32(), rng.next_f32()));
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0) * n as f64 / (n as f64 - 1.0);
    (mean, (var / n as f64).sqrt())
}

/// Irradiance (lane 0 of a spectrum-flat light) at `ctx` from `light` by light sampling:
/// E = mean of L · max(cos θ, 0) / pdf, with its standard error.
pub fn irradiance_estimate(
    light: &Light,
    ctx: LightSampleContext,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    let wl = SampledWavelengths::sample_uniform(0.5);
    mean_and_standard_error(n, seed, |u| match light.sample_li(&ctx, u, &wl) {
        Some(s) => {
            let cos = f64::from(s.wi.dot(ctx.n).max(0.0));
            f64::from(s.radiance.to_array()[0]) * cos / f64::from(s.pdf)
        }
        None => 0.0,
    })
}

/// A chi-square configuration for `tests` tests sharing a 1 % family-wise error rate.
pub fn chi2_config(tests: usize, seed: u64) -> Chi2Config {
    Chi2Config {
        theta_bins: 12,
        sample_count: 400_000,
        integration_resolution: 8,
        significance: prism_testkit::chi2::sidak(0.01, tests),
        seed,
        ..Chi2Config::default()
    }
}
