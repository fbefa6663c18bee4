//! Area lights built from scene JSON: χ² of `sample_li` against `pdf_li` (hits found
//! through the geometry, as the path tracer finds them), analytic irradiance, photometry
//! and the errors of bad input.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledWavelengths;

use crate::light::test_support::{
    area_hit, build_error, build_scene, chi2_config, chi2_light, irradiance_estimate,
    photometric_sum,
};
use crate::light::{Light, LightSampleContext};

fn ctx(p: [f32; 3]) -> LightSampleContext {
    LightSampleContext {
        p: Vec3A::from(p),
        n: Vec3A::ZERO,
    }
}

fn facing(p: [f32; 3], n: [f32; 3]) -> LightSampleContext {
    LightSampleContext {
        p: Vec3A::from(p),
        n: Vec3A::from(n).normalize(),
    }
}

/// The lights of scene `json` (built in a scratch directory), for tests that need no
/// geometry.
fn lights_of(json: &str) -> crate::light::LightSet {
    let dir = tempfile::tempdir().unwrap();
    build_scene(dir.path(), json).unwrap().1
}

/// The light's irradiance estimate at `c` (200 000 samples) within 4 standard errors of
/// `exact` (plus 10⁻⁵ of it for f32 rounding).
fn assert_irradiance(light: &Light, c: LightSampleContext, exact: f64, seed: u64) {
    let (e, se) = irradiance_estimate(light, c, 200_000, seed);
    assert!(
        (e - exact).abs() < 4.0 * se + 1e-5 * exact,
        "at {:?}: {e} ± {se} vs {exact}",
        c.p
    );
}

fn scene(shape: &str, light_extra: &str) -> String {
    format!(
        r#"{{"shapes": [{shape}],
            "lights": [{{"type": "area", "shape": "lamp", "spectrum": 1 {light_extra}}}]}}"#
    )
}

/// Runs χ² at each reference point; asserts it passes, that the fraction of successful
/// samples is the expected one (when given: 1 where the whole light faces the point) and
/// that ∫ pdf dω over the sphere equals it.
fn check_chi2(json: &str, points: &[([f32; 3], Option<f64>)], seed: u64) {
    let contexts: Vec<_> = points.iter().map(|&(p, f)| (ctx(p), f)).collect();
    check_chi2_at(json, &contexts, seed);
}

/// `check_chi2` from reference points with their normals.
fn check_chi2_at(json: &str, points: &[(LightSampleContext, Option<f64>)], seed: u64) {
    let dir = tempfile::tempdir().unwrap();
    let (geometry, lights) = build_scene(dir.path(), json).unwrap();
    let config = chi2_config(points.len(), seed);
    for &(c, expected_fraction) in points {
        let p = c.p;
        let r = chi2_light(&config, &geometry, &lights, 0, c);
        assert!(r.passed, "at {p:?}: {}", r.message);
        if let Some(f) = expected_fraction {
            // Up to a few grazing samples at the outline.
            assert!(
                (r.success_fraction - f).abs() < 1e-4,
                "at {p:?}: {}",
                r.message
            );
        }
        // ∫pdf over the visible solid angle, numerically (midpoint rule on 24² sub-cells
        // per bin: ~0.5 % error at the light's outline).
        assert!(
            (r.pdf_integral - r.success_fraction).abs() < 0.01,
            "at {p:?}: {}",
            r.message
        );
    }
}

