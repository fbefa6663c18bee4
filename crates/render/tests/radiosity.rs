//! The `radiosity` method (hierarchical radiosity with clustering and a final gather)
//! against `path` on the Cornell box, and its refusals. Passes are independent given the
//! solution (computed once by the first `prepare`), so standard errors come from pass
//! means; the solution's own error (its error bound) is the stated floor.

use prism_scene::{Integrator, SamplerKind};

mod support;
use support::{
    assert_close, lux_disagreements, mean_se, pass_means, repository_scene, sensor_lux,
    with_integrator, Dir,
};

fn radiosity(error_bound_rel: f64, gather_epsilon: f64) -> Integrator {
    Integrator::Radiosity {
        error_bound_rel,
        iterations: 3,
        gather_epsilon,
        sampler: SamplerKind::Independent,
    }
}

/// Whole image, the ceiling (lit only by light reflected at least once: the solution's
/// share) and the floor under the light; with the interpolated gather (ε = 0.1, the
/// default) and with every gather ray traced (ε = 0).
#[test]
fn cornell_box_radiosity_agrees_with_a_deep_path_tracer() {
    let res = 16;
    let path = with_integrator(
        repository_scene("cornell-box.json", res),
        Integrator::Path {
            max_depth: 64,
            sampler: SamplerKind::Independent,
            mis: prism_scene::MisHeuristic::Power,
            rr_depth: 5,
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        },
    );
    let windows = [
        ("image", (0, 0, 16, 16), 0.01),
        ("ceiling", (3, 0, 13, 2), 0.03),
        ("floor", (3, 13, 13, 16), 0.01),
    ];
    let expected: Vec<(f64, f64)> = windows
        .iter()
        .map(|&(_, window, _)| mean_se(&pass_means(&path, 400, 21, window)))
        .collect();
    for epsilon in [0.1, 0.0] {
        let scene = with_integrator(
            repository_scene("cornell-box.json", res),
            radiosity(0.004, epsilon),
        );
        for (&(what, window, floor_rel), &(expected, expected_se)) in windows.iter().zip(&expected)
        {
            let means = pass_means(&scene, 200, 22, window);
            assert_close(
                &format!("{what} (ε {epsilon})"),
                mean_se(&means),
                expected,
                expected_se,
                floor_rel * expected,
            );
        }
    }
}

