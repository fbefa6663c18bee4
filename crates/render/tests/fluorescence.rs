//! Fluorescent surfaces (issue 21) against closed forms, on synthetic matrices only:
//! - one bounce under a uniform sky of spectrum S (D65, then A): L(λ) = R(λ)S(λ) +
//!   ∫M(λi, λ)S(λi)dλi, XYZ by quadrature of the same bilinear matrix; the total and the
//!   fluorescent part (Y − Y_R, against a Lambertian of the same R) within 4 s.e.;
//! - a furnace whose walls re-radiate from band A into a disjoint band B: L = Le/(1 − r)
//!   outside B, (Le + c(λ)·Le/(1 − r))/(1 − r) in B, c(λ) = ∫M(λi, λ)dλi;
//! - `fluorescence_lanes` `all` and `hero` estimate the same image;
//! - the packet tracer, the light tracer and BDPT refuse re-radiation, and every bad input
//!   of the scene format is an error naming its place;
//! - media: a fluorescent surface in a clear medium as in vacuum; one re-emission in a
//!   fluorophore slab under a directional light (issue 21 test 4), also with a spectral σt
//!   and spectral MIS on and off; errors of the `fluorescence` key.
//!
//! Standard errors are over pixels (each pixel an independent estimate); the stated floors
//! cover the 1 nm quadrature of the CMFs.

use prism_testkit::quadrature::simpson;
use std::path::Path;

use glam::UVec2;
use prism_render::integrator::packet::PacketScene;
use prism_render::{render, FilmImage, RenderScene, RenderSettings};
use prism_scene::parse_scene_str;
use prism_spectrum::bfc::{load_bfc, NegativesPolicy};
use prism_spectrum::data::{cmfs, illuminant};
use prism_spectrum::{Observer, ReradiationMatrix};

/// A folder with the synthetic data files: a dye (absorption peak 420 nm over 300–560 nm,
/// emission peak 520 nm, photon counts) and a BFC file (see `write_band_bfc`).
struct Data {
    dir: tempfile::TempDir,
}

impl Data {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        let gaussian = |l: f64, c: f64, w: f64| (-(l - c).powi(2) / (2.0 * w * w)).exp();
        let mut abs = String::from("wavelength_nm,absorption\n");
        for k in 0..=52 {
            let l = 300.0 + 5.0 * k as f64;
            abs += &format!("{l},{}\n", gaussian(l, 420.0, 35.0));
        }
        let mut em = String::from("wavelength_nm,photons\n");
        for k in 0..=70 {
            let l = 450.0 + 5.0 * k as f64;
            em += &format!("{l},{}\n", gaussian(l, 520.0, 25.0));
        }
        std::fs::write(dir.path().join("dye-abs.csv"), abs).unwrap();
        std::fs::write(dir.path().join("dye-em.csv"), em).unwrap();
        write_band_bfc(
            &dir.path().join("band.bfc"),
            0.5,
            0.4,
            (400, 450),
            (560, 610),
        );
        write_band_bfc(&dir.path().join("uv.bfc"), 0.5, 0.4, (300, 340), (500, 550));
        // band.bfc with a negative patch D = −0.01 (measurement noise, exaggerated) from
        // 470–490 nm into 600–620 nm, and a negative diagonal R(700 nm) = −0.02.
        let band = std::fs::read_to_string(dir.path().join("band.bfc")).unwrap();
        let signed: Vec<String> = band
            .split("\r\n")
            .map(|line| {
                let fields: Vec<&str> = line.split('\t').collect();
                match fields[0].parse::<i32>() {
                    Ok(out) if (600..=620).contains(&out) && fields.len() == 55 => {
                        let mut f: Vec<String> = fields.iter().map(|s| s.to_string()).collect();
                        for x in 0..54 {
                            if (470..=490).contains(&(300 + 10 * x)) {
                                f[x as usize + 1] = "-0.01".into();
                            }
                        }
                        f.join("\t")
                    }
                    Ok(700) if fields.len() == 55 => {
                        let mut f: Vec<String> = fields.iter().map(|s| s.to_string()).collect();
                        f[41] = "-0.02".into();
                        f.join("\t")
                    }
                    _ => line.to_string(),
                }
            })
            .collect();
        std::fs::write(dir.path().join("signed.bfc"), signed.join("\r\n")).unwrap();
        Self { dir }
    }

    fn path(&self, name: &str) -> String {
        self.dir.path().join(name).display().to_string()
    }
}

/// A BFC-450 file, excitation 300–830 nm and emission 360–830 nm every 10 nm: R = `r` on
/// the diagonal, and M = k/50 nm⁻¹ (D = M·10 nm per band) at the nodes from band `a` (nm)
/// into band `b`, 0 at the other nodes (bilinear in between, so the bands have 10 nm
/// ramps: `band.bfc`'s A = 400–450 nm reaches 390–460 nm, its B = 560–610 nm 550–620 nm,
/// still disjoint).
fn write_band_bfc(path: &Path, r: f64, k: f64, a: (i32, i32), b: (i32, i32)) {
    let mut text = String::from("VEC_01\t1\r\nBFC-450 Matrix File\r\n; synthetic band matrix\r\n");
    text += "360\t830\t10\t54\t300\t10\r\nr:c:";
    for x in 0..54 {
        text += &format!("\t{}", 300 + 10 * x);
    }
    text += "\r\n";
    for e in 0..48 {
        let out = 360 + 10 * e;
        text += &format!("{out}");
        for x in 0..54 {
            let ex = 300 + 10 * x;
            let d = if ex == out {
                r
            } else if (a.0..=a.1).contains(&ex) && (b.0..=b.1).contains(&out) {
                k / 50.0 * 10.0
            } else {
                0.0
            };
            text += &format!("\t{d}");
        }
        text += "\r\n";
    }
    text += "EOD\r\n";
    std::fs::write(path, text).unwrap();
}

