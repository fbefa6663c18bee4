//! PLY loading through `ply-rs` (ASCII, binary little and big endian). Vertices need x, y, z;
//! nx, ny, nz and u, v (or s, t, texture_u/texture_v, texture_s/texture_t) are used when
//! present. Faces come from a `vertex_indices` or `vertex_index` list and are fan-triangulated.
//! `ply-rs` reads the header and ASCII payloads; binary payloads are decoded by
//! ply_binary.rs.

use std::io::{BufReader, Read};
use std::path::Path;

use glam::{Vec2, Vec3A};
use ply_rs::parser::Parser;
use ply_rs::ply::{DefaultElement, Encoding, Header, Payload, Property, PropertyType};

use crate::error::MeshLoadError;
use crate::mesh::TriangleMesh;
use crate::ply_binary::decode_binary_payload;

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

/// Vertex properties a triangle mesh uses: position, normal and the uv spellings PLY writers
/// use.
pub(crate) const VERTEX_PROPERTIES: [&str; 14] = [
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "u",
    "v",
    "s",
    "t",
    "texture_u",
    "texture_v",
    "texture_s",
    "texture_t",
];

/// The face element's index list, by the names writers give it (first found wins).
pub(crate) const FACE_INDEX_PROPERTIES: [&str; 2] = ["vertex_indices", "vertex_index"];

/// The face element's corner lists.
pub(crate) enum FaceIndices {
    /// Face f's corners are `corners[starts[f]..starts[f + 1]]`.
    Lists {
        starts: Vec<usize>,
        corners: Vec<i64>,
    },
    /// The face element declares no index list.
    Missing,
    /// The index list holds floating-point numbers (or is no list).
    NotIntegers,
}

impl FaceIndices {
    pub(crate) fn default_lists() -> Self {
        FaceIndices::Lists {
            starts: Vec::new(),
            corners: Vec::new(),
        }
    }
}

/// The parts of a PLY payload a triangle mesh is made of, whatever the encoding.
pub(crate) struct MeshColumns {
    pub vertex_count: usize,
    /// The vertex properties of [`VERTEX_PROPERTIES`] the file declares, with their values
    /// (`None` for one declared as a list) in `vertex_columns`.
    pub vertex_names: Vec<String>,
    pub vertex_columns: Vec<Option<Vec<f32>>>,
    pub face_count: usize,
    pub faces: FaceIndices,
}

impl Default for MeshColumns {
    fn default() -> Self {
        MeshColumns {
            vertex_count: 0,
            vertex_names: Vec::new(),
            vertex_columns: Vec::new(),
            face_count: 0,
            faces: FaceIndices::default_lists(),
        }
    }
}

impl MeshColumns {
    /// The property's values: `None` if undeclared, `Some(None)` if declared as a list.
    fn vertex(&self, name: &str) -> Option<Option<&[f32]>> {
        let i = self.vertex_names.iter().position(|n| n == name)?;
        Some(self.vertex_columns[i].as_deref())
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
    let parse_error = |e: std::io::Error| {
        let hint = if e.kind() == std::io::ErrorKind::UnexpectedEof {
            " — the file ends before all elements the header declares were read (truncated file?)"
        } else {
            ""
        };
        let (line, message) = ply_error_message(&e.to_string());
        MeshLoadError::new(path, line, format!("cannot parse PLY: {message}{hint}"))
    };
    // ply-rs has a few panicking paths on malformed input; user input must never panic here.
    let malformed = || err("malformed PLY file (the PLY parser could not make sense of it)".into());
    let parser = Parser::<DefaultElement>::new();
    let header = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        parser.read_header(&mut reader)
    }))
    .map_err(|_| malformed())?
    .map_err(parse_error)?;
    let columns = match header.encoding {
        Encoding::Ascii => {
            // Read again from the start so that ply-rs' error lines count the header's.
            let mut file =
                std::fs::File::open(path).map_err(|e| err(format!("cannot open PLY file: {e}")))?;
            let ply = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                parser.read_ply(&mut file)
            }))
            .map_err(|_| malformed())?
            .map_err(parse_error)?;
            ascii_columns(&ply.header, &ply.payload)
        }
        Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
            let mut bytes = Vec::new();
            reader
                .read_to_end(&mut bytes)
                .map_err(|e| err(format!("cannot read PLY file: {e}")))?;
            decode_binary_payload(&header, &bytes).map_err(err)?
        }
    };
    if !header.elements.contains_key("vertex") {
        return Err(err(
            "no 'vertex' element; expected 'element vertex N' in the header".into(),
        ));
    }
    mesh_from_columns(columns).map_err(err)
}

