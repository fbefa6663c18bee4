//! All shapes of a scene under one two-level BVH.
//!
//! Design: meshes get their own BVH in object space (bottom level) and are placed by
//! instances (transform + shape); a top-level BVH over the instances' world bounds finds the
//! candidates, and each candidate is intersected with the ray taken into its object space
//! (direction not renormalised, so `t` is shared by all levels). One mesh under many
//! transforms is stored once. A scene with a single identity instance pays one extra
//! top-level box test per ray. Analytic shapes (sphere, disk, rectangle) are instances too,
//! intersected in closed form. Cuboids are 12-triangle meshes: their faces are flat (zero
//! curvature is exact), their shared edges get the same watertight test as any closed mesh,
//! and they need no separate intersector.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;

use crate::bvh_build::{build_bvh, bvh_ray, padded_aabb, BuildQuality};
use crate::disk::Disk;
use crate::interaction::SurfaceInteraction;
use crate::mesh::{TriangleMesh, NO_MATERIAL};
use crate::mesh_bvh::MeshBvh;
use crate::ray::{Ray, RayDifferential};
use crate::rectangle::Rectangle;
use crate::sphere::Sphere;
use crate::transform::Transform;
use crate::triangle_geometry::triangle_local_geometry;

/// Index of a mesh added to a [`GeometryBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub u32);

/// What an instance places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Mesh(MeshId),
    Sphere(Sphere),
    Disk(Disk),
    Rectangle(Rectangle),
}

/// A shape placed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub shape: Shape,
    /// Object → world.
    pub to_world: Transform,
    /// Material for analytic shapes and for mesh faces without one; when `Some`, it also
    /// overrides the mesh's per-face materials.
    pub material: Option<u32>,
}

/// The compact result of a closest-hit query; [`Geometry::interaction`] expands it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub instance_id: u32,
    /// Triangle index within the mesh (0 for analytic shapes).
    pub primitive_id: u32,
    /// Barycentrics of vertices 1 and 2 (0 for analytic shapes).
    pub b1: f32,
    pub b2: f32,
}

/// Collects meshes and instances, then builds a [`Geometry`].
#[derive(Default)]
pub struct GeometryBuilder {
    meshes: Vec<TriangleMesh>,
    instances: Vec<Instance>,
}

impl GeometryBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn add_mesh(&mut self, mesh: TriangleMesh) -> MeshId {
        self.meshes.push(mesh);
        MeshId(self.meshes.len() as u32 - 1)
    }

    /// Place a shape; returns its instance id (the order of calls).
    /// Returns `None` if `shape` names a mesh that was not added.
    pub fn add_instance(
        &mut self,
        shape: Shape,
        to_world: Transform,
        material: Option<u32>,
    ) -> Option<u32> {
        if let Shape::Mesh(MeshId(m)) = shape {
            if m as usize >= self.meshes.len() {
                return None;
            }
        }
        self.instances.push(Instance {
            shape,
            to_world,
            material,
        });
        Some(self.instances.len() as u32 - 1)
    }

    /// Build both BVH levels (meshes in parallel inside obvhs when its `parallel` feature is on).
    pub fn build(self, quality: BuildQuality) -> Geometry {
        let meshes: Vec<MeshBvh> = self
            .meshes
            .into_iter()
            .map(|m| MeshBvh::build(m, quality))
            .collect();
        let boxes: Vec<Aabb> = self
            .instances
            .iter()
            .map(|inst| {
                let (lo, hi) = match inst.shape {
                    Shape::Mesh(MeshId(m)) => meshes[m as usize].bounds(),
                    Shape::Sphere(s) => s.bounds(),
                    Shape::Disk(d) => d.bounds(),
                    Shape::Rectangle(r) => r.bounds(),
                };
                if lo.cmpgt(hi).any() {
                    // Empty mesh: a box no ray reaches.
                    return Aabb::new(Vec3A::splat(f32::MAX), Vec3A::splat(f32::MAX));
                }
                let (lo, hi) = inst.to_world.bounds(lo, hi);
                padded_aabb(lo, hi)
            })
            .collect();
        let top = build_bvh(&boxes, quality);
        Geometry {
            meshes,
            instances: self.instances,
            top,
        }
    }
}

/// Every shape of a scene with its acceleration structure; immutable and `Sync`, so many
/// threads can trace against it.
pub struct Geometry {
    meshes: Vec<MeshBvh>,
    instances: Vec<Instance>,
    top: Option<CwBvh>,
}

impl Geometry {
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Number of distinct meshes stored (instances share them).
    pub fn mesh_count(&self) -> usize {
        self.meshes.len()
    }

    pub fn mesh(&self, id: MeshId) -> &TriangleMesh {
        &self.meshes[id.0 as usize].mesh
    }

