//! prism-geometry: rays, frames, transforms, shapes (triangle meshes, spheres, disks,
//! rectangles, cuboids), OBJ/PLY loading, a two-level BVH (obvhs) with watertight triangle
//! intersection, and hit records with uv, ∂p/∂u, ∂n/∂u, principal curvatures and
//! ray differentials.
//!
//! Units: positions and distances in metres, angles in radians, curvature in 1/m.

pub mod bvh_build;
pub mod curvature;
pub mod disk;
pub mod error;
pub mod frame;
pub mod geometry;
pub mod interaction;
pub mod mesh;
pub mod mesh_bvh;
pub mod obj;
pub mod ply;
pub mod ray;
pub mod rectangle;
pub mod sphere;
pub mod transform;
pub mod triangle;
pub mod triangle_geometry;

pub use bvh_build::BuildQuality;
pub use curvature::Curvature;
pub use disk::Disk;
pub use error::MeshLoadError;
pub use frame::Frame;
pub use geometry::{Geometry, GeometryBuilder, Hit, Instance, MeshId, Shape};
pub use interaction::{Differentials, LocalGeometry, SurfaceInteraction};
pub use mesh::{TriangleMesh, NO_MATERIAL};
pub use obj::load_obj;
pub use ply::load_ply;
pub use ray::{Ray, RayDifferential};
pub use rectangle::Rectangle;
pub use sphere::Sphere;
pub use transform::Transform;
pub use triangle::{TriangleHit, WatertightRay};
