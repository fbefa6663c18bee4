//! Fast path only: the types here serve render's packet tracer (`integrator::packet`) and
//! nothing else; they are public only because that tracer lives in another crate. They
//! describe the scene as it is for one tracer's intersection code, and may change with it.
//!
//! The leaves of a small scene as flat world-space patches with constant shading records:
//! what a packet tracer needs to intersect many rays at once without the scene's own
//! per-ray code.
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

/// The two triangles of a box face: (index in the leaf list, vertices in face coordinates).
pub type BoxFace = [(u32, [Vec2; 3]); 2];

/// Object-space bounds of a box mesh and, per triangle, (triangle, face).
type BoxFaces = (Vec3A, Vec3A, Vec<(usize, usize)>);

/// A mesh instance that is a parallelepiped (an affine image of an axis-aligned box, e.g.
/// a placed cube): a packet tracer can test it as one box instead of its 12 triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatBox {
    /// World → box space, where the box is [−1, 1]³: rows (x, y, z, offset).
    pub world_to_box: [[f32; 4]; 3],
    /// Per face `2·axis + (side > 0)`: its two triangles, each as (index in the leaf list,
    /// its vertices in the face's coordinates — box space without `axis`, the other two
    /// axes in increasing order).
    pub faces: [BoxFace; 6],
}

/// Whether `mesh` is an axis-aligned box in object space: 12 triangles with every vertex a
/// corner of the bounds and two triangles in each face plane. Its faces' triangles as
/// (triangle, face, box-space vertices) when it is.
fn box_faces(mesh: &crate::mesh::TriangleMesh) -> Option<BoxFaces> {
    if mesh.triangle_count() != 12 {
        return None;
    }
    let lo = mesh
        .positions
        .iter()
        .fold(Vec3A::INFINITY, |a, &p| a.min(p));
    let hi = mesh
        .positions
        .iter()
        .fold(Vec3A::NEG_INFINITY, |a, &p| a.max(p));
    if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
        return None;
    }
    let corner = |p: Vec3A| (0..3).all(|a| p[a] == lo[a] || p[a] == hi[a]);
    let mut per_face = [0usize; 6];
    let mut faces = Vec::with_capacity(12);
    for (tri, &[a, b, c]) in mesh.indices.iter().enumerate() {
        let p = [a, b, c].map(|i| mesh.positions[i as usize]);
        if !p.iter().all(|&q| corner(q)) {
            return None;
        }
        let face = (0..6).find(|&f| {
            let (axis, bound) = (f / 2, if f % 2 == 1 { hi } else { lo });
            p.iter().all(|q| q[axis] == bound[axis])
        })?;
        per_face[face] += 1;
        faces.push((tri, face));
    }
    per_face.iter().all(|&n| n == 2).then_some((lo, hi, faces))
}

