//! Wavefront OBJ loading through `tobj` (polygons fan-triangulated by tobj, one index per
//! vertex). tobj reports error kinds without a place, so on failure the file is scanned here
//! to find the offending line and say what was expected there.

use std::collections::HashMap;
use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3A};

use crate::error::MeshLoadError;
use crate::mesh::{TriangleMesh, NO_MATERIAL};

/// Load an OBJ file (and the MTL files it names, relative to it) into one mesh: each OBJ
/// object/group becomes an object id (named in `object_names`), each `usemtl` material a
/// material id (named in `material_names`, from the MTL files).
pub fn load_obj(path: impl AsRef<Path>) -> Result<TriangleMesh, MeshLoadError> {
    let path = path.as_ref();
    let text = prism_cpu::text_file::read_text(path)
        .map_err(|e| MeshLoadError::new(path, None, format!("cannot read the OBJ file: {e}")))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mtl_errors: std::cell::RefCell<Vec<(String, String)>> = Default::default();
    let result = tobj::load_obj_buf(&mut BufReader::new(text.as_bytes()), &options, |mtl| {
        let full = dir.join(mtl);
        let r = tobj::load_mtl(&full);
        if let Err(e) = &r {
            mtl_errors
                .borrow_mut()
                .push((full.display().to_string(), e.to_string()));
        }
        r
    });
    let (models, materials) = match result {
        Ok(v) => v,
        Err(e) => {
            let (line, message) =
                scan_for_error(&text).unwrap_or((None, format!("not a valid OBJ file ({e})")));
            return Err(MeshLoadError::new(path, line, message));
        }
    };
    let materials = materials.unwrap_or_default();
    let mtl_errors = mtl_errors.into_inner();

    // Every `usemtl` must name a material that an MTL file defined.
    let defined: HashMap<&str, usize> = materials
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.as_str(), i))
        .collect();
    for (i, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        if it.next() == Some("usemtl") {
            let name = line.trim_start()["usemtl".len()..].trim();
            if !defined.contains_key(name) {
                let mut msg = format!("usemtl '{name}' names a material no mtllib file defines");
                if !mtl_errors.is_empty() {
                    let list: Vec<String> = mtl_errors
                        .iter()
                        .map(|(f, e)| format!("{f}: {e}"))
                        .collect();
                    msg += &format!(" (could not load {})", list.join("; "));
                } else if !materials.is_empty() {
                    let names: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
                    msg += &format!(" (defined: {})", names.join(", "));
                }
                return Err(MeshLoadError::new(path, Some(i + 1), msg));
            }
        }
    }

    let mut mesh = TriangleMesh {
        material_names: materials.iter().map(|m| m.name.clone()).collect(),
        ..Default::default()
    };
    let any_normals = models.iter().any(|m| !m.mesh.normals.is_empty());
    let any_uvs = models.iter().any(|m| !m.mesh.texcoords.is_empty());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut object_ids: HashMap<String, u32> = HashMap::new();
    for model in &models {
        let m = &model.mesh;
        let object_id = *object_ids.entry(model.name.clone()).or_insert_with(|| {
            mesh.object_names.push(model.name.clone());
            mesh.object_names.len() as u32 - 1
        });
        let material_id = m.material_id.map_or(NO_MATERIAL, |i| i as u32);
        let base = mesh.positions.len() as u32;
        let nv = m.positions.len() / 3;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3A::new(p[0], p[1], p[2])),
        );
        if any_normals {
            if m.normals.len() == 3 * nv {
                normals.extend(
                    m.normals
                        .chunks_exact(3)
                        .map(|n| Vec3A::new(n[0], n[1], n[2])),
                );
            } else {
                // Zero normals fall back to the geometric normal at shading time.
                normals.extend(std::iter::repeat_n(Vec3A::ZERO, nv));
            }
        }
        if any_uvs {
            if m.texcoords.len() == 2 * nv {
                uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
            } else {
                uvs.extend(std::iter::repeat_n(Vec2::ZERO, nv));
            }
        }
        for tri in m.indices.chunks_exact(3) {
            mesh.indices
                .push([base + tri[0], base + tri[1], base + tri[2]]);
            mesh.material_ids.push(material_id);
            mesh.object_ids.push(object_id);
        }
    }
    if any_normals {
        mesh.normals = Some(normals);
    }
    if any_uvs {
        mesh.uvs = Some(uvs);
    }
    mesh.validate()
        .map_err(|m| MeshLoadError::new(path, None, m))?;
    Ok(mesh)
}

/// Find the first line tobj would reject and say what was expected there.
fn scan_for_error(text: &str) -> Option<(Option<usize>, String)> {
    let (mut nv, mut nvt, mut nvn) = (0usize, 0usize, 0usize);
    for (i, raw) in text.lines().enumerate() {
        let line_no = Some(i + 1);
        let line = raw.split('#').next().unwrap_or("");
        let mut fields = line.split_whitespace();
        let Some(tag) = fields.next() else { continue };
        let rest: Vec<&str> = fields.collect();
        let all_numbers = |n_min: usize, n_max: usize| {
            rest.len() >= n_min
                && rest.len() <= n_max
                && rest.iter().all(|s| s.parse::<f32>().is_ok())
        };
        match tag {
            "v" => {
                // x y z [w] or x y z r g b
                if !(all_numbers(3, 4) || all_numbers(6, 6)) {
                    return Some((
                        line_no,
                        format!(
                            "vertex position: expected 3 numbers after 'v' (x y z), found '{}'",
                            raw.trim()
                        ),
                    ));
                }
                nv += 1;
            }
            "vt" => {
                if !all_numbers(1, 3) {
                    return Some((
                        line_no,
                        format!(
                            "texture coordinate: expected 1 to 3 numbers after 'vt', found '{}'",
                            raw.trim()
                        ),
                    ));
                }
                nvt += 1;
            }
            "vn" => {
                if !all_numbers(3, 3) {
                    return Some((
                        line_no,
                        format!(
                            "normal: expected 3 numbers after 'vn', found '{}'",
                            raw.trim()
                        ),
                    ));
                }
                nvn += 1;
            }
            "f" => {
                if rest.len() < 3 {
                    return Some((
                        line_no,
                        format!(
                            "face: expected at least 3 vertices after 'f', found '{}'",
                            raw.trim()
                        ),
                    ));
                }
                for corner in &rest {
                    for (k, (part, count, (what, whats))) in corner
                        .split('/')
                        .zip([
                            (nv, ("vertex", "vertices")),
                            (nvt, ("texture coordinate", "texture coordinates")),
                            (nvn, ("normal", "normals")),
                        ])
                        .map(|(p, (c, w))| (p, c, w))
                        .enumerate()
                    {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let Ok(idx) = part.parse::<i64>() else {
                            return Some((
                                line_no,
                                format!("face: expected an integer {what} index in '{corner}', found '{part}'"),
                            ));
                        };
                        let resolved = if idx < 0 { count as i64 + idx + 1 } else { idx };
                        if idx == 0 || resolved < 1 || resolved > count as i64 {
                            return Some((
                                line_no,
                                format!(
                                    "face: {what} index {idx} is out of range; {count} {whats} are defined before this line (OBJ indices start at 1, negative ones count back)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}
