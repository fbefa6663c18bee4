//! Physics checks of the path tracer with area and infinite lights (issue 4): white
//! furnaces, the uniform-disk irradiance E = πL sin²α (and its off-axis closed form), and
//! colorimetry end to end against the library behind `prism color`.
//!
//! Tolerances come from the image's own noise: the relative error per pixel has spread σ
//! over the pixels; the mean must be within 5σ/√n of 0 and every pixel within 6σ.

use prism_render::{render, FilmImage, RenderScene, RenderSettings, RenderStats};
use prism_scene::parse_scene_str;

fn render_json(json: &str, spp: u32, seed: u64) -> (FilmImage, RenderStats) {
    let description = parse_scene_str(json, "test.json").expect("test scene parses");
    let scene = RenderScene::build(&description, None).expect("test scene builds");
    let settings = RenderSettings {
        spp,
        seed,
        ..RenderSettings::default()
    };
    render(&scene, &settings, &|_| {})
}

/// (mean, σ, worst) of the relative errors of `values` against `expected`.
fn relative_errors(values: &[f64], expected: &[f64]) -> (f64, f64, f64) {
    let rel: Vec<f64> = values
        .iter()
        .zip(expected)
        .map(|(&v, &a)| (v - a) / a)
        .collect();
    let n = rel.len() as f64;
    let mean = rel.iter().sum::<f64>() / n;
    let sigma = (rel.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let worst = rel.iter().fold(0.0f64, |m, r| m.max((r - mean).abs()));
    (mean, sigma, worst)
}

fn assert_unbiased(label: &str, values: &[f64], expected: &[f64], max_sigma: f64) {
    let (mean, sigma, worst) = relative_errors(values, expected);
    let n = values.len() as f64;
    eprintln!("{label}: mean rel. error {mean:.2e}, σ {sigma:.2e}, worst {worst:.2e}, n {n}");
    assert!(
        sigma < max_sigma,
        "{label}: noise σ = {sigma} above {max_sigma}"
    );
    assert!(
        mean.abs() < 5.0 * sigma / n.sqrt() + 2e-4,
        "{label}: biased, mean relative error {mean} (σ/√n = {})",
        sigma / n.sqrt()
    );
    assert!(
        worst < 6.0 * sigma + 1e-3,
        "{label}: worst pixel {worst}, σ {sigma}"
    );
}

fn y(image: &FilmImage) -> Vec<f64> {
    image.y.iter().map(|&v| f64::from(v)).collect()
}

#[test]
fn white_furnace_convex_sphere_in_a_uniform_sky_reflects_r_times_l() {
    // A convex Lambertian sphere (R = 0.8) under a uniform sky L = 1: every ray from the
    // sphere escapes, so the sphere shows R·L and the background L, at every wavelength.
    let json = r#"{
      "camera": {"type": "pinhole", "fov_deg": 30, "transform": {"look_at": {"eye": [0, 0, 5], "target": [0, 0, 0]}}},
      "film": {"resolution": [24, 24], "filter": {"type": "box", "radius_px": 0.5}},
      "integrator": {"type": "path", "max_depth": 16, "sampler": "independent"},
      "materials": {"white": {"type": "lambert", "reflectance": 0.8}},
      "shapes": [{"type": "sphere", "radius_m": 1, "material": "white"}],
      "lights": [{"type": "sky", "spectrum": 1.0, "scale": 1.0}]
    }"#;
    let description = parse_scene_str(json, "test.json").expect("test scene parses");
    let scene = RenderScene::build(&description, None).expect("test scene builds");
    let settings = RenderSettings {
        spp: 256,
        seed: 3,
        spectral_bins: Some(prism_render::SpectralBins::new(10).unwrap()),
        ..RenderSettings::default()
    };
    let (image, stats) = render(&scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    let depth = image.aov("depth.Z").expect("depth layer").values.clone();
    let (mut on, mut on_expected, mut off, mut off_expected) = (vec![], vec![], vec![], vec![]);
    for (i, &d) in depth.iter().enumerate() {
        // Only pixels fully on or fully off the sphere (silhouette pixels mix both).
        let v = f64::from(image.y[i]);
        if d.is_finite() && d < 4.5 {
            on.push(v);
            on_expected.push(0.8);
        } else if d.is_infinite() {
            off.push(v);
            off_expected.push(1.0);
        }
    }
    assert!(on.len() > 100 && off.len() > 50);
    assert_unbiased("furnace sphere", &on, &on_expected, 0.05);
    assert_unbiased("furnace background", &off, &off_expected, 0.05);
    // At every wavelength: each of 10 spectral bins (47 nm wide) over the sphere's pixels.
    let bins = image.spectral.as_ref().expect("spectral bins");
    for (b, plane) in bins.planes.iter().enumerate() {
        let values: Vec<f64> = depth
            .iter()
            .zip(plane)
            .filter(|(d, _)| d.is_finite() && **d < 4.5)
            .map(|(_, &v)| f64::from(v))
            .collect();
        let expected = vec![0.8; values.len()];
        let label = format!("furnace sphere, bin at {:.0} nm", bins.centres_nm[b]);
        assert_unbiased(&label, &values, &expected, 0.1);
    }
}

#[test]
fn white_furnace_closed_emitting_sphere_gives_le_over_one_minus_r() {
    // Inside a closed sphere whose wall emits Le and reflects R (two-sided Lambertian):
    // L = Le Σ Rᵏ = Le / (1 − R) everywhere. Exercises area-light MIS, roulette and depth.
    let json = r#"{
      "camera": {"type": "pinhole", "fov_deg": 60, "transform": {"look_at": {"eye": [0, 0, 0], "target": [0, 0, -1]}}},
      "film": {"resolution": [16, 16], "filter": {"type": "box", "radius_px": 0.5}},
      "integrator": {"type": "path", "max_depth": 200, "rr_depth": 3},
      "materials": {"wall": {"type": "lambert", "reflectance": 0.5},
                    "two": {"type": "two_sided", "material": "wall"}},
      "shapes": [{"type": "sphere", "name": "shell", "radius_m": 1, "material": "two"}],
      "lights": [{"type": "area", "shape": "shell", "two_sided": true, "spectrum": 1.0, "scale": 0.25}]
    }"#;
    let (image, stats) = render_json(json, 256, 5);
    assert_eq!(stats.non_finite_samples, 0);
    let expected = vec![0.25 / (1.0 - 0.5); image.y.len()];
    assert_unbiased("closed furnace", &y(&image), &expected, 0.08);
}

