//! A triangle-mesh emitter: every instance of one mesh that a shape places (a `mesh`,
//! `cuboid` or `instances` shape). A sample picks an instance in proportion to its world
//! area, a triangle of it in proportion to its world area, then a point uniform in the
//! triangle (Heitz 2019; an affine map keeps uniform densities uniform), so the world
//! area density is 1/A everywhere, A the total world area; converted to solid angle.
//!
//! The normal of a sampled point is the one a hit there reports (prism-geometry
//! `triangle_local_geometry`): the winding normal (p₀ − p₂) × (p₁ − p₂), flipped to the
//! side of the interpolated vertex normal when the mesh has them, mapped to the world by
//! the inverse transpose.
//!
//! Instances placed by a similarity share one triangle distribution (their world areas
//! are the local ones times s²); others get their own (4 bytes per triangle).

use std::sync::Arc;

use glam::{Mat3A, Vec2, Vec3A};
use prism_geometry::{Transform, TriangleMesh};

use super::{area_to_solid_angle, ShapeSample};
use crate::light::piecewise_constant::PiecewiseConstant1D;
use crate::light::warp::sample_uniform_triangle;
use crate::light::LightHit;

/// The part of a mesh an emitter needs (object space, metres).
#[derive(Clone, Debug, PartialEq)]
pub struct EmitterMesh {
    pub positions: Vec<Vec3A>,
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex shading normals, as in `TriangleMesh`.
    pub normals: Option<Vec<Vec3A>>,
}

impl EmitterMesh {
    pub fn from_triangle_mesh(mesh: &TriangleMesh) -> Self {
        Self {
            positions: mesh.positions.clone(),
            indices: mesh.indices.clone(),
            normals: mesh.normals.clone(),
        }
    }

    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3A; 3] {
        self.indices[i].map(|k| self.positions[k as usize])
    }
}

#[derive(Clone, Debug, PartialEq)]
struct EmitterInstance {
    to_world: Transform,
    normal_matrix: Mat3A,
    triangles: Arc<PiecewiseConstant1D>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct MeshEmitter {
    mesh: Arc<EmitterMesh>,
    instances: Vec<EmitterInstance>,
    instance_distribution: PiecewiseConstant1D,
    area_m2: f64,
}

/// ½ |(b − a) × (c − a)|.
#[inline]
fn triangle_area([a, b, c]: [Vec3A; 3]) -> f64 {
    0.5 * (b - a).as_dvec3().cross((c - a).as_dvec3()).length()
}

/// s when the linear part of `t` is s × an orthogonal matrix (relative tolerance 1e-5).
fn similarity_scale(t: &Transform) -> Option<f64> {
    let m = Mat3A::from_mat4(t.matrix());
    let c = [m.x_axis, m.y_axis, m.z_axis].map(|v| v.as_dvec3());
    let s2 = (c[0].length_squared() + c[1].length_squared() + c[2].length_squared()) / 3.0;
    let tol = 1e-5 * s2;
    let ok = c[0].dot(c[1]).abs() < tol
        && c[0].dot(c[2]).abs() < tol
        && c[1].dot(c[2]).abs() < tol
        && c.iter().all(|v| (v.length_squared() - s2).abs() < tol);
    (ok && s2 > 0.0).then_some(s2)
}

impl MeshEmitter {
    /// The mesh placed by each of `transforms` (object → world).
    pub fn new(mesh: Arc<EmitterMesh>, transforms: &[Transform]) -> Self {
        let count = mesh.indices.len();
        let local_areas: Vec<f64> = (0..count)
            .map(|i| triangle_area(mesh.triangle(i)))
            .collect();
        let local_total: f64 = local_areas.iter().sum();
        let mut shared: Option<Arc<PiecewiseConstant1D>> = None;
        let mut instance_areas = Vec::with_capacity(transforms.len());
        let mut instances = Vec::with_capacity(transforms.len());
        for t in transforms {
            let (triangles, area) = match similarity_scale(t) {
                Some(s2) => {
                    let d = shared
                        .get_or_insert_with(|| {
                            let v: Vec<f32> = local_areas.iter().map(|&a| a as f32).collect();
                            Arc::new(PiecewiseConstant1D::new(&v))
                        })
                        .clone();
                    (d, s2 * local_total)
                }
                None => {
                    let world: Vec<f64> = (0..count)
                        .map(|i| triangle_area(mesh.triangle(i).map(|p| t.point(p))))
                        .collect();
                    let v: Vec<f32> = world.iter().map(|&a| a as f32).collect();
                    (Arc::new(PiecewiseConstant1D::new(&v)), world.iter().sum())
                }
            };
            instance_areas.push(area as f32);
            instances.push(EmitterInstance {
                to_world: *t,
                normal_matrix: t.normal_matrix(),
                triangles,
            });
        }
        let area_m2: f64 = instance_areas.iter().map(|&a| f64::from(a)).sum();
        // NaN/∞ (a degenerate transform) count as no area: nothing is sampled.
        let area_m2 = if area_m2.is_finite() { area_m2 } else { 0.0 };
        Self {
            mesh,
            instances,
            instance_distribution: PiecewiseConstant1D::new(&instance_areas),
            area_m2,
        }
    }