impl Geometry {
    /// The scene's leaves as flat patches, when it is a small scene made only of baked
    /// triangles of meshes without vertex normals and of rectangles (fast path: the
    /// packet tracer's, see [`crate::fast_path`]).
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
                Shape::Sphere(_) | Shape::Disk(_) | Shape::Tiled(_) => return None,
            }
        }
        Some(leaves)
    }

    /// The mesh instances among `leaves` (from [`Geometry::flat_leaves`]) that are
    /// parallelepipeds (fast path: the packet tracer's, see [`crate::fast_path`]).
    pub fn flat_boxes(&self, leaves: &[FlatLeaf]) -> Vec<FlatBox> {
        let mut boxes = Vec::new();
        for (i, inst) in self.instances().iter().enumerate() {
            let Shape::Mesh(id) = inst.shape else {
                continue;
            };
            let mesh = self.mesh(id);
            let Some((lo, hi, faces)) = box_faces(mesh) else {
                continue;
            };
            let leaf_of = |tri: usize| {
                leaves.iter().position(|l| {
                    l.kind == PatchKind::Triangle
                        && l.record.instance_id == i as u32
                        && l.record.primitive_id == tri as u32
                })
            };
            let centre = (lo + hi) * 0.5;
            let half = (hi - lo) * 0.5;
            let inv = inst.to_world.inverse_matrix();
            let rows = [inv.row(0), inv.row(1), inv.row(2)];
            let world_to_box = [0, 1, 2].map(|a| {
                let r = rows[a];
                [
                    r.x / half[a],
                    r.y / half[a],
                    r.z / half[a],
                    (r.w - centre[a]) / half[a],
                ]
            });
            let mut out = [[(u32::MAX, [Vec2::ZERO; 3]); 2]; 6];
            let mut filled = [0usize; 6];
            let mut complete = true;
            for (tri, face) in faces {
                let Some(leaf) = leaf_of(tri) else {
                    complete = false;
                    break;
                };
                let (u, v) = match face / 2 {
                    0 => (1, 2),
                    1 => (0, 2),
                    _ => (0, 1),
                };
                let vertices = mesh.indices[tri].map(|k| {
                    let q = (mesh.positions[k as usize] - centre) / half;
                    Vec2::new(q[u], q[v])
                });
                out[face][filled[face]] = (leaf as u32, vertices);
                filled[face] += 1;
            }
            let finite = world_to_box.iter().flatten().all(|x| x.is_finite());
            if complete && finite {
                boxes.push(FlatBox {
                    world_to_box,
                    faces: out,
                });
            }
        }
        boxes
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

    /// A 2 m × 2 m rectangle at the origin, material 0.
    fn add_unit_rectangle(b: &mut GeometryBuilder) {
        b.add_instance(
            Shape::Rectangle(Rectangle {
                half_width_m: 1.0,
                half_height_m: 1.0,
            }),
            Transform::IDENTITY,
            Some(0),
        );
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

    /// The placed cube is found as a box whose map sends its world corners to ±1 and whose
    /// faces list its 12 triangles once each.
    #[test]
    fn a_placed_cube_is_a_flat_box() {
        let g = scene();
        let leaves = g.flat_leaves().unwrap();
        let boxes = g.flat_boxes(&leaves);
        assert_eq!(boxes.len(), 1);
        let b = &boxes[0];
        let mut seen: Vec<u32> = b.faces.iter().flatten().map(|(leaf, _)| *leaf).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), 12);
        for leaf in seen.iter().map(|&i| &leaves[i as usize]) {
            for p in [leaf.p0, leaf.p0 + leaf.e1, leaf.p0 + leaf.e2] {
                for row in &b.world_to_box {
                    let q = row[0] * p.x + row[1] * p.y + row[2] * p.z + row[3];
                    assert!((q.abs() - 1.0).abs() < 1e-5, "{q}");
                }
            }
        }
        // A rectangle is not a box; nor is a cube missing a triangle.
        let mut b = GeometryBuilder::new();
        let mut open = cube();
        open.indices.pop();
        open.material_ids.pop();
        open.object_ids.pop();
        let m = b.add_mesh(open);
        b.add_instance(Shape::Mesh(m), Transform::IDENTITY, Some(0));
        add_unit_rectangle(&mut b);
        let g = b.build(BuildQuality::Fast);
        assert!(g.flat_boxes(&g.flat_leaves().unwrap()).is_empty());
    }

    #[test]
    fn scenes_with_curved_leaves_or_vertex_normals_have_none() {
        let mut b = GeometryBuilder::new();
        b.add_instance(
            Shape::Sphere(Sphere { radius_m: 1.0 }),
            Transform::IDENTITY,
            Some(0),
        );
        add_unit_rectangle(&mut b);
        assert!(b.build(BuildQuality::Fast).flat_leaves().is_none());

        let mut b = GeometryBuilder::new();
        let mut mesh = cube();
        mesh.normals = Some(mesh.positions.clone());
        let m = b.add_mesh(mesh);
        b.add_instance(Shape::Mesh(m), Transform::IDENTITY, Some(0));
        add_unit_rectangle(&mut b);
        assert!(b.build(BuildQuality::Fast).flat_leaves().is_none());
    }
}