const N: u32 = 24;

#[test]
fn uniform_disk_source_gives_pi_l_sin2_alpha_on_axis_and_the_closed_form_off_axis() {
    // A disk of radius r at height h emitting L downwards over a Lambertian plane (R); an
    // orthographic camera between them looks down. Irradiance at distance ρ from the axis
    // (parallel disk, e.g. Howell's catalogue of configuration factors, C-41):
    //   E(ρ) = πL/2 · [1 − (h² + ρ² − r²) / √((h² + ρ² + r²)² − 4 r² ρ²)],
    // which on the axis is πL r²/(h² + r²) = πL sin²α.
    let (r, h, l, refl) = (0.3, 0.5, 2.0, 0.6);
    let json = format!(
        r#"{{
      "camera": {{"type": "orthographic", "width_m": 2,
                  "transform": {{"look_at": {{"eye": [0, 0.2, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
      "film": {{"resolution": [{N}, {N}], "filter": {{"type": "box", "radius_px": 0.5}}}},
      "integrator": {{"type": "path", "max_depth": 1}},
      "materials": {{"grey": {{"type": "lambert", "reflectance": {refl}}}}},
      "shapes": [
        {{"type": "rectangle", "size_m": [40, 40], "material": "grey",
          "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
        {{"type": "disk", "name": "lamp", "radius_m": {r},
          "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, {h}, 0]}}]}}
      ],
      "lights": [{{"type": "area", "shape": "lamp", "spectrum": 1.0, "scale": {l}}}]
    }}"#
    );
    let (image, stats) = render_json(&json, 256, 9);
    assert_eq!(stats.non_finite_samples, 0);
    let irradiance = |rho: f64| {
        let a = h * h + rho * rho;
        std::f64::consts::PI * l / 2.0
            * (1.0 - (a - r * r) / ((a + r * r).powi(2) - 4.0 * r * r * rho * rho).sqrt())
    };
    let px = 2.0 / f64::from(N);
    let mut expected = Vec::new();
    for j in 0..N {
        for i in 0..N {
            // Mean over the pixel (6×6 midpoints).
            let mut sum = 0.0;
            for a in 0..6 {
                for b in 0..6 {
                    let x = -1.0 + (f64::from(i) + (f64::from(a) + 0.5) / 6.0) * px;
                    let z = -1.0 + (f64::from(j) + (f64::from(b) + 0.5) / 6.0) * px;
                    sum += refl / std::f64::consts::PI * irradiance((x * x + z * z).sqrt());
                }
            }
            expected.push(sum / 36.0);
        }
    }
    assert_unbiased("disk source", &y(&image), &expected, 0.05);
    // On the axis exactly: E = πL sin²α.
    let sin2 = r * r / (h * h + r * r);
    assert!((irradiance(0.0) - std::f64::consts::PI * l * sin2).abs() < 1e-12);
}

#[test]
fn colorchecker_patch_under_a_d65_sky_gives_the_xyz_prism_color_computes() {
    use prism_spectrum::colorimetry::reflectance_to_xyz;
    use prism_spectrum::data::{colorchecker_patch, colorchecker_patch_index, illuminant};
    use prism_spectrum::photometry::y_bar_integral_nm;
    use prism_spectrum::Observer;

    let root = env!("CARGO_MANIFEST_DIR");
    for patch in ["dark skin", "blue", "orange yellow"] {
        // Uniform D65 sky of radiance s·D65(λ); a horizontal Lambertian plane reflects
        // R(λ)·E/π = R(λ)·s·D65(λ) (E = πL on an unoccluded plane).
        let scale = 0.01;
        let json = format!(
            r#"{{
          "camera": {{"type": "orthographic", "width_m": 0.5,
                      "transform": {{"look_at": {{"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
          "film": {{"resolution": [8, 8], "filter": {{"type": "box", "radius_px": 0.5}}}},
          "integrator": {{"type": "path", "max_depth": 1}},
          "materials": {{"patch": {{"type": "lambert",
              "reflectance": {{"file": "{root}/../../spectra/colorchecker.csv", "column": "{patch}"}}}}}},
          "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "patch",
              "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
          "lights": [{{"type": "sky", "spectrum": "D65", "scale": {scale}}}]
        }}"#
        );
        let (image, _) = render_json(&json, 1024, 13);
        let reflectance = colorchecker_patch(colorchecker_patch_index(patch).unwrap()).to_dense();
        let d65 = illuminant("D65").unwrap().to_dense();
        // `prism color`: Y = 100 for the perfect white; the film: XYZ = ∫L x̄ / ∫ȳ.
        let xyz_color = reflectance_to_xyz(&reflectance, &d65, Observer::Cie1931);
        let white_y = d65.inner_product(&prism_spectrum::data::cmfs(Observer::Cie1931).y_bar);
        let to_film = scale * white_y / 100.0 / y_bar_integral_nm(Observer::Cie1931);
        let expected = xyz_color * to_film;
        let n = image.xyz.len() as f64;
        for c in 0..3 {
            let values: Vec<f64> = image.xyz.iter().map(|p| f64::from(p[c])).collect();
            let mean = values.iter().sum::<f64>() / n;
            let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let se = sd / n.sqrt();
            eprintln!(
                "{patch} channel {c}: {mean:.6} vs {:.6} (se {se:.2e})",
                expected[c]
            );
            assert!(
                (mean - expected[c]).abs() < 5.0 * se + 1e-4 * expected[c].abs(),
                "{patch}: channel {c} {mean} vs {} (se {se})",
                expected[c]
            );
        }
    }
}
