//! The path tracer against closed-form irradiance (issue 4 checks): a point source over a
//! diffuse plane, E = I cos θ / d², seen through an orthographic camera so every pixel's
//! radiance is L = (R/π) E (Lambert). Constant spectra give Y = L exactly (the output
//! normalisation of docs/architecture.md), so the only noise is hero-wavelength sampling of Y, and the
//! tolerance comes from the pixels' own spread (standard error of the mean over pixels,
//! plus a per-pixel bound at 6σ).

use prism_render::{render, FilmImage, RenderScene, RenderSettings};
use prism_scene::parse_scene_str;

fn render_json(json: &str, spp: u32, seed: u64) -> (FilmImage, prism_render::RenderStats) {
    let description = parse_scene_str(json, "test.json").expect("test scene parses");
    let scene = RenderScene::build(&description, None).expect("test scene builds");
    let sampler = match description.integrator {
        prism_scene::Integrator::Path { sampler, .. } => sampler,
        _ => prism_render::SamplerKind::Sobol,
    };
    let settings = RenderSettings {
        spp,
        seed,
        sampler,
        ..RenderSettings::default()
    };
    render(&scene, &settings, &|_| {})
}

/// Mean of f over the pixel (i, j) of an n×n film covering [−half, half]² (8×8 midpoints).
fn pixel_mean(n: u32, half_m: f64, i: u32, j: u32, f: impl Fn(f64, f64) -> f64) -> f64 {
    let px = 2.0 * half_m / f64::from(n);
    let mut sum = 0.0;
    for a in 0..8 {
        for b in 0..8 {
            let x = -half_m + (f64::from(i) + (f64::from(a) + 0.5) / 8.0) * px;
            let z = -half_m + (f64::from(j) + (f64::from(b) + 0.5) / 8.0) * px;
            sum += f(x, z);
        }
    }
    sum / 64.0
}

/// Checks `image.y` against `expected` (row-major) pixel by pixel: mean relative error within
/// 5 standard errors, each pixel within 6σ of the spread, and the spread itself small.
fn assert_matches(image: &FilmImage, expected: &[f64], max_sigma: f64) {
    let rel: Vec<f64> = image
        .y
        .iter()
        .zip(expected)
        .map(|(&v, &a)| (f64::from(v) - a) / a)
        .collect();
    let n = rel.len() as f64;
    let mean = rel.iter().sum::<f64>() / n;
    let sigma = (rel.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let worst = rel.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    eprintln!("mean rel. error {mean:.2e}, σ {sigma:.2e}, worst {worst:.2e}");
    assert!(
        sigma < max_sigma,
        "per-pixel noise σ = {sigma} above {max_sigma}"
    );
    assert!(
        mean.abs() < 5.0 * sigma / n.sqrt() + 1e-4,
        "biased: mean relative error {mean} (σ/√n = {})",
        sigma / n.sqrt()
    );
    assert!(worst < 6.0 * sigma + 1e-3, "worst pixel {worst}, σ {sigma}");
}

const N: u32 = 32;

fn point_light_scene(sampler: &str, height_m: f64, intensity: f64) -> String {
    format!(
        r#"{{
  "camera": {{"type": "orthographic", "width_m": 2,
              "transform": {{"look_at": {{"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
  "film": {{"resolution": [{N}, {N}], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {{"type": "path", "max_depth": 4, "sampler": "{sampler}"}},
  "materials": {{"grey": {{"type": "lambert", "reflectance": 0.5}}}},
  "shapes": [{{"type": "rectangle", "size_m": [40, 40],
               "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}, "material": "grey"}}],
  "lights": [{{"type": "point", "position_m": [0, {height_m}, 0], "spectrum": 1.0, "scale": {intensity}}}]
}}"#
    )
}

#[test]
fn point_source_over_a_diffuse_plane_gives_i_cos_over_d_squared() {
    let (h, intensity, r) = (0.5, 2.0, 0.5);
    for sampler in ["sobol", "independent"] {
        let (image, stats) = render_json(&point_light_scene(sampler, h, intensity), 64, 11);
        assert_eq!(stats.non_finite_samples, 0);
        let mut expected = Vec::new();
        for j in 0..N {
            for i in 0..N {
                expected.push(pixel_mean(N, 1.0, i, j, |x, z| {
                    let d2 = x * x + z * z + h * h;
                    r / std::f64::consts::PI * intensity * (h / d2.sqrt()) / d2
                }));
            }
        }
        assert_matches(&image, &expected, 0.03);
    }
}

#[test]
fn splatting_and_filter_importance_sampling_agree_and_splatting_is_less_noisy() {
    // Point source over a plane, Gaussian filter (σ 0.5 px, radius 2): both reconstructions
    // estimate the same filtered image. With independent samples splatting spreads each
    // sample over ≈ π pixel footprints (4πσ² ≈ π), so its per-pixel noise is lower. (With
    // Sobol it is the other way round: splatting mixes neighbours' weighted samples and
    // loses each pixel's stratification — why importance sampling is the default.)
    let scene = |reconstruction: &str| {
        // F11's spikes make hero-wavelength noise dominate (not the position jitter).
        point_light_scene("independent", 0.5, 2.0)
            .replace(r#""spectrum": 1.0"#, r#""spectrum": "F11""#)
            .replace(
            r#""filter": {"type": "box", "radius_px": 0.5}"#,
            &format!(
                r#""filter": {{"type": "gaussian", "radius_px": 2, "sigma_px": 0.5}}, "reconstruction": "{reconstruction}""#
            ),
        )
    };
    let (splat, _) = render_json(&scene("splat"), 64, 21);
    let (importance, _) = render_json(&scene("importance"), 64, 21);
    let (splat2, _) = render_json(&scene("splat"), 64, 22);
    let (importance2, _) = render_json(&scene("importance"), 64, 22);
    let rms = |a: &FilmImage, b: &FilmImage| {
        let n = a.y.len() as f64;
        (a.y.iter()
            .zip(&b.y)
            .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    // Same expectation away from the film's border (within the filter radius of the edge
    // splatting only sees samples from inside, importance sampling also from outside): the
    // interior mean agrees within the noise.
    let interior = |a: &FilmImage| -> Vec<f64> {
        let mut v = Vec::new();
        for y in 2..N - 2 {
            for x in 2..N - 2 {
                v.push(f64::from(a.y[(y * N + x) as usize]));
            }
        }
        v
    };
    let mean = |a: &FilmImage| {
        let v = interior(a);
        v.iter().sum::<f64>() / v.len() as f64
    };
    let noise = rms(&importance, &importance2) / (interior(&importance).len() as f64).sqrt();
    assert!(
        (mean(&splat) - mean(&importance)).abs() < 5.0 * noise + 1e-4,
        "{} vs {} (noise {noise})",
        mean(&splat),
        mean(&importance)
    );
    // Lower per-pixel noise when splatting (seed-to-seed differences).
    let (n_splat, n_is) = (rms(&splat, &splat2), rms(&importance, &importance2));
    eprintln!("seed-to-seed rms: splat {n_splat:.3e}, importance sampling {n_is:.3e}");
    assert!(n_splat < 0.8 * n_is, "splat {n_splat} vs importance {n_is}");
}