fn build(json: &str) -> RenderScene {
    let description = parse_scene_str(json, "test.json").expect("test scene parses");
    RenderScene::build(&description, None).expect("test scene builds")
}

fn render_scene(scene: &RenderScene, spp: u32, seed: u64) -> FilmImage {
    let settings = RenderSettings {
        spp,
        seed,
        sampler: prism_render::SamplerKind::Independent,
        ..RenderSettings::default()
    };
    let (image, stats) = render(scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    image
}

/// Per-channel mean of XYZ over the pixels and its standard error.
fn mean_and_se(image: &FilmImage) -> [(f64, f64); 3] {
    let n = image.xyz.len() as f64;
    [0, 1, 2].map(|c| {
        let values: Vec<f64> = image.xyz.iter().map(|p| f64::from(p[c])).collect();
        let mean = values.iter().sum::<f64>() / n;
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, sd / n.sqrt())
    })
}

/// The film's XYZ of a spectral radiance: Σ L·cmf / Σ ȳ on the CMFs' 1 nm grid.
fn film_xyz(radiance: impl Fn(f64) -> f64) -> [f64; 3] {
    let c = cmfs(Observer::Cie1931);
    let norm: f64 = c.y_bar.values().iter().sum();
    let mut xyz = [0.0; 3];
    for (i, ((x, y), z)) in c
        .x_bar
        .values()
        .iter()
        .zip(c.y_bar.values())
        .zip(c.z_bar.values())
        .enumerate()
    {
        let l = radiance(360.0 + i as f64);
        xyz[0] += l * x;
        xyz[1] += l * y;
        xyz[2] += l * z;
    }
    xyz.map(|v| v / norm)
}

/// ∫ M(λi, λo)·S(λi) dλi by Simpson on 0.25 nm steps over 300–830 nm (exact per linear
/// piece of M up to the illuminant's 5 nm kinks).
fn gathered(m: &ReradiationMatrix, s: &impl Fn(f64) -> f64, lambda_out_nm: f64) -> f64 {
    simpson(300.0, 830.0, 2120, |l| {
        f64::from(m.eval(l as f32, lambda_out_nm as f32)) * s(l)
    })
}

fn assert_close(what: &str, mean: f64, se: f64, expected: f64, floor: f64) {
    eprintln!("{what}: {mean:.6} vs {expected:.6} (se {se:.2e})");
    assert!(
        (mean - expected).abs() < 4.0 * se + floor * expected.abs(),
        "{what}: {mean} vs {expected} (se {se})"
    );
}

