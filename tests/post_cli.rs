//! End-to-end checks of `prism tonemap` and `prism compare` on images Prism renders itself
//! and on a plain Radiance HDR without absolute scale.

use std::path::{Path, PathBuf};

use prism_image::image::Image;
use prism_image::io::{read_image, write_image};
use prism_spectrum::rgb_space::RgbColorSpace;
use serde_json::Value;

mod support;
use support::{prism, prism_simd};

const OPERATORS: [&str; 15] = [
    "linear",
    "mean-value",
    "ward94",
    "exponential",
    "logarithmic",
    "drago03",
    "schlick94",
    "tumblin-rushmeier",
    "reinhard02",
    "reinhard02-local",
    "ferwerda96",
    "ward97-histogram",
    "durand02",
    "aces",
    "agx",
];

fn ok(args: &[&str]) -> String {
    let out = prism(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Standard error of a successful run (status lines).
fn ok_status(args: &[&str]) -> String {
    let out = prism(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {err}");
    err
}

fn fails_with(args: &[&str], needles: &[&str]) {
    let out = prism(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: `{needle}` not in: {err}");
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("prism-post-cli");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A small render of the camera-gallery room (absolute scale in its header).
fn rendered_exr() -> PathBuf {
    let path = scratch("room.exr");
    if !path.exists() {
        ok(&[
            "render",
            "scenes/cameras/pinhole.json",
            "--resolution",
            "48x32",
            "--spp",
            "4",
            "-o",
            path.to_str().unwrap(),
        ]);
    }
    path
}

/// An HDR gradient with a bright spot and no absolute scale, as any other program writes.
fn plain_hdr(path: &Path) {
    let (w, h) = (40usize, 30usize);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let v = 0.01 * (1.0 + x) * (1.0 + 0.3 * y);
            if x > 30.0 && y < 5.0 {
                [200.0, 150.0, 90.0]
            } else {
                [v, 0.8 * v, 0.6 * v]
            }
        })
        .collect();
    let image = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
    write_image(path, &image).unwrap();
}

#[test]
fn list_names_every_operator_with_parameters_and_reference() {
    let text = ok(&["tonemap", "--list"]);
    for op in OPERATORS {
        assert!(
            text.lines().any(|l| l.starts_with(op)),
            "{op} missing:\n{text}"
        );
    }
    assert!(text.contains("--param key=") && text.contains("Reinhard"));
    let json: Value = serde_json::from_str(&ok(&["tonemap", "--list", "--json"])).unwrap();
    assert_eq!(json.as_array().unwrap().len(), OPERATORS.len());
}

#[test]
fn every_operator_maps_a_render_to_png_and_to_exr_in_unit_range() {
    let input = rendered_exr();
    for op in OPERATORS {
        let png = scratch(&format!("{op}.png"));
        ok(&[
            "tonemap",
            input.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--op",
            op,
        ]);
        assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"), "{op}");
        let mapped = read_image(&png).unwrap();
        assert_eq!((mapped.width(), mapped.height()), (48, 32), "{op}");
        let exr = scratch(&format!("{op}.exr"));
        let report: Value = serde_json::from_str(&ok(&[
            "tonemap",
            input.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--op",
            op,
            "--gamut",
            "local-oklab",
            "--target",
            "p3",
            "--wb",
            "grey-world",
            "--json",
        ]))
        .unwrap();
        assert_eq!(report["operator"], op);
        let image = read_image(&exr).unwrap();
        for p in image.pixels() {
            assert!(p.iter().all(|c| (0.0..=1.0).contains(c)), "{op}: {p:?}");
        }
    }
}

/// `--simd` reaches the tone-mapping kernels and changes no bit: each operator's EXR
/// output at each limit (one above the CPU falls back to what it has) equals the scalar
/// one, except where a curve has another form with AVX-512 (drago03's octave polynomials,
/// tumblin-rushmeier's power curve, compared to ~1e-6 in prism-post's kernel tests).
#[test]
fn every_simd_limit_gives_the_scalar_bits() {
    let input = rendered_exr();
    let bits = |op: &str, isa: &str| -> Vec<u32> {
        let exr = scratch(&format!("{op}-{isa}.exr"));
        let o = prism_simd(
            None,
            &[
                "tonemap",
                input.to_str().unwrap(),
                "-o",
                exr.to_str().unwrap(),
                "--op",
                op,
                "--simd",
                isa,
            ],
        );
        assert!(
            o.status.success(),
            "{op} --simd {isa}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let image = read_image(&exr).unwrap();
        image
            .pixels()
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    for op in OPERATORS {
        if matches!(op, "drago03" | "tumblin-rushmeier") {
            continue;
        }
        let scalar = bits(op, "scalar");
        for isa in ["avx2", "avx512"] {
            assert!(bits(op, isa) == scalar, "{op} --simd {isa}");
        }
    }
}

#[test]
fn contact_sheet_has_one_tile_per_operator() {
    let input = rendered_exr();
    let sheet = scratch("sheet.png");
    let report: Value = serde_json::from_str(&ok(&[
        "tonemap",
        input.to_str().unwrap(),
        "-o",
        sheet.to_str().unwrap(),
        "--op",
        "all",
        "--json",
    ]))
    .unwrap();
    assert_eq!(report["tone"].as_array().unwrap().len(), OPERATORS.len());
    let image = read_image(&sheet).unwrap();
    assert!(image.width() > 4 * 48 && image.height() > 3 * 32);
}

#[test]
fn absolute_operators_need_a_scale_on_foreign_images() {
    let hdr = scratch("plain.hdr");
    plain_hdr(&hdr);
    let out = scratch("abs.png");
    for op in ["ward94", "ferwerda96", "ward97-histogram"] {
        fails_with(
            &[
                "tonemap",
                hdr.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--op",
                op,
            ],
            &["--luminance-scale"],
        );
        let report: Value = serde_json::from_str(&ok(&[
            "tonemap",
            hdr.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--op",
            op,
            "--luminance-scale",
            "179",
            "--json",
        ]))
        .unwrap();
        assert_eq!(report["operator"], op);
        assert_eq!(
            report["luminance_scale_cd_m2"].as_f64(),
            Some(179.0),
            "{op}"
        );
        assert_eq!(
            (&report["width"], &report["height"]),
            (&40.into(), &30.into())
        );
        // The image written: full size, and the 200-unit spot (x > 30, y < 5) brighter
        // than the dimmest corner of the gradient (0.097 units at (0, 29)).
        let mapped = read_image(&out).unwrap();
        assert_eq!((mapped.width(), mapped.height()), (40, 30), "{op}");
        let (spot, dim) = (mapped.pixel(35, 2), mapped.pixel(0, 29));
        assert!(
            spot[1] > dim[1] && spot.iter().chain(&dim).all(|c| c.is_finite()),
            "{op}: spot {spot:?}, dim corner {dim:?}"
        );
    }
}

#[test]
fn bad_tonemap_input_is_named() {
    let input = rendered_exr();
    let out = scratch("bad.png");
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    fails_with(
        &["tonemap", i, "-o", o, "--op", "reinhart02"],
        &["reinhart02", "`reinhard02`"],
    );
    fails_with(
        &[
            "tonemap",
            i,
            "-o",
            o,
            "--op",
            "reinhard02",
            "--param",
            "key",
        ],
        &["KEY=VALUE"],
    );
    fails_with(
        &[
            "tonemap",
            i,
            "-o",
            o,
            "--op",
            "reinhard02",
            "--gamut",
            "lhc",
        ],
        &["lhc"],
    );
    fails_with(
        &[
            "tonemap",
            i,
            "-o",
            o,
            "--op",
            "reinhard02",
            "--target",
            "adobe",
        ],
        &["adobe"],
    );
    fails_with(
        &["tonemap", "no/such.exr", "-o", o, "--op", "aces"],
        &["no/such.exr"],
    );
}

#[test]
fn compare_reports_every_metric_and_refuses_mismatched_sizes() {
    let a = scratch("a.hdr");
    plain_hdr(&a);
    let same: Value = serde_json::from_str(&ok(&[
        "compare",
        a.to_str().unwrap(),
        a.to_str().unwrap(),
        "--json",
    ]))
    .unwrap();
    for key in [
        "mse",
        "rmse",
        "relmse",
        "psnr_db",
        "ssim",
        "delta_e2000_mean",
        "delta_e2000_p95",
    ] {
        assert!(same.get(key).is_some(), "{key} missing: {same}");
    }
    assert_eq!(same["mse"].as_f64().unwrap(), 0.0);
    assert_eq!(same["ssim"].as_f64().unwrap(), 1.0);
    assert_eq!(same["per_channel"]["rmse"].as_array().unwrap().len(), 3);
    let table = ok(&["compare", a.to_str().unwrap(), a.to_str().unwrap()]);
    assert!(table.contains("RMSE") && table.contains("SSIM"));
    let room = rendered_exr();
    fails_with(
        &["compare", a.to_str().unwrap(), room.to_str().unwrap()],
        &["40×30", "48×32"],
    );
}

/// Linear sRGB of a neutral reflectance under CIE A (1 nm integration, white diffuser
/// Y = 1), and the XYZ of the white diffuser itself: what a renderer's beauty and
/// illumination AOV hold for a grey surface lit by A.
fn neutral_under_a(reflectance: f64) -> ([f32; 3], [f32; 3]) {
    use prism_spectrum::colorimetry::reflectance_to_xyz;
    use prism_spectrum::{data::illuminant, DenseSpectrum, Observer};
    let a = illuminant("A").unwrap().to_dense();
    let white = reflectance_to_xyz(&DenseSpectrum::constant(1.0), &a, Observer::Cie1931) / 100.0;
    let rgb = RgbColorSpace::srgb().xyz_to_rgb * (white * reflectance);
    (rgb.as_vec3().to_array(), white.as_vec3().to_array())
}

#[test]
fn wb_scene_takes_the_white_from_the_illumination_layer() {
    use prism_spectrum::colorimetry::xyz_to_lab;
    // 10×6 pixels: a grey card (0.18) and a lighter grey (0.5) under A, at two light
    // levels, plus a column of misses (black, no illumination).
    let (w, h) = (10usize, 6usize);
    let mut pixels = Vec::new();
    let mut illumination = Vec::new();
    for i in 0..w * h {
        let (x, y) = (i % w, i / w);
        let level = if y < 3 { 1.0 } else { 0.4 };
        let reflectance = if x < 5 { 0.18 } else { 0.5 };
        let (rgb, white) = neutral_under_a(reflectance);
        if x == 9 {
            pixels.push([0.0; 3]);
            illumination.extend([0.0; 3]);
        } else {
            pixels.push(rgb.map(|c| c * level));
            illumination.extend(white.map(|c| c * level));
        }
    }
    let mut image = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
    image
        .set_layer("illumination", &["X", "Y", "Z"], illumination)
        .unwrap();
    let input = scratch("under_a.exr");
    write_image(&input, &image).unwrap();
    let output = scratch("under_a_balanced.exr");
    let json: Value = serde_json::from_str(&ok(&[
        "tonemap",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--op",
        "linear",
        "--wb",
        "scene",
        "--json",
    ]))
    .unwrap();
    assert_eq!(json["white_balance"], "scene");
    // The estimated white is A's: (0.44757, 0.40745), CIE 15:2018 Table 1.
    let xy = &json["white_balance_source_xy"];
    let (sx, sy) = (xy[0].as_f64().unwrap(), xy[1].as_f64().unwrap());
    assert!(
        (sx - 0.44757).abs() < 5e-5 && (sy - 0.40745).abs() < 5e-5,
        "{xy}"
    );
    // Before: the grey card is strongly yellow; after: neutral against D65.
    let srgb = RgbColorSpace::srgb();
    let lab = |p: [f32; 3]| {
        let xyz = srgb.rgb_to_xyz * glam::DVec3::from(p.map(f64::from));
        xyz_to_lab(xyz, srgb.white_xyz())
    };
    let before = lab(image.pixel(0, 0));
    assert!(before.y.hypot(before.z) > 20.0, "{before}");
    let out = read_image(&output).unwrap();
    for (x, y) in [(0, 0), (7, 1), (2, 4), (6, 5)] {
        let after = lab(out.pixel(x, y));
        assert!(
            after.y.abs() < 0.5 && after.z.abs() < 0.5,
            "pixel ({x}, {y}): Lab {after}"
        );
    }
}

#[test]
fn wb_scene_without_an_illumination_layer_names_the_file_and_the_layer() {
    let hdr = scratch("no_layer.hdr");
    plain_hdr(&hdr);
    let out = scratch("no_layer.png");
    fails_with(
        &[
            "tonemap",
            hdr.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--op",
            "linear",
            "--wb",
            "scene",
        ],
        &["no_layer.hdr", "illumination", "prism render"],
    );
    assert!(!out.exists());
    // A render whose integrator leaves the layer at zero (the diagnostic ones) says so.
    let render = rendered_exr();
    fails_with(
        &[
            "tonemap",
            render.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--op",
            "linear",
            "--wb",
            "scene",
        ],
        &["room.exr", "illumination layer is zero"],
    );
}

#[test]
fn exposure_auto_brings_an_absolute_render_to_middle_grey() {
    // A dim absolute-looking image (luminances near 1e-3): linear with EV 0 is black
    // in 8 bits; `--exposure auto` maps its log-average to 0.18.
    let input = scratch("dim.exr");
    let (w, h) = (32usize, 16usize);
    let pixels: Vec<[f32; 3]> = (0..w * h)
        .map(|i| {
            let v = 1e-3 * (1.0 + (i % w) as f32 / w as f32);
            [v, v, v]
        })
        .collect();
    let ln_mean = pixels.iter().map(|p| f64::from(p[1]).ln()).sum::<f64>() / (w * h) as f64;
    let expected_ev = (0.18 / ln_mean.exp()).log2();
    write_image(
        &input,
        &Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    let out = scratch("dim-auto.exr");
    let report: Value = serde_json::from_str(&ok(&[
        "tonemap",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--op",
        "linear",
        "--exposure",
        "auto",
        "--json",
    ]))
    .unwrap();
    let ev = report["exposure_ev"].as_f64().unwrap();
    assert!((ev - expected_ev).abs() < 1e-4, "{ev} vs {expected_ev}");
    assert_eq!(report["auto_exposure"], Value::Bool(true));
    let mapped = read_image(&out).unwrap();
    let ln_mapped = mapped
        .pixels()
        .iter()
        .map(|p| f64::from(p[1]).ln())
        .sum::<f64>()
        / (w * h) as f64;
    assert!((ln_mapped.exp() - 0.18).abs() < 1e-4, "{}", ln_mapped.exp());

    let text = ok_status(&[
        "tonemap",
        input.to_str().unwrap(),
        "-o",
        scratch("dim-auto.png").to_str().unwrap(),
        "--op",
        "aces",
        "--exposure",
        "auto",
    ]);
    assert!(text.contains("exposure auto: +"), "{text}");

    fails_with(
        &[
            "tonemap",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--op",
            "linear",
            "--exposure",
            "bright",
        ],
        &["--exposure bright", "`auto`"],
    );
    let black = scratch("black.exr");
    write_image(
        &black,
        &Image::new(4, 4, vec![[0.0; 3]; 16], RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    fails_with(
        &[
            "tonemap",
            black.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--op",
            "linear",
            "--exposure",
            "auto",
        ],
        &["black.exr", "--exposure auto", "black image"],
    );
}

#[test]
fn cat_chooses_the_adaptation_transform_of_the_white_balance() {
    use prism_post::colour::white_balance::illuminant_white_xyz_unit_y;
    use prism_spectrum::adaptation::{adaptation_matrix, AdaptationMethod};
    // A saturated orange and a grey under CIE A, both inside [0, 1] after adaptation (the
    // grey turns blue: it was neutral for D65, not for A).
    let srgb = RgbColorSpace::srgb();
    let colours = [[0.45f32, 0.22, 0.05], [0.2, 0.2, 0.2]];
    let pixels: Vec<[f32; 3]> = (0..8).map(|i| colours[i % 2]).collect();
    let input = scratch("cat_input.exr");
    write_image(
        &input,
        &Image::new(4, 2, pixels, RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    let source = illuminant_white_xyz_unit_y("A").unwrap();
    let mut orange_by_cat = Vec::new();
    for (flag, method) in [
        ("bradford", AdaptationMethod::Bradford),
        ("cat16", AdaptationMethod::Cat16),
        ("cat02", AdaptationMethod::Cat02),
        ("von-kries", AdaptationMethod::VonKries),
    ] {
        let output = scratch(&format!("cat_{flag}.exr"));
        let json: Value = serde_json::from_str(&ok(&[
            "tonemap",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
            "--op",
            "linear",
            "--wb",
            "illuminant:A",
            "--cat",
            flag,
            "--json",
        ]))
        .unwrap();
        assert_eq!(json["chromatic_adaptation"], method.name(), "{json}");
        // Each pixel is M_rgb⁻¹ · CAT(A → D65) · M_rgb · pixel (linear operator, exposure 0).
        let cat = adaptation_matrix(method, source, srgb.white_xyz());
        let out = read_image(&output).unwrap();
        for (i, colour) in colours.iter().enumerate() {
            let expected = srgb.xyz_to_rgb
                * (cat * (srgb.rgb_to_xyz * glam::DVec3::from(colour.map(f64::from))));
            let got = out.pixel(i, 0);
            for c in 0..3 {
                assert!(
                    (f64::from(got[c]) - expected[c]).abs() < 2e-5,
                    "--cat {flag}, pixel {i}: got {got:?}, expected {expected}"
                );
            }
        }
        orange_by_cat.push(out.pixel(0, 0));
    }
    // The transforms differ on saturated colours (else the flag would be untestable).
    for other in &orange_by_cat[1..] {
        let gap = (0..3)
            .map(|c| (other[c] - orange_by_cat[0][c]).abs())
            .fold(0.0f32, f32::max);
        assert!(gap > 1e-3, "{orange_by_cat:?}");
    }
}

#[test]
fn cat_refuses_an_unknown_transform() {
    fails_with(
        &[
            "tonemap", "in.exr", "-o", "out.png", "--op", "linear", "--cat", "sharp",
        ],
        &["--cat", "bradford", "cat16", "cat02", "von-kries"],
    );
}

/// FLIP in `prism compare`: the keys, zero for an image against itself, the negative
/// samples HDR-FLIP clamps, the viewing condition, the error map (magma + legend, written
/// atomically) and the refused viewing conditions.
#[test]
fn compare_reports_flip_and_writes_its_error_map() {
    let a = scratch("flip-a.exr");
    plain_hdr(&a);
    let reference = read_image(&a).unwrap();
    let mut pixels = reference.pixels().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        *p = p.map(|v| v * (1.0 + 0.3 * ((i * 7919 % 13) as f32 / 13.0 - 0.5)));
    }
    pixels[5] = [-0.5, 0.1, -0.25];
    let b = scratch("flip-b.exr");
    write_image(&b, &reference.with_pixels(pixels).unwrap()).unwrap();
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let json = |args: &[&str]| -> Value { serde_json::from_str(&ok(args)).unwrap() };

    let same = json(&["compare", a, a, "--json"]);
    for key in [
        "ldr_flip_mean",
        "hdr_flip_mean",
        "ldr_flip_p95",
        "hdr_flip_p95",
    ] {
        assert_eq!(same[key].as_f64(), Some(0.0), "{key}: {same}");
    }
    let diff = json(&["compare", b, a, "--json"]);
    let ldr = diff["ldr_flip_mean"].as_f64().unwrap();
    assert!(ldr > 0.0 && diff["hdr_flip_mean"].as_f64().unwrap() > 0.0);
    assert!(diff["hdr_flip_p95"].as_f64().unwrap() >= diff["hdr_flip_mean"].as_f64().unwrap());
    assert_eq!(diff["hdr_flip_negative_samples"], 2);
    assert!(diff["hdr_flip_exposures"]["count"].as_u64().unwrap() >= 2);
    // A farther viewer (fewer pixels per degree) blurs more: a different score.
    let far = json(&["compare", b, a, "--json", "--ppd", "20"]);
    assert_eq!(far["flip_ppd"], 20.0);
    assert_ne!(far["ldr_flip_mean"].as_f64().unwrap(), ldr);

    let map = scratch("flip-map.png");
    let table = ok(&["compare", b, a, "--error-map", map.to_str().unwrap()]);
    assert!(table.contains("HDR-FLIP mean") && table.contains("negative samples"));
    let img = read_image(&map).unwrap();
    // 40 × 30 map, a 150-px legend, at least 220 px tall.
    assert_eq!((img.width(), img.height()), (190, 220));
    let leftovers: Vec<_> = std::fs::read_dir(map.parent().unwrap())
        .unwrap()
        .filter_map(|e| e.ok())
        // Only this write's temporaries: the folder is shared with tests running beside
        // this one, whose writes are in flight.
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.starts_with(".flip-map.png.") && name.ends_with(".tmp")
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    for ppd in ["0", "-3"] {
        fails_with(&["compare", b, a, "--ppd", ppd], &["pixels per degree"]);
    }
}

/// `--tmqi`: a tone-mapped PNG against its HDR source gives the three keys in [0, 1];
/// two LDR images, or the pair the wrong way round, and mismatched sizes are errors.
/// A 192×180 HDR image with texture at several scales and about 9 stops of range, large
/// enough for TMQI's 5 scales.
fn tmqi_hdr(name: &str) -> PathBuf {
    let (w, h) = (192usize, 180usize);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let t = (x / 3.0).sin() * (y / 5.0).cos() + (x / 17.0 + y / 23.0).sin();
            let v = (2.0 + t).exp2() * (1.0 + x / 8.0);
            [v, 0.8 * v, 0.6 * v]
        })
        .collect();
    let hdr = scratch(name);
    write_image(
        &hdr,
        &Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    hdr
}

#[test]
fn contact_sheet_scores_every_tile_with_tmqi_and_sorts_on_request() {
    let hdr = tmqi_hdr("score.exr");
    let sheet = scratch("score-sheet.png");
    let (hdr, sheet) = (hdr.to_str().unwrap(), sheet.to_str().unwrap());
    let sheet_args = [
        "tonemap", hdr, "-o", sheet, "--op", "all", "--score", "tmqi",
    ];
    let report: Value = serde_json::from_str(&ok(&[
        &sheet_args[..],
        &["--sort", "score", "--luminance-scale", "100", "--json"],
    ]
    .concat()))
    .unwrap();
    assert_eq!(report["score"], "tmqi");
    let scores = report["scores"].as_array().unwrap();
    assert_eq!(scores.len(), report["tone"].as_array().unwrap().len());
    let tmqi: Vec<f64> = scores.iter().map(|s| s["tmqi"].as_f64().unwrap()).collect();
    assert!(tmqi.iter().all(|t| *t > 0.0 && *t <= 1.0), "{tmqi:?}");
    assert!(
        tmqi.windows(2).all(|p| p[0] >= p[1]),
        "not best first: {tmqi:?}"
    );
    // The sheet scores the full-resolution output: a single-operator PNG of the same
    // operator scores the same, up to the PNG's 8-bit quantisation.
    for entry in [&scores[0], scores.last().unwrap()] {
        let op = entry["operator"].as_str().unwrap();
        let png = scratch(&format!("score-{op}.png"));
        let png = png.to_str().unwrap();
        let one: Value = serde_json::from_str(&ok(&[
            "tonemap",
            hdr,
            "-o",
            png,
            "--op",
            op,
            "--score",
            "tmqi",
            "--luminance-scale",
            "100",
            "--json",
        ]))
        .unwrap();
        assert_eq!(one["scores"][0]["tmqi"], entry["tmqi"], "{op}");
        let read: Value =
            serde_json::from_str(&ok(&["compare", png, hdr, "--tmqi", "--json"])).unwrap();
        let (a, b) = (
            entry["tmqi"].as_f64().unwrap(),
            read["tmqi"].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 5e-3, "{op}: sheet {a}, PNG {b}");
    }
    // Catalogue order without --sort; the table under the text output.
    let text = ok(&sheet_args);
    assert!(text.contains("TMQI") && text.contains("linear"), "{text}");
    fails_with(
        &[
            "tonemap", hdr, "-o", sheet, "--op", "all", "--sort", "score",
        ],
        &["--sort score", "--score tmqi"],
    );
    let small = scratch("score-small.hdr");
    plain_hdr(&small);
    fails_with(
        &[
            &sheet_args[..1],
            &[small.to_str().unwrap()],
            &sheet_args[2..],
        ]
        .concat(),
        &["176", "40×30"],
    );
}

#[test]
fn compare_tmqi_scores_a_tone_mapped_png_and_refuses_other_pairings() {
    let hdr = tmqi_hdr("tmqi.exr");
    let ldr = scratch("tmqi-reinhard02.png");
    let (hdr, ldr) = (hdr.to_str().unwrap(), ldr.to_str().unwrap());
    ok(&["tonemap", hdr, "-o", ldr, "--op", "reinhard02"]);
    let t: Value = serde_json::from_str(&ok(&["compare", ldr, hdr, "--tmqi", "--json"])).unwrap();
    for key in ["tmqi", "tmqi_structural_fidelity", "tmqi_naturalness"] {
        let v = t[key].as_f64().unwrap();
        assert!(v > 0.0 && v <= 1.0, "{key} = {v}: {t}");
    }
    assert!(ok(&["compare", ldr, hdr, "--tmqi"]).contains("structural fidelity S"));
    fails_with(&["compare", ldr, ldr, "--tmqi"], &["--tmqi", "PNG", "EXR"]);
    fails_with(&["compare", hdr, ldr, "--tmqi"], &["--tmqi"]);
    let small = scratch("tmqi-small.hdr");
    plain_hdr(&small);
    fails_with(
        &["compare", ldr, small.to_str().unwrap(), "--tmqi"],
        &["192×180", "40×30"],
    );
}

/// `compare --report` writes one self-contained page whose table carries `--json`'s
/// numbers: for two EXRs a viewer with an exposure control, the A and B images as RGBE
/// pairs and the HDR-FLIP, LDR-FLIP and ΔE2000 maps; for two PNGs no exposure control and
/// no HDR-FLIP map. Bad report paths are refused before the comparison.
#[test]
fn compare_report_is_one_self_contained_page() {
    let a = rendered_exr();
    let b = scratch("room-16spp.exr");
    ok(&[
        "render",
        "scenes/cameras/pinhole.json",
        "--resolution",
        "48x32",
        "--spp",
        "16",
        "-o",
        b.to_str().unwrap(),
    ]);
    let html = scratch("report.html");
    let (a, b, html_s) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        html.to_str().unwrap(),
    );
    let json: Value =
        serde_json::from_str(&ok(&["compare", a, b, "--report", html_s, "--json"])).unwrap();
    let page = support::html_report::check_report(&std::fs::read_to_string(&html).unwrap());
    assert_eq!((page.viewers, page.exposure_controls), (1, 1));
    assert_eq!(page.images.len(), 7, "{:?}", page.images);
    assert_eq!(page.images.iter().filter(|s| **s == (48, 32)).count(), 4);
    let table: std::collections::HashMap<&str, &str> = page.tables[0]
        .iter()
        .map(|row| (row[0].as_str(), row[1].as_str()))
        .collect();
    for (name, key) in [
        ("relMSE", "relmse"),
        ("ΔE2000 mean", "delta_e2000_mean"),
        ("LDR-FLIP mean", "ldr_flip_mean"),
        ("HDR-FLIP mean", "hdr_flip_mean"),
    ] {
        let shown: f64 = table[name].parse().unwrap();
        let want = json[key].as_f64().unwrap();
        assert!(
            (shown - want).abs() <= 1e-5 * want.abs().max(1.0),
            "{name}: {shown} vs {want}"
        );
    }

    let (pa, pb) = (scratch("report-a.png"), scratch("report-b.png"));
    for (exr, png) in [(a, &pa), (b, &pb)] {
        ok(&[
            "tonemap",
            exr,
            "-o",
            png.to_str().unwrap(),
            "--op",
            "reinhard02",
        ]);
    }
    ok(&[
        "compare",
        pa.to_str().unwrap(),
        pb.to_str().unwrap(),
        "--report",
        html_s,
    ]);
    let page = support::html_report::check_report(&std::fs::read_to_string(&html).unwrap());
    assert_eq!((page.viewers, page.exposure_controls), (1, 0));
    assert_eq!(
        page.images.len(),
        4,
        "A, B, LDR-FLIP, ΔE2000: {:?}",
        page.images
    );

    fails_with(
        &["compare", a, b, "--report", "report.txt"],
        &["--report", ".html"],
    );
    fails_with(
        &["compare", a, b, "--report", "/no/such/dir/r.html"],
        &["/no/such/dir", "does not exist"],
    );
    fails_with(
        &["compare", a, b, "--tmqi", "--report", html_s],
        &["--report"],
    );
}