    /// Closest hit of `ray` in `(t_min, t_max)`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let top = self.top.as_ref()?;
        if self.instances.len() == 1 {
            // One instance: its box test would only repeat the bottom level's root test.
            return self.intersect_instance(0, ray, ray.t_max);
        }
        let mut best: Option<Hit> = None;
        let mut hit = RayHit::none();
        top.ray_traverse(to_bvh_ray(ray), &mut hit, |r, leaf| {
            match self.intersect_instance(top.primitive_indices[leaf], ray, r.tmax) {
                Some(h) => {
                    best = Some(h);
                    h.t
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// Closest hit on one instance with `t` in `(ray.t_min, t_max)`.
    #[inline]
    fn intersect_instance(&self, instance_id: u32, ray: &Ray, t_max: f32) -> Option<Hit> {
        let inst = &self.instances[instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        match inst.shape {
            Shape::Mesh(MeshId(m)) => self.meshes[m as usize]
                .intersect(o, d, ray.t_min, t_max)
                .map(|h| Hit {
                    t: h.t,
                    instance_id,
                    primitive_id: h.triangle,
                    b1: h.b1,
                    b2: h.b2,
                }),
            _ => analytic_intersect(&inst.shape, &Ray::new(o, d, ray.t_min, t_max)).map(|t| Hit {
                t,
                instance_id,
                primitive_id: 0,
                b1: 0.0,
                b2: 0.0,
            }),
        }
    }

    /// Whether anything blocks `ray` in `(t_min, t_max)` — the shadow-ray query; it stops at
    /// the first hit (obvhs `ray_traverse_miss`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some(top) = self.top.as_ref() else {
            return false;
        };
        if self.instances.len() == 1 {
            return self.occludes(0, ray);
        }
        !top.ray_traverse_miss(to_bvh_ray(ray), |_, leaf| {
            if self.occludes(top.primitive_indices[leaf], ray) {
                ray.t_min
            } else {
                f32::INFINITY
            }
        })
    }

    #[inline]
    fn occludes(&self, instance_id: u32, ray: &Ray) -> bool {
        let inst = &self.instances[instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        match inst.shape {
            Shape::Mesh(MeshId(m)) => self.meshes[m as usize].occluded(o, d, ray.t_min, ray.t_max),
            _ => analytic_intersect(&inst.shape, &Ray::new(o, d, ray.t_min, ray.t_max)).is_some(),
        }
    }

    /// Full world-space record of `hit` (found for `ray`).
    pub fn interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        self.interaction_with(ray, hit, true)
    }

    /// The record of `hit` without the principal curvatures (left at zero): what shading
    /// needs, for less work per path vertex.
    pub fn shading_interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        self.interaction_with(ray, hit, false)
    }

    fn interaction_with(&self, ray: &Ray, hit: &Hit, with_curvature: bool) -> SurfaceInteraction {
        let inst = &self.instances[hit.instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        let p_obj = o + hit.t * d;
        let (local, primitive_id, face_material, object_id) = match inst.shape {
            Shape::Mesh(MeshId(m)) => {
                let mesh = &self.meshes[m as usize].mesh;
                let tri = hit.primitive_id as usize;
                let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
                (
                    triangle_local_geometry(mesh, tri, b),
                    hit.primitive_id,
                    mesh.material_ids[tri],
                    mesh.object_ids[tri],
                )
            }
            Shape::Sphere(s) => (s.local_geometry(p_obj), 0, NO_MATERIAL, 0),
            Shape::Disk(dk) => (dk.local_geometry(p_obj), 0, NO_MATERIAL, 0),
            Shape::Rectangle(r) => (r.local_geometry(p_obj), 0, NO_MATERIAL, 0),
        };
        let mut si =
            SurfaceInteraction::from_local_with(&local, &inst.to_world, hit.t, with_curvature);
        si.primitive_id = primitive_id;
        si.material_id = inst.material.unwrap_or(face_material);
        si.object_id = object_id;
        si.instance_id = hit.instance_id;
        si
    }

    /// Closest hit of a ray differential with its interaction and propagated differentials.
    pub fn intersect_differential(&self, ray: &RayDifferential) -> Option<SurfaceInteraction> {
        let hit = self.intersect(&ray.ray)?;
        let mut si = self.interaction(&ray.ray, &hit);
        si.compute_differentials(ray);
        Some(si)
    }
}

#[inline]
fn to_bvh_ray(ray: &Ray) -> obvhs::ray::Ray {
    bvh_ray(ray.origin, ray.direction, ray.t_min, ray.t_max)
}

#[inline]
fn object_ray(inst: &Instance, ray: &Ray) -> (Vec3A, Vec3A) {
    if inst.to_world.is_identity() {
        (ray.origin, ray.direction)
    } else {
        (
            inst.to_world.inverse_point(ray.origin),
            inst.to_world.inverse_vector(ray.direction),
        )
    }
}

fn analytic_intersect(shape: &Shape, local: &Ray) -> Option<f32> {
    match shape {
        Shape::Sphere(s) => s.intersect(local),
        Shape::Disk(d) => d.intersect(local),
        Shape::Rectangle(r) => r.intersect(local),
        Shape::Mesh(_) => None,
    }
}