/// A horizontal square of `material` under a uniform sky of `scale`·`sky`, seen from above
/// by an orthographic camera, one bounce.
fn sky_scene(data: &Data, material: &str, sky: &str, scale: f64, lanes: &str) -> String {
    format!(
        r#"{{
      "camera": {{"type": "orthographic", "width_m": 0.5,
                  "transform": {{"look_at": {{"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
      "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
      "integrator": {{"type": "path", "max_depth": 1, "fluorescence_lanes": "{lanes}"}},
      "reradiation": {{
        "dye": {{"absorption": "{abs}", "emission": "{em}", "quantum_yield": 0.9,
                 "peak_absorptance": 0.8}}
      }},
      "materials": {{
        "card": {{"type": "fluorescent", "reradiation": "dye", "reflectance": 0.4}},
        "plain": {{"type": "lambert", "reflectance": 0.4}}
      }},
      "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "{material}",
          "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
      "lights": [{{"type": "sky", "spectrum": "{sky}", "scale": {scale}}}]
    }}"#,
        abs = data.path("dye-abs.csv"),
        em = data.path("dye-em.csv"),
    )
}

#[test]
fn one_bounce_under_a_uniform_sky_matches_the_bilinear_model() {
    let data = Data::new();
    let description =
        parse_scene_str(&sky_scene(&data, "card", "D65", 0.01, "all"), "test.json").unwrap();
    let m = description.reradiation[0].matrix().clone();
    for (sky, seed) in [("D65", 1u64), ("A", 2)] {
        let table = illuminant(sky).unwrap();
        let scale = 0.01;
        let s = |l: f64| scale * table.eval(l);
        let reflected = film_xyz(|l| 0.4 * s(l));
        let total = film_xyz(|l| 0.4 * s(l) + gathered(&m, &s, l));
        let card = render_scene(
            &build(&sky_scene(&data, "card", sky, scale, "all")),
            512,
            seed,
        );
        let plain = render_scene(
            &build(&sky_scene(&data, "plain", sky, scale, "all")),
            512,
            seed + 10,
        );
        let (card, plain) = (mean_and_se(&card), mean_and_se(&plain));
        for c in 0..3 {
            let (mean, se) = card[c];
            assert_close(&format!("{sky} total {c}"), mean, se, total[c], 2e-4);
            let (mean_r, se_r) = plain[c];
            assert_close(
                &format!("{sky} fluorescent part {c}"),
                mean - mean_r,
                (se * se + se_r * se_r).sqrt(),
                total[c] - reflected[c],
                2e-3,
            );
        }
        // The dye glows: its fluorescent part is a sizeable share of Y.
        assert!(
            total[1] - reflected[1] > 0.05 * total[1],
            "{total:?} {reflected:?}"
        );
    }
}

/// Lights excite down to 300 nm where their spectrum is defined there: a surface excited
/// only at 300–350 nm glows under a D65 sky (CIE table from 300 nm) as the quadrature says,
/// and not at all under an RGB-given sky (0 below 360 nm, as `--explain` says).
#[test]
fn ultraviolet_excitation_comes_from_lights_defined_below_360_nm() {
    let data = Data::new();
    let m = load_bfc(Path::new(&data.path("uv.bfc")), NegativesPolicy::Clamp)
        .unwrap()
        .matrix;
    let scene = |sky: &str| {
        format!(
            r#"{{
          "camera": {{"type": "orthographic", "width_m": 0.5,
                      "transform": {{"look_at": {{"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
          "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
          "integrator": {{"type": "path", "max_depth": 1}},
          "reradiation": {{"uv": {{"bfc": "{bfc}"}}}},
          "materials": {{"card": {{"type": "fluorescent", "reradiation": "uv"}}}},
          "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "card",
              "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
          "lights": [{{"type": "sky", "spectrum": {sky}, "scale": 0.01}}]
        }}"#,
            bfc = data.path("uv.bfc")
        )
    };
    let d65 = illuminant("D65").unwrap();
    let s = |l: f64| 0.01 * d65.eval(l);
    let expected = film_xyz(|l| 0.5 * s(l) + gathered(&m, &s, l));
    let reflected = film_xyz(|l| 0.5 * s(l));
    assert!(expected[1] - reflected[1] > 0.05 * expected[1]);
    let image = mean_and_se(&render_scene(&build(&scene(r#""D65""#)), 256, 21));
    for (c, (mean, se)) in image.into_iter().enumerate() {
        assert_close(&format!("D65 UV-excited {c}"), mean, se, expected[c], 2e-4);
    }
    // White RGB sky: only the reflected part, exactly (no lane can gather anything).
    let image = render_scene(&build(&scene(r#"{"rgb": [1, 1, 1]}"#)), 64, 22);
    let r_only = render_scene(
        &build(&scene(r#"{"rgb": [1, 1, 1]}"#).replace(
            r#""card": {"type": "fluorescent", "reradiation": "uv"}"#,
            r#""card": {"type": "lambert", "reflectance": 0.5}"#,
        )),
        64,
        22,
    );
    let (a, b) = (mean_and_se(&image), mean_and_se(&r_only));
    for c in 0..3 {
        let diff = a[c].0 - b[c].0;
        let se = (a[c].1.powi(2) + b[c].1.powi(2)).sqrt();
        eprintln!("RGB sky, fluorescent part {c}: {diff:.2e} (se {se:.1e})");
        assert!(
            diff.abs() < 4.0 * se + 1e-6,
            "channel {c}: {diff} (se {se})"
        );
    }
}

/// `negatives: keep` renders the signed matrix and diagonal (λ_in ∝ |M|, the choice by |R|
/// and ∫|M|, the sign in the weight), `clamp` the clamped ones: each matches the quadrature
/// of its own R and M, and they differ.
#[test]
fn kept_negatives_render_the_signed_matrix_and_clamped_ones_the_clamped() {
    let data = Data::new();
    let path = data.path("signed.bfc");
    let mut results = Vec::new();
    for (policy, seed) in [("keep", 31u64), ("clamp", 32)] {
        let data = load_bfc(Path::new(&path), NegativesPolicy::parse(policy).unwrap()).unwrap();
        let (m, r) = (data.matrix, data.reflectance);
        assert_eq!(m.is_signed(), policy == "keep");
        assert_eq!(r.eval(700.0), if policy == "keep" { -0.02 } else { 0.0 });
        let json = format!(
            r#"{{
          "camera": {{"type": "orthographic", "width_m": 0.5,
                      "transform": {{"look_at": {{"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
          "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
          "integrator": {{"type": "path", "max_depth": 1}},
          "reradiation": {{"x": {{"bfc": "{path}", "negatives": "{policy}"}}}},
          "materials": {{"card": {{"type": "fluorescent", "reradiation": "x"}}}},
          "shapes": [{{"type": "rectangle", "size_m": [1000, 1000], "material": "card",
              "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
          "lights": [{{"type": "sky", "spectrum": "D65", "scale": 0.01}}]
        }}"#
        );
        let d65 = illuminant("D65").unwrap();
        let s = |l: f64| 0.01 * d65.eval(l);
        let expected = film_xyz(|l| r.eval(l) * s(l) + gathered(&m, &s, l));
        let image = mean_and_se(&render_scene(&build(&json), 256, seed));
        for (c, (mean, se)) in image.into_iter().enumerate() {
            assert_close(&format!("{policy} {c}"), mean, se, expected[c], 2e-4);
        }
        results.push(expected);
    }
    // The negative patch takes light from 600–620 nm: X (red) drops when it is kept.
    assert!(results[0][0] < results[1][0] - 1e-3, "{results:?}");
}

fn furnace_scene(data: &Data, le: f64, lanes: &str) -> String {
    format!(
        r#"{{
      "camera": {{"type": "pinhole", "fov_deg": 60}},
      "film": {{"resolution": [12, 12]}},
      "integrator": {{"type": "path", "max_depth": 100, "rr_depth": 5,
                      "fluorescence_lanes": "{lanes}"}},
      "reradiation": {{"band": {{"bfc": "{bfc}"}}}},
      "materials": {{"paint": {{"type": "fluorescent", "reradiation": "band"}},
                     "wall": {{"type": "two_sided", "material": "paint"}}}},
      "shapes": [{{"type": "sphere", "name": "ball", "radius_m": 1, "material": "wall"}}],
      "lights": [{{"type": "area", "shape": "ball", "two_sided": true, "spectrum": 1.0,
                   "scale": {le}}}]
    }}"#,
        bfc = data.path("band.bfc"),
    )
}

/// Expected furnace XYZ for walls of reflectance r = 0.5 and column integrals c(λ).
fn furnace_xyz(m: &ReradiationMatrix, le: f64) -> [f64; 3] {
    let r = 0.5;
    film_xyz(|l| (le + m.column_integral(l as f32) as f64 * le / (1.0 - r)) / (1.0 - r))
}

#[test]
fn furnace_with_disjoint_bands_matches_the_closed_form() {
    let data = Data::new();
    let m = load_bfc(Path::new(&data.path("band.bfc")), NegativesPolicy::Clamp)
        .unwrap()
        .matrix;
    // Band B gathers (k/50)·60 nm = 0.48 at its nodes (A's 50 nm plus its two 10 nm ramps
    // at half height): B glows at 1 + 0.48/0.5 = 1.96 times the plain furnace's 2·Le.
    assert!((m.column_integral(580.0) - 0.48).abs() < 1e-6);
    let le = 0.5;
    let expected = furnace_xyz(&m, le);
    let image = render_scene(&build(&furnace_scene(&data, le, "all")), 64, 5);
    for (c, (mean, se)) in mean_and_se(&image).into_iter().enumerate() {
        assert_close(&format!("furnace {c}"), mean, se, expected[c], 2e-4);
    }
}

#[test]
fn hero_and_all_lanes_estimate_the_same_image() {
    let data = Data::new();
    let le = 0.5;
    let all = mean_and_se(&render_scene(
        &build(&furnace_scene(&data, le, "all")),
        64,
        7,
    ));
    let hero = mean_and_se(&render_scene(
        &build(&furnace_scene(&data, le, "hero")),
        64,
        8,
    ));
    for c in 0..3 {
        let ((a, sa), (h, sh)) = (all[c], hero[c]);
        eprintln!("channel {c}: all {a:.5} (se {sa:.1e}), hero {h:.5} (se {sh:.1e})");
        assert!(
            (a - h).abs() < 4.0 * (sa * sa + sh * sh).sqrt() + 1e-5 * a,
            "channel {c}: all {a} vs hero {h}"
        );
        // Ending the secondaries costs variance.
        assert!(sh > sa, "channel {c}: hero se {sh} vs all se {sa}");
    }
}

#[test]
fn packet_light_tracer_and_bdpt_refuse_reradiation_and_path_renders_it() {
    let data = Data::new();
    let mut scene = build(&sky_scene(&data, "card", "D65", 0.01, "all"));
    let Err(why) = PacketScene::new(&scene) else {
        panic!("the packet tracer accepted a re-radiating scene");
    };
    assert_eq!(
        why,
        "material 'card' re-radiates (fluorescence): lanes change wavelength along a path, \
         but the packet tracer evaluates reflectances once per camera sample"
    );
    assert!(scene.packet.is_none());
    // `--explain` prints the refusal and the re-radiation line (material, entry, lanes).
    let request = prism_render::PlanRequest {
        spp: 1,
        spectral_bins: None,
        aov_output: false,
        sampler: "independent",
        sample_plan: Default::default(),
    };
    let plan = prism_render::RenderPlan::new(&scene, &request).to_string();
    assert!(plan.contains(&format!("not used: {why}")), "{plan}");
    assert!(
        plan.contains("re-radiation (fluorescence)") && plan.contains("on, lanes: all"),
        "{plan}"
    );
    assert!(plan.contains("`card` (dye `dye`)"), "{plan}");
    scene.resolution = UVec2::new(4, 4);
    let image = render_scene(&scene, 4, 1);
    assert!(image.y.iter().all(|y| y.is_finite() && *y > 0.0));
    for method in ["light", "bdpt"] {
        let json = sky_scene(&data, "card", "D65", 0.01, "all").replace(
            r#""type": "path", "max_depth": 1, "fluorescence_lanes": "all""#,
            &format!(r#""type": "{method}""#),
        );
        let scene = build(&json);
        let plan = prism_bandwidth::SamplePlan::uniform(scene.resolution, 1).unwrap();
        let settings = RenderSettings {
            spp: 1,
            ..RenderSettings::default()
        };
        let Err(e) = prism_render::render_plan(&scene, &settings, &plan, &|_| {}) else {
            panic!("{method} rendered a re-radiating scene");
        };
        let e = e.to_string();
        assert!(
            e.contains("materials.card") && e.contains("re-radiates") && e.contains("use path"),
            "{method}: {e}"
        );
    }
}

/// The message of the error `json` gives (parsing or building), with its JSON path.
fn error_of(json: &str) -> String {
    match parse_scene_str(json, "bad.json") {
        Err(e) => e.to_string(),
        Ok(d) => match RenderScene::build(&d, None) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {json}"),
        },
    }
}

fn with(data: &Data, reradiation: &str, materials: &str) -> String {
    let json = format!(
        r#"{{"reradiation": {reradiation}, "materials": {materials},
            "shapes": [{{"type": "sphere", "radius_m": 1, "material": "m"}}]}}"#
    );
    json.replace("@ABS@", &data.path("dye-abs.csv"))
        .replace("@EM@", &data.path("dye-em.csv"))
        .replace("@BAND@", &data.path("band.bfc"))
}

const DYE: &str = r#"{"dye": {"absorption": "@ABS@", "emission": "@EM@", "quantum_yield": 0.9,
    "peak_absorptance": 0.8}, "band": {"bfc": "@BAND@"}}"#;

#[test]
fn bad_inputs_are_errors_that_name_their_place() {
    let data = Data::new();
    let dir = data.dir.path();
    let cases: Vec<(String, &[&str])> = vec![
        (
            with(&data, DYE, r#"{"m": {"type": "fluorescent"}}"#),
            &["materials.m", "missing field `reradiation`"],
        ),
        (
            with(
                &data,
                DYE,
                r#"{"m": {"type": "fluorescent", "reradiation": "dey"}}"#,
            ),
            &[
                "materials.m.reradiation",
                "unknown reradiation `dey`",
                "`dye`",
                "`band`",
            ],
        ),
        (
            with(
                &data,
                DYE,
                r#"{"m": {"type": "fluorescent", "reradiation": "band", "reflectance": 0.5}}"#,
            ),
            &["materials.m.reflectance", "BFC", "diagonal"],
        ),
        (
            with(
                &data,
                DYE,
                r#"{"f": {"type": "fluorescent", "reradiation": "dye"},
                    "m": {"type": "coated", "diffuse": "f"}}"#,
            ),
            &["materials.m.diffuse", "not supported yet"],
        ),
        (
            with(
                &data,
                DYE,
                r#"{"f": {"type": "fluorescent", "reradiation": "dye"},
                    "g": {"type": "lambert"},
                    "m": {"type": "mix", "materials": ["f", "g"], "weight": 0.5}}"#,
            ),
            &["materials.m", "not supported yet"],
        ),
        (
            with(
                &data,
                r#"{"x": {"bfc": "@BAND@", "negatives": "drop"}}"#,
                "{}",
            ),
            &["reradiation.x.negatives", "`clamp`"],
        ),
        (
            with(&data, r#"{"x": {"quantum_yield": 0.5}}"#, "{}"),
            &["reradiation.x", "expected a BFC entry"],
        ),
        (
            with(&data, r#"{"x": {"bfc": "missing.bfc"}}"#, "{}"),
            &["reradiation.x.bfc", "not found"],
        ),
        (
            r#"{"integrator": {"type": "path", "fluorescence_lanes": "some"}}"#.into(),
            &["integrator.fluorescence_lanes", "`all`", "`hero`"],
        ),
    ];
    // Excitation below 300 nm, an emission file that does not say photons or energy, a
    // yield above 1, a BFC file with negatives under `error` and one without `EOD`.
    std::fs::write(
        dir.join("uv.csv"),
        "wavelength_nm,absorption\n250,0.1\n400,1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("plain-em.csv"),
        "wavelength_nm,value\n450,0\n500,1\n600,0\n",
    )
    .unwrap();
    let band = std::fs::read_to_string(dir.join("band.bfc")).unwrap();
    std::fs::write(
        dir.join("negative.bfc"),
        band.replacen("\t0\t", "\t-0.01\t", 1),
    )
    .unwrap();
    std::fs::write(dir.join("short.bfc"), band.replace("EOD\r\n", "")).unwrap();
    let p = |name: &str| dir.join(name).display().to_string();
    let more: Vec<(String, &[&str])> = vec![
        (
            with(
                &data,
                &format!(
                    r#"{{"x": {{"absorption": "{}", "emission": "@EM@", "quantum_yield": 0.9,
                        "peak_absorptance": 0.8}}}}"#,
                    p("uv.csv")
                ),
                "{}",
            ),
            &["reradiation.x.absorption", "250", "300–830 nm"],
        ),
        (
            with(
                &data,
                &format!(
                    r#"{{"x": {{"absorption": "@ABS@", "emission": "{}", "quantum_yield": 0.9,
                        "peak_absorptance": 0.8}}}}"#,
                    p("plain-em.csv")
                ),
                "{}",
            ),
            &["reradiation.x.emission", "`photons`", "`energy`"],
        ),
        (
            with(
                &data,
                r#"{"x": {"absorption": "@ABS@", "emission": "@EM@", "quantum_yield": 1.5,
                    "peak_absorptance": 0.8}}"#,
                "{}",
            ),
            &["reradiation.x.quantum_yield"],
        ),
        (
            with(
                &data,
                &format!(
                    r#"{{"x": {{"bfc": "{}", "negatives": "error"}}}}"#,
                    p("negative.bfc")
                ),
                "{}",
            ),
            &["reradiation.x.bfc", "negative.bfc:6:5", "negative"],
        ),
        (
            with(
                &data,
                &format!(r#"{{"x": {{"bfc": "{}"}}}}"#, p("short.bfc")),
                "{}",
            ),
            &["reradiation.x.bfc", "EOD"],
        ),
    ];
    for (json, needles) in cases.iter().chain(&more) {
        let e = error_of(json);
        for needle in needles.iter() {
            assert!(e.contains(needle), "`{needle}` not in: {e}");
        }
    }
    // `keep` and `clamp` load the same file; the policy is kept for `--explain`.
    for policy in ["clamp", "keep"] {
        let json = with(
            &data,
            &format!(
                r#"{{"x": {{"bfc": "{}", "negatives": "{policy}"}}}}"#,
                p("negative.bfc")
            ),
            r#"{"m": {"type": "fluorescent", "reradiation": "x"}}"#,
        );
        let d = parse_scene_str(&json, "ok.json").unwrap();
        RenderScene::build(&d, None).unwrap();
    }
}

/// A fluorescent surface renders through the volumetric loop (a scene with a medium, here
/// a clear one the camera and the sky sit in) with the same closed form as in vacuum.
#[test]
fn a_fluorescent_surface_in_a_medium_scene_matches_the_bilinear_model() {
    let data = Data::new();
    let vacuum = sky_scene(&data, "card", "D65", 0.01, "all");
    let json = vacuum.replacen(
        r#""reradiation":"#,
        r#""media": {"air": {"sigma_s_per_m": 0}}, "world_medium": "air", "reradiation":"#,
        1,
    );
    assert_ne!(json, vacuum);
    let description = parse_scene_str(&json, "test.json").unwrap();
    let m = description.reradiation[0].matrix().clone();
    let scene = build(&json);
    assert!(scene.media.is_some());
    let table = illuminant("D65").unwrap();
    let s = |l: f64| 0.01 * table.eval(l);
    let total = film_xyz(|l| 0.4 * s(l) + gathered(&m, &s, l));
    let image = mean_and_se(&render_scene(&scene, 512, 21));
    for c in 0..3 {
        let (mean, se) = image[c];
        assert_close(&format!("in a medium {c}"), mean, se, total[c], 2e-4);
    }
}

/// Thickness of the fluorophore slab, m; the camera's angle to its normal (μ = cos).
const INK_D_M: f64 = 0.5;
const INK_VIEW_DEG: f64 = 30.0;
/// The directional light's irradiance, W·m⁻²·nm⁻¹ at every wavelength.
const INK_E: f64 = 2.0;

/// A slab (z in ±INK_D_M/2, an `interface` cuboid) of medium `ink` = `medium` under a
/// directional light travelling −z, seen from below at INK_VIEW_DEG by an orthographic
/// camera (nothing behind the slab: all it sees is what the slab re-emits).
fn ink_scene(medium: &str, integrator: &str) -> String {
    let (s, c) = INK_VIEW_DEG.to_radians().sin_cos();
    format!(
        r#"{{
      "camera": {{"type": "orthographic", "width_m": 0.2,
                  "transform": {{"look_at": {{"eye": [0, {ey}, {ez}], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
      "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
      "integrator": {integrator},
      "media": {{"ink": {medium}}},
      "materials": {{"boundary": {{"type": "interface"}}}},
      "shapes": [{{"type": "cuboid", "size_m": [6, 6, {INK_D_M}], "material": "boundary",
                   "interior_medium": "ink"}}],
      "lights": [{{"type": "directional", "direction": [0, 0, -1], "spectrum": 1, "scale": {INK_E}}}]
    }}"#,
        ey = -2.0 * s,
        ez = -2.0 * c,
    )
}

/// The fluorophore: absorption 4·gauss(420 nm, 35 nm) m⁻¹ over 300–560 nm, `dye-em.csv`'s
/// emission, Φ = 0.9; `sigma_a`: the medium's own σa.
fn ink_medium(data: &Data, sigma_a: &str, sigma_s: f64) -> String {
    let gaussian = |l: f64| (-(l - 420.0f64).powi(2) / (2.0 * 35.0 * 35.0)).exp();
    let mut abs = String::from("wavelength_nm,sigma_per_m\n");
    for k in 0..=52 {
        let l = 300.0 + 5.0 * k as f64;
        abs += &format!("{l},{}\n", 4.0 * gaussian(l));
    }
    std::fs::write(data.dir.path().join("ink-abs.csv"), abs).unwrap();
    format!(
        r#"{{"sigma_a_per_m": {sigma_a}, "sigma_s_per_m": {sigma_s},
            "fluorescence": {{"absorption_per_m": "{abs}", "emission": "{em}",
                              "quantum_yield": 0.9}}}}"#,
        abs = data.path("ink-abs.csv"),
        em = data.path("dye-em.csv"),
    )
}

/// Issue 21 test 4: L(λo) = ∫dλi E·M(λi, λo)/4π ∫₀ᵈ e^(−σt(λi)z)·e^(−σt(λo)(d−z)/μ) dz/μ,
/// the inner integral exact, the outer by Simpson on 0.25 nm steps over 300–830 nm; σt =
/// σa + σf, M and σf the ones the scene built (the dye's 5 nm nodes, linear between), all
/// times `density`.
fn ink_expected_xyz(scene_json: &str, sigma_a: &dyn Fn(f64) -> f64, density: f64) -> [f64; 3] {
    let description = parse_scene_str(scene_json, "test.json").unwrap();
    let f = description.media[0].fluorescence.as_ref().unwrap();
    let peak = density * f.peak_absorption_per_m;
    let sigma_t = |l: f64| density * sigma_a(l) + peak * f.dye.absorptance(l);
    let mu = INK_VIEW_DEG.to_radians().cos();
    let d = INK_D_M;
    let depth_integral = |a: f64, b: f64| {
        // ∫₀ᵈ e^(−a z − b (d − z)/μ) dz / μ
        let k = a - b / mu;
        let inner = if k.abs() < 1e-9 {
            d
        } else {
            (1.0 - (-k * d).exp()) / k
        };
        (-b * d / mu).exp() * inner / mu
    };
    film_xyz(|lo| {
        let sum = simpson(300.0, 830.0, 2120, |li| {
            let m = peak * f64::from(f.dye.matrix().eval(li as f32, lo as f32));
            if m > 0.0 {
                m * depth_integral(sigma_t(li), sigma_t(lo))
            } else {
                0.0
            }
        });
        INK_E * sum / (4.0 * std::f64::consts::PI)
    })
}

/// (what, the medium's σa in the scene, σa(λ), spectral MIS, seed).
type InkCase<'a> = (&'a str, &'a str, &'a dyn Fn(f64) -> f64, bool, u64);

#[test]
fn one_reemission_in_a_fluorophore_slab_matches_the_closed_form() {
    let data = Data::new();
    // A spectral σa of the medium itself, 0.2 m⁻¹ at 300 nm rising to 1.2 at 830 nm.
    std::fs::write(
        data.dir.path().join("sigma-a.csv"),
        "wavelength_nm,value\n300,0.2\n830,1.2\n",
    )
    .unwrap();
    let spectral = |l: f64| 0.2 + (l - 300.0) / 530.0;
    let sigma_a_file = format!("\"{}\"", data.path("sigma-a.csv"));
    let cases: [InkCase; 3] = [
        ("σa = 0", "0", &|_| 0.0, true, 131),
        (
            "spectral σt, spectral MIS",
            &sigma_a_file,
            &spectral,
            true,
            132,
        ),
        (
            "spectral σt, hero pdf only",
            &sigma_a_file,
            &spectral,
            false,
            133,
        ),
    ];
    let mut means = Vec::new();
    for (what, sigma_a, f, mis, seed) in cases {
        let json = ink_scene(
            &ink_medium(&data, sigma_a, 0.0),
            &format!(r#"{{"type": "path", "max_depth": 1, "spectral_mis": {mis}}}"#),
        );
        let expected = ink_expected_xyz(&json, f, 1.0);
        let image = mean_and_se(&render_scene(&build(&json), 4096, seed));
        for c in 0..3 {
            let (mean, se) = image[c];
            assert_close(&format!("{what} {c}"), mean, se, expected[c], 2e-3);
        }
        assert!(expected[1] > 1e-3, "the slab glows: {expected:?}");
        means.push(image);
    }
    // The two estimators of the spectral case agree with each other too.
    for (c, (&(a, sa), &(b, sb))) in means[1].iter().zip(&means[2]).enumerate() {
        assert_close(
            &format!("spectral MIS on vs off {c}"),
            a,
            (sa * sa + sb * sb).sqrt(),
            b,
            2e-3,
        );
    }
}

/// After re-emission the lanes travel at their excitation wavelengths, where the medium's
/// σt differs: with scattering and more bounces (no closed form), spectral MIS on and off
/// estimate the same image.
#[test]
fn spectral_mis_after_a_shift_keeps_the_mean() {
    let data = Data::new();
    std::fs::write(
        data.dir.path().join("sigma-a.csv"),
        "wavelength_nm,value\n300,0.2\n830,1.2\n",
    )
    .unwrap();
    let sigma_a = format!("\"{}\"", data.path("sigma-a.csv"));
    let mut results = Vec::new();
    for (mis, seed) in [(true, 41u64), (false, 42)] {
        let json = ink_scene(
            &ink_medium(&data, &sigma_a, 1.5),
            &format!(r#"{{"type": "path", "max_depth": 6, "spectral_mis": {mis}}}"#),
        );
        results.push(mean_and_se(&render_scene(&build(&json), 1024, seed)));
    }
    for (c, (&(a, sa), &(b, sb))) in results[0].iter().zip(&results[1]).enumerate() {
        assert_close(
            &format!("max_depth 6, on vs off {c}"),
            a,
            (sa * sa + sb * sb).sqrt(),
            b,
            2e-3,
        );
    }
    assert!(results[0][1].0 > 1e-3, "{results:?}");
}

#[test]
fn bad_fluorescence_keys_are_errors_that_name_their_place() {
    let data = Data::new();
    let dir = data.dir.path();
    std::fs::write(
        dir.join("plain-em.csv"),
        "wavelength_nm,value\n450,0\n500,1\n600,0\n",
    )
    .unwrap();
    std::fs::write(dir.join("zero.csv"), "wavelength_nm,sigma\n400,0\n500,0\n").unwrap();
    let medium = |fluorescence: &str| {
        let json = format!(
            r#"{{"media": {{"ink": {{"sigma_s_per_m": 1, "fluorescence": {fluorescence}}}}},
                "world_medium": "ink"}}"#
        );
        json.replace("@ABS@", &data.path("dye-abs.csv"))
            .replace("@EM@", &data.path("dye-em.csv"))
            .replace("PLAIN", &data.path("plain-em.csv"))
            .replace("ZERO", &data.path("zero.csv"))
    };
    let cases: Vec<(String, &[&str])> = vec![
        (
            medium(
                r#"{"absorption_per_m": "@ABS@", "emission": "@EM@", "quantum_yield": 0.9, "yield": 1}"#,
            ),
            &["media.ink.fluorescence", "yield"],
        ),
        (
            medium(r#"{"emission": "@EM@", "quantum_yield": 0.9}"#),
            &["media.ink.fluorescence", "absorption_per_m"],
        ),
        (
            medium(r#"{"absorption_per_m": "@ABS@", "emission": "@EM@", "quantum_yield": 1.5}"#),
            &["media.ink.fluorescence.quantum_yield", "1.5"],
        ),
        (
            medium(r#"{"absorption_per_m": "@ABS@", "emission": "PLAIN", "quantum_yield": 0.9}"#),
            &["media.ink.fluorescence.emission", "`photons`", "`energy`"],
        ),
        (
            medium(r#"{"absorption_per_m": "ZERO", "emission": "@EM@", "quantum_yield": 0.9}"#),
            &["media.ink.fluorescence", "zero"],
        ),
        (
            medium(
                r#"{"absorption_per_m": "missing.csv", "emission": "@EM@", "quantum_yield": 0.9}"#,
            ),
            &["media.ink.fluorescence.absorption_per_m", "not found"],
        ),
        (medium(r#""dye""#), &["media.ink.fluorescence"]),
    ];
    for (json, needles) in &cases {
        let e = error_of(json);
        for needle in needles.iter() {
            assert!(e.contains(needle), "`{needle}` not in: {e}");
        }
    }
}

/// A grid medium scales the fluorophore's σf and M by its density as it does σa: test 4
/// through a constant grid of density 0.6 (the majorant cells bound it exactly).
#[test]
fn a_fluorescent_grid_scales_the_fluorophore_by_its_density() {
    let data = Data::new();
    let density = 0.6f32;
    let half = 0.5 * INK_D_M as f32;
    // A Mitsuba .vol (version 3, float32, 1 channel), 2×2×2 voxels of `density`.
    let mut vol = b"VOL".to_vec();
    vol.push(3);
    vol.extend_from_slice(&1i32.to_le_bytes());
    for r in [2i32, 2, 2] {
        vol.extend_from_slice(&r.to_le_bytes());
    }
    vol.extend_from_slice(&1i32.to_le_bytes());
    for x in [-3.0f32, -3.0, -half, 3.0, 3.0, half] {
        vol.extend_from_slice(&x.to_le_bytes());
    }
    for _ in 0..8 {
        vol.extend_from_slice(&density.to_le_bytes());
    }
    std::fs::write(data.dir.path().join("ink.vol"), vol).unwrap();
    let medium = ink_medium(&data, "0.3", 0.0).replacen(
        "{",
        &format!(
            r#"{{"type": "grid", "density": "{}", "#,
            data.path("ink.vol")
        ),
        1,
    );
    let json = ink_scene(&medium, r#"{"type": "path", "max_depth": 1}"#);
    let expected = ink_expected_xyz(&json, &|_| 0.3, f64::from(density));
    let image = mean_and_se(&render_scene(&build(&json), 2048, 51));
    for (c, &(mean, se)) in image.iter().enumerate() {
        assert_close(&format!("grid {c}"), mean, se, expected[c], 2e-3);
    }
    // Density 1 would glow differently: the test tells the two apart.
    let unscaled = ink_expected_xyz(&json, &|_| 0.3, 1.0);
    assert!(
        (unscaled[1] - expected[1]).abs() > 10.0 * image[1].1,
        "{unscaled:?}"
    );
}

/// `fluorescence_lanes: hero` in a fluorescent medium (the secondary lanes end where any
/// lane re-emits) estimates the same as `all`: test 4's closed form.
#[test]
fn hero_lanes_in_a_fluorescent_medium_match_the_closed_form() {
    let data = Data::new();
    let json = ink_scene(
        &ink_medium(&data, "0.3", 0.0),
        r#"{"type": "path", "max_depth": 1, "fluorescence_lanes": "hero"}"#,
    );
    let expected = ink_expected_xyz(&json, &|_| 0.3, 1.0);
    let image = mean_and_se(&render_scene(&build(&json), 4096, 61));
    for (c, &(mean, se)) in image.iter().enumerate() {
        assert_close(&format!("hero lanes {c}"), mean, se, expected[c], 2e-3);
    }
}

/// `--explain` names a fluorescent medium, and its σt range includes the dye's σf (4 m⁻¹
/// at the 420 nm peak, over σa 0.3).
#[test]
fn the_plan_names_a_fluorescent_medium() {
    let data = Data::new();
    let json = ink_scene(
        &ink_medium(&data, "0.3", 0.0),
        r#"{"type": "path", "max_depth": 1}"#,
    );
    let scene = build(&json);
    let plan = prism_render::RenderPlan::new(&scene, &prism_render::PlanRequest::default());
    let media: Vec<String> = plan
        .choices
        .iter()
        .filter(|c| c.feature == "medium")
        .map(|c| format!("{} | {}", c.setting, c.reason))
        .collect();
    assert_eq!(media.len(), 1, "{media:?}");
    assert!(
        media[0].starts_with(
            "`ink`: homogeneous, σt 0.3000–4.3000 m⁻¹ over 360–830 nm, fluorescent (re-emits"
        ),
        "{}",
        media[0]
    );
    assert!(media[0].contains("chromatic σt"), "{}", media[0]);
}
