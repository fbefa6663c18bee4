//! Depth, normal and albedo integrators and AOVs on a floor seen straight down, scene
//! building errors, and thread-count independence of the tile driver.

use prism_render::{render, FilmImage, RenderScene, RenderSettings};
use prism_scene::parse_scene_str;

fn floor_scene(integrator: &str) -> String {
    format!(
        r#"{{
      "camera": {{"type": "orthographic", "width_m": 1,
                 "transform": {{"look_at": {{"eye": [0, 2, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
      "film": {{"resolution": [8, 8], "filter": "box"}},
      "integrator": "{integrator}",
      "materials": {{"red": {{"type": "lambert", "reflectance": {{"rgb": [0.6, 0.08, 0.06]}}}}}},
      "shapes": [{{"type": "rectangle", "size_m": [10, 10], "material": "red",
                  "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}]
    }}"#
    )
}

fn render_scene(json: &str, threads: usize) -> FilmImage {
    let description = parse_scene_str(json, "test.json").expect("parses");
    let scene = RenderScene::build(&description, None).expect("builds");
    let settings = RenderSettings {
        spp: 4,
        seed: 3,
        tile_size_px: 3,
        ..RenderSettings::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| render(&scene, &settings, &|_| {})).0
}

#[test]
fn depth_integrator_gives_metres_and_aovs_hold_depth_normal_albedo() {
    let image = render_scene(&floor_scene("depth"), 1);
    for &y in &image.y {
        assert!((y - 2.0).abs() < 1e-5, "{y}");
    }
    let depth = image.aov("depth.Z").unwrap();
    assert!(depth.values.iter().all(|d| (d - 2.0).abs() < 1e-5));
    let ny = image.aov("normal.Y").unwrap();
    assert!(ny.values.iter().all(|n| (n - 1.0).abs() < 1e-5));
    let r = image.aov("albedo.R").unwrap();
    assert!(r.values.iter().all(|v| (v - 0.6).abs() < 1e-6));
    assert!(image.aov("spp.Y").unwrap().values.iter().all(|&s| s == 4.0));
}

#[test]
fn normal_integrator_maps_n_to_half_n_plus_half_and_albedo_is_the_reflectance() {
    let image = render_scene(&floor_scene("normal"), 1);
    for rgb in &image.rgb {
        for (c, e) in rgb.iter().zip([0.5, 1.0, 0.5]) {
            assert!((c - e).abs() < 1e-4, "{rgb:?}");
        }
    }
    let image = render_scene(&floor_scene("albedo"), 1);
    for rgb in &image.rgb {
        for (c, e) in rgb.iter().zip([0.6, 0.08, 0.06]) {
            assert!((c - e).abs() < 1e-4, "{rgb:?}");
        }
    }
}

#[test]
fn images_are_identical_for_one_and_two_threads() {
    let json = floor_scene("ambient_occlusion").replace(
        r#""shapes": ["#,
        r#""shapes": [{"type": "sphere", "radius_m": 0.3}, {"type": "cuboid", "size_m": [0.2, 0.5, 0.2],
           "transform": {"translate": [0.3, 0, 0.2]}},"#,
    );
    let one = render_scene(&json, 1);
    let two = render_scene(&json, 2);
    assert_eq!(one, two);
    assert!(one.y.iter().any(|&y| y < 0.99), "the occluders should show");
}

#[test]
fn bad_mesh_names_the_file_and_place() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv x 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let scene_path = dir.path().join("s.json");
    std::fs::write(
        &scene_path,
        r#"{"integrator": "depth", "shapes": [{"type": "sphere"}, {"type": "mesh", "file": "bad.obj"}]}"#,
    )
    .unwrap();
    let description = prism_scene::load_scene(&scene_path).unwrap();
    let err = RenderScene::build(&description, None)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("s.json: shapes[1]"), "{err}");
    assert!(err.contains("bad.obj:3"), "{err}");
}

#[test]
fn mesh_instances_are_placed_by_their_own_then_the_shape_transform() {
    // A 0.8 m square (two triangles in z = 0, normal +z) instanced at x = −1 and x = +1,
    // the shape transform lifting both to y = 0.5, seen along −z by an orthographic camera
    // 3 m away with 1 m pixels: the outer pixels hit a copy at depth 3 m, the middle one
    // (|x| < 0.5) misses.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v -0.4 -0.4 0\nv 0.4 -0.4 0\nv 0.4 0.4 0\nv -0.4 0.4 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let scene_path = dir.path().join("s.json");
    std::fs::write(
        &scene_path,
        r#"{"integrator": "depth",
            "camera": {"type": "orthographic", "width_m": 3,
                       "transform": {"look_at": {"eye": [0, 0.5, 3], "target": [0, 0.5, 0]}}},
            "film": {"resolution": [3, 1], "filter": "box"},
            "meshes": {"quad": "quad.obj"},
            "shapes": [{"type": "instances", "mesh": "quad",
                        "instances": [{"translate": [-1, 0, 0]}, {"translate": [1, 0, 0]}],
                        "transform": {"translate": [0, 0.5, 0]}}]}"#,
    )
    .unwrap();
    let description = prism_scene::load_scene(&scene_path).unwrap();
    let scene = RenderScene::build(&description, None).unwrap();
    let (image, _) = render(
        &scene,
        &RenderSettings {
            spp: 4,
            seed: 0,
            tile_size_px: 16,
            ..RenderSettings::default()
        },
        &|_| {},
    );
    let depth = &image.aov("depth.Z").unwrap().values;
    assert!((depth[0] - 3.0).abs() < 1e-5, "{depth:?}");
    assert!(depth[1].is_infinite(), "{depth:?}");
    assert!((depth[2] - 3.0).abs() < 1e-5, "{depth:?}");
    assert_eq!(scene.geometry.mesh_count(), 1);
}
