//! End-to-end check of `prism merl-export`: a material of a scene file becomes a MERL file
//! of the right size that a `merl` material renders; a wrong material name or an
//! unwritable output is a clear error.

mod support;
use support::{prism, s};

#[test]
fn merl_export_writes_a_table_that_renders() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("grey-ggx.binary");
    let o = prism(&[
        "merl-export",
        "scenes/merl/sources.json",
        "--material",
        "grey-ggx",
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(bytes.len(), 12 + 3 * 90 * 90 * 180 * 8);
    assert_eq!(&bytes[..12], &[90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0]);

    let scene = dir.path().join("scene.json");
    std::fs::write(
        &scene,
        r#"{"camera": {"type": "pinhole", "fov_deg": 40},
            "materials": {"m": {"type": "merl", "file": "grey-ggx.binary"}},
            "shapes": [{"type": "sphere", "radius_m": 1, "material": "m", "transform": {"translate": [0, 0, -4]}}],
            "lights": [{"type": "sky", "spectrum": 1.0}]}"#,
    )
    .unwrap();
    let image = dir.path().join("m.exr");
    let o = prism(&[
        "render",
        s(&scene),
        "-o",
        s(&image),
        "--resolution",
        "16x12",
        "--spp",
        "2",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The sphere in the middle of the frame reflects the sky: the table is not black.
    let image = prism_image::io::exr::read_exr(&image).unwrap();
    assert_eq!((image.width(), image.height()), (16, 12));
    assert!(image
        .pixels()
        .iter()
        .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
    let centre = image.pixel(8, 6);
    assert!(centre.iter().all(|&c| c > 0.0), "{centre:?}");

    let o = prism(&[
        "merl-export",
        "scenes/merl/sources.json",
        "--material",
        "nope",
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no material `nope`") && err.contains("`grey-ggx`"),
        "{err}"
    );
    let bad = dir.path().join("missing-dir").join("x.binary");
    let o = prism(&[
        "merl-export",
        "scenes/merl/sources.json",
        "--material",
        "grey-ggx",
        "-o",
        s(&bad),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("x.binary"), "{err}");
    assert!(!bad.exists());
}
