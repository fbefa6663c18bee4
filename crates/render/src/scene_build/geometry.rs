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
//! - The small-scene intersector (prism-geometry `small_scene`: no BVH, every leaf tested
//!   eight at a time) is allowed where the scene's features are all in
//!   [`SMALL_SCENE_SUPPORTS`]; within that, the geometry crate decides by leaf count.

use std::ops::Range;
use std::path::Path;

use glam::{DMat4, DVec3, Vec3A};
use prism_geometry::{
    BuildOptions, BuildQuality, Disk, Geometry, GeometryBuilder, MeshId, Rectangle, Shape, Sphere,
    TriangleMesh, SMALL_SCENE_MAX_LEAVES,
};
use prism_scene::{MeshFormat, SceneDescription, ShapeKind};

use super::error::SceneBuildError;
use super::features::{SceneFeature, SceneFeatures};
use super::tiles::{tile_of, CarrierQuad, TileMeshes};
use super::transform::to_geometry_transform;

/// The features the small-scene intersector handles. It only finds the closest surface:
/// triangles and rectangles in batches, every other leaf (spheres, disks, instanced meshes)
/// one by one, each with the scene's own exact test, so materials, lights, cameras and
/// integrators do not concern it. Participating media are left out until they render: the
/// change that renders them decides.
pub const SMALL_SCENE_SUPPORTS: SceneFeatures = SceneFeatures::of(&[
    SceneFeature::DiagnosticIntegrator,
    SceneFeature::LightPaths,
    SceneFeature::OpacityMasks,
    SceneFeature::ThinGlazing,
    SceneFeature::Dispersion,
    SceneFeature::Textures,
    SceneFeature::NonLambertianBsdfs,
    SceneFeature::TwoSidedMaterials,
    // Materials do not concern it: re-radiation changes wavelengths, not intersections.
    SceneFeature::Reradiation,
    SceneFeature::ShadingNormalMaps,
    SceneFeature::VertexNormals,
    SceneFeature::Quadrics,
    SceneFeature::InfiniteLights,
    SceneFeature::DeltaLights,
    SceneFeature::NonRectangleAreaLights,
    SceneFeature::ThinLensCamera,
    // The solution's visibility and coverage rays are plain queries, and its gathers read
    // the instance and primitive ids the small-scene records carry.
    SceneFeature::RadiositySolution,
    // A tiled carrier is an instance leaf tested on its own (`others`), by the same
    // virtual ray tracing as in the BVH.
    SceneFeature::TiledSurfaces,
]);

/// How to build the geometry of a scene with `features`: the default options, without the
/// small-scene intersector where a feature is outside [`SMALL_SCENE_SUPPORTS`].
pub(crate) fn build_options(features: SceneFeatures) -> BuildOptions {
    let options = BuildOptions::from(BuildQuality::default());
    if features.is_subset_of(SMALL_SCENE_SUPPORTS) {
        options
    } else {
        BuildOptions {
            small_scene_max_leaves: 0,
            ..options
        }
    }
}

/// Why `geometry`, built for `features`, is not traced as a small scene; `None` when it is.
pub fn small_scene_not_used(geometry: &Geometry, features: SceneFeatures) -> Option<String> {
    let outside = features.outside(SMALL_SCENE_SUPPORTS);
    if !outside.is_empty() {
        return Some(outside.names());
    }
    if geometry.is_small_scene() {
        return None;
    }
    let leaves = geometry.flattened_triangle_count() + geometry.instance_leaf_count();
    Some(match leaves {
        0 => "the scene has no geometry".into(),
        1 => "a single instance, tested directly".into(),
        n => format!("{n} leaves, more than the {SMALL_SCENE_MAX_LEAVES} of a small scene"),
    })
}

/// The shapes of a scene placed in a builder, before its acceleration structure is built.
pub(crate) struct PlacedShapes {
    pub builder: GeometryBuilder,
    /// Per scene shape, in order, the range of instance ids it was given.
    pub ranges: Vec<Range<u32>>,
    /// A mesh that some shape places has vertex normals.
    pub vertex_normals: bool,
}

