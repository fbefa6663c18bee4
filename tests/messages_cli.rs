//! Refused input in the project's words (docs/reliability.md): file, place and expectation,
//! status 1, no Rust internals; outputs and options checked before the work; symbolic-link
//! outputs written through; metrics that are never NaN.

mod support;

use std::path::{Path, PathBuf};

use support::{prism, s, stderr};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn sphere_scene(dir: &Path, name: &str) -> PathBuf {
    write(
        dir,
        name,
        br#"{"integrator": "normal", "film": {"resolution": [8, 8], "spp": 1},
            "shapes": [{"type": "sphere", "transform": {"translate": [0, 0, -3]}}]}"#,
    )
}

/// Runs prism, expects status 1 and returns standard error, checked for leaked internals.
fn refused(args: &[&str]) -> String {
    let o = prism(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    for internal in ["{ ", "Vec3A", "ParseError", "LineCol", "Custom", "panicked"] {
        assert!(
            !err.contains(internal),
            "{args:?} leaks `{internal}`: {err}"
        );
    }
    err
}

#[test]
fn text_files_are_read_in_the_project_s_words() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.exr");
    // A byte-order mark is skipped, not "expected value".
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend(std::fs::read(sphere_scene(dir.path(), "plain.json")).unwrap());
    let bom = write(dir.path(), "bom.json", &bom);
    let o = prism(&["render", s(&bom), "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Latin-1 bytes are located.
    let latin1 = write(dir.path(), "latin1.json", b"{\"integrator\": \"caf\xe9\"}");
    let err = refused(&["render", s(&latin1), "-o", s(&out)]);
    assert!(
        err.contains("latin1.json") && err.contains("byte 19 (line 1, column 20)"),
        "{err}"
    );
    // A mesh path that is a folder, and mesh files without faces.
    std::fs::create_dir(dir.path().join("folder.obj")).unwrap();
    write(dir.path(), "empty.obj", b"");
    write(dir.path(), "notes.obj", b"shopping list\nmilk\n");
    for (mesh, expected) in [
        ("folder.obj", "is a directory"),
        ("empty.obj", "no faces"),
        ("notes.obj", "no faces"),
    ] {
        let scene = format!(
            r#"{{"integrator": "normal", "film": {{"resolution": [8, 8]}},
                "shapes": [{{"type": "mesh", "file": "{mesh}"}}]}}"#
        );
        let scene = write(dir.path(), "mesh.json", scene.as_bytes());
        let err = refused(&["render", s(&scene), "-o", s(&out)]);
        assert!(err.contains(mesh) && err.contains(expected), "{err}");
    }
}

