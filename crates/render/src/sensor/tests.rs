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

/// Illuminance from the strip of a uniform sky of luminance `l` that shows below the
/// horizon past the edge of a 1000 m square floor centred under a receiver 0.5 m up facing
/// `n` (see `uniform_sky_gives_pi_l_…`).
fn sky_below_floor_edge_lx(l: f64, n: DVec3) -> f64 {
    let steps = 20_000;
    let d = std::f64::consts::TAU / steps as f64;
    (0..steps)
        .map(|k| {
            let phi = (k as f64 + 0.5) * d;
            let (s, c) = phi.sin_cos();
            let delta = 0.5 * c.abs().max(s.abs()) / 500.0;
            l * n.normalize().dot(DVec3::new(c, 0.0, s)).max(0.0) * delta * d
        })
        .sum::<f64>()
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
    // The floor (1000 m square) ends 500–707 m away: seen from 0.5 m up, a strip of sky
    // below the horizon, δ(φ) = 0.5 m · max(|cos φ|, |sin φ|) / 500 m high at azimuth φ,
    // is not hidden. It adds L ∫ max(0, n · ω(φ)) δ(φ) dφ (ω horizontal; cos of the
    // elevation ≈ 1): ≈ 1.8 lx on the vertical receiver, 0.1 % of its reading, which the
    // sensors now resolve.
    let strip = |n: DVec3| sky_below_floor_edge_lx(l, n);
    check(
        &pts[1],
        std::f64::consts::PI * l / 2.0 + strip(DVec3::X),
        "vertical over ground",
    );
    // Facing mostly down: the sky above the floor's horizon, (1 − cos α)/2 of πL with
    // cos α the normal's downward component... exactly πL (1 − sin β)/2, β the elevation
    // of the normal below the horizon.
    let n = DVec3::new(0.3, -1.0, 0.2).normalize();
    let sin_beta = -n.y;
    check(
        &pts[2],
        std::f64::consts::PI * l * (1.0 - sin_beta) / 2.0 + strip(n),
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

/// A point no light reaches (inside a closed box, the lamp outside): all its samples are
/// zero, so a relative target cannot be judged and it samples to `max_samples`; an
/// absolute target stops it after the first batch (512 samples).
#[test]
fn a_point_no_sample_lights_is_not_judged_by_a_relative_target() {
    let json = |rule: &str| {
        format!(
            r#"{{"lights": [{{"type": "point", "position_m": [0, 3, 0], "intensity_cd": 1000}}],
                "shapes": [{{"type": "cuboid", "size_m": [1, 1, 1]}}],
                "sensors": [{{"type": "point", "position_m": [0, 0, 0], {rule}}}]}}"#
        )
    };
    for (rule, samples) in [
        (r#""relative_error": 0.01, "max_samples": 4096"#, 4096),
        (
            r#""relative_error": 0.01, "absolute_error_lx": 1, "max_samples": 4096"#,
            512,
        ),
    ] {
        let r = measure(&json(rule));
        let p = &r[0].points[0];
        assert_eq!(p.illuminance_lx, 0.0, "{rule}: {p:?}");
        assert_eq!(p.samples, samples, "{rule}: {p:?}");
    }
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

/// z-scores (reading − exact) / reported s.e. of every point of `json`'s sensors over
/// `seeds` seeds.
fn z_scores(json: &str, exact: &dyn Fn(&PointReading) -> f64, seeds: u64) -> Vec<f64> {
    let (scene, sensors) = scene(json);
    let mut z = Vec::new();
    for seed in 0..seeds {
        let (r, _) = measure_sensors(&scene, &sensors, 1000 + seed, &|_| {});
        for p in r.iter().flat_map(|s| &s.points) {
            assert!(p.std_error_lx > 0.0, "{p:?}");
            z.push((p.illuminance_lx - exact(p)) / p.std_error_lx);
        }
    }
    z
}

/// The reported standard errors are honest: over many seeds the readings' z-scores against
/// the exact value have mean 0 and the variance of Student's t with R − 1 = 31 degrees of
/// freedom (the s.e. comes from R = 32 replicates): 31/29. Tolerances are 4.5 standard
/// errors of those two statistics (t_ν: E z⁴ = 3ν²/((ν − 2)(ν − 4)), so
/// Var z² = E z⁴ − (E z²)²). An s.e. taken as s²/n over the scrambled points, which are not
/// independent, would be too large (z² ≈ 0.5 on the benchmark's furnished room) and fail.
fn check_z_scores(z: &[f64], what: &str) {
    let n = z.len() as f64;
    let nu = f64::from(SENSOR_REPLICATES - 1);
    let var_t = nu / (nu - 2.0);
    let fourth = 3.0 * nu * nu / ((nu - 2.0) * (nu - 4.0));
    let mean = z.iter().sum::<f64>() / n;
    let mean_sq = z.iter().map(|x| x * x).sum::<f64>() / n;
    assert!(
        mean.abs() <= 4.5 * (var_t / n).sqrt(),
        "{what}: mean z-score {mean} over {n} readings"
    );
    let tol = 4.5 * ((fourth - var_t * var_t) / n).sqrt();
    assert!(
        (mean_sq - var_t).abs() <= tol,
        "{what}: mean squared z-score {mean_sq}, expected {var_t} ± {tol} over {n} readings"
    );
}

#[test]
fn standard_errors_are_honest_over_seeds_for_indirect_light() {
    // The closed emitting sphere (E = π L_e / (1 − ρ), light of every order), 8 receivers,
    // 32 seeds each: fixed 512 samples (16 per replicate), and adaptively to 1 % (a first
    // round of 16 per replicate, then more: the stopping rule looks at the s.e. it reports).
    let (le, rho) = (100.0, 0.5);
    let exact = std::f64::consts::PI * le / (1.0 - rho);
    for sampling in [r#""samples": 512"#, r#""relative_error": 0.01"#] {
        let z = z_scores(
            &format!(
                r#"{{"materials": {{"wall": {{"type": "lambert", "reflectance": {rho}}},
                                  "inside": {{"type": "two_sided", "material": "wall"}}}},
                    "integrator": {{"type": "path", "max_depth": 40, "rr_depth": 3}},
                    "shapes": [{{"type": "sphere", "name": "s", "radius_m": 2, "material": "inside"}}],
                    "lights": [{{"type": "area", "shape": "s", "luminance_cd_m2": {le}, "two_sided": true}}],
                    "sensors": [{{"type": "grid", "origin_m": [-1, -0.3, -1], "u_m": [2, 0.5, 0],
                                  "v_m": [0, 0.4, 2], "resolution": [4, 2], "normal": [0.2, 1, -0.3],
                                  {sampling}}}]}}"#
            ),
            &|_| exact,
            32,
        );
        check_z_scores(&z, &format!("furnace, {sampling}"));
    }
}