pub(crate) fn load_mesh(asset: &prism_scene::MeshAsset) -> Result<TriangleMesh, String> {
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
/// per shape, `transforms.len()` for an `instances` shape, one per carrier quad for a
/// `tiled` mesh (whose file is read for it). Equal to the ranges
/// `build_geometry_with_instances` returns for the same scene.
pub fn shape_instance_ranges(scene: &SceneDescription) -> Vec<Range<u32>> {
    let mut next = 0u32;
    scene
        .shapes
        .iter()
        .map(|shape| {
            let count = if tile_of(scene, shape.material).is_some() {
                // A carrier that cannot be read fails the geometry build, which reports it.
                carrier_quads(scene, &shape.kind).map_or(0, |q| q.len() as u32)
            } else {
                match &shape.kind {
                    ShapeKind::Instances { transforms, .. } => transforms.len() as u32,
                    _ => 1,
                }
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
    let placed = place_shapes(scene)?;
    Ok((placed.builder.build(BuildQuality::default()), placed.ranges))
}

/// Loads the meshes of `scene` and places every shape in a `GeometryBuilder`.
pub(crate) fn place_shapes(scene: &SceneDescription) -> Result<PlacedShapes, SceneBuildError> {
    let file: &Path = &scene.file;
    let mut ranges: Vec<Range<u32>> = Vec::with_capacity(scene.shapes.len());
    let mut instance_count = 0u32;
    let default_material = scene.materials.len() as u32;
    let mut builder = GeometryBuilder::new();
    let mut mesh_ids: Vec<Option<MeshId>> = vec![None; scene.meshes.len()];
    let mut unit_cube: Option<MeshId> = None;
    let mut vertex_normals = false;
    let mut tile_meshes = TileMeshes::default();

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
            vertex_normals |= mesh.normals.is_some();
            let id = builder_add_mesh(&mut builder, mesh);
            mesh_ids[m] = Some(id);
            Ok(id)
        };
        let mut placements: Vec<(Shape, DMat4)> = Vec::new();
        let m = shape.transform.matrix;
        if let Some(tile) = tile_of(scene, shape.material) {
            let t = &scene.tiles[tile];
            let material_name = &scene.materials[shape.material.expect("tile_of found it")].name;
            let carriers = carrier_quads(scene, &shape.kind)
                .map_err(|e| err(format!("material `{material_name}` is `tiled`: {e}")))?;
            let mesh = tile_meshes
                .mesh(scene, tile, &mut builder)
                .map_err(|e| SceneBuildError::new(file, format!("tiles.{}", t.name), e))?;
            let first = instance_count;
            for (k, (quad, matrix)) in carriers.iter().enumerate() {
                let at = |e: String| {
                    if carriers.len() == 1 {
                        err(e)
                    } else {
                        err(format!("quad {k}: {e}"))
                    }
                };
                let (tiling, tile_to_world) =
                    quad.tiling(&(m * *matrix), t.period_m, mesh).map_err(at)?;
                let to_world = to_geometry_transform(&tile_to_world).ok_or_else(|| {
                    at("the tile's placement is not invertible in single precision".into())
                })?;
                builder
                    .add_instance(Shape::Tiled(tiling), to_world, material)
                    .ok_or_else(|| {
                        at(format!(
                            "{} × {} periods of tile `{}` are too many copies to address \
                             (cells × the tile's triangles must stay below 2³²)",
                            tiling.cells[0], tiling.cells[1], t.name
                        ))
                    })?;
                instance_count += 1;
            }
            ranges.push(first..instance_count);
            continue;
        }
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
                    let cube = TriangleMesh::cuboid(Vec3A::splat(0.5));
                    vertex_normals |= cube.normals.is_some();
                    builder_add_mesh(&mut builder, cube)
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
    Ok(PlacedShapes {
        builder,
        ranges,
        vertex_normals: vertex_normals || tile_meshes.vertex_normals,
    })
}

/// The carrier quads of a shape with a `tiled` material, each with the matrix that places
/// it in the shape's space (an `instances` copy's transform; identity otherwise): a
/// rectangle is one quad, a mesh its parallelogram quad faces. Other shapes are errors.
fn carrier_quads(
    scene: &SceneDescription,
    kind: &ShapeKind,
) -> Result<Vec<(CarrierQuad, DMat4)>, String> {
    let mesh_quads = |m: usize| -> Result<Vec<CarrierQuad>, String> {
        let asset = scene
            .meshes
            .get(m)
            .ok_or_else(|| format!("mesh index {m} is not in the scene's meshes"))?;
        let mesh = load_mesh(asset).map_err(|e| format!("cannot load the carrier mesh: {e}"))?;
        CarrierQuad::of_mesh(&mesh)
    };
    Ok(match kind {
        ShapeKind::Rectangle { size_m } => vec![(CarrierQuad::rectangle(*size_m), DMat4::IDENTITY)],
        ShapeKind::Mesh { mesh } => mesh_quads(*mesh)?
            .into_iter()
            .map(|q| (q, DMat4::IDENTITY))
            .collect(),
        ShapeKind::Instances { mesh, transforms } => {
            let quads = mesh_quads(*mesh)?;
            transforms
                .iter()
                .flat_map(|t| quads.iter().map(move |q| (*q, t.matrix)))
                .collect()
        }
        ShapeKind::Sphere { .. } | ShapeKind::Disk { .. } | ShapeKind::Cuboid { .. } => {
            return Err(format!(
                "its carrier must be a `rectangle` or a mesh of quadrilateral faces (patches \
                 whose corners are tile corners), not a {}",
                shape_kind_name(kind)
            ))
        }
    })
}

/// What a shape kind is called in the scene format.
fn shape_kind_name(kind: &ShapeKind) -> &'static str {
    match kind {
        ShapeKind::Mesh { .. } => "mesh",
        ShapeKind::Instances { .. } => "mesh placed by `instances`",
        ShapeKind::Sphere { .. } => "sphere",
        ShapeKind::Disk { .. } => "disk",
        ShapeKind::Rectangle { .. } => "rectangle",
        ShapeKind::Cuboid { .. } => "cuboid",
    }
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

    #[test]
    fn a_feature_outside_the_small_scene_list_builds_the_bvh() {
        let json = r#"{"shapes": [{"type": "rectangle"}, {"type": "sphere"}]}"#;
        let scene = prism_scene::parse_scene_str(json, "scene.json").unwrap();
        let quadrics = SceneFeatures::of(&[SceneFeature::Quadrics]);
        assert_eq!(
            build_options(quadrics),
            BuildOptions::from(BuildQuality::default())
        );
        let geometry = place_shapes(&scene)
            .unwrap()
            .builder
            .build_with(build_options(quadrics));
        assert!(geometry.is_small_scene());
        assert_eq!(small_scene_not_used(&geometry, quadrics), None);
        // Participating media are outside the list: no small scene, and the reason names them.
        let fog = SceneFeatures::of(&[SceneFeature::Quadrics, SceneFeature::ParticipatingMedia]);
        assert_eq!(build_options(fog).small_scene_max_leaves, 0);
        let geometry = place_shapes(&scene)
            .unwrap()
            .builder
            .build_with(build_options(fog));
        assert!(!geometry.is_small_scene());
        assert_eq!(
            small_scene_not_used(&geometry, fog).as_deref(),
            Some("participating media")
        );
    }
}
