//! Every kind of bad input names the file, line:column, the JSON path and what was
//! expected, with the closest valid name for typos.

mod common;

use common::Dir;

#[test]
fn unknown_field_lists_the_expected_fields_and_suggests_the_closest() {
    let dir = Dir::new("unknown-field");
    let e = dir.error(
        r#"{
  "shapes": [
    {"type": "sphere", "radius": 2}
  ]
}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:3:24: shapes[0].radius: unknown field `radius`, expected one of \
         `type`, `name`, `transform`, `material`, `interior_medium`, `exterior_medium`, \
         `radius_m` (did you mean `radius_m`?)"
    );
}

#[test]
fn unknown_top_level_field() {
    let dir = Dir::new("unknown-top");
    let e = dir.error("{\"materails\": {}}");
    assert!(
        e.starts_with(
            "DIR/scene.json:1:2: materails: unknown field `materails`, expected one of `camera`"
        ),
        "{e}"
    );
    assert!(e.ends_with("(did you mean `materials`?)"), "{e}");
}

#[test]
fn wrong_type_says_what_was_expected_and_found() {
    let dir = Dir::new("wrong-type");
    let e = dir.error(
        r#"{
  "film": {"resolution": [640, "480"]}
}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:2:32: film.resolution[1]: expected a whole number ≥ 1, found the string \"480\""
    );
    let e = dir.error(r#"{"camera": {"type": "pinhole", "fov_deg": "wide"}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:43: camera.fov_deg: expected a number, found the string \"wide\""
    );
    let e = dir.error(r#"{"shapes": {"type": "sphere"}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:12: shapes: expected an array, found an object"
    );
}

#[test]
fn missing_asset_names_the_path_it_looked_for() {
    let dir = Dir::new("missing-asset");
    let e = dir.error(
        r#"{
  "shapes": [
    {"type": "sphere"},
    {"type": "mesh", "file": "meshes/bunny.obj"}
  ]
}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:4:30: shapes[1].file: mesh file `meshes/bunny.obj` not found \
         (looked for DIR/meshes/bunny.obj)"
    );
    let e = dir
        .error(r#"{"materials": {"red": {"type": "lambert", "reflectance": "spectra/red.csv"}}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:58: materials.red.reflectance: spectrum file `spectra/red.csv` not \
         found (looked for DIR/spectra/red.csv)"
    );
    let e = dir.error(r#"{"shapes": [{"type": "mesh", "file": "bunny.stl"}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:38: shapes[0].file: expected a mesh file ending in `.obj`, `.ply`, \
         found `bunny.stl`"
    );
}

#[test]
fn bad_spectrum_file_names_both_files_and_the_line() {
    let dir = Dir::new("bad-csv");
    dir.write("red.csv", "400,0.1\n390,0.2\n");
    let e = dir.error(r#"{"spectra": {"red": "red.csv"}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:21: spectra.red: cannot load spectrum: DIR/red.csv:2: wavelengths \
         must increase strictly: 390 nm follows 400 nm"
    );
}

