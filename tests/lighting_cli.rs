//! `prism render` with sensors and luminaires: the readings files beside the image, the
//! false-colour PNGs, and the errors a user sees for a broken photometric file.

mod support;
use support::{png_size, prism_in as prism};

const IES: &str = "IESNA:LM-63-2002\n[TEST] cli\n[MANUFAC] prism\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n600 500 0\n";

#[test]
fn render_writes_sensor_readings_and_false_colour_beside_the_image() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.ies"), IES).unwrap();
    std::fs::write(
        dir.path().join("room.json"),
        r#"{"lights": [{"type": "luminaire", "file": "lamp.ies", "position_m": [0, 2, 0]}],
            "film": {"resolution": [16, 12], "spp": 2},
            "sensors": [{"type": "point", "name": "below", "position_m": [0, 0, 0], "samples": 512},
                        {"type": "grid", "name": "floor plane", "origin_m": [-1, 0, -1], "u_m": [2, 0, 0],
                         "v_m": [0, 0, 2], "resolution": [4, 4], "samples": 64}]}"#,
    )
    .unwrap();
    let o = prism(
        dir.path(),
        &[
            "render",
            "room.json",
            "-o",
            "out.exr",
            "--false-colour",
            "illuminance",
            "--false-colour-scale",
            "log",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out.sensors.json")).unwrap(),
    )
    .unwrap();
    let p = &doc["sensors"][0]["points"][0];
    // 600 cd straight down at 2 m: 150 lx (only the wavelengths are random).
    let e = p["illuminance_lx"].as_f64().unwrap();
    let se = p["std_error_lx"].as_f64().unwrap();
    assert!((e - 150.0).abs() <= 5.0 * se + 1e-6, "{e} ± {se}");
    assert_eq!(
        doc["sensors"][1]["grid_resolution"],
        serde_json::json!([4, 4])
    );
    let csv = std::fs::read_to_string(dir.path().join("out.sensors.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 1 + 16);
    // The 4 × 4 grid at 400 / 4 = 100 px a cell, with the legend beside it.
    let (w, h) = png_size(&dir.path().join("out.floor_plane.falsecolour.png"));
    assert!(h == 400 && w > 400, "{w}×{h}");
    let image = prism_image::io::exr::read_exr(&dir.path().join("out.exr")).unwrap();
    assert_eq!((image.width(), image.height()), (16, 12));
}

#[test]
fn broken_photometric_files_and_flags_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.ies"),
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 10\n0 90 45\n0\n1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("s.json"),
        r#"{"lights": [{"type": "luminaire", "file": "bad.ies"}]}"#,
    )
    .unwrap();
    let o = prism(dir.path(), &["render", "s.json", "-o", "o.exr"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("lights[0].file: cannot use the photometric file:")
            && err.contains(
                "bad.ies:5: vertical angles must increase, but angle 3 (45°) follows 90°"
            ),
        "{err}"
    );
    std::fs::write(
        dir.path().join("t.json"),
        r#"{"lights": [{"type": "point"}]}"#,
    )
    .unwrap();
    let o = prism(
        dir.path(),
        &[
            "render",
            "t.json",
            "-o",
            "o.exr",
            "--false-colour",
            "illuminance",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--false-colour illuminance: t.json has no `grid` sensor"),
        "{err}"
    );
    assert!(
        !dir.path().join("o.exr").exists(),
        "nothing written before the error"
    );
    let o = prism(dir.path(), &["render", "t.json", "--sensors-only"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--sensors-only: t.json has no `sensors`"));
}
