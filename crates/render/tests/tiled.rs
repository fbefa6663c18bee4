//! `tiled` materials: a wicker panel traced by virtual ray tracing against the same panel
//! modelled explicitly (every copy of the tile in a mesh), both rendered by `path`; and the
//! errors of tiles that cannot be placed. The two renders use different seeds, so their
//! pass means are independent and the comparison is a 4-s.e. test.

use glam::Vec3A;
use prism_geometry::{load_obj, TriangleMesh};

mod support;
use support::{
    assert_close, lux_disagreements, lux_disagreements_within, mean_se, pass_images, sensor_lux,
    window_mean, Dir,
};

const PERIOD_M: f32 = 0.1;
const CELLS: [u32; 2] = [8, 6];

fn wicker_path() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/tiled/tiles/wicker.obj")
}

/// Copies the wicker tile and its MTL into `dir`/tiles/, where the test scenes name it.
fn copy_wicker_tile(dir: &Dir) {
    std::fs::create_dir_all(dir.0.join("tiles")).unwrap();
    for file in ["wicker.obj", "wicker.mtl"] {
        std::fs::copy(
            wicker_path().with_file_name(file),
            dir.0.join("tiles").join(file),
        )
        .unwrap();
    }
}

/// The scene around the panel: `panel` is its shape entries (JSON).
fn scene_json(panel: &str, tiles: &str) -> String {
    format!(
        r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 40, "transform": {{"look_at": {{"eye": [0.25, 0.15, 1.3], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [32, 24], "spp": 1}},
  "integrator": {{"type": "path", "max_depth": 6}},
  {tiles}
  "materials": {{
    "cane": {{"type": "lambert", "reflectance": {{"rgb": [0.75, 0.55, 0.32]}}}},
    "dark cane": {{"type": "lambert", "reflectance": {{"rgb": [0.42, 0.26, 0.12]}}}},
    "wickerwork": {{"type": "tiled", "tile": "wicker", "levels": 3}},
    "plaster": {{"type": "lambert", "reflectance": {{"rgb": [0.8, 0.8, 0.78]}}}}
  }},
  "shapes": [
    {panel},
    {{"type": "rectangle", "name": "wall", "size_m": [3, 3], "material": "plaster", "transform": {{"translate": [0, 0, -0.25]}}}},
    {{"type": "rectangle", "name": "lamp", "size_m": [0.3, 0.3], "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 150}}}}, {{"translate": [-0.3, 0.9, 0.9]}}]}}
  ],
  "lights": [
    {{"type": "area", "shape": "lamp", "luminance_cd_m2": 400000}},
    {{"type": "point", "position_m": [0.6, 0.4, 1.2], "power_lm": 3000}}
  ]
}}"#
    )
}

fn tiles_json(mesh: &str, period: &str) -> String {
    format!(
        r#""tiles": {{"wicker": {{"mesh": "{mesh}", "period_m": {period}, "materials": {{"strand_weft": "cane", "strand_warp": "dark cane"}}}}}},"#
    )
}

/// The faces of `tile` with material `name`, copied to every cell of the panel (centred on
/// the origin, as the rectangle carrier places them), as OBJ text with vertex normals.
fn explicit_obj(tile: &TriangleMesh, name: &str) -> String {
    let material = tile.material_names.iter().position(|n| n == name).unwrap() as u32;
    let normals = tile
        .normals
        .as_ref()
        .expect("the wicker tile has vertex normals");
    let corner = Vec3A::new(
        -0.5 * CELLS[0] as f32 * PERIOD_M,
        -0.5 * CELLS[1] as f32 * PERIOD_M,
        0.0,
    );
    let mut v = String::new();
    let mut f = String::new();
    let mut base = 1u32;
    for j in 0..CELLS[1] {
        for i in 0..CELLS[0] {
            let offset = corner + Vec3A::new(i as f32 * PERIOD_M, j as f32 * PERIOD_M, 0.0);
            for (p, n) in tile.positions.iter().zip(normals) {
                let p = *p + offset;
                v += &format!("v {} {} {}\nvn {} {} {}\n", p.x, p.y, p.z, n.x, n.y, n.z);
            }
            for (tri, m) in tile.indices.iter().zip(&tile.material_ids) {
                if *m == material {
                    let [a, b, c] = tri.map(|k| k + base);
                    f += &format!("f {a}//{a} {b}//{b} {c}//{c}\n");
                }
            }
            base += tile.positions.len() as u32;
        }
    }
    v + &f
}

/// Pass means over 8×8-pixel blocks (4 × 3 of them) and the whole image.
fn block_means(images: &[Vec<f32>]) -> Vec<(String, Vec<f64>)> {
    let mut windows = vec![("image".to_string(), (0, 0, 32, 24))];
    for by in 0..3 {
        for bx in 0..4 {
            windows.push((
                format!("block ({bx}, {by})"),
                (8 * bx, 8 * by, 8 * bx + 8, 8 * by + 8),
            ));
        }
    }
    windows
        .into_iter()
        .map(|(name, w)| (name, images.iter().map(|y| window_mean(y, 32, w)).collect()))
        .collect()
}

#[test]
fn virtual_ray_tracing_renders_what_the_explicit_mesh_renders() {
    let dir = Dir::new("tiled", "explicit");
    let tile = load_obj(wicker_path()).unwrap();
    copy_wicker_tile(&dir);
    dir.write("weft.obj", explicit_obj(&tile, "strand_weft").as_bytes());
    dir.write("warp.obj", explicit_obj(&tile, "strand_warp").as_bytes());
    let tiled = dir.scene(&scene_json(
        r#"{"type": "rectangle", "name": "panel", "size_m": [0.8, 0.6], "material": "wickerwork"}"#,
        &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"),
    ));
    let tiled_images = pass_images(&tiled, 160, 31);
    // The same panel as a mesh of 2 × 2 quads (4 × 3 periods each): four carriers.
    dir.write("quads.obj", QUAD_PANEL_OBJ.as_bytes());
    let quads = dir.scene(&scene_json(
        r#"{"type": "mesh", "name": "panel", "file": "quads.obj", "material": "wickerwork"}"#,
        &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"),
    ));
    let quad_images = pass_images(&quads, 160, 33);
    let explicit = dir.scene(&scene_json(
        r#"{"type": "mesh", "file": "weft.obj", "material": "cane"},
    {"type": "mesh", "file": "warp.obj", "material": "dark cane"}"#,
        &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"),
    ));
    let explicit_images = pass_images(&explicit, 160, 32);
    for (carrier, images) in [("rectangle", &tiled_images), ("quad mesh", &quad_images)] {
        for ((name, a), (_, b)) in block_means(images)
            .into_iter()
            .zip(block_means(&explicit_images))
        {
            let (expected, expected_se) = mean_se(&b);
            assert_close(
                &format!("{carrier}: {name}"),
                mean_se(&a),
                expected,
                expected_se,
                0.0,
            );
        }
    }
}

/// The panel (0.8 m × 0.6 m, centred, normal +z) as 2 × 2 quadrilateral faces.
const QUAD_PANEL_OBJ: &str = "v -0.4 -0.3 0\nv 0 -0.3 0\nv 0.4 -0.3 0\n\
    v -0.4 0 0\nv 0 0 0\nv 0.4 0 0\n\
    v -0.4 0.3 0\nv 0 0.3 0\nv 0.4 0.3 0\n\
    f 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\nf 5 6 9 8\n";

fn error_of(dir: &Dir, panel: &str, tiles: &str) -> String {
    dir.build_error(&scene_json(panel, tiles))
}

#[test]
fn tiles_that_cannot_be_placed_are_errors_naming_the_cause() {
    let dir = Dir::new("tiled", "errors");
    copy_wicker_tile(&dir);
    let wicker = tiles_json("tiles/wicker.obj", "[0.1, 0.1]");
    let panel = |shape: &str| {
        format!(r#"{{"type": "{shape}", "name": "panel", "material": "wickerwork"}}"#)
    };
    // Not a rectangle.
    let message = error_of(&dir, &panel("sphere"), &wicker);
    assert!(
        message.contains("shapes[0]") && message.contains("must be a `rectangle`"),
        "{message}"
    );
    // A triangle mesh, and a quad that is not a parallelogram.
    dir.write("triangle.obj", b"v 0 0 0\nv 0.4 0 0\nv 0 0.3 0\nf 1 2 3\n");
    let message = error_of(
        &dir,
        r#"{"type": "mesh", "file": "triangle.obj", "material": "wickerwork"}"#,
        &wicker,
    );
    assert!(
        message.contains("quadrilateral faces") && message.contains("1 triangles"),
        "{message}"
    );
    dir.write(
        "kite.obj",
        b"v 0 0 0\nv 0.4 0 0\nv 0.5 0.4 0\nv 0 0.3 0\nf 1 2 3 4\n",
    );
    let message = error_of(
        &dir,
        r#"{"type": "mesh", "file": "kite.obj", "material": "wickerwork"}"#,
        &wicker,
    );
    assert!(message.contains("not a parallelogram"), "{message}");
    // Not a whole number of periods.
    let message = error_of(
        &dir,
        r#"{"type": "rectangle", "size_m": [0.85, 0.6], "material": "wickerwork"}"#,
        &wicker,
    );
    assert!(
        message.contains("shapes[0]") && message.contains("8.5000 periods"),
        "{message}"
    );
    // A half-height sheet: its edge on y = 0 has no partner on y = 0.1 m.
    dir.write(
        "tiles/sheet.obj",
        b"mtllib sheet.mtl\nv 0 0 0\nv 0.1 0 0\nv 0.1 0.05 0\nv 0 0.05 0\n\
          usemtl strand_weft\nf 1 2 3\nusemtl strand_warp\nf 1 3 4\n",
    );
    dir.write(
        "tiles/sheet.mtl",
        b"newmtl strand_weft\nKd 1 1 1\nnewmtl strand_warp\nKd 1 1 1\n",
    );
    let rect = r#"{"type": "rectangle", "size_m": [0.8, 0.6], "material": "wickerwork"}"#;
    let message = error_of(&dir, rect, &tiles_json("tiles/sheet.obj", "[0.1, 0.1]"));
    assert!(
        message.contains("tiles.wicker")
            && message.contains("1 boundary edge on the period planes"),
        "{message}"
    );
    // A usemtl name the scene does not map.
    let unmapped = r#""tiles": {"wicker": {"mesh": "tiles/wicker.obj", "period_m": [0.1, 0.1], "materials": {"strand_weft": "cane"}}},"#;
    let message = error_of(&dir, rect, unmapped);
    assert!(
        message.contains("tiles.wicker") && message.contains("usemtl strand_warp"),
        "{message}"
    );
    // A tiled surface cannot emit.
    let lit = scene_json(rect, &wicker).replace(r#""shape": "lamp""#, r#""shape": "panel""#);
    let lit = lit.replace(
        r#""size_m": [0.8, 0.6], "material""#,
        r#""name": "panel", "size_m": [0.8, 0.6], "material""#,
    );
    let message = dir.build_error(&lit);
    assert!(message.contains("cannot emit"), "{message}");
}

#[test]
fn the_scene_reader_checks_tiles_and_tiled_materials() {
    let dir = Dir::new("tiled", "reader");
    std::fs::create_dir_all(dir.0.join("tiles")).unwrap();
    std::fs::copy(wicker_path(), dir.0.join("tiles/wicker.obj")).unwrap();
    let parse_error = |json: &str| -> String {
        let path = dir.write("scene.json", json.as_bytes());
        match prism_scene::load_scene(&path) {
            Ok(_) => panic!("parsed: {json}"),
            Err(e) => e.to_string(),
        }
    };
    let rect = r#"{"type": "rectangle", "size_m": [0.8, 0.6], "material": "wickerwork"}"#;
    let message = parse_error(&scene_json(
        rect,
        &tiles_json("tiles/wicker.obj", "[0.1, 0]"),
    ));
    assert!(
        message.contains("tiles.wicker.period_m") && message.contains("> 0"),
        "{message}"
    );
    let message = parse_error(
        &scene_json(rect, &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"))
            .replace(r#""tile": "wicker""#, r#""tile": "wickr""#),
    );
    assert!(message.contains("unknown tile `wickr`"), "{message}");
    let message = parse_error(
        &scene_json(rect, &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"))
            .replace(r#""levels": 3"#, r#""levels": 0"#),
    );
    assert!(message.contains("levels"), "{message}");
    let message = parse_error(
        &scene_json(rect, &tiles_json("tiles/wicker.obj", "[0.1, 0.1]"))
            .replace(r#""strand_weft": "cane""#, r#""strand_weft": "wickerwork""#),
    );
    assert!(
        message.contains("a tile's faces need a surface material"),
        "{message}"
    );
}

/// A closed 2 m room lit by a ceiling panel, with the wicker panel standing in it: the
/// faces of the room with the scene's integrator (JSON), sensors on the floor in front of,
/// under and behind the panel and on the walls.
/// The six 2 m faces of a closed room centred on the origin (JSON shape entries), each
/// with `material(name)`.
fn room_faces(material: impl Fn(&str) -> &'static str) -> String {
    let face = |name: &str, transform: &str| {
        format!(
            r#"{{"type": "rectangle", "name": "{name}", "size_m": [2, 2], "material": "{}", "transform": {transform}}}"#,
            material(name)
        )
    };
    [
        face(
            "floor",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [0, -1, 0]}]"#,
        ),
        face(
            "ceiling",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 1, 0]}]"#,
        ),
        face("back", r#"[{"translate": [0, 0, -1]}]"#),
        face(
            "front",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 180}}, {"translate": [0, 0, 1]}]"#,
        ),
        face(
            "left",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}, {"translate": [-1, 0, 0]}]"#,
        ),
        face(
            "right",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": -90}}, {"translate": [1, 0, 0]}]"#,
        ),
    ]
    .join(",\n    ")
}

