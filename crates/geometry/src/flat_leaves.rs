//! The leaves of a small scene as flat world-space patches with constant shading records:
//! what a packet tracer needs to intersect many rays at once without the scene's own
//! per-ray code (render's `integrator::packet`).
//!
//! A patch is a triangle or a parallelogram `p0 + u·e1 + v·e2`. Its record (normals,
//! tangent `dpdu`, material, instance, primitive) is the one [`Geometry::shading_interaction`]
//! returns for every hit on it — computed by the same functions at the patch's centre — so
//! it is offered only where that record is the same at every point: baked triangles of
//! meshes without vertex normals, and rectangles. Scenes with other leaves (spheres, disks,
//! meshes kept instanced or with vertex normals) and BVH scenes get `None`.

use glam::{Vec2, Vec3A};

use crate::geometry::{Geometry, Shape};
use crate::interaction::SurfaceInteraction;
use crate::mesh::NO_MATERIAL;
use crate::triangle_geometry::triangle_local_geometry;

/// The shape of a [`FlatLeaf`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchKind {
    /// Points `p0 + u·e1 + v·e2` with u, v ≥ 0 and u + v ≤ 1.
    Triangle,
    /// Points `p0 + u·e1 + v·e2` with u, v ∈ [0, 1].
    Parallelogram,
}

/// One flat leaf: its world-space patch and the shading record of every hit on it (only
/// `p`, `t` and `uv` vary, and the packet tracer computes `p` itself).
#[derive(Clone, Debug, PartialEq)]
pub struct FlatLeaf {
    pub kind: PatchKind,
    /// Corner (metres, world).
    pub p0: Vec3A,
    /// Edges from `p0` (metres, world).
    pub e1: Vec3A,
    pub e2: Vec3A,
    /// The interaction `shading_interaction` gives at the patch's centre.
    pub record: SurfaceInteraction,
}

impl Geometry {
    /// The scene's leaves as flat patches, when it is a small scene made only of baked
    /// triangles of meshes without vertex normals and of rectangles (see module docs).
    pub fn flat_leaves(&self) -> Option<Vec<FlatLeaf>> {
        if !self.is_small_scene() || self.has_other_small_leaves() {
            return None;
        }
        let mut leaves = Vec::new();
        for (i, inst) in self.instances().iter().enumerate() {
            let instance_id = i as u32;
            match inst.shape {
                Shape::Mesh(id) => {
                    let mesh = self.mesh(id);
                    if mesh.normals.is_some() {
                        return None;
                    }
                    // The baked soup transforms each vertex once (`bake_mesh_instance`).
                    let world: Vec<Vec3A> = if inst.to_world.is_identity() {
                        mesh.positions.clone()
                    } else {
                        mesh.positions
                            .iter()
                            .map(|&p| inst.to_world.point(p))
                            .collect()
                    };
                    for (tri, &[a, b, c]) in mesh.indices.iter().enumerate() {
                        let (a, b, c) = (world[a as usize], world[b as usize], world[c as usize]);
                        let third = 1.0 / 3.0;
                        let local = triangle_local_geometry(mesh, tri, [third; 3]);
                        let mut record =
                            SurfaceInteraction::from_local_with(&local, &inst.to_world, 0.0, false);
                        record.primitive_id = tri as u32;
                        record.material_id = inst.material.unwrap_or(mesh.material_ids[tri]);
                        record.object_id = mesh.object_ids[tri];
                        record.instance_id = instance_id;
                        leaves.push(FlatLeaf {
                            kind: PatchKind::Triangle,
                            p0: a,
                            e1: b - a,
                            e2: c - a,
                            record,
                        });
                    }
                }
                Shape::Rectangle(r) => {
                    let (w, h) = (r.half_width_m, r.half_height_m);
                    let local = r.local_geometry(Vec3A::ZERO);
                    let mut record =
                        SurfaceInteraction::from_local_with(&local, &inst.to_world, 0.0, false);
                    record.uv = Vec2::splat(0.5);
                    record.primitive_id = 0;
                    record.material_id = inst.material.unwrap_or(NO_MATERIAL);
                    record.object_id = 0;
                    record.instance_id = instance_id;
                    leaves.push(FlatLeaf {
                        kind: PatchKind::Parallelogram,
                        p0: inst.to_world.point(Vec3A::new(-w, -h, 0.0)),
                        e1: inst.to_world.vector(Vec3A::new(2.0 * w, 0.0, 0.0)),
                        e2: inst.to_world.vector(Vec3A::new(0.0, 2.0 * h, 0.0)),
                        record,
                    });
                }
                Shape::Sphere(_) | Shape::Disk(_) => return None,
            }
        }
        Some(leaves)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh_build::BuildQuality;
    use crate::geometry::GeometryBuilder;
    use crate::mesh::TriangleMesh;
    use crate::ray::Ray;
    use crate::rectangle::Rectangle;
    use crate::sphere::Sphere;
    use crate::transform::Transform;
    use glam::{Mat4, Vec3};

    fn cube() -> TriangleMesh {
        let p = [
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
        ]
        .map(Vec3A::from_array);
        let idx = vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [3, 6, 2],
            [3, 7, 6],
            [0, 4, 7],
            [0, 7, 3],
            [1, 2, 6],
            [1, 6, 5],
        ];
        TriangleMesh::new(p.to_vec(), idx)
    }