#[test]
fn spectrum_files_that_would_render_wrong_are_refused() {
    let dir = Dir::new("wrong-csv");
    // A reflectance above 1 (a percentage), as a constant 1.5 already is.
    dir.write("percent.csv", "400,0.1\n500,85\n700,90\n");
    let e = dir.error(r#"{"materials": {"m": {"type": "lambert", "reflectance": "percent.csv"}}}"#);
    assert!(
        e.contains("DIR/percent.csv:2: a reflectance must be at most 1, found 85 at 500 nm"),
        "{e}"
    );
    // Emission may exceed 1.
    dir.write("bright.csv", "400,10\n700,90\n");
    let scene =
        r#"{"lights": [{"type": "point", "position_m": [0, 0, 0], "spectrum": "bright.csv"}]}"#;
    assert!(dir.load(scene).is_ok());
    // One row, or a table outside 360–830 nm: black without a word before.
    dir.write("one.csv", "550,0.5\n");
    let e = dir.error(r#"{"spectra": {"one": "one.csv"}}"#);
    assert!(
        e.contains("DIR/one.csv:1: 1 row: expected a table of at least two"),
        "{e}"
    );
    dir.write("micro.csv", "10,0.5\n20,0.6\n");
    let e = dir.error(r#"{"spectra": {"micro": "micro.csv"}}"#);
    assert!(
        e.contains("DIR/micro.csv:1: the table covers 10–20 nm, outside the 360–830 nm"),
        "{e}"
    );
}

#[test]
fn bad_values_are_refused_with_the_valid_range() {
    let dir = Dir::new("bad-values");
    let e = dir.error(r#"{"shapes": [{"type": "sphere", "radius_m": -1}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:44: shapes[0].radius_m: expected a positive number, found -1"
    );
    let e = dir
        .error(r#"{"camera": {"type": "fisheye", "projection": "orthographic", "fov_deg": 200}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:73: camera.fov_deg: expected a field of view in (0, 180] degrees \
         for the orthographic fisheye projection, found 200"
    );
    let e = dir
        .error(r#"{"camera": {"type": "fisheye", "projection": "stereographic", "fov_deg": 360}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:74: camera.fov_deg: expected a field of view in (0, 360) degrees \
         for the stereographic fisheye projection, found 360"
    );
    let e = dir.error(r#"{"camera": {"type": "fisheye", "fov_deg": 361}}"#);
    assert!(e.contains("(0, 360] degrees for the equidistant"), "{e}");
    let e = dir.error(r#"{"camera": {"fov_deg": 180}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:24: camera.fov_deg: expected a field of view in (0, 180) degrees \
         for a perspective camera, found 180"
    );
    let e = dir.error(
        r#"{"camera": {"type": "thin_lens", "f_number": 2, "aperture_radius_m": 0.01, "focus_distance_m": 1}}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:1:70: camera.aperture_radius_m: give only one of `f_number`, \
         `aperture_radius_m`, found both `f_number` and `aperture_radius_m`"
    );
    let e = dir.error(r#"{"camera": {"type": "thin_lens", "f_number": 2, "focus_distance_m": 0}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:69: camera.focus_distance_m: expected a positive number, found 0"
    );
    let e = dir.error(r#"{"camera": {"type": "thin_lens", "f_number": 2}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:12: camera: missing field `focus_distance_m`: expected the distance \
         in focus, in metres"
    );
    let e = dir.error(r#"{"materials": {"m": {"type": "lambert", "reflectance": 1.5}}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:56: materials.m.reflectance: expected a reflectance in [0, 1], found 1.5"
    );
    let e = dir.error(r#"{"media": {"fog": {"g": 1}}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:25: media.fog.g: expected a Henyey–Greenstein g in (-1, 1), found 1"
    );
    let e = dir.error(r#"{"film": {"spp": 0}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:18: film.spp: expected a whole number ≥ 1, found 0"
    );
    let e = dir.error(r#"{"shapes": [{"type": "cuboid", "transform": {"scale": 0}}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:55: shapes[0].transform.scale: expected non-zero scale factors, \
         found [0.0, 0.0, 0.0]"
    );
}

#[test]
fn nan_and_overflowing_numbers_are_json_errors_with_position() {
    let dir = Dir::new("nan");
    let e = dir.error("{\"shapes\": [{\"type\": \"sphere\",\n  \"radius_m\": NaN}]}");
    assert_eq!(e, "DIR/scene.json:2:15: invalid JSON: expected value");
    let e = dir.error("{\"film\": {\"spp\": 1e999}}");
    assert_eq!(e, "DIR/scene.json:1:22: invalid JSON: number out of range");
}

#[test]
fn malformed_json_reports_line_and_column() {
    let dir = Dir::new("malformed");
    let e = dir.error("{\n  \"film\": {\"spp\": 4\n  \"seed\": 1}\n}");
    assert_eq!(e, "DIR/scene.json:3:3: invalid JSON: expected `,` or `}`");
    let e = dir.error("{\"film\": {}");
    assert_eq!(
        e,
        "DIR/scene.json:1:11: invalid JSON: EOF while parsing an object"
    );
    let e = dir.error("{\"film\": {\"spp\": 4, \"spp\": 8}}");
    assert_eq!(
        e,
        "DIR/scene.json:1:21: invalid JSON: duplicate field `spp`"
    );
}

#[test]
fn unknown_material_suggests_the_closest_name() {
    let dir = Dir::new("unknown-material");
    let e = dir.error(
        r#"{
  "materials": {"white": "lambert", "red": {"type": "lambert", "reflectance": 0.2}},
  "shapes": [
    {"type": "sphere", "material": "white"},
    {"type": "cuboid",
     "material": "whte"}
  ]
}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:6:18: shapes[1].material: unknown material `whte` (defined: `white`, \
         `red`) (did you mean `white`?)"
    );
    let e = dir.error(r#"{"materials": {"a": {"type": "two_sided", "material": "b"}, "b": {"type": "mask", "material": "a"}}}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:21: materials.a: material `a` refers back to itself through `material`"
    );
}

#[test]
fn unknown_type_suggests_the_closest_type() {
    let dir = Dir::new("unknown-type");
    let e = dir.error(r#"{"shapes": [{"type": "sphere"}, {"type": "sphear"}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:42: shapes[1].type: unknown shape type `sphear`, expected one of \
         `mesh`, `sphere`, `rectangle`, `disk`, `cuboid`, `instances` (did you mean `sphere`?)"
    );
    let e = dir.error(r#"{"camera": {"type": "fisheye", "projection": "equisolid_angle"}}"#);
    assert!(
        e.starts_with(
            "DIR/scene.json:1:46: camera.projection: unknown fisheye projection `equisolid_angle`"
        ),
        "{e}"
    );
    assert!(e.ends_with("(did you mean `equisolid`?)"), "{e}");
    let e = dir.error(r#"{"integrator": "ambient_occlusoin"}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:16: integrator: unknown integrator type `ambient_occlusoin`, expected \
         one of `depth`, `normal`, `albedo`, `ambient_occlusion`, `path`, `light`, `bdpt`, \
         `photon`, `photon_progressive`, `radiosity` (did you mean `ambient_occlusion`?)"
    );
    // The photon integrators' keys: positioned errors for bad values and unknown keys.
    let e = dir.error(r#"{"integrator": {"type": "photon_progressive", "alpha": 1.2}}"#);
    assert!(
        e.starts_with(
            "DIR/scene.json:1:56: integrator.alpha: `alpha` must lie strictly between 0 and 1"
        ),
        "{e}"
    );
    let e =
        dir.error(r#"{"integrator": {"type": "photon", "radius_m": 0.1, "nearest_photons": 8}}"#);
    assert!(
        e.contains("integrator.nearest_photons: give only one of"),
        "{e}"
    );
    let e = dir.error(r#"{"integrator": {"type": "photon_progressive", "initial_radius_m": -1}}"#);
    assert!(e.contains("integrator.initial_radius_m"), "{e}");
    let e = dir.error(r#"{"integrator": {"type": "photon", "photons_per_pass": 0}}"#);
    assert!(e.contains("integrator.photons_per_pass"), "{e}");
    let e = dir.error(r#"{"integrator": {"type": "photon_progressive", "radius_m": 0.1}}"#);
    assert!(
        e.contains("integrator.radius_m") && e.contains("unknown"),
        "{e}"
    );
    let e = dir.error(r#"{"lights": [{"type": "spotlight"}]}"#);
    assert!(e.ends_with("(did you mean `spot`?)"), "{e}");
    let e = dir.error(r#"{"film": {"filter": {"type": "mitchel"}}}"#);
    assert!(e.ends_with("(did you mean `mitchell`?)"), "{e}");
    let e = dir.error(r#"{"materials": {"m": {"type": "conductor", "metal": "Gold"}}}"#);
    assert!(
        e.starts_with("DIR/scene.json:1:52: materials.m.metal: unknown metal `Gold`"),
        "{e}"
    );
    let e = dir.error(r#"{"shapes": [{"radius_m": 1}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:13: shapes[0]: missing field `type`: expected one of `mesh`, \
         `sphere`, `rectangle`, `disk`, `cuboid`, `instances`"
    );
}

#[test]
fn unknown_spectrum_and_shape_names_suggest() {
    let dir = Dir::new("unknown-names");
    let e =
        dir.error(r#"{"spectra": {"warm": 1}, "lights": [{"type": "point", "spectrum": "D66"}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:67: lights[0].spectrum: unknown spectrum `D66`: expected a name \
         from `spectra` (named spectra: `warm`), a CIE illuminant or a .csv file (did you mean \
         `D60`, `D65`, `D50`?)"
    );
    let e = dir.error(
        r#"{"shapes": [{"type": "disk", "name": "lamp"}, {"type": "disk", "name": "lamp"}]}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:1:72: shapes[1].name: shape name `lamp` is used twice; names must be unique"
    );
    let e = dir.error(
        r#"{"shapes": [{"type": "rectangle", "name": "lamp"}], "lights": [{"type": "area", "shape": "lmap"}]}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:1:90: lights[0].shape: unknown shape `lmap` (named shapes: `lamp`) \
         (did you mean `lamp`?)"
    );
}

#[test]
fn errors_deep_in_nested_arrays_point_at_the_value() {
    let dir = Dir::new("nested");
    let e = dir.error(
        r#"{
  "shapes": [
    {"type": "sphere"},
    {"type": "cuboid", "transform": [
      {"translate": [0, 1, 0]},
      {"scale": 2},
      {"rotate": {"axis": [0, 1, 0], "angle_deg": "90"}}
    ]}
  ]
}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:7:51: shapes[1].transform[2].rotate.angle_deg: expected a number, \
         found the string \"90\""
    );
    let e = dir.error(r#"{"shapes": [{"type": "cuboid", "transform": [{"translate": [0, 1]}]}]}"#);
    assert_eq!(
        e,
        "DIR/scene.json:1:60: shapes[0].transform[0].translate: expected an array of 3 \
         numbers, found 2"
    );
    let e = dir.error(r#"{"shapes": [{"type": "cuboid", "transform": [{"rotat": {}}]}]}"#);
    assert!(
        e.starts_with("DIR/scene.json:1:47: shapes[0].transform[0].rotat: unknown field `rotat`, expected one of `translate`, `rotate`"),
        "{e}"
    );
    assert!(e.ends_with("(did you mean `rotate`?)"), "{e}");
    let e = dir.error(
        r#"{"camera": {"transform": {"look_at": {"eye": [0, 1, 0], "target": [0, 1, 0]}}}}"#,
    );
    assert_eq!(
        e,
        "DIR/scene.json:1:38: camera.transform.look_at: expected `eye` ≠ `target` and `up` not \
         parallel to the view direction"
    );
}

#[test]
fn unreadable_scene_file_names_it() {
    let dir = Dir::new("unreadable");
    let e = prism_scene::load_scene(dir.0.join("nope.json")).unwrap_err();
    let e = e.to_string().replace(&dir.0.display().to_string(), "DIR");
    assert!(
        e.starts_with("DIR/nope.json: cannot read the scene file: "),
        "{e}"
    );
}

#[test]
fn light_tracing_refuses_mis_and_bdpt_takes_path_keys() {
    let dir = Dir::new("light-mis");
    let e = dir.error(r#"{"integrator": {"type": "light", "mis": "power"}}"#);
    assert!(
        e.starts_with(
            "DIR/scene.json:1:41: integrator.mis: `mis` does not apply to the `light` integrator"
        ),
        "{e}"
    );
    let e = dir.error(r#"{"integrator": {"type": "bdpt", "mis": "powr"}}"#);
    assert!(e.contains("integrator.mis"), "{e}");
    let e = dir.error(r#"{"integrator": {"type": "light", "max_depth": 0}}"#);
    assert!(e.contains("integrator.max_depth"), "{e}");
}

#[test]
fn an_unknown_environment_filter_names_the_two_filters() {
    let dir = Dir::new("environment-filter");
    dir.write("sky.exr", "");
    let e = dir
        .error(r#"{"lights": [{"type": "environment", "file": "sky.exr", "filter": "linear"}]}"#);
    assert!(
        e.starts_with("DIR/scene.json:1:66: lights[0].filter: unknown environment map filter `linear`, expected one of `nearest`, `bilinear` (did you mean `bilinear`?)"),
        "{e}"
    );
}
