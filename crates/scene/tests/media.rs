//! The media section (issue 20): every form the format documents, and every bad input
//! refused with the JSON path.

mod common;

use common::Dir;
use prism_scene::*;

#[test]
fn every_medium_form_parses() {
    let dir = Dir::new("media-forms");
    dir.write("phase.csv", "cos_theta,value\n-1,1\n0,2\n1,5\n");
    // A 1×1×1 .vol (header, 1 voxel); the reader in render checks it, this only needs a file.
    dir.write("smoke.vol", "VOL");
    let s = dir
        .load(
            r#"{
  "world_medium": "fog",
  "media": {
    "fog": {"type": "homogeneous", "sigma_a_per_m": 0.01, "sigma_s_per_m": {"rgb": [0.2, 0.2, 0.25]},
            "phase": {"type": "hg", "g": 0.3}},
    "air": {"sigma_s_per_m": 2, "phase": "rayleigh"},
    "old": {"g": -0.5},
    "iso": {"phase": {"type": "isotropic"}},
    "table": {"phase": {"type": "tabulated", "file": "phase.csv"}, "emission": 3},
    "smoke": {"type": "grid", "density": "smoke.vol", "bounds_m": [[-1, 0, -1], [1, 2, 1]],
              "sigma_a_per_m": 0.5, "sigma_s_per_m": 8}
  },
  "materials": {"boundary": {"type": "interface"}},
  "camera": {"medium": "air"},
  "shapes": [{"type": "sphere", "material": "boundary", "interior_medium": "smoke"}],
  "lights": [{"type": "point", "medium": "iso"}, {"type": "point"}]
}"#,
        )
        .unwrap();
    let phase = |i: usize| s.media[i].phase.clone();
    assert_eq!(phase(0), Phase::HenyeyGreenstein { g: 0.3 });
    assert_eq!(phase(1), Phase::Rayleigh);
    assert_eq!(phase(2), Phase::HenyeyGreenstein { g: -0.5 });
    assert_eq!(phase(3), Phase::Isotropic);
    match phase(4) {
        Phase::Tabulated {
            cos_theta, values, ..
        } => {
            assert_eq!(cos_theta, vec![-1.0, 0.0, 1.0]);
            assert_eq!(values, vec![1.0, 2.0, 5.0]);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.media[4].emission, Some(SpectrumRef::Constant(3.0)));
    assert_eq!(s.media[1].sigma_a_per_m, SpectrumRef::Constant(0.0));
    match &s.media[5].kind {
        MediumKind::Grid { density, bounds_m } => {
            assert!(density.ends_with("smoke.vol"));
            assert_eq!(*bounds_m, Some([[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]]));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.world_medium, Some(0));
    assert_eq!(s.camera_medium, Some(1));
    assert_eq!(s.light_media, vec![Some(3), Some(0)]);
    // The unnamed exterior of a shape with an interior is the world medium.
    assert_eq!(
        (s.shapes[0].interior_medium, s.shapes[0].exterior_medium),
        (Some(5), Some(0))
    );
    assert_eq!(s.materials[0].kind, MaterialKind::Interface);
}

#[test]
fn without_world_medium_the_camera_and_lights_are_in_vacuum() {
    let dir = Dir::new("media-vacuum");
    let s = dir
        .load(r#"{"media": {"fog": {}}, "lights": [{"type": "point"}]}"#)
        .unwrap();
    assert_eq!((s.world_medium, s.camera_medium), (None, None));
    assert_eq!(s.light_media, vec![None]);
}

#[test]
fn bad_media_are_refused_at_their_json_path() {
    let dir = Dir::new("media-errors");
    dir.write("flat.csv", "0,1\n1,1\n");
    dir.write("down.csv", "-1,1\n0.5,1\n0.2,1\n1,1\n");
    dir.write("neg.csv", "-1,1\n1,-2\n");
    dir.write("zero.csv", "-1,0\n1,0\n");
    dir.write("smoke.vol", "VOL");
    let cases: &[(&str, &str)] = &[
        (
            r#"{"media": {"fog": {"g": 0.3, "phase": "rayleigh"}}}"#,
            "media.fog.phase: give only one of `g`, `phase`, found both `g` and `phase`",
        ),
        (
            r#"{"media": {"fog": {"phase": "mie"}}}"#,
            "media.fog.phase: unknown phase function type `mie`",
        ),
        (
            r#"{"media": {"fog": {"phase": {"type": "hg"}}}}"#,
            "media.fog.phase: missing field `g`",
        ),
        (
            r#"{"media": {"fog": {"phase": {"type": "hg", "g": 1}}}}"#,
            "media.fog.phase.g: expected a Henyey–Greenstein g in (-1, 1), found 1",
        ),
        (
            r#"{"media": {"fog": {"type": "cloud"}}}"#,
            "media.fog.type: unknown medium type `cloud`",
        ),
        (
            r#"{"media": {"fog": {"sigma_s_per_m": -1}}}"#,
            "media.fog.sigma_s_per_m: expected a value ≥ 0, found -1",
        ),
        (
            r#"{"media": {"s": {"type": "grid"}}}"#,
            "media.s: missing field `density`",
        ),
        (
            r#"{"media": {"s": {"type": "grid", "density": "smoke.vol", "bounds_m": [[0, 0, 0], [1, 0, 1]]}}}"#,
            "media.s.bounds_m: empty box",
        ),
        (
            r#"{"media": {"s": {"type": "grid", "density": "none.vol"}}}"#,
            "media.s.density: density grid file `none.vol` not found",
        ),
        (
            r#"{"media": {"t": {"phase": {"type": "tabulated", "file": "flat.csv"}}}}"#,
            "media.t.phase.file: DIR/flat.csv: the table must run from cos θ = -1 to 1",
        ),
        (
            r#"{"media": {"t": {"phase": {"type": "tabulated", "file": "down.csv"}}}}"#,
            "media.t.phase.file: DIR/down.csv:3: cos θ must increase",
        ),
        (
            r#"{"media": {"t": {"phase": {"type": "tabulated", "file": "neg.csv"}}}}"#,
            "media.t.phase.file: DIR/neg.csv:2: expected cos θ in [-1, 1] and a value ≥ 0",
        ),
        (
            r#"{"media": {"t": {"phase": {"type": "tabulated", "file": "zero.csv"}}}}"#,
            "media.t.phase.file: DIR/zero.csv: every value is 0",
        ),
        (
            r#"{"media": {"fog": {}}, "world_medium": "smog"}"#,
            "world_medium: unknown medium `smog` (defined: `fog`)",
        ),
        (
            r#"{"media": {"fog": {}}, "camera": {"medium": "smog"}}"#,
            "camera.medium: unknown medium `smog` (defined: `fog`)",
        ),
        (
            r#"{"media": {"fog": {}}, "lights": [{"type": "point", "medium": "smog"}]}"#,
            "lights[0].medium: unknown medium `smog` (defined: `fog`)",
        ),
        (
            r#"{"media": {"fog": {}}, "shapes": [{"type": "sphere", "interior_medium": "smog"}]}"#,
            "shapes[0].interior_medium: unknown medium `smog` (defined: `fog`)",
        ),
        (
            r#"{"media": {"fog": {}}, "shapes": [{"type": "rectangle", "interior_medium": "fog"}]}"#,
            "shapes[0].interior_medium: a rectangle or disk is open",
        ),
        (
            r#"{"media": {"fog": {}}, "shapes": [{"type": "disk", "interior_medium": "fog"}]}"#,
            "shapes[0].interior_medium: a rectangle or disk is open",
        ),
        (
            r#"{"materials": {"b": {"type": "interface", "reflectance": 1}}}"#,
            "materials.b.reflectance: unknown field `reflectance`, expected one of `type`",
        ),
    ];
    let mut failures = Vec::new();
    for (scene, expected) in cases {
        let e = dir.error(scene);
        // Drop "DIR/scene.json:line:col: ".
        let message = e.split_once(": ").map_or(e.as_str(), |(_, m)| m);
        if !message.starts_with(expected) {
            failures.push(format!(
                "{scene}\n  got:      {message}\n  expected: {expected}…"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `fluorescence` (issue 21): the dye model with an absorption coefficient; the peak is the
/// largest value on the 5 nm excitation grid, and the stored dye has peak absorptance 1.
#[test]
fn a_fluorescent_medium_parses_its_dye() {
    let dir = Dir::new("media-fluorescence");
    dir.write(
        "abs.csv",
        "wavelength_nm,sigma\n380,0\n400,2\n420,6\n440,1\n460,0\n",
    );
    dir.write(
        "em.csv",
        "wavelength_nm,energy\n480,0\n520,1\n560,0.5\n600,0\n",
    );
    let s = dir
        .load(
            r#"{"media": {"ink": {"type": "homogeneous", "sigma_s_per_m": 5,
                "fluorescence": {"absorption_per_m": "abs.csv", "emission": "em.csv",
                                 "quantum_yield": 0.9}}}}"#,
        )
        .unwrap();
    let f = s.media[0].fluorescence.as_ref().unwrap();
    assert_eq!(f.peak_absorption_per_m, 6.0);
    assert_eq!(f.units, prism_spectrum::EmissionUnits::Energy);
    assert_eq!(f.quantum_yield, 0.9);
    assert!((f.dye.absorptance(420.0) - 1.0).abs() < 1e-12);
    assert!((f.dye.absorptance(400.0) - 2.0 / 6.0).abs() < 1e-12);
}
