//! The Prism scene being assembled: sections in a fixed order (camera, film, integrator,
//! textures, materials, shapes, lights), unique names, asset paths relative to where the
//! JSON will live, and the side files the importer must write (inline meshes).

use std::path::{Component, Path, PathBuf};

use serde_json::{Map, Value};

use crate::unsupported::Unsupported;

/// A file the importer writes next to the JSON (path relative to `ImportOptions::output_dir`).
#[derive(Debug, Clone, PartialEq)]
pub struct SideFile {
    pub relative_path: String,
    pub contents: Vec<u8>,
}

/// The result of an import.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The Prism scene (docs/scene-format.md).
    pub scene: Value,
    pub side_files: Vec<SideFile>,
    pub unsupported: Unsupported,
}

impl Imported {
    /// Readable, deterministic JSON (keys in insertion order, two-space indent).
    pub fn to_json_text(&self) -> String {
        let mut text = String::new();
        write_value(&mut text, &self.scene, 0);
        text.push('\n');
        text
    }
}

/// Sections of the scene under construction.
#[derive(Debug, Default)]
pub struct SceneBuilder {
    pub camera: Option<Value>,
    pub film: Map<String, Value>,
    pub integrator: Option<Value>,
    pub textures: Map<String, Value>,
    pub materials: Map<String, Value>,
    pub shapes: Vec<Value>,
    pub lights: Vec<Value>,
    pub side_files: Vec<SideFile>,
    pub unsupported: Unsupported,
    output_dir: PathBuf,
    side_dir: String,
    used_shape_names: Vec<String>,
}

impl SceneBuilder {
    pub fn new(output_dir: &Path, side_dir: &str) -> Self {
        SceneBuilder {
            output_dir: output_dir.to_path_buf(),
            side_dir: side_dir.to_string(),
            ..Default::default()
        }
    }

    /// `base` if no material has that name yet, else `base-2`, `base-3`, …
    pub fn unique_material_name(&self, base: &str) -> String {
        unique(base, |n| self.materials.contains_key(n))
    }

    pub fn unique_texture_name(&self, base: &str) -> String {
        unique(base, |n| self.textures.contains_key(n))
    }

    /// Reserves a unique shape name.
    pub fn unique_shape_name(&mut self, base: &str) -> String {
        let name = unique(base, |n| self.used_shape_names.iter().any(|u| u == n));
        self.used_shape_names.push(name.clone());
        name
    }

    /// An asset path as the JSON should spell it: relative to the output folder when the
    /// asset lies below it, absolute otherwise (so the JSON works from where it is written).
    pub fn asset_path(&self, absolute: &Path) -> String {
        let abs = normalise(absolute);
        let out = normalise(&self.output_dir);
        match abs.strip_prefix(&out) {
            Ok(rel) if !out.as_os_str().is_empty() => rel.to_string_lossy().replace('\\', "/"),
            _ => abs.to_string_lossy().into_owned(),
        }
    }

    /// Adds a side file named `file_name` in the side folder; returns its JSON path.
    pub fn add_side_file(&mut self, file_name: &str, contents: Vec<u8>) -> String {
        let relative_path = format!("{}/{file_name}", self.side_dir);
        self.side_files.push(SideFile {
            relative_path: relative_path.clone(),
            contents,
        });
        relative_path
    }

    pub fn finish(self) -> Imported {
        let mut scene = Map::new();
        if let Some(camera) = self.camera {
            scene.insert("camera".into(), camera);
        }
        if !self.film.is_empty() {
            scene.insert("film".into(), Value::Object(self.film));
        }
        if let Some(integrator) = self.integrator {
            scene.insert("integrator".into(), integrator);
        }
        if !self.textures.is_empty() {
            scene.insert("textures".into(), Value::Object(self.textures));
        }
        if !self.materials.is_empty() {
            scene.insert("materials".into(), Value::Object(self.materials));
        }
        scene.insert("shapes".into(), Value::Array(self.shapes));
        if !self.lights.is_empty() {
            scene.insert("lights".into(), Value::Array(self.lights));
        }
        Imported {
            scene: Value::Object(scene),
            side_files: self.side_files,
            unsupported: self.unsupported,
        }
    }
}

/// Pretty JSON with arrays of numbers and strings on one line (vectors, matrix rows).
fn write_value(out: &mut String, v: &Value, indent: usize) {
    let pad = |n: usize| "  ".repeat(n);
    let scalar = |v: &Value| !(v.is_array() || v.is_object());
    match v {
        Value::Object(map) if !map.is_empty() => {
            out.push_str("{\n");
            for (i, (k, x)) in map.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                out.push_str(&Value::String(k.clone()).to_string());
                out.push_str(": ");
                write_value(out, x, indent + 1);
                if i + 1 < map.len() {
                    out.push(',');
                }
                out.push('\n');
            }
            out.push_str(&pad(indent));
            out.push('}');
        }
        Value::Array(items) if !items.is_empty() && !items.iter().all(scalar) => {
            out.push_str("[\n");
            for (i, x) in items.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                write_value(out, x, indent + 1);
                if i + 1 < items.len() {
                    out.push(',');
                }
                out.push('\n');
            }
            out.push_str(&pad(indent));
            out.push(']');
        }
        Value::Array(items) => {
            let parts: Vec<String> = items.iter().map(Value::to_string).collect();
            out.push('[');
            out.push_str(&parts.join(", "));
            out.push(']');
        }
        other => out.push_str(&other.to_string()),
    }
}

fn unique(base: &str, taken: impl Fn(&str) -> bool) -> String {
    if !taken(base) {
        return base.to_string();
    }
    (2..)
        .map(|i| format!("{base}-{i}"))
        .find(|n| !taken(n))
        .expect("an unbounded range always yields a free name")
}

/// Removes `.` and resolves `..` lexically (no file-system access: assets are checked by
/// Prism's scene reader).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// A 4×4 matrix (glam, column-major) as Prism's row-major `{"matrix": …}` transform step.
pub fn matrix_json(m: &glam::DMat4) -> Value {
    let rows: Vec<Value> = (0..4)
        .map(|r| Value::from((0..4).map(|c| m.col(c)[r]).collect::<Vec<f64>>()))
        .collect();
    serde_json::json!({ "matrix": rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asset_paths_are_relative_below_the_output_folder_and_absolute_elsewhere() {
        let b = SceneBuilder::new(Path::new("/scenes/room"), "room-assets");
        assert_eq!(
            b.asset_path(Path::new("/scenes/room/./meshes/a.obj")),
            "meshes/a.obj"
        );
        assert_eq!(
            b.asset_path(Path::new("/scenes/other/a.obj")),
            "/scenes/other/a.obj"
        );
    }

    #[test]
    fn names_are_made_unique() {
        let mut b = SceneBuilder::new(Path::new("/"), "x");
        assert_eq!(b.unique_shape_name("wall"), "wall");
        assert_eq!(b.unique_shape_name("wall"), "wall-2");
    }
}