fn room_with_wicker(dir: &Dir, integrator: &str) -> prism_render::RenderScene {
    copy_wicker_tile(dir);
    let faces = room_faces(|_| "plaster");
    let json = format!(
        r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "transform": {{"look_at": {{"eye": [0, 0, 0.9], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {integrator},
  {tiles}
  "materials": {{
    "cane": {{"type": "lambert", "reflectance": {{"rgb": [0.75, 0.55, 0.32]}}}},
    "dark cane": {{"type": "lambert", "reflectance": {{"rgb": [0.42, 0.26, 0.12]}}}},
    "wickerwork": {{"type": "tiled", "tile": "wicker"}},
    "plaster": {{"type": "lambert", "reflectance": 0.6}}
  }},
  "shapes": [
    {faces},
    {{"type": "rectangle", "name": "lamp", "size_m": [0.5, 0.5], "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, 0.99, 0.3]}}]}},
    {{"type": "rectangle", "name": "panel", "size_m": [1.2, 1.0], "material": "wickerwork",
      "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": -60}}}}, {{"translate": [0, -0.3, 0]}}]}}
  ],
  "lights": [{{"type": "area", "shape": "lamp", "luminance_cd_m2": 10000}}],
  "sensors": [
    {{"type": "points", "name": "floor", "samples": 4096,
      "positions_m": [[0, -0.999, 0.6], [0, -0.999, 0.1], [0, -0.999, -0.3], [0.5, -0.999, -0.6], [-0.7, -0.999, 0]],
      "normal": [0, 1, 0]}},
    {{"type": "points", "name": "back wall", "samples": 4096,
      "positions_m": [[0, -0.5, -0.999], [0.5, 0, -0.999]], "normal": [0, 0, 1]}}
  ]
}}"#,
        tiles = tiles_json("tiles/wicker.obj", "[0.1, 0.1]")
    );
    dir.scene(&json)
}

