//! `prism render` with the `radiosity` integrator on the Cornell box: the solution saved,
//! exported as PLY and loaded again for another render, carried in the render's spectral
//! bins, and the errors of misused solution files.

mod support;
use support::prism_in as prism;

/// scenes/radiosity/cornell-box.json with its walls' reflectance scaled by `scale` (1: the
/// scene itself), written into `dir` with the light's spectrum file given absolutely.
fn cornell(dir: &std::path::Path, name: &str, scale: f64) {
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(scenes.join("radiosity/cornell-box.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["lights"][0]["spectrum"] = serde_json::Value::String(
        scenes
            .join("cornell-box/light-radiance.csv")
            .display()
            .to_string(),
    );
    for m in json["materials"].as_object_mut().unwrap().values_mut() {
        let rgb = m["reflectance"]["rgb"].as_array_mut().unwrap();
        for c in rgb.iter_mut() {
            *c = serde_json::json!(c.as_f64().unwrap() * scale);
        }
    }
    json["film"]["resolution"] = serde_json::json!([12, 12]);
    json["film"]["spp"] = serde_json::json!(2);
    std::fs::write(dir.join(name), json.to_string()).unwrap();
}

#[test]
fn a_saved_solution_renders_the_same_image_and_exports_a_ply() {
    let dir = tempfile::tempdir().unwrap();
    cornell(dir.path(), "room.json", 1.0);
    let o = prism(
        dir.path(),
        &[
            "render",
            "room.json",
            "-o",
            "a.exr",
            "--save-solution",
            "room.rad",
            "--export-solution",
            "room.ply",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("radiosity: iteration 3:"), "{err}");
    let o = prism(
        dir.path(),
        &[
            "render",
            "room.json",
            "-o",
            "b.exr",
            "--load-solution",
            "room.rad",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        !err.contains("radiosity: iteration"),
        "a loaded solution is not solved: {err}"
    );
    let a = prism_image::io::exr::read_exr(&dir.path().join("a.exr")).unwrap();
    let b = prism_image::io::exr::read_exr(&dir.path().join("b.exr")).unwrap();
    assert_eq!(a.pixels(), b.pixels());
    // The PLY: a header naming its counts, then that many vertex lines with positive lux.
    let ply = std::fs::read_to_string(dir.path().join("room.ply")).unwrap();
    let count = |what: &str| -> usize {
        ply.lines()
            .find_map(|l| l.strip_prefix(&format!("element {what} ")))
            .and_then(|n| n.parse().ok())
            .unwrap()
    };
    let (vertices, faces) = (count("vertex"), count("face"));
    let body: Vec<&str> = ply.split("end_header\n").nth(1).unwrap().lines().collect();
    assert_eq!(body.len(), vertices + faces);
    assert!(faces >= 7, "{faces} faces");
    let lux: Vec<f64> = body[..vertices]
        .iter()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    assert!(lux.iter().all(|&e| e >= 0.0) && lux.iter().any(|&e| e > 0.0));
}

#[test]
fn misused_solution_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    cornell(dir.path(), "room.json", 1.0);
    cornell(dir.path(), "darker.json", 0.5);
    let room = std::fs::read_to_string(dir.path().join("room.json")).unwrap();
    let mut path: serde_json::Value = serde_json::from_str(&room).unwrap();
    path["integrator"] = serde_json::json!({"type": "path"});
    std::fs::write(dir.path().join("path.json"), path.to_string()).unwrap();
    let o = prism(
        dir.path(),
        &[
            "render",
            "room.json",
            "-o",
            "a.exr",
            "--save-solution",
            "room.rad",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let error = |args: &[&str]| {
        let o = prism(dir.path(), args);
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = error(&[
        "render",
        "darker.json",
        "-o",
        "b.exr",
        "--load-solution",
        "room.rad",
    ]);
    assert!(
        e.contains("room.rad: this solution was solved for another scene"),
        "{e}"
    );
    let e = error(&[
        "render",
        "path.json",
        "-o",
        "b.exr",
        "--save-solution",
        "x.rad",
    ]);
    assert!(
        e.contains("--save-solution") && e.contains("needs the `radiosity` integrator"),
        "{e}"
    );
    let bytes = std::fs::read(dir.path().join("room.rad")).unwrap();
    std::fs::write(dir.path().join("cut.rad"), &bytes[..bytes.len() / 2]).unwrap();
    let e = error(&[
        "render",
        "room.json",
        "-o",
        "b.exr",
        "--load-solution",
        "cut.rad",
    ]);
    assert!(e.contains("cut.rad:"), "{e}");
    std::fs::write(dir.path().join("junk.rad"), b"not a solution").unwrap();
    let e = error(&[
        "render",
        "room.json",
        "-o",
        "b.exr",
        "--load-solution",
        "junk.rad",
    ]);
    assert!(e.contains("not a Prism radiosity solution"), "{e}");
    assert!(!dir.path().join("b.exr").exists());
}

/// With `--spectral-bins N` the solution is carried in the N bins (here 47 of 10 nm over
/// 360–830 nm) instead of 16 bands of 25 nm: the same lux within 4 s.e., and a solution saved
/// in one set of bands is refused by a render in the other.
#[test]
fn a_solution_is_carried_in_the_renders_spectral_bins() {
    let dir = tempfile::tempdir().unwrap();
    cornell(dir.path(), "room.json", 1.0);
    let text = std::fs::read_to_string(dir.path().join("room.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["sensors"] = serde_json::json!([{"type": "points", "name": "floor", "samples": 4096,
        "positions_m": [[0.0, -0.999, 0.85], [-0.6, -0.999, 0.5], [0.7, -0.999, -0.6]],
        "normal": [0, 1, 0]}]);
    std::fs::write(dir.path().join("room.json"), json.to_string()).unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec!["render", "room.json", "-o", out];
        args.extend_from_slice(extra);
        let o = prism(dir.path(), &args);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{err}");
        err
    };
    let err = render("a.exr", &[]);
    assert!(err.contains("(16 bands of 25.000 nm from 380 nm)"), "{err}");
    let err = render(
        "b.exr",
        &["--spectral-bins", "47", "--save-solution", "fine.rad"],
    );
    assert!(err.contains("(47 bands of 10.000 nm from 360 nm)"), "{err}");
    // (lux, its standard error) per point.
    let lux = |name: &str| -> Vec<(f64, f64)> {
        let text = std::fs::read_to_string(dir.path().join(name)).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["sensors"][0]["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let value = |key: &str| p[key].as_f64().unwrap();
                (value("illuminance_lx"), value("std_error_lx"))
            })
            .collect()
    };
    let (coarse, fine) = (lux("a.sensors.json"), lux("b.sensors.json"));
    assert_eq!(coarse.len(), 3);
    // Within 4 combined standard errors (measured: 0.15 % at most, s.e. 0.1–0.25 %).
    for (&(c, c_se), &(f, f_se)) in coarse.iter().zip(&fine) {
        let se = (c_se * c_se + f_se * f_se).sqrt();
        assert!((f - c).abs() < 4.0 * se, "{coarse:?} {fine:?}");
    }
    let o = prism(
        dir.path(),
        &[
            "render",
            "room.json",
            "-o",
            "c.exr",
            "--load-solution",
            "fine.rad",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains("this solution is in 47 wavelength bands, the render asks for 16"),
        "{err}"
    );
}
