//! Scene transforms (f64 `DMat4`, local-to-world) to geometry transforms (f32 affine).

use glam::DMat4;
use prism_geometry::Transform;

/// The f32 transform of a scene matrix; `None` when it is not affine-invertible in f32
/// (prism-scene already rejects singular matrices in f64, so this is a precision limit).
pub fn to_geometry_transform(matrix: &DMat4) -> Option<Transform> {
    Transform::from_matrix(matrix.as_mat4())
}
