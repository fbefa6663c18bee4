//! Analytic sphere/disk/rectangle intersection, and curvature of spheres (1/r), planes (0),
//! tessellated spheres with smooth normals (≈1/r) and ellipsoids (non-uniform scale).

use glam::Vec3A;
use prism_geometry::{
    BuildQuality, Disk, Geometry, GeometryBuilder, Ray, Rectangle, Shape, Sphere, Transform,
    TriangleMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn one(shape: Shape, t: Transform) -> Geometry {
    let mut b = GeometryBuilder::new();
    b.add_instance(shape, t, Some(3)).unwrap();
    b.build(BuildQuality::Fast)
}

fn one_mesh(mesh: TriangleMesh, t: Transform) -> Geometry {
    let mut b = GeometryBuilder::new();
    let id = b.add_mesh(mesh);
    b.add_instance(Shape::Mesh(id), t, None).unwrap();
    b.build(BuildQuality::Fast)
}

#[test]
fn sphere_intersection_matches_closed_form() {
    let s = Sphere { radius_m: 2.0 };
    let r = Ray::infinite(Vec3A::new(0.0, 0.0, -5.0), Vec3A::Z);
    assert_eq!(s.intersect(&r), Some(3.0));
    // From inside: the far side.
    assert_eq!(
        s.intersect(&Ray::infinite(Vec3A::ZERO, Vec3A::X * 0.5)),
        Some(4.0)
    );
    // Beyond t_max, and a miss just outside the silhouette.
    assert_eq!(
        s.intersect(&Ray::new(Vec3A::new(0.0, 0.0, -5.0), Vec3A::Z, 0.0, 2.9)),
        None
    );
    assert_eq!(
        s.intersect(&Ray::infinite(Vec3A::new(2.001, 0.0, -5.0), Vec3A::Z)),
        None
    );
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..10_000 {
        let o = Vec3A::new(rng.gen_range(-4.0..4.0), rng.gen_range(-4.0..4.0), -6.0);
        let d =
            (Vec3A::new(rng.gen_range(-2.5..2.5), rng.gen_range(-2.5..2.5), 0.0) - o).normalize();
        let t = s.intersect(&Ray::infinite(o, d));
        // Closed form: distance of the line from the centre decides hit or miss.
        let closest = o - d * o.dot(d);
        match t {
            Some(t) => {
                assert!((o + t * d).length() - 2.0 < 1e-5);
                assert!(closest.length() <= 2.0 + 1e-5);
            }
            None => assert!(closest.length() >= 2.0 - 1e-5),
        }
    }
}

#[test]
fn disk_and_rectangle_hits_uv_and_normals() {
    let disk = Disk { radius_m: 1.5 };
    let down = |x: f32, y: f32| Ray::infinite(Vec3A::new(x, y, 2.0), -Vec3A::Z);
    assert_eq!(disk.intersect(&down(1.0, 1.0)), Some(2.0));
    assert_eq!(disk.intersect(&down(1.1, 1.1)), None); // √2·1.1 > 1.5
    let g = disk.local_geometry(Vec3A::new(0.0, 0.75, 0.0));
    assert!(
        (g.uv.x - 0.25).abs() < 1e-6 && (g.uv.y - 0.5).abs() < 1e-6,
        "{:?}",
        g.uv
    );
    assert_eq!(g.n_geometric, Vec3A::Z);
    assert!(g.dpdu.cross(g.dpdv).normalize().dot(Vec3A::Z) > 0.999);

    let rect = Rectangle {
        half_width_m: 2.0,
        half_height_m: 0.5,
    };
    assert_eq!(rect.intersect(&down(1.99, -0.49)), Some(2.0));
    assert_eq!(rect.intersect(&down(2.01, 0.0)), None);
    assert_eq!(rect.intersect(&down(0.0, 0.51)), None);
    assert_eq!(
        rect.intersect(&Ray::infinite(Vec3A::new(0.0, 0.0, 2.0), Vec3A::X)),
        None
    ); // parallel
    let g = rect.local_geometry(Vec3A::new(1.0, 0.25, 0.0));
    assert!((g.uv - glam::Vec2::new(0.75, 0.75)).length() < 1e-6);
    // From below (two-sided) the same hit.
    assert_eq!(
        rect.intersect(&Ray::infinite(Vec3A::new(0.0, 0.0, -1.0), Vec3A::Z)),
        Some(1.0)
    );
}

#[test]
fn analytic_sphere_curvature_is_one_over_radius() {
    let mut rng = Pcg64::seed_from_u64(3);
    for radius_m in [0.25f32, 1.0, 4.0] {
        let g = one(
            Shape::Sphere(Sphere { radius_m }),
            Transform::translate(Vec3A::new(1.0, 2.0, 3.0)),
        );
        for _ in 0..500 {
            let offset = Vec3A::new(rng.gen_range(-0.6..0.6), rng.gen_range(-0.6..0.6), 0.0);
            let target = Vec3A::new(1.0, 2.0, 3.0) + offset * radius_m;
            let o = Vec3A::new(target.x, target.y, 3.0 + 10.0 * radius_m);
            let ray = Ray::infinite(o, -Vec3A::Z);
            let hit = g.intersect(&ray).expect("aimed inside the silhouette");
            let si = g.interaction(&ray, &hit);
            let k = 1.0 / radius_m;
            assert!((si.curvature.k1 - k).abs() < 1e-3 * k, "{:?}", si.curvature);
            assert!((si.curvature.k2 - k).abs() < 1e-3 * k, "{:?}", si.curvature);
            assert!((si.curvature.mean() - k).abs() < 1e-3 * k);
            assert!(
                ((si.p - Vec3A::new(1.0, 2.0, 3.0)).length() - radius_m).abs() < 1e-4 * radius_m
            );
            assert!(si.n_geometric.dot(Vec3A::Z) > 0.0);
            assert_eq!(si.material_id, 3);
            // Principal directions are tangent and orthonormal.
            assert!(si.curvature.dir1.dot(si.n_shading).abs() < 1e-4);
            assert!(si.curvature.dir1.dot(si.curvature.dir2).abs() < 1e-4);
        }
    }
}

#[test]
fn planes_have_zero_curvature() {
    for shape in [
        Shape::Disk(Disk { radius_m: 1.0 }),
        Shape::Rectangle(Rectangle {
            half_width_m: 1.0,
            half_height_m: 2.0,
        }),
    ] {
        let g = one(shape, Transform::rotate(Vec3A::X, 0.3).unwrap());
        let ray = Ray::infinite(Vec3A::new(0.2, 0.1, 5.0), -Vec3A::Z);
        let si = g.interaction(&ray, &g.intersect(&ray).unwrap());
        assert_eq!((si.curvature.k1, si.curvature.k2), (0.0, 0.0));
    }
    let cube = one_mesh(TriangleMesh::cuboid(Vec3A::ONE), Transform::IDENTITY);
    let ray = Ray::infinite(Vec3A::new(0.3, 0.2, 5.0), -Vec3A::Z);
    let si = cube.interaction(&ray, &cube.intersect(&ray).unwrap());
    assert_eq!(si.curvature.mean(), 0.0);
    assert!(
        (si.n_geometric - Vec3A::Z).length() < 1e-6,
        "{:?}",
        si.n_geometric
    );
}

#[test]
fn tessellated_sphere_with_smooth_normals_has_curvature_near_one_over_radius() {
    let radius_m = 2.0;
    let mut rng = Pcg64::seed_from_u64(11);
    for mesh in [
        TriangleMesh::uv_sphere(radius_m, 96, 192),
        TriangleMesh::icosphere(radius_m, 5),
    ] {
        let g = one_mesh(mesh, Transform::IDENTITY);
        for _ in 0..500 {
            let d = Vec3A::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
            .normalize();
            let ray = Ray::infinite(d * 10.0, -d);
            let si = g.interaction(&ray, &g.intersect(&ray).unwrap());
            // Interpolated normals p/r over a chord surface inside the sphere: within 0.1 %.
            for k in [si.curvature.k1, si.curvature.k2] {
                assert!((k - 0.5).abs() < 5e-4, "{:?} at {:?}", si.curvature, si.p);
            }
            assert!(si.n_shading.dot(d) > 0.999);
        }
    }
}

#[test]
fn scaled_sphere_instances_give_ellipsoid_and_scaled_curvatures() {
    // Uniform scale s: k = 1/(s r).
    let g = one(
        Shape::Sphere(Sphere { radius_m: 1.0 }),
        Transform::scale(Vec3A::splat(3.0)).unwrap(),
    );
    let ray = Ray::infinite(Vec3A::new(0.0, 0.0, 10.0), -Vec3A::Z);
    let si = g.interaction(&ray, &g.intersect(&ray).unwrap());
    assert!(
        (si.curvature.k1 - 1.0 / 3.0).abs() < 1e-4 && (si.curvature.k2 - 1.0 / 3.0).abs() < 1e-4
    );
    // Ellipsoid with semi-axes (a, b, c) = (2, 1, 0.5) at (a, 0, 0): curvatures a/b² and a/c².
    let g = one(
        Shape::Sphere(Sphere { radius_m: 1.0 }),
        Transform::scale(Vec3A::new(2.0, 1.0, 0.5)).unwrap(),
    );
    let ray = Ray::infinite(Vec3A::new(10.0, 0.0, 0.0), -Vec3A::X);
    let hit = g.intersect(&ray).unwrap();
    assert!((hit.t - 8.0).abs() < 1e-5);
    let si = g.interaction(&ray, &hit);
    assert!(
        (si.n_shading - Vec3A::X).length() < 1e-5,
        "{:?}",
        si.n_shading
    );
    assert!((si.curvature.k1 - 8.0).abs() < 1e-3, "{:?}", si.curvature);
    assert!((si.curvature.k2 - 2.0).abs() < 1e-3, "{:?}", si.curvature);
    assert!(
        si.curvature.dir1.dot(Vec3A::Z).abs() > 0.999,
        "k1 along the short axis"
    );
}

#[test]
fn rectangle_shading_record_equals_the_transformed_local_geometry_bit_for_bit() {
    // `shading_interaction` copies a rectangle's constant normals and tangents from a record
    // made at build time; it must equal `from_local_with` of the hit's local geometry,
    // field by field, under identity, rotated, scaled and mirrored transforms.
    use prism_geometry::SurfaceInteraction;
    let rect = Rectangle {
        half_width_m: 0.7,
        half_height_m: 0.4,
    };
    let transforms = [
        Transform::IDENTITY,
        Transform::rotate(Vec3A::new(1.0, 0.3, -0.2), 1.1)
            .unwrap()
            .compose(&Transform::scale(Vec3A::new(0.23, 0.19, 1.0)).unwrap()),
        Transform::translate(Vec3A::new(0.0, 0.99, 0.01))
            .compose(&Transform::rotate(Vec3A::X, std::f32::consts::FRAC_PI_2).unwrap())
            .compose(&Transform::scale(Vec3A::new(-0.5, 0.19, 2.0)).unwrap()),
    ];
    let mut rng = Pcg64::seed_from_u64(7);
    for to_world in transforms {
        let g = one(Shape::Rectangle(rect), to_world);
        let mut hits = 0;
        for _ in 0..2_000 {
            let target = to_world.point(Vec3A::new(
                rng.gen_range(-0.8..0.8),
                rng.gen_range(-0.5..0.5),
                0.0,
            ));
            let o = target
                + Vec3A::new(
                    rng.gen_range(-3.0..3.0),
                    rng.gen_range(-3.0..3.0),
                    rng.gen_range(-3.0..3.0),
                );
            let ray = Ray::infinite(o, (target - o).normalize());
            let Some(hit) = g.intersect(&ray) else {
                continue;
            };
            hits += 1;
            let o_obj = to_world.inverse_point(ray.origin);
            let d_obj = to_world.inverse_vector(ray.direction);
            let local = rect.local_geometry(o_obj + hit.t * d_obj);
            let expected = SurfaceInteraction::from_local_with(&local, &to_world, hit.t, false);
            let got = g.shading_interaction(&ray, &hit);
            let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
            assert_eq!(bits(got.p), bits(expected.p));
            assert_eq!(got.t.to_bits(), expected.t.to_bits());
            assert_eq!(bits(got.n_geometric), bits(expected.n_geometric));
            assert_eq!(bits(got.n_shading), bits(expected.n_shading));
            assert_eq!(
                got.uv.to_array().map(f32::to_bits),
                expected.uv.to_array().map(f32::to_bits)
            );
            assert_eq!(bits(got.dpdu), bits(expected.dpdu));
            assert_eq!(bits(got.dpdv), bits(expected.dpdv));
            assert_eq!(bits(got.dndu), bits(expected.dndu));
            assert_eq!(bits(got.dndv), bits(expected.dndv));
            assert_eq!(got.curvature, expected.curvature);
            assert_eq!(got.differentials, expected.differentials);
            assert_eq!(
                (
                    got.material_id,
                    got.instance_id,
                    got.primitive_id,
                    got.object_id
                ),
                (3, 0, 0, 0)
            );
            // The full record (with curvature) still comes from the generic path.
            let full = g.interaction(&ray, &hit);
            assert_eq!(bits(full.p), bits(got.p));
        }
        assert!(hits > 500, "{hits}");
    }
}
