//! Every .json under the workspace's scenes/ is a complete scene that loads.

use std::path::{Path, PathBuf};

use prism_scene::{load_scene, CameraKind};

fn json_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            json_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "json") {
            out.push(path);
        }
    }
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn every_scene_under_scenes_loads() {
    let mut files = Vec::new();
    json_files(&scenes_dir(), &mut files);
    assert!(files.len() >= 9, "{files:?}");
    for file in &files {
        let scene = load_scene(file).unwrap_or_else(|e| panic!("{e}"));
        // What was loaded is what the file says: every shape and light, the film it asks
        // for (or a usable default), mesh files that exist.
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
        let count = |key: &str| json.get(key).and_then(|v| v.as_array()).map_or(0, Vec::len);
        let what = file.display();
        assert_eq!(scene.file, *file, "{what}");
        assert!(!scene.shapes.is_empty(), "{what}: no shapes");
        assert_eq!(scene.shapes.len(), count("shapes"), "{what}: shapes");
        assert_eq!(scene.lights.len(), count("lights"), "{what}: lights");
        let materials = json.get("materials").and_then(|m| m.as_object());
        assert!(
            scene.materials.len() >= materials.map_or(0, |m| m.len()),
            "{what}: {} materials",
            scene.materials.len()
        );
        let film = json.get("film");
        match film.and_then(|f| f.get("resolution")) {
            Some(r) => assert_eq!(
                serde_json::json!(scene.film.resolution),
                *r,
                "{what}: resolution"
            ),
            None => assert!(scene.film.resolution.iter().all(|&n| n > 0), "{what}"),
        }
        match film.and_then(|f| f.get("spp")) {
            Some(spp) => assert_eq!(serde_json::json!(scene.film.spp), *spp, "{what}: spp"),
            None => assert!(scene.film.spp > 0, "{what}"),
        }
        for mesh in &scene.meshes {
            assert!(mesh.path.is_file(), "{what}: {}", mesh.path.display());
        }
    }
}

#[test]
fn the_camera_gallery_is_one_room_seen_by_every_camera_model() {
    let names = [
        "pinhole",
        "thin-lens",
        "fisheye-equidistant",
        "fisheye-equisolid",
        "fisheye-orthographic",
        "fisheye-stereographic",
        "orthographic",
        "spherical",
    ];
    let scenes: Vec<_> = names
        .iter()
        .map(|n| load_scene(scenes_dir().join(format!("cameras/{n}.json"))).unwrap())
        .collect();
    for s in &scenes[1..] {
        assert_eq!(s.shapes, scenes[0].shapes);
        assert_eq!(s.materials, scenes[0].materials);
        assert_eq!(s.lights, scenes[0].lights);
        assert_eq!(s.integrator, scenes[0].integrator);
    }
    let kinds: Vec<&str> = scenes
        .iter()
        .map(|s| match s.camera.kind {
            CameraKind::Pinhole { .. } => "pinhole",
            CameraKind::ThinLens { .. } => "thin-lens",
            CameraKind::Fisheye { projection, .. } => match projection {
                prism_scene::FisheyeProjection::Equidistant => "fisheye-equidistant",
                prism_scene::FisheyeProjection::Equisolid => "fisheye-equisolid",
                prism_scene::FisheyeProjection::Orthographic => "fisheye-orthographic",
                prism_scene::FisheyeProjection::Stereographic => "fisheye-stereographic",
            },
            CameraKind::Orthographic { .. } => "orthographic",
            CameraKind::Spherical => "spherical",
        })
        .collect();
    assert_eq!(kinds, names);
}

/// No panics on user input: every truncation of a real scene, and every single-character
/// replacement with a troublesome character, gives a value or an error, and every error
/// names the file it is about.
#[test]
fn truncated_and_corrupted_scenes_never_panic() {
    let path = scenes_dir().join("cameras/thin-lens.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let chars: Vec<char> = text.chars().collect();
    let names_the_file = |e: &prism_scene::SceneError| {
        let message = e.to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
    };
    for end in 0..chars.len() {
        let prefix: String = chars[..end].iter().collect();
        if prefix.trim_end() == text.trim_end() {
            continue;
        }
        match prism_scene::parse_scene_str(&prefix, &path) {
            Ok(_) => panic!("a truncation to {end} characters parsed"),
            Err(e) => names_the_file(&e),
        }
    }
    let (mut errors, mut parsed) = (0, 0);
    for i in (0..chars.len()).step_by(3) {
        for c in ['"', '-', '0', '}', ']', 'x'] {
            let mut corrupted = chars.clone();
            corrupted[i] = c;
            let corrupted: String = corrupted.into_iter().collect();
            match prism_scene::parse_scene_str(&corrupted, &path) {
                Ok(_) => parsed += 1,
                Err(e) => {
                    names_the_file(&e);
                    errors += 1;
                }
            }
        }
    }
    // Most replacements break the JSON; a few land in a number or a name and still parse.
    println!("{errors} corrupted scenes refused, {parsed} parsed");
    assert!(
        errors > parsed && errors + parsed == 6 * chars.len().div_ceil(3),
        "{errors} refused, {parsed} parsed"
    );
}