#[test]
fn chi2_area_sphere() {
    let sphere = r#"{"type": "sphere", "name": "lamp", "radius_m": 1}"#;
    // Outside: cone sampling, near (the cap fills a wide cone) and far.
    check_chi2(
        &scene(sphere, ""),
        &[([0.2, -0.3, 1.3], Some(1.0)), ([0.0, 0.5, -2.5], Some(1.0))],
        11,
    );
    // Inside a two-sided sphere: area sampling.
    check_chi2(
        &scene(sphere, r#", "two_sided": true"#),
        &[([0.3, 0.2, -0.4], Some(1.0))],
        12,
    );
    // Inside a one-sided sphere nothing emits towards the point.
    check_chi2(&scene(sphere, ""), &[([0.3, 0.2, -0.4], Some(0.0))], 13);
    // An ellipsoid (non-uniform scale): area sampling with Nanson's stretch factor; from
    // outside only the part facing the point emits towards it (one-sided, convex), from
    // inside a two-sided one is seen whole.
    let ellipsoid = r#"{"type": "sphere", "name": "lamp", "radius_m": 1,
        "transform": [{"scale": [1, 2, 0.5]}, {"rotate": {"axis": [1, 1, 0], "angle_deg": 30}}]}"#;
    check_chi2(&scene(ellipsoid, ""), &[([0.0, 0.3, 1.6], None)], 14);
    check_chi2(
        &scene(ellipsoid, r#", "two_sided": true"#),
        &[([0.1, 0.2, 0.0], Some(1.0))],
        15,
    );
}

#[test]
fn chi2_area_disk() {
    let disk = r#"{"type": "disk", "name": "lamp", "radius_m": 1}"#;
    check_chi2(
        &scene(disk, ""),
        &[
            ([0.0, 0.0, 0.4], Some(1.0)),
            ([0.9, -0.5, 0.3], Some(1.0)),
            ([0.0, 0.0, -0.5], Some(0.0)),
        ],
        21,
    );
    // An ellipse, two-sided, seen from behind.
    let ellipse = r#"{"type": "disk", "name": "lamp", "radius_m": 1,
        "transform": [{"scale": [2, 0.7, 1]}, {"rotate": {"axis": [0, 1, 0], "angle_deg": 20}}]}"#;
    check_chi2(
        &scene(ellipse, r#", "two_sided": true"#),
        &[([0.3, 0.1, -0.6], Some(1.0))],
        22,
    );
}

#[test]
fn chi2_area_rectangle() {
    let rect = r#"{"type": "rectangle", "name": "lamp", "size_m": [2, 1]}"#;
    // Near (uniform in solid angle: within `SOLID_ANGLE_SAMPLING_RANGE` half-diagonals,
    // 2.24 m here) and far (uniform in area).
    check_chi2(
        &scene(rect, ""),
        &[
            ([0.0, 0.0, 0.5], Some(1.0)),
            ([1.5, 0.2, 0.3], Some(1.0)),
            ([0.9, 0.4, 0.02], Some(1.0)),
            ([0.5, -0.3, 3.0], Some(1.0)),
        ],
        31,
    );
    // Near, from receivers with a normal: the solid-angle sample warped by their corner
    // cosines (one receiver faces the light, one is a wall beside it).
    check_chi2_at(
        &scene(rect, ""),
        &[
            (facing([0.3, 0.2, 0.4], [0.2, 0.1, -1.0]), Some(1.0)),
            (facing([1.4, 0.0, 0.3], [-1.0, 0.0, 0.0]), Some(1.0)),
        ],
        33,
    );
    // A sheared parallelogram.
    let sheared = r#"{"type": "rectangle", "name": "lamp", "size_m": [1, 1],
        "transform": {"matrix": [[1, 0.6, 0, 0], [0, 1, 0.2, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}"#;
    check_chi2(&scene(sheared, ""), &[([0.2, 0.0, 0.7], Some(1.0))], 32);
}

#[test]
fn chi2_area_mesh() {
    // A convex closed mesh (cuboid), non-uniformly scaled and rotated: only the faces that
    // face the point emit towards it, and they are exactly the visible ones.
    let cuboid = r#"{"type": "cuboid", "name": "lamp", "size_m": [1, 0.6, 1.4],
        "transform": {"rotate": {"axis": [1, 2, 3], "angle_deg": 35}}}"#;
    check_chi2(
        &scene(cuboid, ""),
        &[([0.2, 0.1, 1.1], None), ([-0.9, 0.4, 0.5], None)],
        41,
    );
    // Instances of one triangle under different transforms, two-sided, side by side.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let json = r#"{"meshes": {"tri": "tri.obj"},
        "shapes": [{"type": "instances", "name": "lamp", "mesh": "tri", "instances": [
            {"translate": [-1.2, -0.5, 0]},
            [{"scale": [0.8, 1.5, 1]}, {"translate": [0.2, -0.7, 0.1]}],
            [{"rotate": {"axis": [0, 0, 1], "angle_deg": 180}}, {"translate": [0.0, 1.4, -0.2]}]]}],
        "lights": [{"type": "area", "shape": "lamp", "two_sided": true, "spectrum": 1}]}"#;
    let (geometry, lights) = build_scene(dir.path(), json).unwrap();
    let config = chi2_config(2, 42);
    for p in [[0.1f32, 0.2, 0.8], [0.3, -0.2, -0.9]] {
        let r = chi2_light(&config, &geometry, &lights, 0, ctx(p));
        assert!(r.passed, "at {p:?}: {}", r.message);
        assert!((r.success_fraction - 1.0).abs() < 1e-4, "{}", r.message);
        assert!((r.pdf_integral - 1.0).abs() < 0.01, "{}", r.message);
    }
}

#[test]
fn chi2_area_mesh_success_fraction_of_a_cuboid_is_its_visible_area_share() {
    // From a point in front of one face of a unit cube only that face (1/6 of the area)
    // emits towards the point: a sixth of the samples succeed, and ∫pdf is the same.
    let dir = tempfile::tempdir().unwrap();
    let json = scene(r#"{"type": "cuboid", "name": "lamp"}"#, "");
    let (geometry, lights) = build_scene(dir.path(), &json).unwrap();
    let r = chi2_light(
        &chi2_config(1, 43),
        &geometry,
        &lights,
        0,
        ctx([0.1, 0.0, 1.0]),
    );
    assert!(r.passed, "{}", r.message);
    // Binomial standard error of 1/6 at 4·10⁵ samples: 5.9e-4.
    assert!(
        (r.success_fraction - 1.0 / 6.0).abs() < 4.0 * 5.9e-4,
        "{}",
        r.message
    );
    assert!((r.pdf_integral - 1.0 / 6.0).abs() < 0.005, "{}", r.message);
}

#[test]
fn disk_light_irradiance_on_axis_is_pi_l_sin2_alpha() {
    // E = π L sin²α, sin²α = R²/(R² + h²), on a surface facing the disk on its axis.
    let json = scene(
        r#"{"type": "disk", "name": "lamp", "radius_m": 0.5,
            "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 2, 0]}]}"#,
        r#", "two_sided": true, "scale": 3"#,
    );
    let lights = lights_of(&json);
    for h in [0.3f32, 1.0, 4.0] {
        let c = facing([0.0, 2.0 - h, 0.0], [0.0, 1.0, 0.0]);
        let (r, h) = (0.5f64, f64::from(h));
        let exact = std::f64::consts::PI * 3.0 * r * r / (r * r + h * h);
        assert_irradiance(lights.light(0), c, exact, 7);
    }
}

#[test]
fn a_two_sided_rectangle_seen_from_its_own_plane_gives_finite_samples_or_none() {
    // Points on the light itself (a path vertex on a two-sided emitter) and just off its
    // plane, where the solid angle degenerates: every sample and density is finite.
    let json = scene(
        r#"{"type": "rectangle", "name": "lamp", "size_m": [2, 1]}"#,
        r#", "two_sided": true"#,
    );
    let lights = lights_of(&json);
    let light = lights.light(0);
    let wl = SampledWavelengths::sample_uniform(0.5);
    for z in [0.0f32, 1e-7, -1e-7, 1e-4] {
        for c in [
            facing([0.3, 0.1, z], [0.0, 0.0, 1.0]),
            ctx([0.3, 0.1, z]),
            ctx([1.0, 0.5, z]),
        ] {
            let mut sampled = 0;
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.01, (i / 8) as f32 / 8.0 + 0.01);
                if let Some(s) = light.sample_li(&c, u, &wl) {
                    assert!(s.pdf.is_finite() && s.pdf > 0.0, "z {z}: pdf {}", s.pdf);
                    assert!(s.wi.is_finite() && s.p_light.is_finite(), "z {z}: {s:?}");
                    sampled += 1;
                }
            }
            // Off the plane the whole light is seen: every sample lands.
            if z == 1e-4 {
                assert_eq!(sampled, 64, "z {z} at {:?}", c.p);
            }
        }
    }
}

