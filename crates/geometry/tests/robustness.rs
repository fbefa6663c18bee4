//! Edge cases: empty scenes and meshes, rays spawned from surfaces (t_min offset), and
//! rays with exactly-zero or negative-zero direction components.

use glam::Vec3A;
use prism_geometry::{BuildQuality, Frame, GeometryBuilder, Ray, Shape, Transform, TriangleMesh};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

#[test]
fn empty_scene_and_empty_mesh_miss_everything() {
    let g = GeometryBuilder::new().build(BuildQuality::Fast);
    let ray = Ray::infinite(Vec3A::ZERO, Vec3A::X);
    assert!(g.intersect(&ray).is_none() && !g.occluded(&ray));

    let mut b = GeometryBuilder::new();
    let empty = b.add_mesh(TriangleMesh::new(Vec::new(), Vec::new()));
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::ONE));
    b.add_instance(Shape::Mesh(empty), Transform::IDENTITY, None)
        .unwrap();
    b.add_instance(
        Shape::Mesh(cube),
        Transform::translate(Vec3A::new(5.0, 0.0, 0.0)),
        None,
    )
    .unwrap();
    assert!(b
        .add_instance(
            Shape::Mesh(prism_geometry::MeshId(7)),
            Transform::IDENTITY,
            None
        )
        .is_none());
    let g = b.build(BuildQuality::Fast);
    let hit = g.intersect(&ray).unwrap();
    assert_eq!(hit.instance_id, 1);
    assert!((hit.t - 4.0).abs() < 1e-6);
}

#[test]
fn spawned_rays_do_not_rehit_the_surface_they_leave() {
    let mut rng = Pcg64::seed_from_u64(21);
    let mut b = GeometryBuilder::new();
    let m = b.add_mesh(TriangleMesh::icosphere(1.0, 4));
    b.add_instance(
        Shape::Mesh(m),
        Transform::translate(Vec3A::new(10.0, -3.0, 2.0)),
        None,
    )
    .unwrap();
    let g = b.build(BuildQuality::Fast);
    let centre = Vec3A::new(10.0, -3.0, 2.0);
    for _ in 0..5_000 {
        let d = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        )
        .normalize();
        let ray = Ray::infinite(centre + d * 5.0, -d);
        let si = g.interaction(&ray, &g.intersect(&ray).unwrap());
        // Leave outward into the hemisphere of the geometric normal: a convex mesh is never hit.
        let f = Frame::from_z(si.n_geometric);
        let local = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(0.01..1.0),
        );
        let out = Ray::spawn(si.p, f.from_local(local.normalize()));
        assert!(
            g.intersect(&out).is_none(),
            "self-intersection from {:?}",
            si.p
        );
        // A shadow ray to a point outside does not hit the surface it starts on.
        assert!(!g.occluded(&Ray::spawn_to(si.p, si.p + si.n_geometric * 3.0)));
    }
}

#[test]
fn axis_aligned_rays_with_signed_zero_directions_hit() {
    let mut b = GeometryBuilder::new();
    let m = b.add_mesh(TriangleMesh::cuboid(Vec3A::ONE));
    b.add_instance(Shape::Mesh(m), Transform::IDENTITY, None)
        .unwrap();
    let g = b.build(BuildQuality::Fast);
    for d in [
        Vec3A::new(-0.0, 0.0, 1.0),
        Vec3A::new(0.0, -0.0, -1.0),
        Vec3A::new(-0.0, -1.0, -0.0),
        Vec3A::new(1.0, -0.0, 0.0),
    ] {
        // From the centre, and from points lying in the cube's face planes and edges.
        for o in [
            Vec3A::ZERO,
            Vec3A::new(1.0, 0.0, 0.0) * (1.0 - d.x.abs()),
            Vec3A::new(1.0, 1.0, 0.0) * (1.0 - d.abs()),
        ] {
            let ray = Ray::infinite(o - d * 3.0, d);
            assert!(g.intersect(&ray).is_some(), "{ray:?}");
            assert!(g.occluded(&ray), "{ray:?}");
        }
    }
}