#[test]
fn outputs_and_options_are_checked_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_scene(dir.path(), "sphere.json");
    let out = dir.path().join("o.exr");
    let stats = dir.path().join("missing/stats.json");
    let err = refused(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--stats-json",
        s(&stats),
    ]);
    assert!(
        err.contains("--stats-json") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!out.exists(), "refused before the render");
    let err = refused(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--false-colour",
        "luminance",
        "--false-colour-scale",
        "log",
        "--false-colour-range",
        "0:100",
    ]);
    assert!(err.contains("minimum > 0"), "{err}");
    assert!(!out.exists(), "refused before the render");
    // compare's error map, before the metrics.
    let o = prism(&["render", s(&scene), "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let map = dir.path().join("missing/map.png");
    let err = refused(&["compare", s(&out), s(&out), "--error-map", s(&map)]);
    assert!(
        err.contains("--error-map") && err.contains("does not exist"),
        "{err}"
    );
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_output_is_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_scene(dir.path(), "sphere.json");
    std::fs::create_dir(dir.path().join("real")).unwrap();
    let link = dir.path().join("link.exr");
    std::os::unix::fs::symlink("real/image.exr", &link).unwrap();
    let o = prism(&["render", s(&scene), "-o", s(&link)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(dir.path().join("real/image.exr").is_file());
    // tonemap refuses to replace its input unless told to.
    let png = dir.path().join("real/image.png");
    let o = prism(&["tonemap", s(&link), "-o", s(&png), "--op", "linear"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = refused(&["tonemap", s(&png), "-o", s(&png), "--op", "linear"]);
    assert!(
        err.contains("it is the input file") && err.contains("--overwrite"),
        "{err}"
    );
    let exr = dir.path().join("real/image.exr");
    let err = refused(&["tonemap", s(&exr), "-o", s(&link), "--op", "linear"]);
    assert!(
        err.contains("it is the input file"),
        "through the link: {err}"
    );
    let o = prism(&[
        "tonemap",
        s(&exr),
        "-o",
        s(&exr),
        "--op",
        "linear",
        "--overwrite",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn equal_and_black_images_compare_without_nan() {
    let dir = tempfile::tempdir().unwrap();
    // A normal-integrator render of nothing: black.
    let scene = write(
        dir.path(),
        "black.json",
        br#"{"integrator": "normal", "film": {"resolution": [16, 16], "spp": 1}, "shapes": []}"#,
    );
    let black = dir.path().join("black.exr");
    let o = prism(&["render", s(&scene), "-o", s(&black)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = prism(&["compare", s(&black), s(&black)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!text.to_lowercase().contains("nan"), "{text}");
    assert!(
        text.contains("+∞") && text.contains("identical images"),
        "{text}"
    );
    let o = prism(&["compare", s(&black), s(&black), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["psnr_db"].is_null(), "{v}");
    assert_eq!(v["psnr_note"], "identical images: PSNR is +∞");
    assert_eq!(
        (v["mse"].as_f64(), v["relmse"].as_f64()),
        (Some(0.0), Some(0.0))
    );
}

#[test]
fn photometric_images_get_the_auto_exposure_unless_one_is_given() {
    let dir = tempfile::tempdir().unwrap();
    // A dim emitter: a render in cd/m² far below 1 (black under `linear` at 0 EV).
    let scene = write(
        dir.path(),
        "dim.json",
        br#"{"film": {"resolution": [16, 16], "spp": 4},
            "lights": [{"type": "point", "position_m": [0, 0, 0], "power_lm": 0.01}],
            "shapes": [{"type": "sphere", "transform": {"translate": [0, 0, -3]}}]}"#,
    );
    let exr = dir.path().join("dim.exr");
    let o = prism(&["render", s(&scene), "-o", s(&exr)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = |extra: &[&str]| -> serde_json::Value {
        let png = dir.path().join("dim.png");
        let mut args = vec![
            "tonemap",
            s(&exr),
            "-o",
            s(&png),
            "--op",
            "linear",
            "--json",
        ];
        args.extend(extra);
        let o = prism(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let auto = json(&[]);
    assert_eq!(auto["auto_exposure_photometric"], true, "{auto}");
    assert!(auto["exposure_ev"].as_f64().unwrap() > 1.0, "{auto}");
    let kept = json(&["--exposure", "0"]);
    assert_eq!(kept["auto_exposure_photometric"], false);
    assert_eq!(kept["exposure_ev"], 0.0);
    // The text report says so in one line.
    let png = dir.path().join("dim.png");
    let o = prism(&["tonemap", s(&exr), "-o", s(&png), "--op", "linear"]);
    let text = stderr(&o);
    assert!(o.stdout.is_empty(), "status lines go to standard error");
    assert_eq!(
        text.matches("the image is photometric").count(),
        1,
        "{text}"
    );
    // An exposure whose scale overflows says so, not that the input had NaN/∞.
    let err = refused(&[
        "tonemap",
        s(&exr),
        "-o",
        s(&png),
        "--op",
        "linear",
        "--exposure",
        "1e6",
    ]);
    assert!(err.contains("outside the range of 32-bit floats"), "{err}");
    let bright = write(
        dir.path(),
        "bright.json",
        br#"{"film": {"resolution": [16, 16], "spp": 4},
            "lights": [{"type": "point", "position_m": [0, 0, 0], "power_lm": 1e9}],
            "shapes": [{"type": "sphere", "transform": {"translate": [0, 0, -3]}}]}"#,
    );
    let exr = dir.path().join("bright.exr");
    let o = prism(&["render", s(&bright), "-o", s(&exr)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = prism(&[
        "tonemap",
        s(&exr),
        "-o",
        s(&png),
        "--op",
        "linear",
        "--exposure",
        "127",
    ]);
    let text = stderr(&o);
    assert!(
        text.contains("overflowed to ∞") && !text.contains("NaN/∞ components"),
        "{text}"
    );
}

#[test]
fn a_light_of_zero_power_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(
        dir.path(),
        "dark.json",
        br#"{"film": {"resolution": [8, 8], "spp": 1},
            "lights": [{"type": "point", "position_m": [0, 0, 0], "power_lm": 100},
                       {"type": "point", "position_m": [0, 1, 0], "power_lm": 0}],
            "shapes": [{"type": "sphere", "transform": {"translate": [0, 0, -3]}}]}"#,
    );
    let o = prism(&["render", s(&scene), "--explain"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("lights[1] has zero power"), "{err}");
    assert!(!err.contains("lights[0]"), "{err}");
}

/// `prism render --explain` of `scene` (written to `dir`): its standard error.
fn explain(dir: &Path, name: &str, scene: &str) -> String {
    let path = write(dir, name, scene.as_bytes());
    let o = prism(&["render", s(&path), "--explain"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    err
}

#[test]
fn a_camera_inside_a_closed_one_sided_shape_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    // The default camera sits at the origin, inside the dome; the lamp is inside too.
    let scene = |dome_material: &str| {
        format!(
            r#"{{"film": {{"resolution": [8, 8], "spp": 1}},
                "materials": {{"white": {{"type": "lambert", "reflectance": 0.8}},
                               "both": {{"type": "two_sided", "material": "white"}},
                               "glass": {{"type": "dielectric", "ior": 1.5}}}},
                "lights": [{{"type": "point", "position_m": [0, 0.5, 0], "power_lm": 100}}],
                "shapes": [{{"type": "sphere", "transform": {{"translate": [0, 0, -1]}},
                             "radius_m": 0.2}},
                           {{"name": "dome", "type": "sphere", "radius_m": 4,
                             "material": "{dome_material}"}}]}}"#
        )
    };
    let err = explain(dir.path(), "inside.json", &scene("white"));
    assert!(
        err.contains("inside.json: warning: the camera is inside shapes[1] (`dome`)")
            && err.contains("two_sided"),
        "{err}"
    );
    assert_eq!(err.matches("warning").count(), 1, "{err}");
    assert!(!err.contains("lights[0]"), "{err}");
    // Seen from inside, a two-sided or a transmissive dome is not black.
    for material in ["both", "glass"] {
        let err = explain(dir.path(), "fine.json", &scene(material));
        assert!(!err.contains("warning"), "{material}: {err}");
    }
}

#[test]
fn a_light_shut_inside_a_closed_opaque_shape_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    // The spot light sits inside a closed box in front of the camera (outside it).
    let scene = |box_material: &str| {
        format!(
            r#"{{"film": {{"resolution": [8, 8], "spp": 1}},
                "materials": {{"white": {{"type": "lambert", "reflectance": 0.8}},
                               "both": {{"type": "two_sided", "material": "white"}},
                               "glass": {{"type": "dielectric", "ior": 1.5}}}},
                "lights": [{{"type": "point", "position_m": [3, 3, 0], "power_lm": 100}},
                           {{"type": "point", "position_m": [0, 0.1, -5], "power_lm": 100}}],
                "shapes": [{{"name": "box", "type": "cuboid", "size_m": [1, 1, 1],
                             "material": "{box_material}",
                             "transform": {{"translate": [0, 0, -5]}}}}]}}"#
        )
    };
    for material in ["white", "both"] {
        let err = explain(dir.path(), "shut.json", &scene(material));
        assert!(
            err.contains("shut.json: warning: lights[1] is inside shapes[0] (`box`)"),
            "{material}: {err}"
        );
        assert!(
            !err.contains("lights[0]") && !err.contains("the camera is inside"),
            "{err}"
        );
    }
    let err = explain(dir.path(), "glass.json", &scene("glass"));
    assert!(!err.contains("warning"), "{err}");
}

/// An area light (a small glowing sphere, or a panel) inside a closed opaque box the camera
/// is outside of is warned about like a point light; in a glass box, or with the camera in
/// the box too, it is not.
#[test]
fn an_area_light_shut_inside_a_closed_opaque_shape_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |emitter: &str, box_material: &str, eye_z: f64| {
        format!(
            r#"{{"camera": {{"type": "pinhole", "fov_deg": 40,
                            "transform": {{"look_at": {{"eye": [0, 0, {eye_z}], "target": [0, 0, -5]}}}}}},
                "film": {{"resolution": [8, 8], "spp": 1}},
                "materials": {{"white": {{"type": "lambert", "reflectance": 0.8}},
                               "glass": {{"type": "dielectric", "ior": 1.5}}}},
                "lights": [{{"type": "area", "shape": "lamp", "luminance_cd_m2": 1000}}],
                "shapes": [{{"name": "box", "type": "cuboid", "size_m": [2, 2, 2],
                             "material": "{box_material}",
                             "transform": {{"translate": [0, 0, -5]}}}},
                           {emitter}]}}"#
        )
    };
    let sphere = r#"{"name": "lamp", "type": "sphere", "radius_m": 0.1, "material": "white",
                     "transform": {"translate": [0, 0, -5]}}"#;
    let panel = r#"{"name": "lamp", "type": "rectangle", "size_m": [0.5, 0.5], "material": "white",
                    "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}},
                                  {"translate": [0, 0.9, -5]}]}"#;
    for (what, emitter) in [("sphere", sphere), ("panel", panel)] {
        let err = explain(dir.path(), "shut.json", &scene(emitter, "white", 0.0));
        assert!(
            err.contains("shut.json: warning: lights[0] is inside shapes[0] (`box`)"),
            "{what}: {err}"
        );
        let err = explain(dir.path(), "glass.json", &scene(emitter, "glass", 0.0));
        assert!(!err.contains("warning"), "{what} in glass: {err}");
        // The camera inside the box sees the lamp: nothing to warn about.
        let err = explain(dir.path(), "inside.json", &scene(emitter, "white", -4.5));
        assert!(
            !err.contains("lights[0] is inside"),
            "{what}, camera inside: {err}"
        );
    }
}
