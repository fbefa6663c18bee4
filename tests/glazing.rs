//! Thin glazing (material/glazing.rs): light sampling crosses a `thin_dielectric` pane with
//! its straight-through transmittance T' = (1 − R)/(1 + R), and paths pass it as a null
//! event. Checked with illuminance sensors under a horizontal pane (n = 1.5) against
//! closed forms: a point source (only light sampling can reach it: before this, the pane
//! blocked it entirely) and a rectangular Lambertian source (light sampling and paths
//! through the pane, MIS-weighted: counting either twice or not at all would miss the
//! reference by tens of percent).

use prism_render::sensor::{measure_sensors, PointReading};
use prism_render::RenderScene;

const N_GLASS: f64 = 1.5;
const PANE_Y_M: f64 = 1.5;

/// Unpolarised Fresnel reflectance of one air–glass interface at incidence `cos_i`.
fn fresnel(cos_i: f64, n: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).max(0.0).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Straight-through transmittance of the thin sheet, summing the inter-reflections of the
/// unpolarised mean R (as Mitsuba's `thindielectric` and Prism's `thin_dielectric`).
fn pane_transmittance(cos_i: f64) -> f64 {
    let r = fresnel(cos_i, N_GLASS);
    (1.0 - r) / (1.0 + r)
}

fn measure(json: &str) -> Vec<PointReading> {
    let dir = tempfile::tempdir().unwrap();
    let description = prism_scene::parse_scene_str(json, dir.path().join("scene.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    let scene = RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"));
    let (readings, _) = measure_sensors(&scene, &description.sensors, 7, &|_| {});
    readings.into_iter().next().unwrap().points
}

/// A 20 m × 20 m horizontal pane at PANE_Y_M and the lights and floor sensors given.
fn scene_json(lights: &str, extra_shapes: &str, xs: &[f64]) -> String {
    let positions: Vec<String> = xs.iter().map(|x| format!("[{x}, 0, 0]")).collect();
    format!(
        r#"{{"materials": {{"glass": {{"type": "thin_dielectric", "ior": {N_GLASS}}}}},
            "shapes": [{{"type": "rectangle", "name": "pane", "size_m": [20, 20], "material": "glass",
                         "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                                       {{"translate": [0, {PANE_Y_M}, 0]}}]}}{extra_shapes}],
            "lights": [{lights}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normal": [0, 1, 0],
                          "relative_error": 0.003}}]}}"#,
        positions.join(", ")
    )
}

fn check(label: &str, ours: &PointReading, reference_lx: f64) {
    let error = ours.illuminance_lx - reference_lx;
    println!(
        "{label}: reference {reference_lx:.4} lx, ours {:.4} ± {:.4} lx ({:+.3} %)",
        ours.illuminance_lx,
        ours.std_error_lx,
        100.0 * error / reference_lx
    );
    assert!(
        error.abs() <= 4.5 * ours.std_error_lx + 1e-9 * reference_lx,
        "{label}: {} ± {} lx against {reference_lx} lx",
        ours.illuminance_lx,
        ours.std_error_lx
    );
}

#[test]
fn a_point_source_behind_thin_glazing_lights_the_floor_through_it() {
    let (intensity_cd, height_m) = (1000.0, 3.0);
    let xs = [0.0, 1.0, 2.5, 4.0];
    let json = scene_json(
        &format!(
            r#"{{"type": "point", "position_m": [0, {height_m}, 0], "intensity_cd": {intensity_cd}}}"#
        ),
        "",
        &xs,
    );
    let readings = measure(&json);
    for (x, ours) in xs.iter().zip(&readings) {
        let d2 = x * x + height_m * height_m;
        let cos = height_m / d2.sqrt();
        let reference = intensity_cd * cos / d2 * pane_transmittance(cos);
        // A point light is a Dirac: without glazing in the shadow rays this read 0 lx.
        assert!(ours.illuminance_lx > 0.5 * reference, "x = {x}: {ours:?}");
        check(&format!("point source, x = {x} m"), ours, reference);
    }
}

#[test]
fn an_area_source_behind_thin_glazing_is_counted_once_by_light_sampling_and_paths() {
    let (w, h, y, l) = (1.0, 1.0, 3.0, 4000.0);
    let xs = [0.0, 1.5];
    // A rectangle's normal is +Z locally; rotating by +90° about X turns it to −Y.
    let extra = format!(
        r#", {{"type": "rectangle", "name": "panel", "size_m": [{w}, {h}],
              "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                            {{"translate": [0, {y}, 0]}}]}}"#
    );
    let json = scene_json(
        &format!(r#"{{"type": "area", "shape": "panel", "luminance_cd_m2": {l}}}"#),
        &extra,
        &xs,
    );
    let readings = measure(&json);
    for (x, ours) in xs.iter().zip(&readings) {
        // E = ∫ L T'(θ) cos θ_r cos θ_l / r² dA over the source (midpoint rule, 400²
        // cells); the pane is horizontal, so its incidence angle is the receiver's.
        let cells = 400;
        let mut e = 0.0;
        for i in 0..cells {
            for j in 0..cells {
                let px = -w / 2.0 + (i as f64 + 0.5) * w / cells as f64;
                let pz = -h / 2.0 + (j as f64 + 0.5) * h / cells as f64;
                let (dx, dz) = (px - x, pz);
                let r2 = dx * dx + y * y + dz * dz;
                let cos = y / r2.sqrt();
                e += l * pane_transmittance(cos) * cos * cos / r2;
            }
        }
        let reference = e * (w * h) / (cells * cells) as f64;
        check(&format!("area source, x = {x} m"), ours, reference);
    }
}