    pub fn area_m2(&self) -> f64 {
        self.area_m2
    }

    /// The shared mesh, in its local space.
    pub fn mesh(&self) -> &EmitterMesh {
        &self.mesh
    }

    /// Each instance's placement (local → world).
    pub fn instance_transforms(&self) -> impl Iterator<Item = &Transform> {
        self.instances.iter().map(|i| &i.to_world)
    }

    pub fn triangle_count(&self) -> usize {
        self.mesh.indices.len() * self.instances.len()
    }

    /// A point uniform in area over every instance: world position and the unit normal
    /// a hit there reports.
    #[inline(always)]
    fn sample_point(&self, u: Vec2) -> Option<(Vec3A, Vec3A)> {
        let (k, _, ux) = self.instance_distribution.sample_discrete(u.x);
        let inst = self.instances.get(k)?;
        let (tri, _, ux) = inst.triangles.sample_discrete(ux);
        if tri >= self.mesh.indices.len() {
            return None;
        }
        let b = sample_uniform_triangle(Vec2::new(ux, u.y));
        let [p0, p1, p2] = self.mesh.triangle(tri);
        let p_local = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let mut ng = (p0 - p2).cross(p1 - p2).normalize_or_zero();
        if let Some(normals) = &self.mesh.normals {
            let idx = self.mesh.indices[tri].map(|i| i as usize);
            let ns = b[0] * normals[idx[0]] + b[1] * normals[idx[1]] + b[2] * normals[idx[2]];
            if ns.length_squared() > 0.0 && ng.dot(ns) < 0.0 {
                ng = -ng;
            }
        }
        let n = (inst.normal_matrix * ng).normalize_or_zero();
        if n == Vec3A::ZERO {
            return None;
        }
        Some((inst.to_world.point(p_local), n))
    }

    #[inline]
    pub fn sample(&self, reference: Vec3A, u: Vec2) -> Option<ShapeSample> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        let (p, n) = self.sample_point(u)?;
        let pdf = area_to_solid_angle((1.0 / self.area_m2) as f32, reference, p, n);
        Some(ShapeSample { p, n, pdf })
    }

    /// A point uniform in area (`sample_le`): world position, normal, density 1/A.
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> Option<(Vec3A, Vec3A, f32)> {
        if self.area_m2 <= 0.0 {
            return None;
        }
        let (p, n) = self.sample_point(u)?;
        Some((p, n, self.pdf_area()))
    }

    /// Area density of `sample_area`: 1/A (0 without area).
    #[inline]
    pub fn pdf_area(&self) -> f32 {
        if self.area_m2 > 0.0 {
            (1.0 / self.area_m2) as f32
        } else {
            0.0
        }
    }

    #[inline]
    pub fn pdf(&self, reference: Vec3A, hit: &LightHit) -> f32 {
        if self.area_m2 <= 0.0 {
            return 0.0;
        }
        area_to_solid_angle((1.0 / self.area_m2) as f32, reference, hit.p, hit.n)
    }
}
