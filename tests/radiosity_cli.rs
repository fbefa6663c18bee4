//! `prism render` with the `radiosity` integrator: the solution saved, exported as PLY and
//! loaded again for another render, and the errors of misused solution files.

mod support;
use support::prism_in as prism;

/// A closed 2 m room (six inward rectangles) with a ceiling lamp and a point light.
fn room(reflectance: f64) -> String {
    let faces = [
        (
            "floor",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [0, -1, 0]}]"#,
        ),
        (
            "ceiling",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 1, 0]}]"#,
        ),
        ("back", r#"[{"translate": [0, 0, -1]}]"#),
        (
            "front",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 180}}, {"translate": [0, 0, 1]}]"#,
        ),
        (
            "left",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}, {"translate": [-1, 0, 0]}]"#,
        ),
        (
            "right",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": -90}}, {"translate": [1, 0, 0]}]"#,
        ),
    ];
    let mut shapes: Vec<String> = faces
        .iter()
        .map(|(n, t)| {
            format!(r#"{{"type": "rectangle", "name": "{n}", "size_m": [2, 2], "material": "wall", "transform": {t}}}"#)
        })
        .collect();
    shapes.push(
        r#"{"type": "rectangle", "name": "lamp", "size_m": [0.4, 0.4], "material": "wall", "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 0.99, 0]}]}"#
            .into(),
    );
    format!(
        r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 70, "transform": {{"look_at": {{"eye": [0, 0, 0.9], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [12, 12], "spp": 2}},
  "integrator": {{"type": "radiosity"}},
  "materials": {{"wall": {{"type": "lambert", "reflectance": {reflectance}}}}},
  "shapes": [{}],
  "lights": [{{"type": "area", "shape": "lamp", "luminance_cd_m2": 1000}},
             {{"type": "point", "position_m": [0.5, 0.5, 0.5], "intensity_cd": 20}}],
  "sensors": [{{"type": "grid", "name": "floor", "origin_m": [-0.9, -0.99, -0.9], "u_m": [1.8, 0, 0], "v_m": [0, 0, 1.8], "resolution": [3, 3], "samples": 256}}]
}}"#,
        shapes.join(", ")
    )
}

#[test]
fn a_saved_solution_renders_the_same_image_and_exports_a_ply() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("room.json"), room(0.6)).unwrap();
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
    std::fs::write(dir.path().join("room.json"), room(0.6)).unwrap();
    std::fs::write(dir.path().join("darker.json"), room(0.3)).unwrap();
    std::fs::write(
        dir.path().join("path.json"),
        room(0.6).replace(r#""type": "radiosity""#, r#""type": "path""#),
    )
    .unwrap();
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
