//! `path` in participating media against closed forms (issue 20, tests 1–5), and the
//! errors of media scenes. Each test renders a small image whose pixels all estimate the
//! same value (an orthographic camera, or a uniform answer), so the pixels' spread gives
//! the standard error of their mean; tolerances are 4 standard errors plus a stated floor.
//! Spectral coefficients come from CSV files, so the expected Y is the exact
//! ∫ L(λ) ȳ(λ) dλ / ∫ ȳ dλ over 360–830 nm (the film's normalisation).

use prism_render::{render, FilmImage, RenderScene, RenderSettings};
use prism_spectrum::data::{cmfs, Observer};

mod support;
use support::{vol_bytes, Dir};

fn render_scene(scene: &RenderScene, spp: u32, seed: u64) -> FilmImage {
    let settings = RenderSettings {
        spp,
        seed,
        ..RenderSettings::default()
    };
    render(scene, &settings, &|_| {}).0
}

/// Mean and standard error of the pixels' Y.
fn mean_and_se(image: &FilmImage) -> (f64, f64) {
    let n = image.y.len() as f64;
    let mean = image.y.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = image
        .y
        .iter()
        .map(|&v| (f64::from(v) - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn assert_close(what: &str, image: &FilmImage, expected: f64, floor: f64) {
    let (mean, se) = mean_and_se(image);
    eprintln!("{what}: mean {mean:.5}, expected {expected:.5}, s.e. {se:.2e}");
    assert!(
        (mean - expected).abs() <= 4.0 * se + floor,
        "{what}: mean {mean}, expected {expected} (s.e. {se}, floor {floor})"
    );
}

/// ∫ f(λ) ȳ dλ / ∫ ȳ dλ on the 1 nm CIE 1931 table.
fn y_weighted(f: impl Fn(f64) -> f64) -> f64 {
    let y = cmfs(Observer::Cie1931).y_bar.values();
    let (mut num, mut den) = (0.0, 0.0);
    for (k, &w) in y.iter().enumerate() {
        let wl = 360.0 + k as f64;
        num += f(wl) * w;
        den += w;
    }
    num / den
}

/// A spectral CSV of `points` (λ nm, value), and the same function (linear, held at the
/// ends) for the expected values.
fn spectrum_csv(points: &[(f64, f64)]) -> (String, impl Fn(f64) -> f64 + '_) {
    let mut text = String::from("wavelength_nm,value\n");
    for (wl, v) in points {
        text.push_str(&format!("{wl},{v}\n"));
    }
    let f = move |wl: f64| {
        if wl <= points[0].0 {
            return points[0].1;
        }
        for w in points.windows(2) {
            if wl <= w[1].0 {
                let t = (wl - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        points[points.len() - 1].1
    };
    (text, f)
}

const SLAB_D_M: f64 = 0.5;
const LE: f64 = 2.0;

/// An orthographic camera at z = 1 looking down −z through a slab (z in [−0.25, 0.25])
/// of medium `medium` (inside an `interface` cuboid) at an emitter of radiance LE at z = −1.
fn slab_scene(media: &str, integrator: &str) -> String {
    format!(
        r#"{{
  "camera": {{"type": "orthographic", "width_m": 0.2,
              "transform": {{"look_at": {{"eye": [0, 0, 1], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {integrator},
  "media": {{{media}}},
  "materials": {{"boundary": {{"type": "interface"}}, "black": {{"type": "lambert", "reflectance": 0}}}},
  "shapes": [
    {{"type": "cuboid", "size_m": [4, 4, {SLAB_D_M}], "material": "boundary", "interior_medium": "slab"}},
    {{"type": "rectangle", "name": "emitter", "size_m": [4, 4], "material": "black",
      "transform": {{"translate": [0, 0, -1]}}}}
  ],
  "lights": [{{"type": "area", "shape": "emitter", "spectrum": 1, "scale": {LE}}}]
}}"#
    )
}

/// Test 1: L = Le·e^(−τ(λ)) through an absorbing slab with spectral σa, for a homogeneous
/// medium, a constant grid (test 4: the same image's mean) and a linear ramp along the
/// view axis (τ exact by the trapezoid rule over voxel centres, edge values held).
#[test]
fn beer_lambert_through_an_absorbing_slab() {
    let dir = Dir::new("media", "beer-lambert");
    let points = [(360.0, 0.5), (550.0, 1.5), (830.0, 3.0)];
    let (csv, sigma_a) = spectrum_csv(&points);
    dir.write("sigma_a.csv", csv.as_bytes());
    // max_depth 1: the two interface crossings are not bounces (pbrt-v3 #69), so the
    // emitter behind them is still reached.
    let integrator = r#"{"type": "path", "max_depth": 1}"#;
    let (z0, z1) = (-0.5 * SLAB_D_M as f32, 0.5 * SLAB_D_M as f32);
    dir.write(
        "constant.vol",
        &vol_bytes([2, 2, 2], [-2.0, -2.0, z0], [2.0, 2.0, z1], &[1.0; 8]),
    );
    let ramp = [0.2f32, 0.6, 1.0, 1.4];
    dir.write(
        "ramp.vol",
        &vol_bytes([1, 1, 4], [-2.0, -2.0, z0], [2.0, 2.0, z1], &ramp),
    );
    // ∫ density dz: half a voxel of each end value, trapezoids between the centres.
    let h = SLAB_D_M / ramp.len() as f64;
    let ramp_integral = h
        * (0.5 * f64::from(ramp[0])
            + ramp
                .windows(2)
                .map(|w| 0.5 * f64::from(w[0] + w[1]))
                .sum::<f64>()
            + 0.5 * f64::from(ramp[3]));
    let cases = [
        (
            "homogeneous",
            r#""slab": {"sigma_a_per_m": "sigma_a.csv"}"#.to_string(),
            SLAB_D_M,
        ),
        (
            "constant grid",
            r#""slab": {"type": "grid", "density": "constant.vol", "sigma_a_per_m": "sigma_a.csv"}"#
                .to_string(),
            SLAB_D_M,
        ),
        (
            "ramp grid",
            r#""slab": {"type": "grid", "density": "ramp.vol", "sigma_a_per_m": "sigma_a.csv"}"#
                .to_string(),
            ramp_integral,
        ),
    ];
    for (what, media, depth_m) in cases {
        let scene = dir.scene(&slab_scene(&media, integrator));
        assert!(scene.packet.is_none());
        let image = render_scene(&scene, 256, 1);
        let expected = y_weighted(|wl| LE * (-sigma_a(wl) * depth_m).exp());
        assert_close(what, &image, expected, 1e-3);
    }
}

/// An emissive absorbing slab (σa spectral, emission Le_m) in front of a black wall:
/// L = Le_m·(1 − e^(−σa·d)).
#[test]
fn an_emissive_slab_glows_with_its_closed_form() {
    let dir = Dir::new("media", "emissive");
    let points = [(360.0, 0.5), (550.0, 1.5), (830.0, 3.0)];
    let (csv, sigma_a) = spectrum_csv(&points);
    dir.write("sigma_a.csv", csv.as_bytes());
    let le_m = 3.0;
    let lit = slab_scene(
        &format!(r#""slab": {{"sigma_a_per_m": "sigma_a.csv", "emission": {le_m}}}"#),
        r#"{"type": "path", "max_depth": 4}"#,
    );
    // The wall behind stays black: no light.
    let json = lit.replace(
        r#""lights": [{"type": "area", "shape": "emitter", "spectrum": 1, "scale": 2}]"#,
        r#""lights": []"#,
    );
    assert_ne!(json, lit);
    let image = render_scene(&dir.scene(&json), 256, 6);
    let expected = y_weighted(|wl| le_m * (1.0 - (-sigma_a(wl) * SLAB_D_M).exp()));
    assert_close("emissive slab", &image, expected, 1e-3);
}

/// Single scattering of an isotropic point light of intensity I along a camera ray:
/// ∫₀^∞ σs p(θ(s)) I e^(−σt (s + r(s))) / r(s)² ds, by the midpoint rule.
fn single_scattering(
    sigma_s: f64,
    sigma_t: f64,
    intensity: f64,
    light: [f64; 3],
    phase: impl Fn(f64) -> f64,
) -> f64 {
    let (n, s_max) = (400_000, 40.0 / sigma_t);
    let ds = s_max / n as f64;
    let mut sum = 0.0;
    for k in 0..n {
        let s = (k as f64 + 0.5) * ds;
        // The camera ray runs along −z from the origin.
        let to_light = [light[0], light[1], light[2] + s];
        let r2 = to_light.iter().map(|x| x * x).sum::<f64>();
        let r = r2.sqrt();
        // cos of the scattering angle: the light's propagation (from the light) against
        // the ray's way to the camera (+z).
        let cos_theta = -to_light[2] / r;
        sum += sigma_s * phase(cos_theta) * intensity * (-sigma_t * (s + r)).exp() / r2 * ds;
    }
    sum
}

/// Sun et al. 2005's closed form of the same integral for the isotropic phase function.
fn airlight_sun(sigma_s: f64, sigma_t: f64, intensity: f64, d: f64, gamma: f64, dv: f64) -> f64 {
    let (t, tv) = (sigma_t * d, sigma_t * dv);
    let (a, b) = (
        gamma / 2.0,
        std::f64::consts::FRAC_PI_4 + 0.5 * ((tv - t * gamma.cos()) / (t * gamma.sin())).atan(),
    );
    let n = 200_000;
    let h = (b - a) / n as f64;
    let integral: f64 = (0..n)
        .map(|k| (-(t * gamma.sin()) * (a + (k as f64 + 0.5) * h).tan()).exp() * h)
        .sum();
    sigma_s * sigma_t * intensity * (-t * gamma.cos()).exp()
        / (2.0 * std::f64::consts::PI * t * gamma.sin())
        * integral
}

/// Test 2: airlight of an isotropic point light in `world_medium`, `max_depth` 1, with the
/// isotropic phase function (against quadrature and Sun et al. 2005) and, by quadrature of
/// the single-scattering integral, Henyey–Greenstein, Rayleigh and a tabulated one.
#[test]
fn airlight_of_a_point_light() {
    let dir = Dir::new("media", "airlight");
    let (sigma_s, sigma_a, intensity) = (0.4, 0.1, 3.0);
    let sigma_t = sigma_s + sigma_a;
    let light: [f64; 3] = [0.0, 1.0, -1.5];
    // The closed form and the quadrature agree (γ: angle between the ray and the light).
    let d: f64 = (light[1] * light[1] + light[2] * light[2]).sqrt();
    let gamma = (-light[2] / d).acos();
    let iso = |_: f64| 1.0 / (4.0 * std::f64::consts::PI);
    let quadrature = single_scattering(sigma_s, sigma_t, intensity, light, iso);
    let sun = airlight_sun(sigma_s, sigma_t, intensity, d, gamma, 1e6);
    assert!(
        (sun - quadrature).abs() < 1e-4 * quadrature,
        "Sun {sun}, quadrature {quadrature}"
    );
    let g = 0.6;
    let hg = |c: f64| {
        (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * c).powf(1.5))
    };
    let rayleigh = |c: f64| 3.0 / (16.0 * std::f64::consts::PI) * (1.0 + c * c);
    // A forward-peaked table, linear between its rows, normalised to ∫ p dω = 1.
    let rows = [
        (-1.0, 1.0),
        (-0.5, 1.0),
        (0.0, 2.0),
        (0.5, 4.0),
        (1.0, 10.0),
    ];
    let csv: String = rows.iter().map(|(c, v)| format!("{c},{v}\n")).collect();
    dir.write("phase.csv", csv.as_bytes());
    let area: f64 = rows
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    let table = |c: f64| {
        let w = rows.windows(2).find(|w| c <= w[1].0).unwrap_or(&rows[3..5]);
        let t = (c - w[0].0) / (w[1].0 - w[0].0);
        (w[0].1 + t * (w[1].1 - w[0].1)) / (2.0 * std::f64::consts::PI * area)
    };
    for (what, phase, expected) in [
        ("isotropic", r#""isotropic""#.to_string(), sun),
        (
            "hg 0.6",
            format!(r#"{{"type": "hg", "g": {g}}}"#),
            single_scattering(sigma_s, sigma_t, intensity, light, hg),
        ),
        (
            "rayleigh",
            r#""rayleigh""#.to_string(),
            single_scattering(sigma_s, sigma_t, intensity, light, rayleigh),
        ),
        (
            "tabulated",
            r#"{"type": "tabulated", "file": "phase.csv"}"#.to_string(),
            single_scattering(sigma_s, sigma_t, intensity, light, table),
        ),
    ] {
        let json = format!(
            r#"{{
  "camera": {{"type": "orthographic", "width_m": 0.001,
              "transform": {{"look_at": {{"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {{"type": "path", "max_depth": 1}},
  "world_medium": "air",
  "media": {{"air": {{"sigma_a_per_m": {sigma_a}, "sigma_s_per_m": {sigma_s}, "phase": {phase}}}}},
  "shapes": [{{"type": "sphere", "radius_m": 0.01, "transform": {{"translate": [0, 0, 50]}}}}],
  "lights": [{{"type": "point", "position_m": {light:?}, "spectrum": 1, "scale": {intensity}}}]
}}"#
        );
        let image = render_scene(&dir.scene(&json), 1024, 2);
        assert_close(what, &image, expected, 2e-3 * expected);
    }
}

/// Test 3: a camera inside a closed black sphere that emits Le, filled with a
/// non-absorbing medium (spectral σs 1–20 m⁻¹, g 0.8): every pixel sees Le, whatever the
/// scattering; homogeneous and a random grid.
#[test]
fn furnace_inside_an_emitting_sphere() {
    let dir = Dir::new("media", "furnace");
    let (csv, _) = spectrum_csv(&[(360.0, 1.0), (600.0, 20.0), (830.0, 5.0)]);
    dir.write("sigma_s.csv", csv.as_bytes());
    let mut state = 12345u64;
    let random: Vec<f32> = (0..6 * 6 * 6)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    dir.write(
        "random.vol",
        &vol_bytes([6, 6, 6], [-1.0; 3], [1.0; 3], &random),
    );
    for (what, medium) in [
        (
            "homogeneous",
            r#"{"sigma_s_per_m": "sigma_s.csv", "phase": {"type": "hg", "g": 0.8}}"#,
        ),
        (
            "random grid",
            r#"{"type": "grid", "density": "random.vol", "sigma_s_per_m": "sigma_s.csv", "phase": {"type": "hg", "g": 0.8}}"#,
        ),
    ] {
        let json = format!(
            r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "medium": "fog",
              "transform": {{"look_at": {{"eye": [0, 0, 0.2], "target": [0, 0, -1], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {{"type": "path", "max_depth": 2000, "rr_depth": 2000}},
  "media": {{"fog": {medium}}},
  "materials": {{"black": {{"type": "lambert", "reflectance": 0}}}},
  "shapes": [{{"type": "sphere", "name": "wall", "radius_m": 1, "material": "black", "interior_medium": "fog"}}],
  "lights": [{{"type": "area", "shape": "wall", "two_sided": true, "spectrum": 1, "scale": {LE}}}]
}}"#
        );
        let image = render_scene(&dir.scene(&json), 64, 3);
        assert_close(what, &image, LE, 1e-3 * LE);
    }
}

/// Test 5: σt 2/6/9 m⁻¹ in three bands (a chromatic scattering slab in front of an
/// emitter): spectral MIS on and off have the same mean, and on has the lower variance.
#[test]
fn spectral_mis_keeps_the_mean_and_lowers_the_variance() {
    let dir = Dir::new("media", "spectral-mis");
    let csv = "wavelength_nm,value\n360,2\n489,2\n490,6\n589,6\n590,9\n830,9\n";
    dir.write("bands.csv", csv.as_bytes());
    let media = r#""slab": {"sigma_s_per_m": "bands.csv", "phase": {"type": "hg", "g": 0.5}}"#;
    let mut results = Vec::new();
    for on in [true, false] {
        let integrator = format!(r#"{{"type": "path", "max_depth": 16, "spectral_mis": {on}}}"#);
        let image = render_scene(&dir.scene(&slab_scene(media, &integrator)), 256, 4);
        results.push(mean_and_se(&image));
    }
    let ((mean_on, se_on), (mean_off, se_off)) = (results[0], results[1]);
    eprintln!("spectral MIS on {mean_on:.5} ± {se_on:.2e}, off {mean_off:.5} ± {se_off:.2e}");
    let se = (se_on * se_on + se_off * se_off).sqrt();
    assert!(
        (mean_on - mean_off).abs() <= 4.0 * se + 1e-4,
        "means differ: on {mean_on}, off {mean_off} (s.e. {se})"
    );
    assert!(
        se_on < se_off,
        "spectral MIS s.e. {se_on} ≥ hero-only {se_off}"
    );
}

/// Light-path methods and the packet tracer refuse media; path renders them.
#[test]
fn light_bdpt_and_packets_refuse_media() {
    let dir = Dir::new("media", "refusals");
    let media = r#""slab": {"sigma_a_per_m": 1}"#;
    for method in ["light", "bdpt"] {
        let e = dir.build_error(&slab_scene(media, &format!(r#"{{"type": "{method}"}}"#)));
        assert_eq!(
            e,
            format!(
                "DIR/scene.json: integrator: `{method}` samples no participating media yet \
                 (the scene has `slab`): use `path`"
            )
        );
    }
    let scene = dir.scene(&slab_scene(media, r#"{"type": "path"}"#));
    let Err(why) = prism_render::integrator::packet::PacketScene::new(&scene) else {
        panic!("the packet tracer took a scene with media");
    };
    assert_eq!(
        why,
        "the scene has participating media (slab): the packet tracer samples no media"
    );
    assert!(
        scene.packet.is_none(),
        "media scenes go through the scalar tracer"
    );
    // And that tracer renders the medium (e^(−0.5) of the emitter, not vacuum).
    let image = render_scene(&scene, 16, 5);
    assert_close("scalar tracer", &image, LE * (-SLAB_D_M).exp(), 1e-3);
}

/// Bad inputs only render can see, refused at their JSON path.
#[test]
fn media_errors_name_the_entry() {
    let dir = Dir::new("media", "errors");
    // An open mesh (one triangle) around an interior medium.
    dir.write("tri.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let e = dir.build_error(
        r#"{"media": {"fog": {}}, "shapes": [{"type": "mesh", "file": "tri.obj", "interior_medium": "fog"}]}"#,
    );
    assert!(
        e.starts_with("DIR/scene.json: shapes[0].interior_medium: the mesh DIR/tri.obj is open (3 boundary edges"),
        "{e}"
    );
    // A camera that says fog but sits outside the fog sphere it looks at.
    let e = dir.build_error(
        r#"{"media": {"fog": {}},
            "camera": {"medium": "fog", "transform": {"look_at": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}}},
            "shapes": [{"type": "sphere", "name": "ball", "interior_medium": "fog"}]}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json: camera.medium: the camera is in `fog` but sits outside shapes[0] \
         (`ball`), the first medium boundary along its view axis, where the medium is vacuum"
    );
    // A light that says vacuum but sits inside the fog sphere below it.
    let e = dir.build_error(
        r#"{"media": {"fog": {}},
            "camera": {"transform": {"look_at": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}}},
            "shapes": [{"type": "sphere", "name": "ball", "interior_medium": "fog"}],
            "lights": [{"type": "point", "position_m": [0, 0.5, 0]}]}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json: lights[0].medium: the light is in vacuum but sits inside shapes[0] \
         (`ball`), the first medium boundary straight below it, where the medium is `fog`"
    );
    // Sensors are not measured in media yet.
    let e = dir.build_error(
        r#"{"media": {"fog": {}}, "sensors": [{"type": "point", "name": "s", "position_m": [0, 0, 0], "normal": [0, 1, 0]}]}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json: sensors[0]: illuminance sensors are not measured in scenes with \
         participating media yet"
    );
    // A bad .vol names the file and what is wrong.
    dir.write("bad.vol", b"VOX\x03");
    let e = dir.build_error(r#"{"media": {"s": {"type": "grid", "density": "bad.vol"}}}"#);
    assert!(
        e.starts_with("DIR/scene.json: media.s.density: DIR/bad.vol:"),
        "{e}"
    );
}

/// `--explain` lists each medium (σt range, spectral MIS, grid size), says why packets are
/// off, and warns of a point light inside a closed dielectric (a volumetric caustic).
#[test]
fn the_plan_lists_media_and_warns_of_volumetric_caustics() {
    let dir = Dir::new("media", "plan");
    dir.write(
        "grid.vol",
        &vol_bytes([2, 3, 4], [-1.0; 3], [1.0; 3], &[0.5; 24]),
    );
    let scene = dir.scene(
        r#"{
  "world_medium": "fog",
  "media": {"fog": {"sigma_a_per_m": 0.1, "sigma_s_per_m": {"rgb": [0.2, 0.4, 0.9]}},
            "smoke": {"type": "grid", "density": "grid.vol", "sigma_s_per_m": 2}},
  "materials": {"glass": {"type": "dielectric", "ior": 1.5}},
  "shapes": [{"type": "sphere", "radius_m": 0.3, "material": "glass"}],
  "lights": [{"type": "point", "position_m": [0, 0, 0]}]
}"#,
    );
    let plan = prism_render::RenderPlan::new(&scene, &prism_render::PlanRequest::default());
    let line = |feature: &str| -> Vec<String> {
        plan.choices
            .iter()
            .filter(|c| c.feature == feature)
            .map(|c| format!("{} | {}", c.setting, c.reason))
            .collect()
    };
    let media = line("medium");
    assert_eq!(media.len(), 2, "{media:?}");
    assert!(
        media[0].starts_with("`fog`: homogeneous, σt "),
        "{}",
        media[0]
    );
    assert!(media[0].contains("chromatic σt"), "{}", media[0]);
    assert!(
        media[1].starts_with("`smoke`: grid, σt 2.0000–2.0000 m⁻¹ over 360–830 nm, 2×3×4 voxels"),
        "{}",
        media[1]
    );
    assert!(media[1].contains("grey σt"), "{}", media[1]);
    assert_eq!(
        line("medium transport"),
        vec![
            "null-scattering delta tracking, spectral MIS on, light and BSDF samples weighted \
             by the balance heuristic | the scene has participating media: `path` follows \
             pbrt-v4's VolPathIntegrator (rescaled path probabilities; docs/media.md)"
        ]
    );
    let caustic = line("volumetric caustic");
    assert_eq!(caustic.len(), 1, "{caustic:?}");
    assert!(caustic[0].starts_with(
        "warning: the point light at [0.0, 0.0, 0.0] m is inside a closed dielectric"
    ));
    assert!(caustic[0].ends_with("volumetric caustic: use photon_progressive"));
    let packet = line("packet tracing");
    assert_eq!(
        packet,
        vec!["off | not used: the scene has participating media (fog, smoke): the packet tracer samples no media"]
    );
}

/// Boundaries that disagree with the medium a ray arrives in are counted (and `prism
/// render` warns); consistent ones are not.
#[test]
fn inconsistent_boundaries_are_counted() {
    let dir = Dir::new("media", "mismatch");
    let scene = |inner_exterior: &str| {
        format!(
            r#"{{
  "media": {{"fog": {{"sigma_s_per_m": 0.1}}, "smoke": {{"sigma_s_per_m": 0.2}}}},
  "camera": {{"transform": {{"look_at": {{"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8]}},
  "materials": {{"b": {{"type": "interface"}}}},
  "shapes": [
    {{"type": "sphere", "radius_m": 2, "material": "b", "interior_medium": "fog"}},
    {{"type": "sphere", "radius_m": 1, "material": "b", "interior_medium": "smoke",
      "exterior_medium": "{inner_exterior}"}}
  ],
  "lights": [{{"type": "point", "position_m": [0, 3, 3]}}]
}}"#
        )
    };
    let settings = RenderSettings {
        spp: 4,
        seed: 1,
        ..RenderSettings::default()
    };
    let consistent = render(&dir.scene(&scene("fog")), &settings, &|_| {}).1;
    assert_eq!(consistent.medium_mismatches, 0);
    let nested_wrong = render(&dir.scene(&scene("smoke")), &settings, &|_| {}).1;
    assert!(
        nested_wrong.medium_mismatches > 0,
        "{}",
        nested_wrong.medium_mismatches
    );
}

/// A dispersive glass ball (Cauchy flint) holding a chromatic scattering medium in front of
/// an emitter: the glass ends the secondary lanes at the first hit, and from then on only
/// the hero's estimate counts, so spectral MIS on must divide by the hero's pdf as off does
/// (the lane average biased it): the two agree.
#[test]
fn after_dispersion_spectral_mis_on_and_off_agree() {
    let dir = Dir::new("media", "dispersion");
    let csv = "wavelength_nm,value\n360,2\n489,2\n490,6\n589,6\n590,9\n830,9\n";
    dir.write("bands.csv", csv.as_bytes());
    let mut results = Vec::new();
    for (on, seed) in [(true, 7u64), (false, 8)] {
        let json = format!(
            r#"{{
  "camera": {{"type": "orthographic", "width_m": 0.4,
              "transform": {{"look_at": {{"eye": [0, 0, 2], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {{"type": "path", "max_depth": 16, "spectral_mis": {on}}},
  "media": {{"fog": {{"sigma_s_per_m": "bands.csv", "phase": {{"type": "hg", "g": 0.5}}}}}},
  "materials": {{"flint": {{"type": "dielectric", "ior": {{"cauchy": {{"a": 1.67, "b_um2": 0.0074}}}}}},
                 "black": {{"type": "lambert", "reflectance": 0}}}},
  "shapes": [
    {{"type": "sphere", "radius_m": 0.5, "material": "flint", "interior_medium": "fog"}},
    {{"type": "rectangle", "name": "emitter", "size_m": [6, 6], "material": "black",
      "transform": {{"translate": [0, 0, -1]}}}}
  ],
  "lights": [{{"type": "area", "shape": "emitter", "spectrum": 1, "scale": {LE}}}]
}}"#
        );
        let image = render_scene(&dir.scene(&json), 1024, seed);
        results.push(mean_and_se(&image));
    }
    let ((mean_on, se_on), (mean_off, se_off)) = (results[0], results[1]);
    eprintln!("dispersion: on {mean_on:.5} ± {se_on:.2e}, off {mean_off:.5} ± {se_off:.2e}");
    let se = (se_on * se_on + se_off * se_off).sqrt();
    assert!(
        (mean_on - mean_off).abs() <= 4.0 * se + 1e-3 * mean_off,
        "means differ: on {mean_on}, off {mean_off} (s.e. {se})"
    );
    assert!(
        mean_off > 0.1 * LE,
        "the emitter shows through the ball: {mean_off}"
    );
}