/// The columns of an ASCII payload read by ply-rs.
fn ascii_columns(header: &Header, payload: &Payload<DefaultElement>) -> MeshColumns {
    let mut columns = MeshColumns::default();
    let no_elements = Vec::new();
    if let Some(def) = header.elements.get("vertex") {
        let vertices = payload.get("vertex").unwrap_or(&no_elements);
        columns.vertex_count = vertices.len();
        for (name, prop) in &def.properties {
            if !VERTEX_PROPERTIES.contains(&name.as_str()) {
                continue;
            }
            columns.vertex_names.push(name.clone());
            columns.vertex_columns.push(match prop.data_type {
                PropertyType::Scalar(_) => Some(
                    vertices
                        .iter()
                        .map(|v| v.get(name).and_then(scalar).unwrap_or(0.0))
                        .collect(),
                ),
                PropertyType::List(..) => None,
            });
        }
    }
    if let Some(def) = header.elements.get("face") {
        let faces = payload.get("face").unwrap_or(&no_elements);
        columns.face_count = faces.len();
        let list_name = FACE_INDEX_PROPERTIES
            .iter()
            .find(|p| def.properties.contains_key(**p));
        columns.faces = match list_name {
            None => FaceIndices::Missing,
            Some(list_name) => {
                let mut starts = vec![0];
                let mut corners = Vec::new();
                let mut integers = true;
                for face in faces {
                    match face.get(*list_name).and_then(index_list) {
                        Some(idx) => corners.extend(idx),
                        None => integers = false,
                    }
                    starts.push(corners.len());
                }
                if integers {
                    FaceIndices::Lists { starts, corners }
                } else {
                    FaceIndices::NotIntegers
                }
            }
        };
    }
    columns
}

/// The mesh the columns describe: positions required; normals and uvs where declared; faces
/// fan-triangulated. Errors are sentences naming the vertex or face.
fn mesh_from_columns(columns: MeshColumns) -> Result<TriangleMesh, String> {
    let nv = columns.vertex_count;
    let mut xyz: [&[f32]; 3] = [&[]; 3];
    for (slot, c) in xyz.iter_mut().zip(["x", "y", "z"]) {
        match columns.vertex(c) {
            None if nv > 0 => {
                return Err(format!(
                    "element 'vertex' has no scalar property '{c}'; expected x, y, z"
                ))
            }
            Some(None) if nv > 0 => {
                return Err("vertex 0: x, y, z must be numeric scalars".to_string())
            }
            None | Some(None) => {}
            Some(Some(values)) => *slot = values,
        }
    }
    let positions: Vec<Vec3A> = (0..nv)
        .map(|i| Vec3A::new(xyz[0][i], xyz[1][i], xyz[2][i]))
        .collect();
    let scalar_column = |name: &str| -> Result<Option<&[f32]>, String> {
        match columns.vertex(name) {
            None => Ok(None),
            Some(None) => Err(format!(
                "vertex property '{name}' is a list; expected a scalar"
            )),
            Some(Some(values)) => Ok(Some(values)),
        }
    };
    let normals = match (
        scalar_column("nx")?,
        scalar_column("ny")?,
        scalar_column("nz")?,
    ) {
        (Some(x), Some(y), Some(z)) => Some(
            (0..nv)
                .map(|i| Vec3A::new(x[i], y[i], z[i]))
                .collect::<Vec<_>>(),
        ),
        _ => None,
    };
    let uv_names = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ];
    let mut uvs = None;
    for (u, v) in uv_names {
        if let (Some(u), Some(v)) = (scalar_column(u)?, scalar_column(v)?) {
            uvs = Some((0..nv).map(|i| Vec2::new(u[i], v[i])).collect::<Vec<_>>());
            break;
        }
    }

    let mut indices = Vec::new();
    if columns.face_count > 0 {
        let (starts, corners) = match &columns.faces {
            FaceIndices::Lists { starts, corners } => (starts, corners),
            FaceIndices::Missing => {
                return Err(
                    "face 0 has no 'vertex_indices' or 'vertex_index' list property".to_string(),
                )
            }
            FaceIndices::NotIntegers => {
                return Err("face 0: vertex indices must be an integer list".to_string())
            }
        };
        indices.reserve(corners.len().saturating_sub(2 * columns.face_count));
        for (f, span) in starts.windows(2).enumerate() {
            let idx = &corners[span[0]..span[1]];
            if idx.len() < 3 {
                return Err(format!(
                    "face {f} has {} vertices; expected at least 3",
                    idx.len()
                ));
            }
            if let Some(&i) = idx.iter().find(|&&i| i < 0 || i as usize >= nv) {
                return Err(format!(
                    "face {f} refers to vertex {i}, but element 'vertex' has {nv} vertices (indices start at 0)"
                ));
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
    mesh.validate()?;
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