#[test]
fn refusals_name_what_radiosity_cannot_hold() {
    let dir = Dir::new("radiosity", "refusals");
    let scene = |shape: &str, material: &str, light: &str| {
        format!(
            r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 40, "transform": {{"look_at": {{"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {{"type": "radiosity"}},
  "materials": {{"m": {material}}},
  "shapes": [{shape}, {{"type": "rectangle", "name": "lamp", "size_m": [0.2, 0.2], "material": "m", "transform": {{"translate": [0, 0, 2]}}}}],
  "lights": [{light}]
}}"#
        )
    };
    let rect = r#"{"type": "rectangle", "size_m": [1, 1], "material": "m"}"#;
    let lambert = r#"{"type": "lambert", "reflectance": 0.5}"#;
    let area = r#"{"type": "area", "shape": "lamp", "spectrum": 1}"#;
    let cases = [
        (
            scene(
                r#"{"type": "sphere", "radius_m": 1, "material": "m",
                    "transform": {"scale": [1, 2, 1]}}"#,
                lambert,
                area,
            ),
            "non-uniform scale",
        ),
        (
            scene(rect, r#"{"type": "dielectric", "ior": 1.5}"#, area),
            "lambert",
        ),
    ];
    for (json, expected) in cases {
        let message = dir.build_error(&json);
        assert!(message.contains(expected), "{expected}: {message}");
    }
    let json = scene(rect, lambert, area).replace(
        r#"{"type": "radiosity"}"#,
        r#"{"type": "radiosity", "gather_epsilon": -0.1}"#,
    );
    let path = dir.write("scene.json", json.as_bytes());
    let message = prism_scene::load_scene(&path)
        .expect_err("a negative ε is refused")
        .to_string();
    assert!(
        message.contains("integrator.gather_epsilon") && message.contains("≥ 0"),
        "{message}"
    );
}

/// The Cornell box (its own path tracer's scene) with five illuminance points: on the
/// floor, the back wall and the ceiling (lit by reflected light only: all of its lux come
/// from the solution).
fn cornell_with_sensors(dir: &Dir, integrator: &str) -> prism_render::RenderScene {
    cornell_with_sensors_lit(dir, integrator, None, &[])
}

/// As `cornell_with_sensors`, with `light` (JSON) in place of the area light.
fn cornell_with_sensors_lit(
    dir: &Dir,
    integrator: &str,
    light: Option<&str>,
    shapes: &[&str],
) -> prism_render::RenderScene {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let text = std::fs::read_to_string(root.join("cornell-box.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["lights"][0]["spectrum"] = serde_json::Value::String(
        root.join("cornell-box/light-radiance.csv")
            .display()
            .to_string(),
    );
    json["integrator"] = serde_json::from_str(integrator).unwrap();
    if let Some(light) = light {
        json["lights"] = serde_json::from_str(&format!("[{light}]")).unwrap();
    }
    if !shapes.is_empty() {
        // In place of the two boxes.
        let mut all: Vec<serde_json::Value> = json["shapes"].as_array().unwrap()[..6].to_vec();
        all.extend(shapes.iter().map(|s| serde_json::from_str(s).unwrap()));
        json["shapes"] = serde_json::Value::Array(all);
    }
    json["sensors"] = serde_json::json!([{
        "type": "points", "name": "probe", "samples": 16384,
        "positions_m": [[0.0, -0.999, 0.0], [0.6, -0.999, 0.6], [-0.7, -0.999, -0.2]],
        "normal": [0, 1, 0]
    }, {
        "type": "points", "name": "wall", "samples": 16384,
        "positions_m": [[0.0, 0.0, -0.999], [-0.5, 0.5, -0.999]], "normal": [0, 0, 1]
    }, {
        "type": "points", "name": "ceiling", "samples": 16384,
        "positions_m": [[0.6, 0.999, 0.6], [-0.6, 0.999, -0.5]], "normal": [0, -1, 0]
    }]);
    dir.scene_at(&json.to_string(), Some(8))
}

/// Illuminance sensors read the solution (direct light by light sampling, the rest from
/// the solution at the cosine-sampled ray's hit): within 2 % of a 64-bounce path tracer
/// (plus 4 s.e.) on the floor, the back wall and the ceiling.
#[test]
fn sensors_read_the_solution_within_two_percent_of_path() {
    let dir = Dir::new("radiosity", "sensors");
    let path = cornell_with_sensors(
        &dir,
        r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
    );
    let expected = sensor_lux(&path, &dir, 7);
    let scene = cornell_with_sensors(&dir, r#"{"type": "radiosity", "error_bound_rel": 0.0005}"#);
    let got = sensor_lux(&scene, &dir, 7);
    assert_eq!(lux_disagreements(&expected, &got), 0);
}
/// A closed cube whose six inward faces all emit L and reflect ρ = ½: the illuminance is
/// π L / (1 − ρ) everywhere inside. A sensor at the centre, by `radiosity` (light
/// sampling + the solution at the gather ray's hit) and by `path`.
#[test]
fn a_closed_emitting_box_reads_pi_l_over_one_minus_rho() {
    let dir = Dir::new("radiosity", "furnace");
    let names = ["floor", "ceiling", "back", "front", "left", "right"];
    let shapes = box_faces(&names, "grey");
    let lights: Vec<String> = names
        .iter()
        .map(|name| format!(r#"{{"type": "area", "shape": "{name}", "spectrum": 1}}"#))
        .collect();
    let scene = |integrator: &str| {
        let json = format!(
            r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "transform": {{"look_at": {{"eye": [0, 0, 0.5], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {integrator},
  "materials": {{"grey": {{"type": "lambert", "reflectance": 0.5}}}},
  "shapes": [{}],
  "lights": [{}],
  "sensors": [{{"type": "points", "name": "centre", "samples": 8192,
    "positions_m": [[0, 0, 0], [0.5, -0.999, 0.5]], "normal": [0, 1, 0]}}]
}}"#,
            shapes.join(", "),
            lights.join(", ")
        );
        let path = dir.write("scene.json", json.as_bytes());
        let description = prism_scene::load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let built =
            prism_render::RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"));
        let (readings, _) =
            prism_render::sensor::measure_sensors(&built, &description.sensors, 3, &|_| {});
        readings[0]
            .points
            .iter()
            .map(|p| (p.illuminance_lx, p.std_error_lx))
            .collect::<Vec<_>>()
    };
    let path = scene(r#"{"type": "path", "max_depth": 64, "rr_depth": 64}"#);
    let radiosity = scene(r#"{"type": "radiosity"}"#);
    // L = 1 W·m⁻²·sr⁻¹·nm⁻¹ at every wavelength: E_v = K_m ∫ȳ dλ · π/(1 − ρ) lx.
    let closed_form = prism_render::film::xyz::cd_m2_per_unit() * std::f64::consts::PI / 0.5;
    for (i, (&(e, e_se), &(g, g_se))) in path.iter().zip(&radiosity).enumerate() {
        let se = (e_se * e_se + g_se * g_se).sqrt();
        eprintln!("furnace point {i}: radiosity {g:.3} lx, path {e:.3} lx, s.e. {se:.3}");
        assert!(
            (g - e).abs() <= 0.005 * e + 4.0 * se,
            "point {i}: {g} vs {e}"
        );
        assert!(
            (g - closed_form).abs() <= 0.005 * closed_form + 4.0 * g_se,
            "point {i}: {g} vs π L/(1 − ρ) = {closed_form}"
        );
    }
}

/// A point light (in place of the area light) reaches the solution as direct irradiance
/// with shadows: the sensors agree with `path` as for the area light.
#[test]
fn a_point_light_reaches_the_solution() {
    let dir = Dir::new("radiosity", "point");
    let light = r#"{"type": "point", "position_m": [0, 0.8, 0], "intensity_cd": 50}"#;
    let path = cornell_with_sensors_lit(
        &dir,
        r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
        Some(light),
        &[],
    );
    let expected = sensor_lux(&path, &dir, 7);
    let scene = cornell_with_sensors_lit(&dir, r#"{"type": "radiosity"}"#, Some(light), &[]);
    let got = sensor_lux(&scene, &dir, 7);
    let mut failures = 0;
    for (i, (&(e, e_se), &(g, g_se))) in expected.iter().zip(&got).enumerate() {
        let se = (e_se * e_se + g_se * g_se).sqrt();
        eprintln!("point light, point {i}: radiosity {g:.3} lx, path {e:.3} lx, s.e. {se:.3}");
        failures += usize::from((g - e).abs() > 0.02 * e + 4.0 * se);
    }
    assert_eq!(failures, 0);
}

/// The office (scenes/office/office.json: IES downlights and linear luminaires, 240 work
/// plane points and two on the back wall) measured by its own `path` and by `radiosity`:
/// the work plane's mean within 0.5 %, every point within 2 % plus 4 s.e.
#[test]
fn office_sensors_agree_with_path() {
    let file = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/office/office.json");
    let description = prism_scene::load_scene(&file).unwrap_or_else(|e| panic!("{e}"));
    let path = prism_render::RenderScene::build(&description, Some(glam::UVec2::splat(8)))
        .unwrap_or_else(|e| panic!("{e}"));
    let scene = with_integrator(
        prism_render::RenderScene::build(&description, Some(glam::UVec2::splat(8))).unwrap(),
        radiosity(0.004, 0.1),
    );
    let measure = |s: &prism_render::RenderScene| {
        prism_render::sensor::measure_sensors(s, &description.sensors, 5, &|_| {}).0
    };
    let (expected, got) = (measure(&path), measure(&scene));
    let (mut sum_rel, mut count, mut failures) = (0.0, 0, 0);
    for (e, g) in expected.iter().zip(&got) {
        for (pe, pg) in e.points.iter().zip(&g.points) {
            let (a, b) = (pe.illuminance_lx, pg.illuminance_lx);
            let se = pe.std_error_lx.hypot(pg.std_error_lx);
            if (b - a).abs() > 0.02 * a + 4.0 * se {
                eprintln!("{}: {b:.2} lx vs path {a:.2} lx (s.e. {se:.2})", e.name);
                failures += 1;
            }
            if e.name == "work plane" {
                sum_rel += (b - a) / a;
                count += 1;
            }
        }
    }
    let mean_rel = sum_rel / f64::from(count);
    eprintln!("work plane: mean difference {:+.3} %", 100.0 * mean_rel);
    assert!(mean_rel.abs() < 0.005, "{mean_rel}");
    assert_eq!(failures, 0);
}

/// A room without a roof under a uniform sky: the sky reaches the solution through
/// stratified directions with shadow rays; sensors on the floor and a wall agree with
/// `path`.
#[test]
fn a_sky_reaches_the_solution() {
    let dir = Dir::new("radiosity", "sky");
    let shapes = box_faces(&["floor", "back", "left", "right"], "m");
    let measure = |integrator: &str| {
        let json = format!(
            r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "transform": {{"look_at": {{"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {integrator},
  "materials": {{"m": {{"type": "lambert", "reflectance": 0.7}}}},
  "shapes": [{}],
  "lights": [{{"type": "sky", "luminance_cd_m2": 3000}}],
  "sensors": [{{"type": "points", "name": "floor", "samples": 16384,
    "positions_m": [[0, -0.999, 0], [-0.8, -0.999, -0.8]], "normal": [0, 1, 0]}},
    {{"type": "points", "name": "wall", "samples": 16384,
    "positions_m": [[0, 0, -0.999]], "normal": [0, 0, 1]}}]
}}"#,
            shapes.join(", ")
        );
        let path = dir.write("scene.json", json.as_bytes());
        let description = prism_scene::load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let scene =
            prism_render::RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"));
        let (readings, _) =
            prism_render::sensor::measure_sensors(&scene, &description.sensors, 9, &|_| {});
        readings
            .iter()
            .flat_map(|r| r.points.iter().map(|p| (p.illuminance_lx, p.std_error_lx)))
            .collect::<Vec<_>>()
    };
    let expected = measure(r#"{"type": "path", "max_depth": 64, "rr_depth": 5}"#);
    let got = measure(r#"{"type": "radiosity"}"#);
    for (i, (&(e, e_se), &(g, g_se))) in expected.iter().zip(&got).enumerate() {
        let se = e_se.hypot(g_se);
        eprintln!("sky, point {i}: radiosity {g:.1} lx, path {e:.1} lx, s.e. {se:.1}");
        assert!(
            (g - e).abs() <= 0.02 * e + 4.0 * se,
            "point {i}: {g} vs {e}"
        );
    }
}

/// Named faces of the cube [−1, 1]³ as inward-facing 2 m rectangles of material
/// `material` (scene JSON): floor, ceiling, back, front, left, right.
fn box_faces(names: &[&str], material: &str) -> Vec<String> {
    let transform = |name: &str| match name {
        "floor" => {
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [0, -1, 0]}]"#
        }
        "ceiling" => {
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 1, 0]}]"#
        }
        "back" => r#"[{"translate": [0, 0, -1]}]"#,
        "front" => {
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 180}}, {"translate": [0, 0, 1]}]"#
        }
        "left" => {
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}, {"translate": [-1, 0, 0]}]"#
        }
        "right" => {
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": -90}}, {"translate": [1, 0, 0]}]"#
        }
        other => panic!("no face {other}"),
    };
    names
        .iter()
        .map(|&name| {
            format!(
                r#"{{"type": "rectangle", "name": "{name}", "size_m": [2, 2], "material": "{material}", "transform": {}}}"#,
                transform(name)
            )
        })
        .collect()
}

/// The interpolated gather (ε = 0.1) against every gather ray traced (ε = 0), with the
/// same seeds so that the direct light's noise cancels in the paired differences, in
/// 8 × 8-pixel blocks of the Cornell box at 32².
#[test]
fn interpolated_gather_agrees_with_the_traced_gather() {
    let res = 32;
    let images = |epsilon: f64| {
        let scene = with_integrator(
            repository_scene("cornell-box.json", res),
            radiosity(0.004, epsilon),
        );
        support::pass_images(&scene, 64, 31)
    };
    let (interpolated, traced) = (images(0.1), images(0.0));
    for by in 0..4 {
        for bx in 0..4 {
            let window = (bx * 8, by * 8, bx * 8 + 8, by * 8 + 8);
            let diffs: Vec<f64> = interpolated
                .iter()
                .zip(&traced)
                .map(|(a, b)| {
                    support::window_mean(a, res, window) - support::window_mean(b, res, window)
                })
                .collect();
            let (d, d_se) = mean_se(&diffs);
            let level = mean_se(
                &traced
                    .iter()
                    .map(|b| support::window_mean(b, res, window))
                    .collect::<Vec<_>>(),
            )
            .0;
            eprintln!(
                "block ({bx}, {by}): traced {level:.5}, interpolated − traced {d:+.5} ± {d_se:.5} ({:+.2} %)",
                100.0 * d / level
            );
            // ε bounds each source's variation over an element, not a pixel's error: the
            // blocks are held to 2 % of their level beyond 4 s.e. (measured: all within
            // ±2 %, the largest beyond its s.e. +1.3 % ± 0.3 %).
            assert!(
                d.abs() <= 4.0 * d_se + 0.02 * level,
                "block ({bx}, {by}): interpolated − traced {d} (s.e. {d_se}, level {level})"
            );
        }
    }
}

/// Spheres and disks are meshed for the solution: the Cornell box with a sphere and a
/// disk in place of its boxes, then lit by a small spherical area light instead of its
/// rectangle; the sensors agree with `path` within 2 % plus 4 s.e. (one point that sees
/// the sphere's underside within 8 %).
#[test]
fn spheres_and_disks_reach_the_solution() {
    let dir = Dir::new("radiosity", "spheres");
    let shapes = [
        r#"{"type": "sphere", "name": "ball", "radius_m": 0.3, "material": "white",
            "transform": {"translate": [-0.35, -0.6, -0.2]}}"#,
        r#"{"type": "disk", "name": "table", "radius_m": 0.3, "material": "white",
            "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}},
                          {"translate": [0.4, -0.5, 0.3]}]}"#,
    ];
    let bulb = r#"{"type": "sphere", "name": "bulb", "radius_m": 0.08, "material": "white",
        "transform": {"translate": [0.1, 0.7, 0.1]}}"#;
    let bulb_light = r#"{"type": "area", "shape": "bulb", "spectrum": 40}"#;
    for (what, light, extra) in [
        ("rectangle light", None, None),
        ("sphere light", Some(bulb_light), Some(bulb)),
    ] {
        let mut all: Vec<&str> = shapes.to_vec();
        all.extend(extra);
        let path = cornell_with_sensors_lit(
            &dir,
            r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
            light,
            &all,
        );
        let expected = sensor_lux(&path, &dir, 9);
        let scene = cornell_with_sensors_lit(&dir, r#"{"type": "radiosity"}"#, light, &all);
        let got = sensor_lux(&scene, &dir, 9);
        eprintln!("{what}:");
        // Point 2 (the floor beside the sphere) sees the sphere's underside, whose small
        // triangles take whole clusters as sources at 16 samples: their radiosity is off
        // by tens of per cent (docs/radiosity.md, "Spheres and disks"), which reaches
        // this point as +4 … +6 %. It is held to 8 % + 4 s.e. until that is mended.
        let (near, rest): (Vec<usize>, Vec<usize>) = (0..got.len()).partition(|&i| i == 2);
        let pick = |v: &[(f64, f64)], idx: &[usize]| idx.iter().map(|&i| v[i]).collect::<Vec<_>>();
        assert_eq!(
            lux_disagreements(&pick(&expected, &rest), &pick(&got, &rest)),
            0,
            "{what}"
        );
        for i in near {
            let ((e, e_se), (g, g_se)) = (expected[i], got[i]);
            let se = (e_se * e_se + g_se * g_se).sqrt();
            assert!(
                (g - e).abs() <= 0.08 * e + 4.0 * se,
                "{what}, point {i}: {g} vs {e}"
            );
        }
    }
}
