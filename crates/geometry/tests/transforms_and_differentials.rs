//! Transforms (inverse, composition, normals under non-uniform scale, look-at), instancing,
//! and ray-differential propagation (pbrt-v4 §10.1.1).

use glam::{Mat4, Vec3A};
use prism_geometry::{
    BuildQuality, Frame, GeometryBuilder, Ray, RayDifferential, Rectangle, Shape, Transform,
    TriangleMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn close(a: Vec3A, b: Vec3A, tol: f32) -> bool {
    (a - b).length() <= tol
}

#[test]
fn transform_inverse_and_composition_round_trip() {
    let mut rng = Pcg64::seed_from_u64(8);
    for _ in 0..200 {
        let axis = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let t = Transform::translate(Vec3A::new(1.0, -2.0, 0.5))
            .compose(&Transform::rotate(axis, rng.gen_range(-3.0..3.0)).unwrap())
            .compose(
                &Transform::scale(Vec3A::new(
                    rng.gen_range(0.2..3.0),
                    rng.gen_range(0.2..3.0),
                    rng.gen_range(0.2..3.0),
                ))
                .unwrap(),
            );
        let p = Vec3A::new(
            rng.gen_range(-5.0..5.0),
            rng.gen_range(-5.0..5.0),
            rng.gen_range(-5.0..5.0),
        );
        assert!(close(t.inverse_point(t.point(p)), p, 1e-4));
        assert!(close(t.inverse().point(t.point(p)), p, 1e-4));
        let m = t.matrix() * t.inverse_matrix();
        assert!(m.abs_diff_eq(Mat4::IDENTITY, 1e-4));
        let from_m = Transform::from_matrix(t.matrix()).unwrap();
        assert!(close(from_m.inverse_point(p), t.inverse_point(p), 1e-4));
    }
    // Rotation by a quarter turn about z maps x to y (right-handed).
    let r = Transform::rotate(Vec3A::Z, std::f32::consts::FRAC_PI_2).unwrap();
    assert!(close(r.vector(Vec3A::X), Vec3A::Y, 1e-6));
    assert!(Transform::scale(Vec3A::new(1.0, 0.0, 1.0)).is_none());
    assert!(Transform::from_matrix(Mat4::ZERO).is_none());
}

#[test]
fn normals_stay_perpendicular_under_non_uniform_scale() {
    let t = Transform::scale(Vec3A::new(4.0, 1.0, 0.25))
        .unwrap()
        .compose(&Transform::rotate(Vec3A::new(1.0, 2.0, 3.0), 0.7).unwrap());
    let n = Vec3A::new(1.0, 1.0, 0.0).normalize();
    let f = Frame::from_z(n);
    let n_w = t.normal(n);
    for tangent in [f.x, f.y, f.x + f.y] {
        assert!(t.vector(tangent).dot(n_w).abs() < 1e-5);
    }
    // Naively transforming the normal as a vector would not be perpendicular.
    assert!(t.vector(f.x).dot(t.vector(n)).abs() > 1e-2);
}

#[test]
fn look_at_points_minus_z_at_the_target() {
    let eye = Vec3A::new(1.0, 2.0, 3.0);
    let target = Vec3A::new(-2.0, 0.0, 1.0);
    let t = Transform::look_at(eye, target, Vec3A::Y).unwrap();
    assert!(close(t.point(Vec3A::ZERO), eye, 1e-6));
    assert!(close(t.vector(-Vec3A::Z), (target - eye).normalize(), 1e-6));
    assert!(t.vector(Vec3A::Y).dot(Vec3A::Y) > 0.0);
    assert!(Transform::look_at(eye, eye, Vec3A::Y).is_none());
    assert!(Transform::look_at(eye, eye + Vec3A::Y, Vec3A::Y).is_none());
}

#[test]
fn frames_are_orthonormal() {
    let mut rng = Pcg64::seed_from_u64(4);
    for _ in 0..1000 {
        let z = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        )
        .normalize();
        let f = Frame::from_z(z);
        assert!((f.x.length() - 1.0).abs() < 1e-5 && (f.y.length() - 1.0).abs() < 1e-5);
        assert!(f.x.dot(f.y).abs() < 1e-5 && f.x.dot(z).abs() < 1e-5);
        assert!(close(f.x.cross(f.y), z, 1e-5));
        let v = Vec3A::new(0.3, -0.2, 0.9);
        assert!(close(f.from_local(f.to_local(v)), v, 1e-5));
    }
}

