//! Shape descriptions: mesh files (OBJ, PLY — parsed by prism-geometry), analytic sphere,
//! rectangle, disk and cuboid, and instances of one named mesh under many transforms.

use std::path::PathBuf;

use crate::material::material_index;
use crate::reader::{quoted_list, suggest, Result, V};
use crate::schema::schema;
use crate::transform::{parse_transform, Transform};

/// A mesh file to load once and share between the shapes that use it.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshAsset {
    /// The key in the `meshes` section; `None` for a file given directly on a shape.
    pub name: Option<String>,
    /// Resolved against the scene file's folder; checked to exist.
    pub path: PathBuf,
    pub format: MeshFormat,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Unique when given; area lights refer to shapes by name.
    pub name: Option<String>,
    pub kind: ShapeKind,
    /// Local-to-world.
    pub transform: Transform,
    /// Index into `SceneDescription::materials`; `None`: the default diffuse material
    /// (lambert, reflectance 0.5).
    pub material: Option<usize>,
    /// Indices into `SceneDescription::media`: inside the surface, and outside it.
    pub interior_medium: Option<usize>,
    pub exterior_medium: Option<usize>,
}

/// Analytic shapes are centred on their local origin.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeKind {
    /// Index into `SceneDescription::meshes`.
    Mesh {
        mesh: usize,
    },
    Sphere {
        radius_m: f64,
    },
    /// In the local XY plane, normal +Z; width along X, height along Y.
    Rectangle {
        size_m: [f64; 2],
    },
    /// In the local XY plane, normal +Z.
    Disk {
        radius_m: f64,
    },
    /// Axis-aligned box with these edge lengths along X, Y, Z.
    Cuboid {
        size_m: [f64; 3],
    },
    /// One mesh placed many times: instance i maps to the world by `transforms[i]` then
    /// the shape's own `transform`.
    Instances {
        mesh: usize,
        transforms: Vec<Transform>,
    },
}

pub const SHAPE_TYPES: [&str; 6] = ["mesh", "sphere", "rectangle", "disk", "cuboid", "instances"];

/// Resolves a mesh file path and its format from the extension.
pub(crate) fn parse_mesh_file(v: &V) -> Result<(PathBuf, MeshFormat)> {
    let path = v.asset("mesh", &["obj", "ply"])?;
    let is_ply = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ply"));
    Ok((
        path,
        if is_ply {
            MeshFormat::Ply
        } else {
            MeshFormat::Obj
        },
    ))
}

/// The `meshes` section: `{"bunny": "meshes/bunny.ply"}` or `{"bunny": {"file": …}}`.
pub(crate) fn parse_meshes(v: &V) -> Result<Vec<MeshAsset>> {
    let mut out = Vec::new();
    for (name, entry) in v.map()? {
        let file = if entry.str().is_ok() {
            entry
        } else {
            entry
                .object(schema!("meshes.*"))?
                .req("file", "a .obj or .ply file")?
        };
        let (path, format) = parse_mesh_file(&file)?;
        out.push(MeshAsset {
            name: Some(name.to_string()),
            path,
            format,
        });
    }
    Ok(out)
}

/// Names that shapes may refer to.
pub(crate) struct ShapeContext<'a> {
    pub materials: &'a [&'a str],
    pub media: &'a [&'a str],
}

pub(crate) fn named_index(v: &V, what: &str, section: &str, names: &[&str]) -> Result<usize> {
    let wanted = v.str()?;
    names.iter().position(|n| *n == wanted).ok_or_else(|| {
        let known = if names.is_empty() {
            format!("the `{section}` section is empty")
        } else {
            format!("defined: {}", quoted_list(names))
        };
        v.err(format!(
            "unknown {what} `{wanted}` ({known}){}",
            suggest(wanted, names.iter().copied())
        ))
    })
}

pub(crate) fn named_mesh(v: &V, meshes: &[MeshAsset]) -> Result<usize> {
    let names: Vec<&str> = meshes.iter().filter_map(|m| m.name.as_deref()).collect();
    let wanted = names[named_index(v, "mesh", "meshes", &names)?];
    Ok(meshes
        .iter()
        .position(|m| m.name.as_deref() == Some(wanted))
        .unwrap_or_default())
}