#[test]
fn standard_errors_are_honest_over_seeds_for_direct_light() {
    // Point source (inverse-square cosine law; only the wavelengths are random) and a
    // uniform sky over a black floor (light sampling and cosine sampling combined by MIS).
    let light = DVec3::new(0.0, 2.0, 0.0);
    let point = |p: &PointReading| {
        let to = light - DVec3::from(p.position_m);
        let d2 = to.length_squared();
        1000.0 * (to / d2.sqrt()).dot(DVec3::from(p.normal)).max(0.0) / d2
    };
    let z = z_scores(
        r#"{"lights": [{"type": "point", "position_m": [0, 2, 0], "intensity_cd": 1000}],
            "sensors": [{"type": "points", "positions_m": [[0, 0, 0], [1.5, 0, 0], [0, 0, 3]],
                         "normals": [[0, 1, 0], [0, 1, 0], [0, 1, -1]], "samples": 64}]}"#,
        &point,
        96,
    );
    check_z_scores(&z, "point source");
    let l = 1000.0;
    let z = z_scores(
        &format!(
            r#"{{"materials": {{"black": {{"type": "lambert", "reflectance": 0}}}},
                "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "black",
                            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
                "lights": [{{"type": "sky", "luminance_cd_m2": {l}}}],
                "sensors": [{{"type": "points", "positions_m": [[0, 0.5, 0], [0, 0.5, 0]],
                              "normals": [[0, 1, 0], [1, 0, 0]], "samples": 128}}]}}"#
        ),
        &|p: &PointReading| {
            let full = std::f64::consts::PI * l;
            if p.normal[1] > 0.5 {
                full
            } else {
                full / 2.0 + sky_below_floor_edge_lx(l, DVec3::from(p.normal))
            }
        },
        96,
    );
    check_z_scores(&z, "sky over a black floor");
}