#[test]
fn hit_on_instance_k_reports_k_and_world_position() {
    let radius_m = 0.5;
    let mut b = GeometryBuilder::new();
    let sphere = b.add_mesh(TriangleMesh::icosphere(radius_m, 3));
    let centres: Vec<Vec3A> = (0..8)
        .map(|k| Vec3A::new(3.0 * k as f32, 0.0, -(k as f32)))
        .collect();
    for (k, &c) in centres.iter().enumerate() {
        let rot = Transform::rotate(Vec3A::Y, 0.4 * k as f32).unwrap();
        assert_eq!(
            b.add_instance(
                Shape::Mesh(sphere),
                Transform::translate(c).compose(&rot),
                Some(k as u32 + 10)
            ),
            Some(k as u32)
        );
    }
    let g = b.build(BuildQuality::Fast);
    assert_eq!(
        g.mesh_count(),
        1,
        "the mesh is stored once for all instances"
    );
    for (k, &c) in centres.iter().enumerate() {
        let ray = Ray::infinite(c + Vec3A::new(0.05, 0.02, 5.0), -Vec3A::Z);
        let hit = g.intersect(&ray).unwrap();
        let si = g.interaction(&ray, &hit);
        assert_eq!(si.instance_id, k as u32);
        assert_eq!(si.material_id, k as u32 + 10);
        assert!(close(si.p, ray.at(hit.t), 1e-5));
        assert!(((si.p - c).length() - radius_m).abs() < 0.01 * radius_m);
        assert!(
            si.n_geometric.dot(si.p - c) > 0.0,
            "outward normal in world space"
        );
    }
}

#[test]
fn differentials_on_a_plane_match_the_pinhole_footprint() {
    // Camera 5 m above a 4 m × 2 m rectangle looking down; pixel offset angle δ.
    let mut b = GeometryBuilder::new();
    b.add_instance(
        Shape::Rectangle(Rectangle {
            half_width_m: 2.0,
            half_height_m: 1.0,
        }),
        Transform::IDENTITY,
        None,
    )
    .unwrap();
    let g = b.build(BuildQuality::Fast);
    let delta = 1e-3;
    let o = Vec3A::new(0.5, 0.25, 5.0);
    let d = -Vec3A::Z;
    let rd = RayDifferential {
        ray: Ray::infinite(o, d),
        rx_origin: o,
        rx_direction: Vec3A::new(delta, 0.0, -1.0),
        ry_origin: o,
        ry_direction: Vec3A::new(0.0, delta, -1.0),
    };
    let si = g.intersect_differential(&rd).unwrap();
    let dif = si.differentials;
    assert!(
        close(dif.dpdx, Vec3A::new(5.0 * delta, 0.0, 0.0), 1e-6),
        "{:?}",
        dif.dpdx
    );
    assert!(close(dif.dpdy, Vec3A::new(0.0, 5.0 * delta, 0.0), 1e-6));
    // u spans 4 m, v spans 2 m.
    assert!((dif.dudx - 5.0 * delta / 4.0).abs() < 1e-6 && dif.dvdx.abs() < 1e-7);
    assert!((dif.dvdy - 5.0 * delta / 2.0).abs() < 1e-6 && dif.dudy.abs() < 1e-7);
    // Depth: t is the distance for a unit direction.
    assert!((si.t - 5.0).abs() < 1e-6);
    // A tilted view stretches the footprint by 1/cos θ along the tilt.
    let tilt = 0.5f32;
    let dir = Vec3A::new(tilt.sin(), 0.0, -tilt.cos());
    let o2 = -dir * (5.0 / tilt.cos()); // hits the rectangle's centre
    let rot = |a: f32| Vec3A::new((tilt + a).sin(), 0.0, -(tilt + a).cos());
    let rd = RayDifferential {
        ray: Ray::infinite(o2, dir),
        rx_origin: o2,
        rx_direction: rot(delta),
        ry_origin: o2,
        ry_direction: dir,
    };
    let si = g.intersect_differential(&rd).unwrap();
    let dist = 5.0 / tilt.cos();
    let expected = dist * delta / tilt.cos();
    assert!(
        (si.differentials.dpdx.x - expected).abs() < 2e-3 * expected,
        "{} vs {expected}",
        si.differentials.dpdx.x
    );
}
