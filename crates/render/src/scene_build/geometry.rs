//! Scene shapes → one `prism_geometry::Geometry` (two-level BVH, docs/geometry.md).
//!
//! - Mesh files are loaded once each (OBJ/PLY via prism-geometry) the first time a shape
//!   uses them; a file that fails to parse is reported with the mesh file and line and the
//!   index of the first shape that uses it.
//! - `instances` place the same mesh once per transform: copy i maps to the world by its
//!   own transform, then the shape's (`shape.transform · transforms[i]`).
//! - Cuboids share one unit cube (12 triangles, flat faces) scaled by their size, then
//!   placed by the shape transform.
//! - Every instance carries `material = Some(index)` with index into the scene's
//!   `materials`, or `materials.len()` for the default lambert 0.5; hits report it as
//!   `material_id`.
//! - Instances are added in shape order, so the instances of `shapes[i]` are a contiguous
//!   range of ids (`build_geometry_with_instances`, `shape_instance_ranges`); area lights
//!   use it to find the instances of their shape.

use std::ops::Range;
use std::path::Path;

use glam::{DMat4, DVec3, Vec3A};
use prism_geometry::{
    BuildQuality, Disk, Geometry, GeometryBuilder, MeshId, Rectangle, Shape, Sphere, TriangleMesh,
};
use prism_scene::{MeshFormat, SceneDescription, ShapeKind};

use super::error::SceneBuildError;
use super::transform::to_geometry_transform;

fn load_mesh(asset: &prism_scene::MeshAsset) -> Result<TriangleMesh, String> {
    let mesh = match asset.format {
        MeshFormat::Obj => prism_geometry::load_obj(&asset.path),
        MeshFormat::Ply => prism_geometry::load_ply(&asset.path),
    }
    .map_err(|e| e.to_string())?;
    mesh.validate()
        .map_err(|e| format!("{}: {e}", asset.path.display()))?;
    Ok(mesh)
}

/// Builds the geometry of every shape in `scene`.
pub fn build_geometry(scene: &SceneDescription) -> Result<Geometry, SceneBuildError> {
    build_geometry_with_instances(scene).map(|(geometry, _)| geometry)
}

/// The instance ids of each scene shape, in shape order, without building anything: one
/// per shape, `transforms.len()` for an `instances` shape. Equal to the ranges
/// `build_geometry_with_instances` returns for the same scene.
pub fn shape_instance_ranges(scene: &SceneDescription) -> Vec<Range<u32>> {
    let mut next = 0u32;
    scene
        .shapes
        .iter()
        .map(|shape| {
            let count = match &shape.kind {
                ShapeKind::Instances { transforms, .. } => transforms.len() as u32,
                _ => 1,
            };
            let range = next..next + count;
            next += count;
            range
        })
        .collect()
}

/// Builds the geometry and returns, per scene shape (in order), the range of instance ids
/// it was given.
pub fn build_geometry_with_instances(
    scene: &SceneDescription,
) -> Result<(Geometry, Vec<Range<u32>>), SceneBuildError> {
    let file: &Path = &scene.file;
    let mut ranges: Vec<Range<u32>> = Vec::with_capacity(scene.shapes.len());
    let mut instance_count = 0u32;
    let default_material = scene.materials.len() as u32;
    let mut builder = GeometryBuilder::new();
    let mut mesh_ids: Vec<Option<MeshId>> = vec![None; scene.meshes.len()];
    let mut unit_cube: Option<MeshId> = None;

    for (i, shape) in scene.shapes.iter().enumerate() {
        let place = match &shape.name {
            Some(name) => format!("shapes[{i}] (`{name}`)"),
            None => format!("shapes[{i}]"),
        };
        let err = |message: String| SceneBuildError::new(file, place.clone(), message);
        let material = Some(shape.material.map_or(default_material, |m| m as u32));
        let mut mesh_id = |m: usize| -> Result<MeshId, SceneBuildError> {
            if let Some(Some(id)) = mesh_ids.get(m) {
                return Ok(*id);
            }
            let asset = scene
                .meshes
                .get(m)
                .ok_or_else(|| err(format!("mesh index {m} is not in the scene's meshes")))?;
            let mesh = load_mesh(asset).map_err(|e| err(format!("cannot load the mesh: {e}")))?;
            let id = builder_add_mesh(&mut builder, mesh);
            mesh_ids[m] = Some(id);
            Ok(id)
        };
        let mut placements: Vec<(Shape, DMat4)> = Vec::new();
        let m = shape.transform.matrix;
        match &shape.kind {
            ShapeKind::Mesh { mesh } => placements.push((Shape::Mesh(mesh_id(*mesh)?), m)),
            ShapeKind::Instances { mesh, transforms } => {
                let id = mesh_id(*mesh)?;
                for t in transforms {
                    placements.push((Shape::Mesh(id), m * t.matrix));
                }
            }
            ShapeKind::Sphere { radius_m } => placements.push((
                Shape::Sphere(Sphere {
                    radius_m: *radius_m as f32,
                }),
                m,
            )),
            ShapeKind::Disk { radius_m } => placements.push((
                Shape::Disk(Disk {
                    radius_m: *radius_m as f32,
                }),
                m,
            )),
            ShapeKind::Rectangle { size_m } => placements.push((
                Shape::Rectangle(Rectangle {
                    half_width_m: (0.5 * size_m[0]) as f32,
                    half_height_m: (0.5 * size_m[1]) as f32,
                }),
                m,
            )),
            ShapeKind::Cuboid { size_m } => {
                let id = *unit_cube.get_or_insert_with(|| {
                    builder_add_mesh(&mut builder, TriangleMesh::cuboid(Vec3A::splat(0.5)))
                });
                placements.push((Shape::Mesh(id), m * DMat4::from_scale(DVec3::from(*size_m))));
            }
        }
        let first = instance_count;
        for (k, (geometry_shape, matrix)) in placements.into_iter().enumerate() {
            let to_world = to_geometry_transform(&matrix).ok_or_else(|| {
                err(format!(
                    "transform{} is not invertible in single precision",
                    if matches!(shape.kind, ShapeKind::Instances { .. }) {
                        format!(" of instance {k}")
                    } else {
                        String::new()
                    }
                ))
            })?;
            builder
                .add_instance(geometry_shape, to_world, material)
                .ok_or_else(|| {
                    err("internal error: instance of a mesh that was not added".into())
                })?;
            instance_count += 1;
        }
        ranges.push(first..instance_count);
    }
    Ok((builder.build(BuildQuality::default()), ranges))
}

fn builder_add_mesh(builder: &mut GeometryBuilder, mesh: TriangleMesh) -> MeshId {
    builder.add_mesh(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_instance_ranges_match_the_built_geometry() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("tri.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let json = r#"{"meshes": {"tri": "tri.obj"}, "shapes": [
            {"type": "sphere"},
            {"type": "instances", "mesh": "tri", "instances": [{"translate": [1, 0, 0]}, {"translate": [2, 0, 0]}, {"scale": 2}]},
            {"type": "cuboid"}, {"type": "mesh", "mesh": "tri"}, {"type": "disk"}]}"#;
        let scene = prism_scene::parse_scene_str(json, dir.path().join("scene.json")).unwrap();
        let (geometry, ranges) = build_geometry_with_instances(&scene).unwrap();
        assert_eq!(ranges, vec![0..1, 1..4, 4..5, 5..6, 6..7]);
        assert_eq!(shape_instance_ranges(&scene), ranges);
        assert_eq!(geometry.instances().len(), 7);
    }
}
