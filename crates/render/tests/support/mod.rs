//! Shared by the render crate's scene tests: each test file declares `mod support;`.
#![allow(dead_code)]

use std::path::PathBuf;

use prism_render::RenderScene;
use prism_scene::load_scene;

/// A test's own scene folder (removed when dropped): scene JSON and its data files.
pub struct Dir(pub PathBuf);

impl Dir {
    /// `prefix` names the test file, `test` the test.
    pub fn new(prefix: &str, test: &str) -> Dir {
        let dir =
            std::env::temp_dir().join(format!("prism-{prefix}-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Dir(dir)
    }
    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
    pub fn scene(&self, json: &str) -> RenderScene {
        let path = self.write("scene.json", json.as_bytes());
        let description = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"))
    }
    pub fn build_error(&self, json: &str) -> String {
        let path = self.write("scene.json", json.as_bytes());
        let description = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        match RenderScene::build(&description, None) {
            Ok(_) => panic!("built a scene that should be refused: {json}"),
            Err(e) => e.to_string().replace(&self.0.display().to_string(), "DIR"),
        }
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A Mitsuba `.vol` (version 3, float32, 1 channel) of `values` (x fastest) over the box.
#[allow(dead_code)] // not every test binary that shares this module writes grids
pub fn vol_bytes(res: [i32; 3], min: [f32; 3], max: [f32; 3], values: &[f32]) -> Vec<u8> {
    let mut b = b"VOL".to_vec();
    b.push(3);
    b.extend_from_slice(&1i32.to_le_bytes());
    for r in res {
        b.extend_from_slice(&r.to_le_bytes());
    }
    b.extend_from_slice(&1i32.to_le_bytes());
    for x in min.iter().chain(max.iter()) {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}
