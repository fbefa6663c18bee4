//! Affine transforms with their inverse (pbrt-v4 §3.9 "Transformations"; §3.10 "Applying
//! transformations", normals by the inverse transpose, §3.10.3).

use glam::{Affine3A, Mat3A, Mat4, Vec3, Vec3A};

use crate::ray::Ray;

/// An affine transform `M` stored with `M⁻¹`, mapping object space to world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    m: Affine3A,
    m_inv: Affine3A,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        m: Affine3A::IDENTITY,
        m_inv: Affine3A::IDENTITY,
    };

    /// Translation by `offset_m`.
    pub fn translate(offset_m: Vec3A) -> Self {
        Self {
            m: Affine3A::from_translation(offset_m.into()),
            m_inv: Affine3A::from_translation((-offset_m).into()),
        }
    }

    /// Rotation by `angle_rad` about `axis` (normalised here), right-handed.
    /// Returns `None` for a zero or non-finite axis.
    pub fn rotate(axis: Vec3A, angle_rad: f32) -> Option<Self> {
        let axis = Vec3::from(axis).try_normalize()?;
        let m = Affine3A::from_axis_angle(axis, angle_rad);
        Some(Self {
            m,
            m_inv: Affine3A::from_axis_angle(axis, -angle_rad),
        })
    }

    /// Scale by per-axis factors. Returns `None` when a factor is zero or not finite.
    pub fn scale(factors: Vec3A) -> Option<Self> {
        if !(factors.is_finite() && factors.cmpne(Vec3A::ZERO).all()) {
            return None;
        }
        Some(Self {
            m: Affine3A::from_scale(factors.into()),
            m_inv: Affine3A::from_scale(factors.recip().into()),
        })
    }

    /// From a 4×4 matrix (column-major, glam convention) whose last row is (0, 0, 0, 1).
    /// Returns `None` when the matrix is not affine, not finite or singular.
    pub fn from_matrix(matrix: Mat4) -> Option<Self> {
        if !matrix.is_finite() || matrix.row(3) != glam::Vec4::W {
            return None;
        }
        let m = Affine3A::from_mat4(matrix);
        let det = m.matrix3.determinant();
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let m_inv = m.inverse();
        m_inv.is_finite().then_some(Self { m, m_inv })
    }

    /// Camera-to-world transform of a viewer at `eye_m` looking at `target_m` with `up`
    /// (right-handed, Y up: local −Z looks at the target, +Y is up, +X is right — the glam
    /// `look_at_rh` convention, inverted so that it maps camera space to world space).
    /// Returns `None` when `eye_m == target_m` or `up` is parallel to the view direction.
    pub fn look_at(eye_m: Vec3A, target_m: Vec3A, up: Vec3A) -> Option<Self> {
        let forward = (target_m - eye_m).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let true_up = right.cross(forward);
        let m = Affine3A::from_cols(right, true_up, -forward, eye_m);
        Some(Self {
            m,
            m_inv: m.inverse(),
        })
    }

    /// `self ∘ inner`: apply `inner` first, then `self`.
    pub fn compose(&self, inner: &Transform) -> Self {
        Self {
            m: self.m * inner.m,
            m_inv: inner.m_inv * self.m_inv,
        }
    }

    pub fn inverse(&self) -> Self {
        Self {
            m: self.m_inv,
            m_inv: self.m,
        }
    }

    pub fn matrix(&self) -> Mat4 {
        Mat4::from(self.m)
    }

    pub fn inverse_matrix(&self) -> Mat4 {
        Mat4::from(self.m_inv)
    }

    pub fn is_identity(&self) -> bool {
        self.m == Affine3A::IDENTITY
    }

    /// Whether the transform flips orientation (negative determinant); pbrt-v4
    /// `SwapsHandedness`, used to keep geometric normals outward.
    pub fn swaps_handedness(&self) -> bool {
        self.m.matrix3.determinant() < 0.0
    }

    #[inline]
    pub fn point(&self, p: Vec3A) -> Vec3A {
        self.m.transform_point3a(p)
    }

    #[inline]
    pub fn vector(&self, v: Vec3A) -> Vec3A {
        self.m.transform_vector3a(v)
    }

    /// Normals transform by the inverse transpose of the linear part (pbrt-v4 §3.10.3).
    /// The result is not normalised.
    #[inline]
    pub fn normal(&self, n: Vec3A) -> Vec3A {
        self.normal_matrix() * n
    }

    /// `(M⁻¹)ᵀ` of the linear part.
    #[inline]
    pub fn normal_matrix(&self) -> Mat3A {
        self.m_inv.matrix3.transpose()
    }

    #[inline]
    pub fn inverse_point(&self, p: Vec3A) -> Vec3A {
        self.m_inv.transform_point3a(p)
    }

    #[inline]
    pub fn inverse_vector(&self, v: Vec3A) -> Vec3A {
        self.m_inv.transform_vector3a(v)
    }

    /// World ray → object ray. The direction is not renormalised, so `t` keeps its meaning
    /// and `t_min`/`t_max` carry over unchanged.
    #[inline]
    pub fn inverse_ray(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.inverse_point(ray.origin),
            direction: self.inverse_vector(ray.direction),
            t_min: ray.t_min,
            t_max: ray.t_max,
        }
    }

    /// Object-space bounds → world-space bounds (all eight corners).
    pub fn bounds(&self, min: Vec3A, max: Vec3A) -> (Vec3A, Vec3A) {
        let mut lo = Vec3A::splat(f32::INFINITY);
        let mut hi = Vec3A::splat(f32::NEG_INFINITY);
        for i in 0..8 {
            let c = Vec3A::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            );
            let w = self.point(c);
            lo = lo.min(w);
            hi = hi.max(w);
        }
        (lo, hi)
    }
}