#[test]
fn scrambled_replicates_beat_independent_samples_on_a_lit_room() {
    // Why sensors use randomised QMC: in a closed diffuse box lit by a point lamp, the
    // variance of a 512-sample reading (observed over 64 seeds) is well below that of the
    // mean of 512 independent samples (their per-sample variance / 512).
    let json = r#"{"materials": {"w": {"type": "lambert", "reflectance": 0.6},
                                  "in": {"type": "two_sided", "material": "w"}},
                   "shapes": [{"type": "cuboid", "size_m": [4, 3, 4], "material": "in",
                               "transform": {"translate": [0, 1.5, 0]}}],
                   "lights": [{"type": "point", "position_m": [0.5, 2.7, 0.3], "intensity_cd": 500}],
                   "sensors": [{"type": "points", "positions_m": [[0.2, 0.01, -0.4]],
                                "normals": [[0, 1, 0]], "samples": 512}]}"#;
    let (scene, sensors) = scene(json);
    let readings: Vec<f64> = (0..64)
        .map(|seed| measure_sensors(&scene, &sensors, seed, &|_| {}).0[0].points[0].illuminance_lx)
        .collect();
    let n = readings.len() as f64;
    let mean = readings.iter().sum::<f64>() / n;
    let var_rqmc = readings.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    // Independent samples at the same point: the per-sample variance / 512.
    let tracer = sensor_tracer(&scene);
    let sampler = PixelSampler::with_kind(crate::sampler::SamplerKind::Independent, 5);
    let mut stats = RunningStats::default();
    let mut counters = PathCounters::default();
    let (p, nrm) = (Vec3A::new(0.2, 0.01, -0.4), Vec3A::Y);
    for k in 0..20_000 {
        let mut stream = sampler.stream(UVec2::ZERO, k);
        stats.push(sample_illuminance_lx(
            &tracer,
            &scene,
            p,
            nrm,
            sensor_light_samples(&scene),
            &mut stream,
            &mut counters,
        ));
    }
    let var_independent = stats.m2 / (stats.n - 1) as f64 / 512.0;
    // Unbiased: the two means agree within their errors.
    let se = (var_rqmc / n + stats.std_error().powi(2)).sqrt();
    assert!(
        (mean - stats.mean).abs() <= 4.5 * se,
        "{mean} vs {}",
        stats.mean
    );
    // 64 readings estimate var_rqmc to ±18 % (1σ); ask for at least 1.5× less variance.
    assert!(
        var_rqmc * 1.5 < var_independent,
        "RQMC variance {var_rqmc} vs independent {var_independent}"
    );
}

