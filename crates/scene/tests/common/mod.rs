//! Test helpers: a fresh folder per test with a scene and its assets written into it.

#![allow(dead_code)]

use std::path::PathBuf;

use prism_scene::{load_scene, SceneDescription, SceneError};

pub struct Dir(pub PathBuf);

impl Dir {
    pub fn new(test: &str) -> Dir {
        let dir = std::env::temp_dir().join(format!("prism-scene-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Dir(dir)
    }

    pub fn write(&self, name: &str, text: &str) -> PathBuf {
        let path = self.0.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
        path
    }

    pub fn load(&self, scene: &str) -> Result<SceneDescription, SceneError> {
        load_scene(self.write("scene.json", scene))
    }

    /// The error message with the folder replaced by `DIR`, for exact comparisons.
    pub fn error(&self, scene: &str) -> String {
        let e = self.load(scene).expect_err("the scene should be refused");
        e.to_string().replace(&self.0.display().to_string(), "DIR")
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
