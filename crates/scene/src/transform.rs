//! Transforms: a list of steps (translate, rotate, scale, matrix, look_at) applied in the
//! order written, so `[A, B, C]` maps a point p to C·B·A·p. Lengths in metres, angles in
//! degrees in the file (`angle_deg`), radians inside.

use glam::{DMat4, DVec3};

use crate::reader::{Result, V};
use crate::schema::schema;

/// A local-to-world affine map and its inverse (f64; render may narrow to `Mat4`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    pub matrix: DMat4,
    pub inverse: DMat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// Determinants below this are treated as singular (a scale of 1e-4 on every axis).
const MIN_ABS_DETERMINANT: f64 = 1e-12;

impl Transform {
    pub const IDENTITY: Transform = Transform {
        matrix: DMat4::IDENTITY,
        inverse: DMat4::IDENTITY,
    };

    /// `None` when the matrix is not finite or not invertible.
    pub fn from_matrix(matrix: DMat4) -> Option<Transform> {
        let det = matrix.determinant();
        if !matrix.is_finite() || !det.is_finite() || det.abs() < MIN_ABS_DETERMINANT {
            return None;
        }
        Some(Transform {
            matrix,
            inverse: matrix.inverse(),
        })
    }

    /// `self` first, then `next`.
    pub fn then(&self, next: &Transform) -> Transform {
        Transform {
            matrix: next.matrix * self.matrix,
            inverse: self.inverse * next.inverse,
        }
    }

    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.matrix.transform_point3(p)
    }

    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.matrix.transform_vector3(v)
    }

    /// Camera-style placement: local origin at `eye`, local −Z towards `target`, local +Y
    /// as close to `up` as possible (the OpenGL/gluLookAt convention, inverted to map
    /// local to world).
    pub fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> Option<Transform> {
        let forward = (target - eye).normalize_or_zero();
        let side = forward.cross(up);
        if forward == DVec3::ZERO || side.length() < 1e-9 * up.length() || !eye.is_finite() {
            return None;
        }
        let right = side.normalize();
        let true_up = right.cross(forward);
        let matrix = DMat4::from_cols(
            right.extend(0.0),
            true_up.extend(0.0),
            (-forward).extend(0.0),
            eye.extend(1.0),
        );
        Transform::from_matrix(matrix)
    }
}

pub(crate) const STEPS: [&str; 5] = ["translate", "rotate", "scale", "matrix", "look_at"];

/// Parses a transform: a list of steps, or one step on its own.
pub(crate) fn parse_transform(v: &V) -> Result<Transform> {
    let steps = match v.array() {
        Ok(items) => items,
        Err(_) => vec![v.clone()],
    };
    let mut total = Transform::IDENTITY;
    for step in &steps {
        total = total.then(&parse_step(step)?);
    }
    Ok(total)
}

fn parse_step(v: &V) -> Result<Transform> {
    let o = v.object(schema!("@transform")).map_err(|e| {
        if !v.is_object() && v.array().is_err() {
            v.type_err("a transform step such as {\"translate\": [x, y, z]} or a list of steps")
        } else {
            e
        }
    })?;
    let Some((kind, arg)) = o.at_most_one(&STEPS)? else {
        return Err(v.err(
            "expected one transform step: `translate`, `rotate`, `scale`, `matrix` or `look_at`",
        ));
    };
    let singular = || arg.err("the transform is not invertible");
    match kind {
        "translate" => {
            let t = arg.numbers::<3>()?;
            Ok(Transform::from_matrix(DMat4::from_translation(t.into())).ok_or_else(singular)?)
        }
        "rotate" => {
            let r = arg.object(schema!("@transform.rotate"))?;
            let axis_v = r.req("axis", "an axis such as [0, 1, 0]")?;
            let axis = DVec3::from(axis_v.numbers::<3>()?);
            if axis.length() < 1e-12 {
                return Err(axis_v.err("expected a non-zero rotation axis"));
            }
            let angle_deg = r.req("angle_deg", "an angle in degrees")?.f64()?;
            let m = DMat4::from_axis_angle(axis.normalize(), angle_deg.to_radians());
            Ok(Transform::from_matrix(m).ok_or_else(singular)?)
        }
        "scale" => {
            let s = match arg.f64() {
                Ok(s) => [s; 3],
                Err(_) => arg
                    .numbers::<3>()
                    .map_err(|_| arg.type_err("a number or an array of 3 numbers"))?,
            };
            if s.contains(&0.0) {
                return Err(arg.err(format!("expected non-zero scale factors, found {s:?}")));
            }
            Ok(Transform::from_matrix(DMat4::from_scale(s.into())).ok_or_else(singular)?)
        }
        "matrix" => {
            let rows = arg.array()?;
            if rows.len() != 4 {
                return Err(arg.err(format!(
                    "expected 4 rows of 4 numbers (row-major), found {} rows",
                    rows.len()
                )));
            }
            let mut m = [[0.0; 4]; 4];
            for (row, item) in m.iter_mut().zip(&rows) {
                *row = item.numbers::<4>()?;
            }
            // Rows as written; glam stores columns.
            let matrix = DMat4::from_cols_array_2d(&m).transpose();
            Ok(Transform::from_matrix(matrix).ok_or_else(singular)?)
        }
        _ => {
            let l = arg.object(schema!("@transform.look_at"))?;
            let eye = DVec3::from(
                l.req("eye", "a position [x, y, z] in metres")?
                    .numbers::<3>()?,
            );
            let target = DVec3::from(
                l.req("target", "a position [x, y, z] in metres")?
                    .numbers::<3>()?,
            );
            let up = DVec3::from(l.vec3_or("up", [0.0, 1.0, 0.0])?);
            Transform::look_at(eye, target, up).ok_or_else(|| {
                arg.err("expected `eye` ≠ `target` and `up` not parallel to the view direction")
            })
        }
    }
}