/// `radiosity` holds the tiled panel as a directional patch per side (its pyramid's Γ per
/// direction bin: the top level, as its elements stay above one period) seen through by
/// the tile's own geometry: its sensors agree
/// with `path` within 2 % + 4 s.e. (−0.6 … −2.5 %; −0.9 … −2.8 % as a diffuse
/// equivalent).
#[test]
fn radiosity_with_a_tiled_panel_agrees_with_path_at_the_sensors() {
    let dir = Dir::new("tiled", "radiosity");
    let path = room_with_wicker(
        &dir,
        r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
    );
    let expected = sensor_lux(&path, &dir, 9);
    let radiosity = room_with_wicker(&dir, r#"{"type": "radiosity", "error_bound_rel": 0.001}"#);
    let got = sensor_lux(&radiosity, &dir, 9);
    assert_eq!(lux_disagreements(&expected, &got), 0);
}

/// scenes/office/office.json with its floor paved by `scenes/office/tiles/paving.obj`
/// (30 × 20 stones of 0.2 m, 15 mm high) and the integrator `integrator` (JSON), written
/// into `dir` as `scene.json`.
fn paved_office(dir: &Dir, integrator: &str) -> prism_render::RenderScene {
    let office = support::scenes_dir().join("office");
    let mut json = dir.repository_json(
        "office/office.json",
        &["tiles/paving.obj", "tiles/paving.mtl"],
    );
    json["integrator"] = serde_json::from_str(integrator).unwrap();
    json["tiles"] = serde_json::json!({"paving": {"mesh": "tiles/paving.obj", "period_m": [0.2, 0.2],
        "materials": {"grout": "grout", "stone": "stone"}}});
    json["materials"]["grout"] = serde_json::json!({"type": "lambert", "reflectance": 0.15});
    json["materials"]["stone"] = serde_json::json!({"type": "lambert", "reflectance": 0.35});
    json["materials"]["paving"] = serde_json::json!({"type": "tiled", "tile": "paving"});
    for shape in json["shapes"].as_array_mut().unwrap() {
        if shape["name"] == "floor" {
            shape["material"] = serde_json::json!("paving");
        }
    }
    // The luminaires' files, next to the office scene.
    for light in json["lights"].as_array_mut().unwrap() {
        if let Some(file) = light["file"].as_str() {
            light["file"] = serde_json::json!(office.join(file).display().to_string());
        }
    }
    dir.scene_at(&json.to_string(), Some(8))
}

/// The issue's office with a tiled floor: radiosity (the paved floor directional by its
/// pyramid's top level) against `path` on the office's 240 work-plane points and two wall
/// points.
#[test]
fn a_paved_office_reads_the_same_lux_by_radiosity_and_by_path() {
    let dir = Dir::new("tiled", "office");
    let path = paved_office(&dir, r#"{"type": "path", "max_depth": 64, "rr_depth": 5}"#);
    let expected = sensor_lux(&path, &dir, 5);
    let radiosity = paved_office(&dir, r#"{"type": "radiosity"}"#);
    let got = sensor_lux(&radiosity, &dir, 5);
    let (mut failures, mut sum_rel, mut worst) = (0, 0.0, 0.0f64);
    for (&(e, e_se), &(g, g_se)) in expected.iter().zip(&got) {
        let se = (e_se * e_se + g_se * g_se).sqrt();
        let rel = g / e - 1.0;
        sum_rel += rel;
        worst = worst.max(rel.abs());
        if (g - e).abs() > 0.02 * e + 4.0 * se {
            eprintln!("radiosity {g:.2} lx vs path {e:.2} lx (s.e. {se:.2})");
            failures += 1;
        }
    }
    eprintln!(
        "{} points: mean {:+.2} %, largest {:.2} %",
        expected.len(),
        100.0 * sum_rel / expected.len() as f64,
        100.0 * worst
    );
    assert_eq!(failures, 0);
}

/// A tiled carrier's two patches are seen through by its tile's τ in a cluster's
/// Z-buffer (`Visibility::transparency`); every other patch is opaque.
#[test]
fn a_tiled_carriers_patches_are_the_see_through_ones() {
    let dir = Dir::new("tiled", "see-through");
    let scene = room_with_wicker(&dir, r#"{"type": "radiosity"}"#);
    let (patches, map) =
        prism_render::integrator::radiosity::patches::scene_patches(&scene, Default::default())
            .unwrap();
    assert_eq!(map.carriers.0.len(), 1);
    let carrier = &map.carriers.0[0];
    let first = map.first_patch[carrier.instance as usize].unwrap();
    for patch in 0..patches.len() as u32 {
        let expected = (first..first + 2).contains(&patch).then_some(0);
        assert_eq!(map.carrier_of_patch(patch), expected, "patch {patch}");
    }
    // Seen straight on, the wicker lets some light through and hides the rest.
    let tau = map.carriers.transparency_towards(0, carrier.normal);
    assert!(tau > 0.05 && tau < 0.5, "{tau}");
}

/// A tile of one 2 m period, its left half white (ρ 0.8) and its right half dark (ρ 0.1):
/// two quads.
const HALVES_OBJ: &[u8] =
    b"mtllib halves.mtl\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 2 0\nv 1 2 0\nv 2 2 0\n\
    usemtl white\nf 1 2 5\nf 1 5 4\nusemtl dark\nf 2 3 6\nf 2 6 5\n";

/// A closed 2 m room lit from its ceiling whose back wall is one period of the two-tone
/// tile, `levels` levels; sensors at 0.5 m from the wall, facing it, in front of each half
/// (the lamp is behind them: they read the wall's light alone, and the side walls').
fn room_with_two_tone_wall(dir: &Dir, integrator: &str, levels: u32) -> prism_render::RenderScene {
    std::fs::create_dir_all(dir.0.join("tiles")).unwrap();
    dir.write("tiles/halves.obj", HALVES_OBJ);
    dir.write(
        "tiles/halves.mtl",
        b"newmtl white\nKd 1 1 1\nnewmtl dark\nKd 0 0 0\n",
    );
    let faces = room_faces(|name| {
        if name == "back" {
            "two-tone"
        } else {
            "plaster"
        }
    });
    let json = format!(
        r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "transform": {{"look_at": {{"eye": [0, 0, 0.9], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {integrator},
  "tiles": {{"halves": {{"mesh": "tiles/halves.obj", "period_m": [2, 2], "materials": {{"white": "white", "dark": "dark"}}}}}},
  "materials": {{
    "white": {{"type": "lambert", "reflectance": 0.8}},
    "dark": {{"type": "lambert", "reflectance": 0.1}},
    "two-tone": {{"type": "tiled", "tile": "halves", "levels": {levels}}},
    "plaster": {{"type": "lambert", "reflectance": 0.3}}
  }},
  "shapes": [
    {faces},
    {{"type": "rectangle", "name": "lamp", "size_m": [0.5, 0.5], "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, 0.99, 0.3]}}]}}
  ],
  "lights": [{{"type": "area", "shape": "lamp", "luminance_cd_m2": 10000}}],
  "sensors": [
    {{"type": "points", "name": "facing the wall", "samples": 8192,
      "positions_m": [[-0.5, 0, -0.5], [0.5, 0, -0.5], [-0.5, -0.6, -0.5], [0.5, -0.6, -0.5]],
      "normal": [0, 0, -1]}}
  ]
}}"#
    );
    dir.scene(&json)
}

/// Per-level Γ (Mostefaoui et al. §3): the wall's elements read the pyramid cells they
/// cover, so the sensors in front of the white half read more than those in front of the
/// dark half, as `path` does; with the pyramid's top level alone both read the mean.
#[test]
fn a_tiled_walls_elements_read_the_pyramid_cells_they_cover() {
    let dir = Dir::new("tiled", "two-tone");
    let path = room_with_two_tone_wall(
        &dir,
        r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
        2,
    );
    let expected = sensor_lux(&path, &dir, 3);
    let radiosity = room_with_two_tone_wall(&dir, r#"{"type": "radiosity"}"#, 2);
    let got = sensor_lux(&radiosity, &dir, 3);
    assert_eq!(lux_disagreements(&expected, &got), 0);
    // The solution saved with its deepened pyramid loads for the scene it was solved for.
    let bytes = radiosity
        .radiosity_solution()
        .unwrap()
        .unwrap()
        .solution
        .to_bytes();
    let loaded = prism_render::integrator::radiosity::solution_io::load_solution(
        &radiosity,
        std::path::Path::new("two-tone.prismrad"),
        &bytes,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(loaded.solution.to_bytes() == bytes);
    let top_only = room_with_two_tone_wall(&dir, r#"{"type": "radiosity"}"#, 1);
    let flat = sensor_lux(&top_only, &dir, 3);
    eprintln!("top level only:");
    // Each half's sensors are ≥ 10 % off with the whole period's mean.
    assert_eq!(
        lux_disagreements_within(&expected, &flat, 0.1),
        expected.len()
    );
}

/// A finer pyramid is made only within half the memory limit: beyond it the elements read
/// the deepest pyramid that fits, and the solution says so.
#[test]
fn a_finer_pyramid_stays_within_the_memory_limit() {
    let dir = Dir::new("tiled", "two-tone-memory");
    let scene = room_with_two_tone_wall(&dir, r#"{"type": "radiosity"}"#, 5);
    let prism_render::integrator::Integrator::Radiosity(method) = scene.integrator else {
        panic!("a radiosity scene");
    };
    let solved = |limit_mib: u64| {
        let method = prism_render::integrator::radiosity::RadiosityMethod {
            memory_limit_bytes: Some(limit_mib << 20),
            ..method
        };
        prism_render::integrator::radiosity::solve(&scene, &method)
            .unwrap_or_else(|e| panic!("{e}"))
            .1
    };
    // Its elements get down to 1/8 of the 2 m period: 4 levels, 170 MiB to simulate.
    let roomy = solved(1024);
    assert!(
        roomy.iter().any(|l| l.contains("a 4-level pyramid")),
        "{roomy:#?}"
    );
    let tight = solved(200);
    assert!(
        tight
            .iter()
            .any(|l| l.contains("more than half the memory limit")
                && l.ends_with("they read 3 levels")),
        "{tight:#?}"
    );
    assert!(
        tight.iter().any(|l| l.contains("a 3-level pyramid")),
        "{tight:#?}"
    );
}
