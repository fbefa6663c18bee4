//! End-to-end checks of `prism render`: every example scene renders, determinism across
//! thread counts, output formats and layers, statistics, and error messages.

use std::path::{Path, PathBuf};

use prism_image::io::exr::read_exr;
use prism_image::io::spectral_exr::{read_spectral_exr, RADIANCE_UNITS};
use serde_json::Value;

mod support;
use support::{png_size, prism, prism_simd, s, stderr};

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            scene_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "json") {
            out.push(path);
        }
    }
}

#[test]
fn every_example_scene_renders_at_a_tiny_resolution() {
    let mut files = Vec::new();
    scene_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        &mut files,
    );
    assert!(files.len() >= 9, "{files:?}");
    let dir = tempfile::tempdir().unwrap();
    for (i, f) in files.iter().enumerate() {
        let out = dir.path().join(format!("{i}.exr"));
        let o = prism(&[
            "render",
            s(f),
            "-o",
            s(&out),
            "--resolution",
            "16x12",
            "--spp",
            "1",
        ]);
        assert!(o.status.success(), "{}: {}", f.display(), stderr(&o));
        let image = read_exr(&out).unwrap();
        assert_eq!((image.width(), image.height()), (16, 12), "{}", f.display());
        // Finite RGB (components may be negative: linear sRGB of colours outside its gamut)
        // and a luminance of 16 × 12 values ≥ 0.
        let bad = image
            .pixels()
            .iter()
            .find(|p| !p.iter().all(|c| c.is_finite()));
        assert!(bad.is_none(), "{}: {bad:?}", f.display());
        let luminance = &image.layer("luminance").expect("luminance layer").samples;
        assert_eq!(luminance.len(), 16 * 12, "{}", f.display());
        let bad = luminance.iter().find(|&&y| !(y.is_finite() && y >= 0.0));
        assert!(bad.is_none(), "{}: luminance {bad:?}", f.display());
    }
}

#[test]
fn same_seed_gives_bit_identical_exr_pixels_for_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("t{threads}.exr"));
        let o = prism(&[
            "render",
            "scenes/cameras/thin-lens.json",
            "-o",
            s(&out),
            "--resolution",
            "40x30",
            "--spp",
            "3",
            "--seed",
            "11",
            "--threads",
            threads,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        images.push(read_exr(&out).unwrap());
    }
    let bits = |im: &prism_image::Image| -> Vec<u32> {
        let mut v: Vec<u32> = im.pixels().iter().flatten().map(|x| x.to_bits()).collect();
        for l in im.layers() {
            v.extend(l.samples.iter().map(|x| x.to_bits()));
        }
        v
    };
    assert_eq!(bits(&images[0]), bits(&images[1]));
}