    fn scene() -> Geometry {
        let mut b = GeometryBuilder::new();
        let m = b.add_mesh(cube());
        let place = Transform::from_matrix(
            Mat4::from_translation(Vec3::new(0.2, -0.3, 0.1))
                * Mat4::from_rotation_y(0.4)
                * Mat4::from_scale(Vec3::new(0.3, 0.5, 0.3)),
        )
        .unwrap();
        b.add_instance(Shape::Mesh(m), place, Some(1));
        let wall = Transform::from_matrix(
            Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0)) * Mat4::from_rotation_x(0.3),
        )
        .unwrap();
        b.add_instance(
            Shape::Rectangle(Rectangle {
                half_width_m: 1.5,
                half_height_m: 1.0,
            }),
            wall,
            Some(2),
        );
        b.build(BuildQuality::Fast)
    }

    /// Every patch's record is what the scene's own closest-hit query returns at points
    /// spread over the patch (the record is constant), and the patch holds the hit point.
    #[test]
    fn records_equal_the_scene_interaction_over_each_patch() {
        let g = scene();
        let leaves = g.flat_leaves().expect("triangles and a rectangle only");
        assert_eq!(leaves.len(), 13);
        let mut checked = 0;
        for leaf in &leaves {
            let n = leaf.e1.cross(leaf.e2).normalize();
            for (u, v) in [(0.2f32, 0.3f32), (0.5, 0.1), (0.1, 0.6)] {
                let target = leaf.p0 + u * leaf.e1 + v * leaf.e2;
                let origin = target + 0.05 * n;
                let ray = Ray::new(origin, (target - origin).normalize(), 0.0, f32::INFINITY);
                let Some(hit) = g.intersect(&ray) else {
                    continue;
                };
                if hit.instance_id != leaf.record.instance_id
                    || hit.primitive_id != leaf.record.primitive_id
                {
                    continue; // another patch lies in front
                }
                let si = g.shading_interaction(&ray, &hit);
                assert!((si.p - target).length() < 1e-5);
                assert_eq!(si.n_geometric, leaf.record.n_geometric);
                assert_eq!(si.n_shading, leaf.record.n_shading);
                assert_eq!(si.dpdu, leaf.record.dpdu);
                assert_eq!(si.material_id, leaf.record.material_id);
                checked += 1;
            }
        }
        assert!(checked >= 30, "only {checked} probes reached their patch");
    }

    #[test]
    fn scenes_with_curved_leaves_or_vertex_normals_have_none() {
        let mut b = GeometryBuilder::new();
        b.add_instance(
            Shape::Sphere(Sphere { radius_m: 1.0 }),
            Transform::IDENTITY,
            Some(0),
        );
        b.add_instance(
            Shape::Rectangle(Rectangle {
                half_width_m: 1.0,
                half_height_m: 1.0,
            }),
            Transform::IDENTITY,
            Some(0),
        );
        assert!(b.build(BuildQuality::Fast).flat_leaves().is_none());

        let mut b = GeometryBuilder::new();
        let mut mesh = cube();
        mesh.normals = Some(mesh.positions.clone());
        let m = b.add_mesh(mesh);
        b.add_instance(Shape::Mesh(m), Transform::IDENTITY, Some(0));
        b.add_instance(
            Shape::Rectangle(Rectangle {
                half_width_m: 1.0,
                half_height_m: 1.0,
            }),
            Transform::IDENTITY,
            Some(0),
        );
        assert!(b.build(BuildQuality::Fast).flat_leaves().is_none());
    }
}