/// Parses one shape; mesh files named directly on it are appended to `meshes`.
pub(crate) fn parse_shape(v: &V, cx: &ShapeContext, meshes: &mut Vec<MeshAsset>) -> Result<Shape> {
    let kind = v.tag("shape", &SHAPE_TYPES, None)?;
    let (o, kind) = match kind {
        "mesh" => {
            let o = v.object(schema!("shapes[]<mesh>"))?;
            let mesh = match o.at_most_one(&["file", "mesh"])? {
                Some(("file", f)) => {
                    let (path, format) = parse_mesh_file(&f)?;
                    meshes.push(MeshAsset {
                        name: None,
                        path,
                        format,
                    });
                    meshes.len() - 1
                }
                Some((_, m)) => named_mesh(&m, meshes)?,
                None => {
                    return Err(v.err(
                        "missing field `file`: expected a .obj or .ply file (or `mesh`: a name from `meshes`)",
                    ))
                }
            };
            (o, ShapeKind::Mesh { mesh })
        }
        "sphere" => {
            let o = v.object(schema!("shapes[]<sphere>"))?;
            let radius_m = o.positive_or("radius_m", 1.0)?;
            (o, ShapeKind::Sphere { radius_m })
        }
        "rectangle" => {
            let o = v.object(schema!("shapes[]<rectangle>"))?;
            let size_m = match o.get("size_m") {
                None => [1.0, 1.0],
                Some(s) => positive_numbers::<2>(&s)?,
            };
            (o, ShapeKind::Rectangle { size_m })
        }
        "disk" => {
            let o = v.object(schema!("shapes[]<disk>"))?;
            let radius_m = o.positive_or("radius_m", 1.0)?;
            (o, ShapeKind::Disk { radius_m })
        }
        "cuboid" => {
            let o = v.object(schema!("shapes[]<cuboid>"))?;
            let size_m = match o.get("size_m") {
                None => [1.0, 1.0, 1.0],
                Some(s) => positive_numbers::<3>(&s)?,
            };
            (o, ShapeKind::Cuboid { size_m })
        }
        _ => {
            let o = v.object(schema!("shapes[]<instances>"))?;
            let mesh = named_mesh(&o.req("mesh", "a name from the `meshes` section")?, meshes)?;
            let list = o.req("instances", "a list of transforms, one per instance")?;
            let transforms = list
                .array()?
                .iter()
                .map(parse_transform)
                .collect::<Result<Vec<_>>>()?;
            if transforms.is_empty() {
                return Err(list.err("expected at least one instance transform"));
            }
            (o, ShapeKind::Instances { mesh, transforms })
        }
    };
    // A medium inside needs an inside: flat shapes have none (meshes are checked for
    // boundary edges when render loads them).
    if let (Some(m), ShapeKind::Rectangle { .. } | ShapeKind::Disk { .. }) =
        (o.get("interior_medium"), &kind)
    {
        return Err(m.err(
            "a rectangle or disk is open (it encloses no volume), so it has no interior \
             medium: give a closed shape (sphere, cuboid, closed mesh) or only \
             `exterior_medium`",
        ));
    }
    Ok(Shape {
        name: o
            .get("name")
            .map(|n| n.str().map(str::to_string))
            .transpose()?,
        kind,
        transform: o
            .get("transform")
            .map_or(Ok(Transform::IDENTITY), |t| parse_transform(&t))?,
        material: o
            .get("material")
            .map(|m| material_index(&m, cx.materials))
            .transpose()?,
        interior_medium: o
            .get("interior_medium")
            .map(|m| named_index(&m, "medium", "media", cx.media))
            .transpose()?,
        exterior_medium: o
            .get("exterior_medium")
            .map(|m| named_index(&m, "medium", "media", cx.media))
            .transpose()?,
    })
}

fn positive_numbers<const N: usize>(v: &V) -> Result<[f64; N]> {
    let values = v.numbers::<N>()?;
    for (i, item) in v.array()?.iter().enumerate() {
        if values[i] <= 0.0 {
            return Err(item.err(format!("expected a positive size, found {}", values[i])));
        }
    }
    Ok(values)
}