#[test]
fn rectangle_light_irradiance_is_the_parallel_form_factors() {
    // A surface parallel to a rectangle of radiance L at height h: E = π L F, F by the
    // corner form factor (1/2π)[X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))],
    // X = x/h, Y = y/h, summed over the four corners with signs. From close by (solid-angle
    // sampling, where a point 2 cm under the light is near its plane) and from afar (area
    // sampling).
    let json = scene(
        r#"{"type": "rectangle", "name": "lamp", "size_m": [2, 1]}"#,
        r#", "scale": 3"#,
    );
    let lights = lights_of(&json);
    let corner = |x: f64, y: f64| {
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / std::f64::consts::TAU
    };
    for p in [
        [0.3f32, 0.1, 0.02],
        [1.2, 0.4, 0.5],
        [0.9, -0.6, 1.5],
        [0.5, 0.2, 4.0],
    ] {
        let c = facing(p, [0.0, 0.0, -1.0]);
        let h = f64::from(p[2]);
        let (x0, x1) = ((-1.0 - f64::from(p[0])) / h, (1.0 - f64::from(p[0])) / h);
        let (y0, y1) = ((-0.5 - f64::from(p[1])) / h, (0.5 - f64::from(p[1])) / h);
        let f = corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
        assert_irradiance(lights.light(0), c, std::f64::consts::PI * 3.0 * f, 9);
    }
}

