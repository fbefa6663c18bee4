//! prism-geometry: rays, frames, transforms, shapes (triangle meshes, spheres, disks,
//! rectangles, cuboids), OBJ/PLY loading, one BVH (obvhs) over the scene — small and
//! single-use meshes flattened into world-space triangles, everything else as instances — with
//! watertight triangle intersection, and hit records with uv, ∂p/∂u, ∂n/∂u, principal
//! curvatures and ray differentials.
//!
//! Units: positions and distances in metres, angles in radians, curvature in 1/m.

pub mod bvh_build;
pub mod coincident_boxes;
pub mod curvature;
pub mod cwbvh_convert;
pub mod disk;
pub mod error;
pub mod fast_path;
pub mod frame;
pub mod geometry;
pub mod interaction;
mod leaf_record;
pub mod mesh;
pub mod mesh_bvh;
pub mod obj;
pub mod ply;
mod ply_binary;
pub mod ray;
pub mod rectangle;
mod small_scene;
pub mod sphere;
pub mod tiling;
pub mod transform;
pub mod triangle;
mod triangle_bvh;
pub mod triangle_geometry;

pub use bvh_build::BuildQuality;
pub use curvature::Curvature;
pub use disk::Disk;
pub use error::MeshLoadError;
pub use frame::Frame;
pub use geometry::{
    BuildOptions, Geometry, GeometryBuilder, Hit, Instance, MeshId, Shape,
    FLATTEN_MAX_SHARED_MESH_TRIANGLES, FLATTEN_SHARED_TRIANGLE_BUDGET, SMALL_SCENE_MAX_LEAVES,
};
pub use interaction::{Differentials, LocalGeometry, SurfaceInteraction};
pub use mesh::{TriangleMesh, NO_MATERIAL};
pub use obj::load_obj;
pub use ply::load_ply;
pub use ray::{Ray, RayDifferential};
pub use rectangle::Rectangle;
pub use sphere::Sphere;
pub use tiling::{open_seam_edges, Tiling};
pub use transform::Transform;
pub use triangle::{TriangleHit, WatertightRay};
