//! PLY loading through `ply-rs` (ASCII, binary little and big endian). Vertices need x, y, z;
//! nx, ny, nz and u, v (or s, t, texture_u/texture_v, texture_s/texture_t) are used when
//! present. Faces come from a `vertex_indices` or `vertex_index` list and are fan-triangulated.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3A};
use ply_rs::parser::Parser;
use ply_rs::ply::{DefaultElement, Property};

use crate::error::MeshLoadError;
use crate::mesh::TriangleMesh;

/// ply-rs' error text in the project's words: its ASCII messages are "Line N: …" followed
/// by the offending text and a nested `Custom { kind: …, error: "… error at 1:3: expected
/// one of …" }` (Debug output of its grammar). Returns the line and a sentence.
fn ply_error_message(raw: &str) -> (Option<usize>, String) {
    let line = raw
        .strip_prefix("Line ")
        .and_then(|r| r.split(':').next())
        .and_then(|n| n.trim().parse::<usize>().ok());
    let text = raw
        .split_once("String: '")
        .and_then(|(_, r)| r.split_once('\''))
        .map(|(t, _)| t.trim());
    let column = raw
        .rsplit_once("error at ")
        .and_then(|(_, r)| r.split(':').nth(1))
        .and_then(|c| c.trim().parse::<usize>().ok());
    match (line, text) {
        (Some(line), Some(text)) => {
            let at = column.map_or(String::new(), |c| format!(" at column {c}"));
            (
                Some(line),
                format!(
                    "cannot read `{text}`{at}; expected the numbers the header declares for \
                     this element, separated by spaces"
                ),
            )
        }
        // Other messages (header, binary data): their first line, without nested Debug.
        _ => {
            let first = raw.lines().next().unwrap_or(raw).trim();
            let first = first.split(" Custom {").next().unwrap_or(first);
            let first = first.split("ParseError {").next().unwrap_or(first).trim();
            (line, first.trim_end_matches(':').to_string())
        }
    }
}

/// Load a PLY mesh file.
pub fn load_ply(path: impl AsRef<Path>) -> Result<TriangleMesh, MeshLoadError> {
    let path = path.as_ref();
    let err = |msg: String| MeshLoadError::new(path, None, msg);
    if path.is_dir() {
        return Err(err("it is a directory; expected a PLY file".into()));
    }
    let file = std::fs::File::open(path).map_err(|e| err(format!("cannot open PLY file: {e}")))?;
    let mut reader = BufReader::new(file);
    // ply-rs has a few panicking paths on malformed input; user input must never panic here.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        Parser::<DefaultElement>::new().read_ply(&mut reader)
    }))
    .map_err(|_| err("malformed PLY file (the PLY parser could not make sense of it)".into()))?;
    let ply = parsed.map_err(|e| {
        let hint = if e.kind() == std::io::ErrorKind::UnexpectedEof {
            " — the file ends before all elements the header declares were read (truncated file?)"
        } else {
            ""
        };
        let (line, message) = ply_error_message(&e.to_string());
        MeshLoadError::new(path, line, format!("cannot parse PLY: {message}{hint}"))
    })?;

    let vertices = ply.payload.get("vertex").ok_or_else(|| {
        err("no 'vertex' element; expected 'element vertex N' in the header".into())
    })?;
    let nv = vertices.len();
    let get = |e: &DefaultElement, name: &str| e.get(name).and_then(scalar);
    let has = |name: &str| vertices.first().is_some_and(|e| e.contains_key(name));
    for c in ["x", "y", "z"] {
        if nv > 0 && !has(c) {
            return Err(err(format!(
                "element 'vertex' has no scalar property '{c}'; expected x, y, z"
            )));
        }
    }
    let mut positions = Vec::with_capacity(nv);
    for (i, v) in vertices.iter().enumerate() {
        let (Some(x), Some(y), Some(z)) = (get(v, "x"), get(v, "y"), get(v, "z")) else {
            return Err(err(format!("vertex {i}: x, y, z must be numeric scalars")));
        };
        positions.push(Vec3A::new(x, y, z));
    }
    let normals = (has("nx") && has("ny") && has("nz")).then(|| {
        vertices
            .iter()
            .map(|v| {
                Vec3A::new(
                    get(v, "nx").unwrap_or(0.0),
                    get(v, "ny").unwrap_or(0.0),
                    get(v, "nz").unwrap_or(0.0),
                )
            })
            .collect::<Vec<_>>()
    });
    let uv_names = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ];
    let uvs = uv_names
        .iter()
        .find(|(u, v)| has(u) && has(v))
        .map(|(u, v)| {
            vertices
                .iter()
                .map(|e| Vec2::new(get(e, u).unwrap_or(0.0), get(e, v).unwrap_or(0.0)))
                .collect::<Vec<_>>()
        });

    let mut indices = Vec::new();
    if let Some(faces) = ply.payload.get("face") {
        for (f, face) in faces.iter().enumerate() {
            let list = face
                .get("vertex_indices")
                .or_else(|| face.get("vertex_index"))
                .ok_or_else(|| {
                    err(format!(
                        "face {f} has no 'vertex_indices' or 'vertex_index' list property"
                    ))
                })?;
            let idx = index_list(list)
                .ok_or_else(|| err(format!("face {f}: vertex indices must be an integer list")))?;
            if idx.len() < 3 {
                return Err(err(format!(
                    "face {f} has {} vertices; expected at least 3",
                    idx.len()
                )));
            }
            for &i in &idx {
                if i < 0 || i as usize >= nv {
                    return Err(err(format!(
                        "face {f} refers to vertex {i}, but element 'vertex' has {nv} vertices (indices start at 0)"
                    )));
                }
            }
            // Fan triangulation (exact for convex polygons, which is what PLY writers emit).
            for k in 1..idx.len() - 1 {
                indices.push([idx[0] as u32, idx[k] as u32, idx[k + 1] as u32]);
            }
        }
    }
    let mut mesh = TriangleMesh::new(positions, indices);
    mesh.normals = normals;
    mesh.uvs = uvs;
    mesh.validate().map_err(err)?;
    Ok(mesh)
}

fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Char(v) => v as f32,
        Property::UChar(v) => v as f32,
        Property::Short(v) => v as f32,
        Property::UShort(v) => v as f32,
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => return None,
    })
}

fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}
