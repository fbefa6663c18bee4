//! The `radiosity` method (hierarchical radiosity with clustering and a final gather)
//! against `path` on the Cornell box, and its refusals. Passes are independent given the
//! solution (computed once by the first `prepare`), so standard errors come from pass
//! means; the solution's own error (its error bound) is the stated floor.

use prism_scene::{Integrator, SamplerKind};

mod support;
use support::{assert_close, mean_se, pass_means, repository_scene, with_integrator, Dir};

fn radiosity(error_bound_rel: f64) -> Integrator {
    Integrator::Radiosity {
        error_bound_rel,
        iterations: 3,
        gather_epsilon: 0.1,
        sampler: SamplerKind::Independent,
    }
}

/// Whole image, the ceiling (lit only by light reflected at least once: the solution's
/// share) and the floor under the light.
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
    let scene = with_integrator(repository_scene("cornell-box.json", res), radiosity(0.004));
    for (what, window, floor_rel) in [
        ("image", (0, 0, 16, 16), 0.01),
        ("ceiling", (3, 0, 13, 2), 0.03),
        ("floor", (3, 13, 13, 16), 0.01),
    ] {
        let (expected, expected_se) = mean_se(&pass_means(&path, 400, 21, window));
        let means = pass_means(&scene, 200, 22, window);
        assert_close(
            what,
            mean_se(&means),
            expected,
            expected_se,
            floor_rel * expected,
        );
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
    let point = r#"{"type": "point", "position_m": [0, 0, 1], "intensity_cd": 10}"#;
    let area = r#"{"type": "area", "shape": "lamp", "spectrum": 1}"#;
    let cases = [
        (
            scene(
                r#"{"type": "sphere", "radius_m": 1, "material": "m"}"#,
                lambert,
                area,
            ),
            "sphere",
        ),
        (
            scene(rect, r#"{"type": "dielectric", "ior": 1.5}"#, area),
            "lambert",
        ),
        (scene(rect, lambert, point), "area lights only"),
    ];
    for (json, expected) in cases {
        let message = dir.build_error(&json);
        assert!(message.contains(expected), "{expected}: {message}");
    }
}
