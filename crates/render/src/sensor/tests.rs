//! Sensors against closed-form illuminances: inverse-square cosine law of a point source,
//! a uniform sky (an infinite light) on horizontal and vertical receivers with and without
//! a ground, a closed diffusely reflecting emitting sphere (indirect light to all orders),
//! and the adaptive rule reaching its standard error. Tolerances: 4.5 standard errors.

use super::*;
use prism_scene::{SensorKind, SensorSampling};

fn scene(json: &str) -> (RenderScene, Vec<Sensor>) {
    let dir = tempfile::tempdir().unwrap();
    let description = prism_scene::parse_scene_str(json, dir.path().join("scene.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    let scene = RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"));
    (scene, description.sensors)
}

fn measure(json: &str) -> Vec<SensorReading> {
    let (scene, sensors) = scene(json);
    measure_sensors(&scene, &sensors, 7, &|_| {}).0
}

fn check(reading: &PointReading, exact: f64, what: &str) {
    let tol = 4.5 * reading.std_error_lx + 1e-9 * exact;
    assert!(
        (reading.illuminance_lx - exact).abs() <= tol,
        "{what}: {} ± {} lx vs exact {exact} lx",
        reading.illuminance_lx,
        reading.std_error_lx
    );
}

#[test]
fn point_source_follows_the_cosine_inverse_square_law() {
    // I = 1000 cd at 2 m above the origin; receivers at horizontal offsets and tilts.
    let r = measure(
        r#"{"lights": [{"type": "point", "position_m": [0, 2, 0], "intensity_cd": 1000}],
            "sensors": [{"type": "points", "positions_m": [[0, 0, 0], [1.5, 0, 0], [0, 0, 3], [1, 1, 0]],
                         "normals": [[0, 1, 0], [0, 1, 0], [0, 1, 1], [1, 0, 0]], "samples": 4000}]}"#,
    );
    let points = &r[0].points;
    let light = DVec3::new(0.0, 2.0, 0.0);
    for p in points {
        let to = light - DVec3::from(p.position_m);
        let d2 = to.length_squared();
        let cos = (to / d2.sqrt()).dot(DVec3::from(p.normal)).max(0.0);
        let exact = 1000.0 * cos / d2;
        check(p, exact, &format!("point at {:?}", p.position_m));
        // Only the wavelengths are random: a small relative error.
        assert!(p.std_error_lx < 0.02 * exact.max(1e-9) || exact == 0.0);
    }
    // The receiver at [1, 1, 0] faces +X, away from the light: nothing arrives.
    assert_eq!(points[3].illuminance_lx, 0.0);
}

#[test]
fn uniform_sky_gives_pi_l_and_half_of_it_on_a_vertical_receiver_over_a_black_ground() {
    let l = 1000.0;
    let sky = format!(r#"{{"type": "sky", "luminance_cd_m2": {l}}}"#);
    let sensors = r#"[{"type": "points", "positions_m": [[0, 0.5, 0], [0, 0.5, 0], [0, 0.5, 0]],
                       "normals": [[0, 1, 0], [1, 0, 0], [0.3, -1, 0.2]], "samples": 20000}]"#;
    // No geometry: every orientation sees a full hemisphere of sky.
    let open = measure(&format!(r#"{{"lights": [{sky}], "sensors": {sensors}}}"#));
    for p in &open[0].points {
        check(p, std::f64::consts::PI * l, "open sky");
    }
    // A huge black floor: the vertical receiver sees half a hemisphere of sky, the one
    // facing down only the floor.
    let floored = measure(&format!(
        r#"{{"materials": {{"black": {{"type": "lambert", "reflectance": 0}}}},
            "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "black",
                        "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
            "lights": [{sky}], "sensors": {sensors}}}"#
    ));
    let pts = &floored[0].points;
    check(&pts[0], std::f64::consts::PI * l, "horizontal over ground");
    // The floor ends 500 m away: seen from 0.5 m up, the missing strip is negligible.
    check(
        &pts[1],
        std::f64::consts::PI * l / 2.0,
        "vertical over ground",
    );
    // Facing mostly down: the sky above the floor's horizon, (1 − cos α)/2 of πL with
    // cos α the normal's downward component... exactly πL (1 − sin β)/2, β the elevation
    // of the normal below the horizon.
    let n = DVec3::new(0.3, -1.0, 0.2).normalize();
    let sin_beta = -n.y;
    check(
        &pts[2],
        std::f64::consts::PI * l * (1.0 - sin_beta) / 2.0,
        "tilted down over ground",
    );
}