#[test]
fn sample_ranges_of_a_fixed_sensor_add_up_to_the_whole_measurement() {
    let json = r#"{"lights": [{"type": "sky", "luminance_cd_m2": 50}],
        "shapes": [{"type": "cuboid", "size_m": [1, 0.2, 1], "transform": {"translate": [0.3, 1.5, 0]}}],
        "sensors": [{"type": "grid", "name": "g", "origin_m": [-1, 0, -1], "u_m": [2, 0, 0], "v_m": [0, 0, 2],
                     "resolution": [2, 2], "samples": 700}]}"#;
    let (room, sensors) = scene(json);
    let (whole, _) = measure_sensors(&room, &sensors, 3, &|_| {});
    // [0, 3) and [3, 8) of an 8-sample render: ⌊3·700/8⌋ = 262 and the remaining 438.
    let share = |start, end| SampleShare {
        start,
        end,
        total: 8,
    };
    let (mut sums, first) = measure_sensor_share(&room, &sensors, 3, share(0, 3), &|_| {}).unwrap();
    assert_eq!(first.samples, 4 * 262);
    let (rest, _) = measure_sensor_share(&room, &sensors, 3, share(3, 8), &|_| {}).unwrap();
    sums[0].add(&rest[0]).unwrap();
    let merged = sums[0].reading();
    for (m, w) in merged.points.iter().zip(&whole[0].points) {
        assert_eq!(m.samples, w.samples);
        // The same samples; the replicate sums are added in another order (f64).
        assert!((m.illuminance_lx - w.illuminance_lx).abs() <= 1e-12 * w.illuminance_lx);
        assert!((m.std_error_lx - w.std_error_lx).abs() <= 1e-9 * w.std_error_lx);
    }
    // An adaptive sensor cannot be split.
    let (adaptive, sensors) = scene(&json.replace("\"samples\": 700", "\"relative_error\": 0.1"));
    let err = measure_sensor_share(&adaptive, &sensors, 3, share(0, 3), &|_| {}).unwrap_err();
    assert!(err.contains("sensor g") && err.contains("fixed"), "{err}");
}

#[test]
fn a_panel_under_a_sky_gives_its_form_factor_whichever_way_light_samples_choose() {
    // A 1 × 1 m panel of 8000 cd/m² 2 m above an upward receiver, under a sky of 150 cd/m²
    // that the panel hides in part: E = π L_panel F + π L_sky (1 − F), F the form factor
    // from the receiver to the panel (four corner rectangles of 0.5 × 0.5 m; Howell's
    // catalogue, differential area to a parallel rectangle). The sensor's cosine rays meet
    // the panel and the sky and are weighed against the light samples' choice, so every
    // choice must give the same lux.
    let (l_panel, l_sky) = (8000.0, 150.0);
    let corner = |x: f64, y: f64| {
        let (ax, ay) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / ax * (y / ax).atan() + y / ay * (x / ay).atan()) / std::f64::consts::TAU
    };
    let f = 4.0 * corner(0.25, 0.25);
    let exact = std::f64::consts::PI * (l_panel * f + l_sky * (1.0 - f));
    let json = format!(
        r#"{{"materials": {{"black": {{"type": "lambert", "reflectance": 0}}}},
            "shapes": [{{"type": "rectangle", "name": "panel", "size_m": [1, 1], "material": "black",
                         "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                                       {{"translate": [0, 2, 0]}}]}}],
            "lights": [{{"type": "area", "shape": "panel", "luminance_cd_m2": {l_panel}}},
                       {{"type": "sky", "luminance_cd_m2": {l_sky}}}],
            "sensors": [{{"type": "points", "positions_m": [[0, 0, 0]], "normals": [[0, 1, 0]],
                          "samples": 20000}}]}}"#
    );
    let (mut scene, sensors) = scene(&json);
    for selection in [
        crate::light::ShadingSelection::InfiniteApart,
        crate::light::ShadingSelection::Power,
        crate::light::ShadingSelection::Bvh,
    ] {
        assert!(scene.set_light_selection(selection));
        let r = measure_sensors(&scene, &sensors, 7, &|_| {}).0;
        check(&r[0].points[0], exact, &format!("{selection:?}"));
    }
}
