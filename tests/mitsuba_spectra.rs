//! Prism's RGB → spectrum upsampling against Mitsuba 3's, on the RGB values of Mitsuba's
//! built-in Cornell box (`mitsuba.cornell_box()`), and scenes/cornell-box.json against the
//! spectra Mitsuba renders that box with. The fixture tests/fixtures/mitsuba_cornell_spectra.json
//! (360–830 nm, 5 nm) is made by tools/mitsuba/export_cornell_spectra.py (Mitsuba 3.6.4,
//! `scalar_spectral`); see docs/mitsuba.md for the conventions found.
//!
//! - Reflectances: both renderers use the Jakob & Hanika (2019) sigmoid model; Mitsuba looks
//!   the coefficients up in its own 64³ table, Prism refines its table lookup by Newton steps
//!   (`Spectrum::rgb_albedo`). They agree to 1.2e-3 (max at 360 nm, red), 4e-4 elsewhere.
//! - Emitter: Mitsuba's RGB emitter (`d65` plugin) is 2·max(rgb) · sigmoid(rgb / 2·max(rgb))
//!   · D65 · MI_CIE_D65_NORMALIZATION, with D65 the 5 nm CIE table over 360–830 nm. Prism's
//!   `Spectrum::rgb_illuminant` is the same formula with its own D65 normalisation, which is
//!   1.0010877 times Mitsuba's, and with D65 zero above 780 nm (its CIE table ends there).
//!   scenes/cornell-box.json therefore gives the light Mitsuba's radiance as a 1 nm table
//!   (scenes/cornell-box/light-radiance.csv), checked here against the fixture.

use std::path::Path;

