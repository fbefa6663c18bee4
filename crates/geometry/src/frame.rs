//! Orthonormal frames (pbrt-v4 §3.3.3 "Coordinate system from a vector", using the branchless
//! construction of Duff et al. 2017, "Building an orthonormal basis, revisited", JCGT 6(1)).

use glam::Vec3A;

/// An orthonormal basis `x, y, z` (right-handed: `x × y = z`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub x: Vec3A,
    pub y: Vec3A,
    pub z: Vec3A,
}

impl Frame {
    /// A frame whose `z` axis is the unit vector `z` (Duff et al. 2017, listing 3).
    pub fn from_z(z: Vec3A) -> Self {
        let sign = 1.0f32.copysign(z.z);
        let a = -1.0 / (sign + z.z);
        let b = z.x * z.y * a;
        let x = Vec3A::new(1.0 + sign * z.x * z.x * a, sign * b, -sign * z.x);
        let y = Vec3A::new(b, sign + z.y * z.y * a, -z.y);
        Self { x, y, z }
    }

    /// A frame from `z` and a direction `x_hint` projected to be orthogonal to it
    /// (Gram–Schmidt); falls back to [`Frame::from_z`] when they are parallel.
    pub fn from_zx(z: Vec3A, x_hint: Vec3A) -> Self {
        let x = x_hint - z * z.dot(x_hint);
        let len = x.length();
        if len > 1e-6 * x_hint.length() && len > 0.0 {
            let x = x / len;
            Self {
                x,
                y: z.cross(x),
                z,
            }
        } else {
            Self::from_z(z)
        }
    }

    /// World vector → local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// Local coordinates → world vector.
    #[inline]
    pub fn from_local(&self, v: Vec3A) -> Vec3A {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}