#[test]
fn sphere_light_irradiance_is_pi_l_r2_over_d2() {
    // A sphere of radius r at distance d from a surface facing its centre gives
    // E = π L (r/d)² (it looks like a point of intensity π r² L).
    let json = scene(
        r#"{"type": "sphere", "name": "lamp", "radius_m": 0.25, "transform": {"translate": [1, 1, 1]}}"#,
        r#", "scale": 2"#,
    );
    let lights = lights_of(&json);
    for d in [0.3f32, 1.0, 10.0] {
        let dir_to = Vec3A::new(1.0, 2.0, -2.0).normalize();
        let p = Vec3A::ONE - dir_to * d;
        let c = LightSampleContext { p, n: dir_to };
        let exact = std::f64::consts::PI * 2.0 * (0.25 / f64::from(d)).powi(2);
        assert_irradiance(lights.light(0), c, exact, 8);
    }
}

#[test]
fn inside_a_closed_emitting_sphere_the_irradiance_is_pi_l_even_on_its_wall() {
    // An enclosure of uniform radiance L gives E = π L at every point and orientation.
    // Reference points on the wall itself (as hits give them, rounded to either side of
    // the surface) must sample the interior, not the degenerate cone of an outside point.
    let json = scene(
        r#"{"type": "sphere", "name": "lamp", "radius_m": 2, "transform": {"translate": [0.5, 0, 0]}}"#,
        r#", "two_sided": true, "scale": 0.25"#,
    );
    let lights = lights_of(&json);
    let c = Vec3A::new(0.5, 0.0, 0.0);
    // On the wall facing inwards, and inside (any orientation).
    for (k, (radial, n)) in [
        (Vec3A::new(1.0, 2.0, -2.0).normalize(), None),
        (Vec3A::new(-0.3, 0.1, 0.9).normalize(), None),
        (Vec3A::Y * 0.4, Some(Vec3A::new(0.3, 0.4, 0.2).normalize())),
    ]
    .into_iter()
    .enumerate()
    {
        for scale in [1.0 - 1e-6, 1.0, 1.0 + 1e-6] {
            let p = c + radial * (2.0 * scale);
            let ctx = LightSampleContext {
                p,
                n: n.unwrap_or(-radial),
            };
            let (e, se) = irradiance_estimate(lights.light(0), ctx, 100_000, 20 + k as u64);
            let exact = std::f64::consts::PI * 0.25;
            assert!(
                (e - exact).abs() < 4.0 * se + 1e-4 * exact,
                "point {k} at {scale}: {e} ± {se} vs {exact}"
            );
        }
    }
}