use prism_scene::{
    CameraKind, FovAxis, Integrator, LightKind, MaterialKind, PixelFilter, SamplerKind, ShapeKind,
    SpectrumRef, Strength,
};
use prism_spectrum::data::cmfs;
use prism_spectrum::{Observer, RgbAlbedoSpectrum, RgbGamut, SigmoidPolynomial, Spectrum};
use serde_json::Value;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture() -> Value {
    let path = root().join("tests/fixtures/mitsuba_cornell_spectra.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn rgb_f32(v: &Value) -> [f32; 3] {
    let c = floats(v);
    [c[0] as f32, c[1] as f32, c[2] as f32]
}

const MATERIALS: [&str; 3] = ["white", "green", "red"];

/// Mitsuba's D65 (and so its RGB emitters) ends at 830 nm, Prism's CIE D65 table at 780 nm.
const PRISM_D65_END_NM: f64 = 780.0;

/// Prism's normalised D65 over Mitsuba's (`mi.cie_d65`), 360–780 nm.
const K_D65: f64 = 1.001_087_7;

/// Largest |a − b| and where.
fn max_abs_diff(a: &[f64], b: &[f64], wavelengths: &[f64]) -> (f64, f64) {
    a.iter()
        .zip(b)
        .zip(wavelengths)
        .map(|((x, y), w)| ((x - y).abs(), *w))
        .fold((0.0, 0.0), |m, d| if d.0 > m.0 { d } else { m })
}

#[test]
fn reflectances_agree_with_mitsuba() {
    let f = fixture();
    let wl = floats(&f["wavelengths_nm"]);
    assert_eq!(wl.len(), 95);
    for name in MATERIALS {
        let m = &f["reflectances"][name];
        let rgb = rgb_f32(&m["rgb"]);
        let mitsuba = floats(&m["values"]);
        let refined = Spectrum::rgb_albedo(RgbGamut::Srgb, rgb).unwrap();
        let ours: Vec<f64> = wl.iter().map(|&w| refined.eval_nm(w)).collect();
        let (d, at) = max_abs_diff(&ours, &mitsuba, &wl);
        println!("{name}: rgb_albedo (refined) vs Mitsuba: max |Δ| = {d:.2e} at {at} nm");
        assert!(d <= 1.5e-3, "{name}: max |Δ| = {d} at {at} nm");

        // The pure table lookup, as Mitsuba does it (Prism's table, Mitsuba's method).
        let table = RgbAlbedoSpectrum::from_table(RgbGamut::Srgb, rgb).unwrap();
        let ours: Vec<f64> = wl.iter().map(|&w| table.eval_nm(w)).collect();
        let (d, at) = max_abs_diff(&ours, &mitsuba, &wl);
        println!("{name}: table lookup vs Mitsuba: max |Δ| = {d:.2e} at {at} nm");
        assert!(d <= 2.5e-3, "{name} (table): max |Δ| = {d} at {at} nm");

        // What the differences mean in colour: linear sRGB of each spectrum under the
        // normalised D65 (1 nm sums; Mitsuba's spectrum from its own coefficients, which
        // reproduce its values to 2e-6, see `sigmoid_model_is_mitsubas`).
        let c = floats(&m["coefficients"]);
        let mitsuba_poly = SigmoidPolynomial::new(c[0] as f32, c[1] as f32, c[2] as f32);
        let to_rgb = |s: &dyn Fn(f64) -> f64| {
            let w = RgbGamut::Srgb.reflectance_rgb_weights();
            (0..471).fold([0.0; 3], |acc, i| {
                let v = s(360.0 + i as f64);
                [
                    acc[0] + w[i][0] * v,
                    acc[1] + w[i][1] * v,
                    acc[2] + w[i][2] * v,
                ]
            })
        };
        let rgb_mitsuba = to_rgb(&|w| mitsuba_poly.eval_f64(w));
        let rgb_prism = to_rgb(&|w| refined.eval_nm(w));
        let err = |x: [f64; 3]| {
            (0..3)
                .map(|i| (x[i] - rgb[i] as f64).abs())
                .fold(0.0, f64::max)
        };
        println!(
            "{name}: RGB round trip: Prism {rgb_prism:.5?} (max |Δ| {:.1e}), Mitsuba \
             {rgb_mitsuba:.5?} (max |Δ| {:.1e}), input {rgb:?}",
            err(rgb_prism),
            err(rgb_mitsuba)
        );
        assert!(err(rgb_prism) <= 2.5e-4, "{name}: {rgb_prism:?}");
        assert!(err(rgb_mitsuba) <= 1.5e-3, "{name}: {rgb_mitsuba:?}");
    }
}

/// Same model: Prism's sigmoid polynomial with Mitsuba's coefficients gives Mitsuba's values
/// (so the differences above come from the coefficient tables alone).
#[test]
fn sigmoid_model_is_mitsubas() {
    let f = fixture();
    let wl = floats(&f["wavelengths_nm"]);
    let sigmoid = |c: &Value| {
        let c = floats(c);
        SigmoidPolynomial::new(c[0] as f32, c[1] as f32, c[2] as f32)
    };
    for name in MATERIALS {
        let m = &f["reflectances"][name];
        let p = sigmoid(&m["coefficients"]);
        for (w, v) in wl.iter().zip(floats(&m["values"])) {
            assert!((p.eval_f64(*w) - v).abs() <= 2e-6, "{name} at {w} nm");
        }
    }
    let e = &f["emitter"];
    let p = sigmoid(&e["coefficients"]);
    let scale = e["scale"].as_f64().unwrap();
    let d65 = floats(&f["d65_normalized"]);
    for ((w, v), d) in wl.iter().zip(floats(&e["values"])).zip(d65) {
        let ours = scale * p.eval_f64(*w) * d;
        assert!(
            (ours - v).abs() <= 2e-6 * v,
            "emitter at {w} nm: {ours} vs {v}"
        );
    }
}

/// Both normalise the same 5 nm CIE D65 table (linear between nodes) to luminance 1, each
/// with its own integral: Prism's is 1.0010877 × Mitsuba's over 360–780 nm and 0 above.
#[test]
fn white_illuminants_differ_by_a_constant_factor() {
    let f = fixture();
    let wl = floats(&f["wavelengths_nm"]);
    let mitsuba = floats(&f["d65_normalized"]);
    let prism = RgbGamut::Srgb.white_illuminant();
    let mut ratios = Vec::new();
    for (w, m) in wl.iter().zip(&mitsuba) {
        let p = prism[(*w - 360.0) as usize] as f64;
        if *w <= PRISM_D65_END_NM {
            ratios.push(p / m);
        } else {
            assert!(m > &0.5 && p == 0.0, "{w} nm: Prism {p}, Mitsuba {m}");
        }
    }
    let (lo, hi) = ratios
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), r| (a.min(*r), b.max(*r)));
    println!("Prism white illuminant / Mitsuba cie_d65 over 360–780 nm: {lo:.7}…{hi:.7}");
    assert!(hi - lo <= 2e-6, "ratio not constant: {lo}…{hi}");

    // The factor is Prism's normalisation Σȳ / Σ D65·ȳ (1 nm) over Mitsuba's
    // MI_CIE_D65_NORMALIZATION = 1 / 98.997….
    let y = cmfs(Observer::Cie1931).y_bar.values();
    let d65 = Spectrum::cie_illuminant("D65").unwrap();
    let sum_y: f64 = y.iter().sum();
    let sum_dy: f64 = (0..471).map(|i| d65.eval_nm(360.0 + i as f64) * y[i]).sum();
    let mi_norm = f["constants"]["MI_CIE_D65_NORMALIZATION"].as_f64().unwrap();
    let k = sum_y / sum_dy / mi_norm;
    println!(
        "Σȳ/ΣD65ȳ = {:.9}, MI_CIE_D65_NORMALIZATION = {mi_norm:.9}, k = {k:.7}",
        sum_y / sum_dy
    );
    assert!(
        (0.5 * (lo + hi) - k).abs() <= 2e-6,
        "k = {k}, measured {lo}…{hi}"
    );
    assert!((k - K_D65).abs() <= 2e-6, "k = {k}");
}