#[test]
fn closed_emitting_reflecting_sphere_gives_pi_le_over_one_minus_rho() {
    // Inside a sphere whose wall emits L_e (two-sided area light) and reflects ρ
    // diffusely, the radiance everywhere is L_e / (1 − ρ) (all orders of reflection), so
    // any receiver anywhere inside gets E = π L_e / (1 − ρ).
    let (le, rho) = (100.0, 0.5);
    let r = measure(&format!(
        r#"{{"materials": {{"wall": {{"type": "lambert", "reflectance": {rho}}},
                          "inside": {{"type": "two_sided", "material": "wall"}}}},
            "integrator": {{"type": "path", "max_depth": 40, "rr_depth": 40}},
            "shapes": [{{"type": "sphere", "name": "s", "radius_m": 2, "material": "inside"}}],
            "lights": [{{"type": "area", "shape": "s", "luminance_cd_m2": {le}, "two_sided": true}}],
            "sensors": [{{"type": "points", "positions_m": [[0, 0, 0], [1.2, -0.5, 0.3]],
                          "normals": [[0, 1, 0], [-1, 0.2, 0.4]], "samples": 4000}}]}}"#
    ));
    // Truncation at 40 bounces: relative bias ρ^41 ≈ 5e-13.
    for p in &r[0].points {
        check(p, std::f64::consts::PI * le / (1.0 - rho), "furnace");
    }
}

#[test]
fn adaptive_sensors_stop_at_the_requested_standard_error() {
    let (scene, sensors) = scene(
        r#"{"lights": [{"type": "sky", "luminance_cd_m2": 50}],
            "shapes": [{"type": "cuboid", "size_m": [1, 0.2, 1], "transform": {"translate": [0.3, 1.5, 0]}}],
            "sensors": [{"type": "grid", "name": "g", "origin_m": [-1, 0, -1], "u_m": [2, 0, 0], "v_m": [0, 0, 2],
                         "resolution": [3, 2], "relative_error": 0.02}]}"#,
    );
    let (r, stats) = measure_sensors(&scene, &sensors, 1, &|_| {});
    assert_eq!(r[0].grid_resolution, Some([3, 2]));
    assert_eq!(r[0].points.len(), 6);
    let mut total = 0;
    for p in &r[0].points {
        assert!(p.std_error_lx <= 0.02 * p.illuminance_lx, "{p:?}");
        assert!(p.illuminance_lx > 0.0 && p.illuminance_lx <= std::f64::consts::PI * 50.0 * 1.1);
        total += p.samples;
    }
    assert_eq!(total, stats.samples);
    // Deterministic: the same seed gives the same readings whatever the thread count.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (again, _) = pool.install(|| measure_sensors(&scene, &sensors, 1, &|_| {}));
    assert_eq!(again, r);
    let u = r[0].uniformity();
    assert!(u.min_lx <= u.average_lx && u.average_lx <= u.max_lx);
    assert!((u.min_over_average - u.min_lx / u.average_lx).abs() < 1e-12);
    // Sampling rule and kind of the parsed sensor.
    assert!(matches!(sensors[0].kind, SensorKind::Grid { .. }));
    assert!(matches!(
        sensors[0].sampling,
        SensorSampling::Adaptive { .. }
    ));
}

#[test]
fn running_stats_merge_like_one_pass() {
    let xs: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 * 0.5).collect();
    let mut one = RunningStats::default();
    xs.iter().for_each(|&x| one.push(x));
    let mut a = RunningStats::default();
    let mut b = RunningStats::default();
    xs[..300].iter().for_each(|&x| a.push(x));
    xs[300..].iter().for_each(|&x| b.push(x));
    a.merge(&b);
    assert_eq!(a.n, one.n);
    assert!((a.mean - one.mean).abs() < 1e-12 && (a.m2 - one.m2).abs() < 1e-8 * one.m2);
    let mean = xs.iter().sum::<f64>() / 1000.0;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 999.0;
    assert!((one.std_error() - (var / 1000.0).sqrt()).abs() < 1e-12);
    assert_eq!(
        Uniformity::of([2.0, 4.0, 6.0]).unwrap().min_over_max,
        2.0 / 6.0
    );
    assert!(Uniformity::of(std::iter::empty()).is_none());
}