#[test]
fn exr_has_rgb_the_aov_and_luminance_layers_and_the_absolute_scale() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    let o = prism(&[
        "render",
        "scenes/cameras/pinhole.json",
        "-o",
        s(&out),
        "--resolution",
        "32x24",
        "--spp",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = read_exr(&out).unwrap();
    // 683.002 lm/W · ∫ȳ dλ (CIE 1931, 1 nm, 360–830 nm: 106.857 nm) ≈ 72983.
    let scale = image.cd_m2_per_unit.expect("prism:cd_m2_per_unit");
    assert!((scale - 72983.0).abs() < 2.0, "{scale}");
    for (layer, channels) in [
        ("depth", vec!["Z"]),
        ("normal", vec!["X", "Y", "Z"]),
        ("albedo", vec!["R", "G", "B"]),
        ("spp", vec!["Y"]),
        ("luminance", vec!["Y"]),
        ("illumination", vec!["X", "Y", "Z"]),
    ] {
        let l = image
            .layer(layer)
            .unwrap_or_else(|| panic!("layer {layer}"));
        // EXR stores channels sorted by name; compare as sets.
        let mut got = l.channels.clone();
        got.sort();
        let mut want: Vec<String> = channels.iter().map(|c| c.to_string()).collect();
        want.sort();
        assert_eq!(got, want, "{layer}");
    }
    // luminance.Y = Y · scale; AO output is a flat spectrum, so Y ∈ [0, 1].
    let lum = &image.layer("luminance").unwrap().samples;
    assert!(lum
        .iter()
        .all(|&v| (0.0..=scale as f32 * 1.0001).contains(&v)));
    assert!(lum.iter().any(|&v| v > 0.1 * scale as f32));
    assert!(image
        .layer("spp")
        .unwrap()
        .samples
        .iter()
        .all(|&v| v == 2.0));
}

#[test]
fn spectral_bins_go_into_the_same_exr_in_the_fichet_layout() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bins.exr");
    let o = prism(&[
        "render",
        "scenes/minimal.json",
        "-o",
        s(&out),
        "--resolution",
        "12x8",
        "--spp",
        "1",
        "--spectral-bins",
        "10",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The spectral reading: ten bands at the bin centres 383.5, 430.5, …, 806.5 nm.
    let spectral = read_spectral_exr(&out).unwrap();
    let centres: Vec<f64> = (0..10).map(|b| 360.0 + 47.0 * (b as f64 + 0.5)).collect();
    assert_eq!(spectral.wavelengths_nm, centres);
    assert_eq!(spectral.emissive_units, RADIANCE_UNITS);
    assert_eq!((spectral.width, spectral.height), (12, 8));
    // The RGB reading of the same file: pixels, layers and luminance in cd/m² as always.
    let image = read_exr(&out).unwrap();
    for layer in ["luminance", "illumination", "spp", "depth"] {
        assert!(image.layer(layer).is_some(), "{layer}");
    }
    assert!(image.layer("S0").is_none());
    assert!(image.cd_m2_per_unit.is_some());
}

#[test]
fn spectral_bins_out_of_range_or_with_a_png_fail_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    for (n, file) in [
        ("0", "a.exr"),
        ("472", "b.exr"),
        ("16", "c.png"),
        ("16", "d.hdr"),
    ] {
        let out = dir.path().join(file);
        let o = prism(&[
            "render",
            "scenes/minimal.json",
            "-o",
            s(&out),
            "--resolution",
            "8x8",
            "--spectral-bins",
            n,
        ]);
        assert!(!o.status.success(), "{n} {file}");
        let e = stderr(&o);
        assert!(e.contains("--spectral-bins"), "{e}");
        if file.ends_with(".exr") {
            assert!(e.contains("1 to 471"), "{e}");
        } else {
            assert!(e.contains(".exr") && e.contains(file), "{e}");
        }
        assert!(!out.exists());
    }
}

#[test]
fn png_output_is_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = prism(&[
        "render",
        "scenes/minimal.json",
        "-o",
        s(&out),
        "--resolution",
        "20x10",
        "--spp",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(png_size(&out), (20, 10));
}

#[test]
fn stats_json_has_every_key_with_sane_values() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    let stats = dir.path().join("stats.json");
    let o = prism(&[
        "render",
        "scenes/cameras/orthographic.json",
        "-o",
        s(&out),
        "--resolution",
        "24x16",
        "--spp",
        "2",
        "--threads",
        "2",
        "--stats-json",
        s(&stats),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in [
        "wall_time_s",
        "rays_traced",
        "rays_per_second",
        "samples",
        "peak_memory_bytes",
        "resolution",
        "spp",
        "threads",
        "integrator",
        "non_finite_samples",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert!(v["wall_time_s"].as_f64().unwrap() > 0.0);
    assert_eq!(v["samples"], 24 * 16 * 2);
    // AO with 1 occlusion ray: one camera ray per sample plus one per hit.
    let rays = v["rays_traced"].as_u64().unwrap();
    assert!((24 * 16 * 2..=24 * 16 * 2 * 2).contains(&rays), "{rays}");
    assert!(v["rays_per_second"].as_f64().unwrap() > 0.0);
    if cfg!(target_os = "linux") {
        assert!(v["peak_memory_bytes"].as_u64().unwrap() > 1_000_000);
    }
    assert_eq!(v["resolution"], serde_json::json!([24, 16]));
    assert_eq!(v["spp"], 2);
    assert_eq!(v["threads"], 2);
    assert_eq!(v["integrator"], "ambient_occlusion");
    assert_eq!(v["non_finite_samples"], 0);
}

#[test]
fn a_bad_scene_is_reported_with_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.json");
    std::fs::write(&scene, "{\n  \"integrator\": \"normal\",\n  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1}]\n}\n").unwrap();
    let o = prism(&["render", s(&scene), "-o", s(&dir.path().join("x.exr"))]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("bad.json:3:"), "{e}");
    assert!(e.contains("radius_m"), "{e}");
    assert!(!dir.path().join("x.exr").exists());
}

#[test]
fn unwritable_output_or_unknown_extension_fails_cleanly_without_files() {
    let dir = tempfile::tempdir().unwrap();
    let not_a_dir = dir.path().join("file.txt");
    std::fs::write(&not_a_dir, "x").unwrap();
    for out in [
        not_a_dir.join("x.exr"),
        dir.path().join("missing/x.exr"),
        dir.path().join("x.tiff"),
    ] {
        let o = prism(&[
            "render",
            "scenes/minimal.json",
            "-o",
            s(&out),
            "--resolution",
            "8x8",
        ]);
        assert!(!o.status.success(), "{}", out.display());
        let e = stderr(&o);
        assert!(e.contains(s(&out)), "{e}");
        assert!(!out.exists());
    }
    let tiff = stderr(&prism(&[
        "render",
        "scenes/minimal.json",
        "-o",
        s(&dir.path().join("x.tiff")),
    ]));
    assert!(tiff.contains(".exr") && tiff.contains(".png"), "{tiff}");
    // Nothing but the file we made: no temporaries left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("file.txt")]);
}

#[test]
fn the_default_path_integrator_warns_about_a_scene_without_lights() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("p.json");
    std::fs::write(&scene, r#"{"shapes": [{"type": "sphere"}]}"#).unwrap();
    let out = dir.path().join("x.exr");
    let o = prism(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--resolution",
        "8x6",
        "--spp",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("p.json: warning: the scene has no lights"),
        "{}",
        stderr(&o)
    );
    let image = read_exr(&out).unwrap();
    assert!(image.pixels().iter().all(|p| p.iter().all(|&c| c == 0.0)));
}

#[test]
fn explain_prints_the_plan_and_renders_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.json");
    std::fs::write(
        &scene,
        r#"{"integrator": {"type": "path", "max_depth": 2},
            "shapes": [{"type": "sphere"}],
            "lights": [{"type": "point", "position_m": [0, 3, 0]}]}"#,
    )
    .unwrap();
    let out = dir.path().join("x.exr");
    let o = prism(&["render", s(&scene), "-o", s(&out), "--explain"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for needle in [
        "dispersion",
        "multiple importance sampling",
        "all lights are delta lights",
        "Russian roulette",
        "spectral output bins",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in:\n{text}");
    }
    assert!(!out.exists(), "--explain must not render");
}

/// A lit fog scene in `dir` (a floor, a point light), with `integrator` (a JSON member line
/// ending in a comma, or nothing for the default path tracer).
fn fog_scene(dir: &Path, integrator: &str) -> PathBuf {
    let scene = dir.join("fog.json");
    std::fs::write(
        &scene,
        format!(
            r#"{{"world_medium": "fog",
            "media": {{"fog": {{"sigma_a_per_m": 0.05, "sigma_s_per_m": {{"rgb": [0.2, 0.3, 0.5]}},
                              "phase": {{"type": "hg", "g": 0.5}}}}}},
            {integrator}
            "camera": {{"transform": {{"look_at": {{"eye": [0, 1, 4], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
            "shapes": [{{"type": "rectangle", "size_m": [10, 10],
                        "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
            "lights": [{{"type": "point", "position_m": [0, 2, 0], "power_lm": 1000}}]}}"#
        ),
    )
    .unwrap();
    scene
}

/// `--explain` of `scene` succeeds and prints every one of `needles`.
fn assert_explains(scene: &Path, out: &Path, needles: &[&str]) {
    let o = prism(&["render", s(scene), "-o", s(out), "--explain"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for needle in needles {
        assert!(text.contains(needle), "missing `{needle}` in:\n{text}");
    }
}

/// `scene` renders at 16×12, 4 spp, into `out`: finite everywhere and lit somewhere.
fn assert_renders_lit(scene: &Path, out: &Path) {
    let o = prism(&[
        "render",
        s(scene),
        "-o",
        s(out),
        "--resolution",
        "16x12",
        "--spp",
        "4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = read_exr(out).unwrap();
    assert!(
        image
            .pixels()
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
            && image.pixels().iter().any(|p| p[1] > 0.0),
        "a lit fog scene rendered black or non-finite"
    );
}

/// A scene with fog: `--explain` lists the medium and why the packet tracer is off, and
/// the render goes through the scalar tracer and comes out non-black.
#[test]
fn a_scene_with_media_is_explained_and_rendered_by_the_scalar_tracer() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fog_scene(dir.path(), "");
    let out = dir.path().join("fog.exr");
    assert_explains(
        &scene,
        &out,
        &[
            "medium",
            "`fog`: homogeneous, σt ",
            "chromatic σt",
            "not used: the scene has participating media (fog): the packet tracer samples no media",
        ],
    );
    assert_renders_lit(&scene, &out);
}

/// The same fog scene with `photon_progressive`: `--explain` names its settings (photons per
/// pass, radius, α, the storage estimate and limit), it renders a lit, finite image, and a
/// sample range that starts after 0 replays the passes before (its per-pixel radii need
/// them) and says so.
#[test]
fn a_photon_integrator_is_explained_and_renders() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fog_scene(
        dir.path(),
        r#""integrator": {"type": "photon_progressive", "photons_per_pass": 5000, "alpha": 0.7},"#,
    );
    let out = dir.path().join("fog.exr");
    assert_explains(
        &scene,
        &out,
        &[
            "photon_progressive, max_depth 8: 5000 photons per pass",
            "initial radius ",
            "α 0.700",
            "photon storage ≤ ",
            "limit",
        ],
    );
    assert_renders_lit(&scene, &out);
    // Its per-pixel statistics come from the passes before: a range after sample 0
    // replays them (and says what that costs); one from 0 has nothing to replay.
    let part = dir.path().join("part.exr");
    let range = |samples: &str| {
        prism(&[
            "render",
            s(&scene),
            "-o",
            s(&part),
            "--resolution",
            "16x12",
            "--spp",
            "4",
            "--samples",
            samples,
        ])
    };
    let o = range("2..4");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("replays the per-pixel statistics of passes 0..2")
            && stderr(&o).contains("(10000 photons)"),
        "{}",
        stderr(&o)
    );
    let o = range("0..2");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("replays"), "{}", stderr(&o));
}

/// A ball of glowing gas inside an `interface` sphere beside the point light, with
/// `photon_progressive`: `--explain` says where photons start (the lights and the medium, by
/// power, plus the per-pixel statistics in the memory line), and it renders lit and finite.
#[test]
fn photons_from_an_emissive_medium_are_explained_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("glow.json");
    std::fs::write(
        &scene,
        r#"{"media": {"glow": {"sigma_a_per_m": 2, "sigma_s_per_m": 1, "emission": 50}},
            "integrator": {"type": "photon_progressive", "photons_per_pass": 5000},
            "materials": {"boundary": {"type": "interface"}},
            "camera": {"transform": {"look_at": {"eye": [0, 1, 4], "target": [0, 0, 0], "up": [0, 1, 0]}}},
            "shapes": [{"type": "rectangle", "size_m": [10, 10],
                        "transform": {"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}},
                       {"type": "sphere", "radius_m": 0.5, "material": "boundary",
                        "interior_medium": "glow", "transform": {"translate": [0, 0.6, 0]}}],
            "lights": [{"type": "point", "position_m": [0, 2, 0], "power_lm": 1000}]}"#,
    )
    .unwrap();
    let out = dir.path().join("glow.exr");
    assert_explains(
        &scene,
        &out,
        &[
            "MiB of per-pixel statistics",
            "photons from the lights ",
            "medium 'glow' ",
            "(by power)",
        ],
    );
    assert_renders_lit(&scene, &out);
}

/// The `simd: <isa> (<why>)` line of `render --explain` with `PRISM_SIMD` set to `env`.
fn explain_simd_line(env: Option<&str>, extra: &[&str]) -> String {
    let mut args = vec!["render", "scenes/cornell-box.json", "--explain"];
    args.extend_from_slice(extra);
    let o = prism_simd(env, &args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("simd: ")).collect();
    assert_eq!(lines.len(), 1, "one simd line in:\n{text}");
    lines[0].to_string()
}

#[test]
fn simd_limit_from_the_environment_or_the_flag_is_explained_and_in_the_stats() {
    use prism_cpu::Isa;
    // Without a limit: the widest ISA this CPU runs, and why.
    let best = Isa::detected();
    let line = explain_simd_line(None, &[]);
    assert!(line.starts_with(&format!("simd: {best} (")), "{line}");
    assert_eq!(
        explain_simd_line(Some("scalar"), &[]),
        "simd: scalar (PRISM_SIMD=scalar)"
    );
    assert_eq!(
        explain_simd_line(None, &["--simd", "scalar"]),
        "simd: scalar (--simd scalar)"
    );
    assert_eq!(
        explain_simd_line(Some("avx512"), &["--simd", "scalar"]),
        "simd: scalar (--simd scalar; PRISM_SIMD=avx512 overridden)"
    );
    // Asking for more than the CPU has falls back to what it has and says what it lacks.
    let line = explain_simd_line(None, &["--simd", "avx512"]);
    match Isa::Avx512.missing() {
        None => assert_eq!(line, "simd: avx512 (--simd avx512)"),
        Some(lacks) => assert_eq!(
            line,
            format!("simd: {best} (--simd avx512; the CPU lacks {lacks})")
        ),
    }

    let dir = tempfile::tempdir().unwrap();
    for (env, flag, want) in [
        (None, None, best.name()),
        (Some("scalar"), None, "scalar"),
        (None, Some("scalar"), "scalar"),
    ] {
        let (out, stats) = (dir.path().join("c.exr"), dir.path().join("stats.json"));
        let mut args = vec![
            "render",
            "scenes/cornell-box.json",
            "-o",
            s(&out),
            "--resolution",
            "16x16",
            "--spp",
            "1",
            "--stats-json",
            s(&stats),
        ];
        args.extend(flag.iter().flat_map(|f| ["--simd", f]));
        let o = prism_simd(env, &args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert_eq!(v["simd"], want, "PRISM_SIMD={env:?} --simd {flag:?}");
    }
}

#[test]
fn an_invalid_simd_limit_is_an_error_naming_the_valid_values() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    let (out, exr) = (s(&out), "missing.exr");
    // Every subcommand that runs fast paths checks PRISM_SIMD before any work.
    for args in [
        vec!["render", "scenes/cornell-box.json", "-o", out],
        vec!["converge", "scenes/cornell-box.json", "--max-spp", "1"],
        vec!["tonemap", exr, "-o", out, "--op", "linear"],
        vec!["compare", exr, exr],
    ] {
        let o = prism_simd(Some("avx3"), &args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = stderr(&o);
        assert!(
            err.contains("PRISM_SIMD=avx3: expected scalar, avx2 or avx512"),
            "{args:?}: {err}"
        );
        let mut flagged = args.clone();
        flagged.extend(["--simd", "sse4"]);
        let o = prism_simd(None, &flagged);
        assert!(!o.status.success(), "{flagged:?} should fail");
        let err = stderr(&o);
        assert!(
            err.contains("sse4") && err.contains("expected scalar, avx2 or avx512"),
            "{flagged:?}: {err}"
        );
    }
    // The flag is for tests and comparisons: hidden from --help.
    let o = prism(&["render", "--help"]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stdout).contains("--simd"));
}