/// Prism's `rgb_illuminant` of the Cornell box light's RGB against Mitsuba's radiance: equal
/// up to the white-illuminant factor (360–780 nm) and the sigmoid tables (≤ 1.9e-3 relative,
/// at 360 nm); above 780 nm Prism's is 0.
#[test]
fn rgb_illuminant_against_mitsuba_emitter() {
    let f = fixture();
    let wl = floats(&f["wavelengths_nm"]);
    let e = &f["emitter"];
    let mitsuba = floats(&e["values"]);
    let prism = Spectrum::rgb_illuminant(RgbGamut::Srgb, rgb_f32(&e["rgb"])).unwrap();
    let k = K_D65;
    let mut worst: (f64, f64) = (0.0, 0.0);
    for (w, m) in wl.iter().zip(&mitsuba) {
        let p = prism.eval_nm(*w);
        if *w <= PRISM_D65_END_NM {
            let rel = (p / (k * m) - 1.0).abs();
            if rel > worst.0 {
                worst = (rel, *w);
            }
        } else {
            assert_eq!(p, 0.0, "{w} nm");
        }
    }
    println!(
        "rgb_illuminant / (1.0010877 · Mitsuba) − 1 over 360–780 nm: max {:.2e} at {} nm",
        worst.0, worst.1
    );
    assert!(worst.0 <= 2.5e-3, "{worst:?}");

    // Luminance (Prism's convention Y = Σ L ȳ / Σ ȳ, 1 nm): the exact Mitsuba radiance is
    // the 1 nm table the Cornell box scene uses.
    let y = cmfs(Observer::Cie1931).y_bar.values();
    let sum_y: f64 = y.iter().sum();
    let table = light_table();
    let lum =
        |s: &dyn Fn(f64) -> f64| (0..471).map(|i| s(360.0 + i as f64) * y[i]).sum::<f64>() / sum_y;
    let y_mitsuba = lum(&|w| table.eval(w));
    let y_prism = lum(&|w| prism.eval_nm(w));
    println!(
        "luminance (Prism convention): Mitsuba's light {y_mitsuba:.5}, Prism rgb_illuminant \
         {y_prism:.5}, ratio {:.6}",
        y_prism / y_mitsuba
    );
    assert!((y_prism / y_mitsuba - k).abs() <= 1e-3);
}