#[test]
fn area_light_luminance_and_flux_are_exact() {
    // 100 cd/m² on a 2 m × 3 m rectangle scaled by 1.5 (A = 13.5 m²): Φ = π · 100 · A lm,
    // and a light given that flux has the same luminance; two-sided halves it.
    let rect =
        r#"{"type": "rectangle", "name": "lamp", "size_m": [2, 3], "transform": {"scale": 1.5}}"#;
    let dir = tempfile::tempdir().unwrap();
    let area = 2.0 * 3.0 * 1.5 * 1.5;
    let flux = std::f64::consts::PI * 100.0 * area;
    for (extra, expected) in [
        (r#", "luminance_cd_m2": 100"#.to_string(), 100.0),
        (format!(r#", "power_lm": {flux}"#), 100.0),
        (format!(r#", "power_lm": {flux}, "two_sided": true"#), 50.0),
    ] {
        let json = format!(
            r#"{{"shapes": [{rect}], "lights": [{{"type": "area", "shape": "lamp", "spectrum": {{"blackbody_k": 3000}} {extra}}}]}}"#
        );
        let (geometry, lights) = build_scene(dir.path(), &json).unwrap();
        let Light::Area(a) = lights.light(0) else {
            panic!()
        };
        assert!((a.shape.area_m2() - area).abs() < 1e-4);
        let (_, hit) =
            area_hit(&geometry, &lights, Vec3A::new(0.0, 0.0, 1.0), Vec3A::NEG_Z).unwrap();
        let luminance = photometric_sum(|wl| lights.light(0).emitted_radiance(&hit, Vec3A::Z, wl));
        assert!(
            (luminance - expected).abs() < 1e-4 * expected,
            "{extra}: {luminance}"
        );
        // Luminous flux π L A · sides.
        let sides = if a.two_sided { 2.0 } else { 1.0 };
        let phi = std::f64::consts::PI * luminance * a.shape.area_m2() * sides;
        assert!((phi - std::f64::consts::PI * expected * area * sides).abs() < 1e-3 * phi);
    }
}

#[test]
fn one_sided_lights_are_dark_from_behind_and_two_sided_ones_are_not() {
    let dir = tempfile::tempdir().unwrap();
    let wl = SampledWavelengths::sample_uniform(0.2);
    for (two_sided, lit) in [(false, false), (true, true)] {
        let json = scene(
            r#"{"type": "rectangle", "name": "lamp"}"#,
            &format!(r#", "two_sided": {two_sided}"#),
        );
        let (geometry, lights) = build_scene(dir.path(), &json).unwrap();
        let behind = ctx([0.1, 0.1, -1.0]);
        let s = lights.light(0).sample_li(&behind, Vec2::splat(0.3), &wl);
        assert_eq!(s.is_some(), lit);
        let (_, hit) = area_hit(&geometry, &lights, behind.p, Vec3A::Z).unwrap();
        assert_eq!(
            lights.light(0).pdf_li(&behind, Vec3A::Z, Some(&hit)) > 0.0,
            lit
        );
        let l = lights.light(0).emitted_radiance(&hit, Vec3A::NEG_Z, &wl);
        assert_eq!(!l.is_black(), lit);
        assert_eq!(lights.light(0).pdf_li(&behind, Vec3A::Z, None), 0.0);
    }
}

#[test]
fn every_instance_of_the_shape_maps_to_its_light() {
    let json = r#"{"shapes": [{"type": "sphere"}, {"type": "cuboid", "name": "lamp"},
        {"type": "disk", "name": "d"}],
        "lights": [{"type": "point"}, {"type": "area", "shape": "d"}, {"type": "area", "shape": "lamp"}]}"#;
    let lights = lights_of(json);
    assert_eq!(lights.area_light_of_instance(0), None);
    assert_eq!(lights.area_light_of_instance(1), Some(2));
    assert_eq!(lights.area_light_of_instance(2), Some(1));
    assert_eq!(lights.area_light_of_instance(3), None);
}

#[test]
fn bad_area_lights_are_errors_naming_the_light() {
    let dir = tempfile::tempdir().unwrap();
    // Zero area: a degenerate triangle.
    std::fs::write(
        dir.path().join("flat.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    )
    .unwrap();
    let e = build_error(
        dir.path(),
        r#"{"shapes": [{"type": "mesh", "name": "lamp", "file": "flat.obj"}],
            "lights": [{"type": "area", "shape": "lamp"}]}"#,
    );
    assert!(
        e.contains("scene.json: lights[0].shape: shape `lamp` (shapes[0]) has zero area"),
        "{e}"
    );
    // Two lights on one shape.
    let e = build_error(
        dir.path(),
        r#"{"shapes": [{"type": "disk", "name": "lamp"}],
            "lights": [{"type": "area", "shape": "lamp"}, {"type": "area", "shape": "lamp"}]}"#,
    );
    assert!(
        e.contains("lights[1].shape: shape `lamp` (shapes[0]) already emits"),
        "{e}"
    );
    // A photometric strength on a spectrum with no luminous content.
    let e = build_error(
        dir.path(),
        r#"{"shapes": [{"type": "disk", "name": "lamp"}],
            "lights": [{"type": "area", "shape": "lamp", "spectrum": 0, "power_lm": 100}]}"#,
    );
    assert!(
        e.contains("lights[0].power_lm: the emission spectrum has no luminous content"),
        "{e}"
    );
}