/// The light's table in scenes/cornell-box/light-radiance.csv, as prism-scene loads it.
fn light_table() -> prism_spectrum::Tabulated {
    let scene = prism_scene::load_scene(root().join("scenes/cornell-box.json")).unwrap();
    assert_eq!(scene.lights.len(), 1);
    match &scene.lights[0].spectrum {
        SpectrumRef::File { table, .. } => table.clone(),
        other => panic!("light spectrum should be the exported table, found {other:?}"),
    }
}

/// scenes/cornell-box.json holds Mitsuba's values: the light's radiance equals Mitsuba's at
/// every fixture wavelength, the reflectances are Mitsuba's RGB, and the integrator, camera
/// and film are the translation docs/mitsuba.md describes.
#[test]
fn cornell_scene_matches_mitsuba() {
    let f = fixture();
    let scene = prism_scene::load_scene(root().join("scenes/cornell-box.json")).unwrap();

    let light = &scene.lights[0];
    assert_eq!(light.strength, Strength::Scale(1.0));
    let LightKind::Area { shape, two_sided } = light.kind else {
        panic!("the Cornell box light is an area light");
    };
    assert!(!two_sided, "Mitsuba's area emitters are one-sided");
    assert_eq!(scene.shapes[shape].name.as_deref(), Some("light"));
    // Mitsuba's rectangle is [-1, 1]² facing +Z; the light faces down (−Y).
    let n = scene.shapes[shape]
        .transform
        .matrix
        .transform_vector3(glam::DVec3::Z);
    assert!(n.normalize().dot(glam::DVec3::NEG_Y) > 1.0 - 1e-9, "{n}");

    let table = light_table();
    let wl = floats(&f["wavelengths_nm"]);
    for (w, m) in wl.iter().zip(floats(&f["emitter"]["values"])) {
        let ours = table.eval(*w);
        assert!(
            (ours - m).abs() <= 1e-6 * m,
            "light at {w} nm: {ours} vs {m}"
        );
    }

    for name in MATERIALS {
        let mat = scene.materials.iter().find(|m| m.name == name).unwrap();
        let MaterialKind::Lambert {
            reflectance: prism_scene::SpectrumParam::Spectrum(SpectrumRef::Rgb { rgb }),
        } = &mat.kind
        else {
            panic!("{name} should be lambert with an RGB reflectance");
        };
        assert_eq!(
            rgb.to_vec(),
            floats(&f["reflectances"][name]["rgb"]),
            "{name}"
        );
    }

    assert_eq!(scene.shapes.len(), 8);
    let cuboids = scene
        .shapes
        .iter()
        .filter(|s| matches!(s.kind, ShapeKind::Cuboid { size_m } if size_m == [2.0; 3]))
        .count();
    let rectangles = scene
        .shapes
        .iter()
        .filter(|s| matches!(s.kind, ShapeKind::Rectangle { size_m } if size_m == [2.0; 2]))
        .count();
    assert_eq!((cuboids, rectangles), (2, 6));

    match scene.integrator {
        Integrator::Path {
            max_depth, sampler, ..
        } => {
            // Mitsuba max_depth 8 (path segments) = Prism 7 (bounces).
            assert_eq!(max_depth, 7);
            assert_eq!(sampler, SamplerKind::Independent);
        }
        other => panic!("integrator {other:?}"),
    }
    match scene.camera.kind {
        CameraKind::Pinhole { fov_rad, fov_axis } => {
            assert!((fov_rad.to_degrees() - 39.3077).abs() < 1e-9);
            assert_eq!(fov_axis, FovAxis::Horizontal);
        }
        ref other => panic!("camera {other:?}"),
    }
    assert_eq!(scene.film.resolution, [256, 256]);
    assert_eq!(
        scene.film.filter,
        PixelFilter::Gaussian {
            radius_px: 2.0,
            sigma_px: 0.5
        }
    );
}
