//! The small-scene path (no BVH, every leaf tested eight at a time) against the BVH path of
//! the same flattened scene: bit-identical hits on random rays, on rays through the shared
//! edges and vertices of baked cuboids (no leaks) and on grazing rays.

mod support;

use glam::{Mat4, Vec3A};
use prism_geometry::{
    BuildOptions, Disk, Geometry, GeometryBuilder, Hit, Ray, Rectangle, Shape, Sphere, Transform,
    TriangleMesh, SMALL_SCENE_MAX_LEAVES,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use support::{edge_and_vertex_targets, random_unit};

fn affine(rows: [[f32; 4]; 3]) -> Transform {
    let mut all = [[0.0, 0.0, 0.0, 1.0]; 4];
    all[..3].copy_from_slice(&rows);
    Transform::from_matrix(Mat4::from_cols_array_2d(&all).transpose()).expect("invertible")
}

/// The Cornell box of scenes/cornell-box.json (mitsuba.cornell_box()): five walls and the
/// light as 2 m rectangles, two cuboids of one shared 12-triangle mesh (baked). Returns the
/// builder, the cuboid instances with their transforms, and the rectangles'.
fn cornell(b: &mut GeometryBuilder) -> (Vec<(u32, Transform)>, Vec<Transform>) {
    let rectangles = [
        [
            [0.23, 0.0, 0.0, 0.0],
            [0.0, -8.305164e-09, -0.19, 0.99],
            [0.0, 0.19, -8.305164e-09, 0.01],
        ],
        [
            [0.99999994, 0.0, 0.0, 0.0],
            [0.0, -4.371139e-08, 1.0, -1.0],
            [0.0, -1.0, -4.371139e-08, 0.0],
        ],
        [
            [0.99999994, 0.0, 0.0, 0.0],
            [0.0, -4.371139e-08, -1.0, 1.0],
            [0.0, 1.0, -4.371139e-08, 0.0],
        ],
        [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, -1.0],
        ],
        [
            [-4.371139e-08, 0.0, -1.0, 1.0],
            [0.0, 0.99999994, 0.0, 0.0],
            [1.0, 0.0, -4.371139e-08, 0.0],
        ],
        [
            [-4.371139e-08, 0.0, 1.0, -1.0],
            [0.0, 0.99999994, 0.0, 0.0],
            [-1.0, 0.0, -4.371139e-08, 0.0],
        ],
    ];
    let mut rects = Vec::new();
    for rows in rectangles {
        let r = Rectangle {
            half_width_m: 1.0,
            half_height_m: 1.0,
        };
        b.add_instance(Shape::Rectangle(r), affine(rows), None);
        rects.push(affine(rows));
    }
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    let size = Transform::scale(Vec3A::splat(2.0)).expect("scale");
    let mut cubes = Vec::new();
    for rows in [
        [
            [0.28689146, 0.0, -0.08771151, 0.335],
            [0.0, 0.3, 0.0, -0.7],
            [0.08771151, 0.0, 0.28689146, 0.38],
        ],
        [
            [0.28490975, 0.0, 0.09394914, -0.33],
            [0.0, 0.61, 0.0, -0.4],
            [-0.09394914, 0.0, 0.28490975, -0.28],
        ],
    ] {
        let t = affine(rows).compose(&size);
        let id = b.add_instance(Shape::Mesh(cube), t, None).unwrap();
        cubes.push((id, t));
    }
    (cubes, rects)
}

/// The Cornell box plus every other kind of leaf: an identity rectangle, a mirrored
/// cuboid, a single-use identity soup (baked with its own bits), a sphere, a disk and two
/// instances of a shared 9 216-triangle uv sphere (kept instanced: too large to bake).
fn mixed(b: &mut GeometryBuilder) {
    cornell(b);
    let r = Rectangle {
        half_width_m: 0.2,
        half_height_m: 0.1,
    };
    b.add_instance(Shape::Rectangle(r), Transform::IDENTITY, None);
    let mirror = Transform::translate(Vec3A::new(0.5, 0.4, -0.3))
        .compose(&Transform::scale(Vec3A::new(-0.2, 0.3, 0.25)).unwrap());
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    b.add_instance(Shape::Mesh(cube), mirror, None);
    let mut rng = Pcg64::seed_from_u64(3);
    let soup = support::triangle_soup(6, 0.8, 0.05..0.3, &mut rng);
    let soup = b.add_mesh(soup);
    b.add_instance(Shape::Mesh(soup), Transform::IDENTITY, None);
    b.add_instance(
        Shape::Sphere(Sphere { radius_m: 0.15 }),
        Transform::translate(Vec3A::new(-0.5, 0.5, 0.4)),
        None,
    );
    b.add_instance(
        Shape::Disk(Disk { radius_m: 0.2 }),
        Transform::translate(Vec3A::new(0.0, 0.8, 0.0))
            .compose(&Transform::rotate(Vec3A::X, 1.2).unwrap()),
        None,
    );
    let big = b.add_mesh(TriangleMesh::uv_sphere(0.1, 48, 96));
    for x in [-0.6f32, 0.6] {
        b.add_instance(
            Shape::Mesh(big),
            Transform::translate(Vec3A::new(x, -0.2, 0.6)),
            None,
        );
    }
}

/// The Cornell box with 56 small panels at random tilts in a grid under its ceiling: more
/// rectangles than one batch, so the largest go first and the rest are grouped by position
/// and culled by their batches' boxes.
fn many_rectangles(b: &mut GeometryBuilder) {
    cornell(b);
    let mut rng = Pcg64::seed_from_u64(9);
    for i in 0..56 {
        let (x, z) = ((i % 8) as f32 * 0.25 - 0.875, (i / 8) as f32 * 0.25 - 0.875);
        let r = Rectangle {
            half_width_m: rng.gen_range(0.02..0.1),
            half_height_m: rng.gen_range(0.02..0.1),
        };
        let tilt = Transform::rotate(random_unit(&mut rng), rng.gen_range(0.0..3.0)).unwrap();
        let at = Transform::translate(Vec3A::new(x, rng.gen_range(0.3..0.95), z));
        b.add_instance(Shape::Rectangle(r), at.compose(&tilt), None);
    }
}

/// The same scene built with the small path (default options) and with the BVH.
fn both(scene: impl Fn(&mut GeometryBuilder)) -> (Geometry, Geometry) {
    let build = |options: BuildOptions| {
        let mut b = GeometryBuilder::new();
        scene(&mut b);
        b.build_with(options)
    };
    let small = build(BuildOptions::default());
    let bvh = build(BuildOptions {
        small_scene_max_leaves: 0,
        ..BuildOptions::default()
    });
    assert!(small.is_small_scene() && !bvh.is_small_scene());
    (small, bvh)
}

#[derive(Default, Debug)]
struct Agreement {
    rays: usize,
    hits: usize,
    /// Both hit at the same `t` but on different leaves (a tie at a shared edge or vertex).
    ties: usize,
    /// Hits on different leaves within [`NEAR_TIE_M`] of each other: coplanar surfaces
    /// (the cuboids stand on the floor) where the order of the tests decides — the BVH tests
    /// later leaves against the shrunken `t_max` before its division, which can reject a
    /// world-space hit an ulp closer, and a baked hit's `t` is then recomputed in object
    /// space (which may move it a few ulps more, docs/geometry.md "Precision").
    near_ties: usize,
}

/// Distance between the two builds' hit points below which hits on different leaves count
/// as a tie: 1 µm, ≈ 16 ulps of f32 at the box's 1 m coordinates (grazing rays stretch the
/// ulp-sized difference of two coplanar surfaces along the ray, so `t` itself may differ by
/// more ulps).
const NEAR_TIE_M: f32 = 1e-6;

/// Closest hit and occlusion of `ray` agree between the two builds; returns the hit.
fn compare(small: &Geometry, bvh: &Geometry, ray: &Ray, stats: &mut Agreement) -> Option<Hit> {
    let (a, b) = (small.intersect(ray), bvh.intersect(ray));
    stats.rays += 1;
    assert_eq!(small.occluded(ray), bvh.occluded(ray), "occlusion {ray:?}");
    assert_eq!(a.is_some(), small.occluded(ray), "closest vs any {ray:?}");
    match (a, b) {
        (None, None) => None,
        (Some(x), Some(y)) => {
            stats.hits += 1;
            if x != y {
                if x.t == y.t {
                    stats.ties += 1;
                } else {
                    assert!(
                        (x.t - y.t).abs() * ray.direction.length() <= NEAR_TIE_M,
                        "{ray:?}: small {x:?}, bvh {y:?}"
                    );
                    stats.near_ties += 1;
                }
            }
            Some(x)
        }
        _ => panic!("{ray:?}: small {a:?}, bvh {b:?}"),
    }
}

#[test]
fn small_scene_path_matches_the_bvh_on_random_rays() {
    for (name, scene) in [
        (
            "cornell",
            &(|b: &mut GeometryBuilder| drop(cornell(b))) as &dyn Fn(&mut GeometryBuilder),
        ),
        ("mixed", &mixed),
        ("many rectangles", &many_rectangles),
    ] {
        let (small, bvh) = both(scene);
        let mut rng = Pcg64::seed_from_u64(11);
        let mut stats = Agreement::default();
        for i in 0..60_000 {
            let o = if i % 3 == 0 {
                // Outside, like the camera (the box is open towards +z).
                Vec3A::new(
                    rng.gen_range(-1.5..1.5),
                    rng.gen_range(-1.5..1.5),
                    rng.gen_range(1.5..4.0),
                )
            } else {
                Vec3A::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                )
            };
            let mut d = random_unit(&mut rng);
            if i % 4 == 1 {
                d *= rng.gen_range(0.01..20.0);
            }
            let ray = match i % 5 {
                0 => Ray::infinite(o, d),
                1 => Ray::new(o, d, rng.gen_range(0.0..0.5), rng.gen_range(0.5..3.0)),
                _ => Ray::spawn(o, d),
            };
            compare(&small, &bvh, &ray, &mut stats);
        }
        // Shadow segments to the light (the rectangle at y ≈ 0.99).
        for _ in 0..20_000 {
            let from = Vec3A::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..0.9),
                rng.gen_range(-1.0..1.0),
            );
            let to = Vec3A::new(rng.gen_range(-0.23..0.23), 0.99, rng.gen_range(-0.18..0.2));
            compare(&small, &bvh, &Ray::spawn_to(from, to), &mut stats);
        }
        eprintln!("{name}: {stats:?}");
        // Most shadow segments are unoccluded and many rays from outside miss the box.
        assert!(stats.hits > stats.rays / 3, "{name}: {stats:?}");
        // Every difference is a tie (asserted in `compare`). Random rays meet them where
        // surfaces coincide: origins inside a cuboid looking at its bottom face, which lies
        // in the floor's plane (0.17 % of the hits of the Cornell box).
        assert!(
            stats.ties + stats.near_ties <= stats.hits / 100,
            "{name}: {stats:?}"
        );
    }
}

#[test]
fn small_scene_rays_through_shared_edges_and_vertices_do_not_leak() {
    let mut b = GeometryBuilder::new();
    let (cubes, rects) = cornell(&mut b);
    let (small, bvh) = both(|b| drop(cornell(b)));
    let mut rng = Pcg64::seed_from_u64(5);
    let mut stats = Agreement::default();
    let cube = TriangleMesh::cuboid(Vec3A::splat(0.5));
    for &(id, to_world) in &cubes {
        // World targets through the baked vertices (each transformed once, as the bake does)
        // and edge points between them.
        let world: Vec<Vec3A> = cube.positions.iter().map(|&p| to_world.point(p)).collect();
        let targets = edge_and_vertex_targets(&TriangleMesh::new(world, cube.indices.clone()));
        let mut origins = vec![to_world.point(Vec3A::ZERO)];
        origins.extend((0..10).map(|_| to_world.point(random_unit(&mut rng) * 0.45)));
        for &o in &origins {
            for &target in &targets {
                let ray = Ray::new(o, target - o, 0.0, f32::INFINITY);
                let hit = compare(&small, &bvh, &ray, &mut stats);
                let hit = hit.unwrap_or_else(|| panic!("leak from inside: {ray:?}"));
                // The cuboids stand on the floor (instance 1; the tall one reaches 1 cm
                // below it): towards targets on or below its plane the floor may come first.
                let on_cube = hit.instance_id == id && (hit.t - 1.0).abs() < 1e-3;
                let floor_first = hit.instance_id == 1 && hit.t < 1.0 + 1e-6;
                assert!(on_cube || floor_first, "{ray:?} {hit:?}");
                // From outside, through the same point, towards the inside.
                let outside = target + (target - o) * 0.2;
                let back = Ray::new(outside, target - outside, 0.0, f32::INFINITY);
                let h = compare(&small, &bvh, &back, &mut stats).expect("hit");
                assert!(h.t <= 1.0 + 1e-3, "leak from outside: {back:?} {h:?}");
            }
        }
    }
    // Corners and edge points of the rectangles, from inside the box.
    for to_world in &rects {
        for (x, y) in [
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, -1.0),
            (-1.0, -1.0),
            (1.0, 0.3),
            (0.2, -1.0),
        ] {
            let target = to_world.point(Vec3A::new(x, y, 0.0));
            for _ in 0..20 {
                let o = Vec3A::new(
                    rng.gen_range(-0.9..0.9),
                    rng.gen_range(-0.9..0.9),
                    rng.gen_range(-0.9..0.9),
                );
                compare(
                    &small,
                    &bvh,
                    &Ray::new(o, target - o, 0.0, f32::INFINITY),
                    &mut stats,
                );
            }
        }
    }
    eprintln!("{stats:?}");
    assert!(stats.rays > 3000, "{stats:?}");
}

#[test]
fn small_scene_grazing_rays_match_the_bvh() {
    let (small, bvh) = both(|b| drop(cornell(b)));
    let mut b = GeometryBuilder::new();
    let (cubes, _) = cornell(&mut b);
    let mut rng = Pcg64::seed_from_u64(9);
    let mut stats = Agreement::default();
    // In the planes of the cuboid faces (object space: a coordinate at exactly ±0.5,
    // direction with zero component along that axis), taken to world space.
    for &(_, to_world) in &cubes {
        for axis in 0..3 {
            for side in [-0.5f32, 0.5] {
                for _ in 0..300 {
                    let mut o = Vec3A::new(
                        rng.gen_range(-1.5..1.5),
                        rng.gen_range(-1.5..1.5),
                        rng.gen_range(-1.5..1.5),
                    );
                    o[axis] = side;
                    let mut d = random_unit(&mut rng);
                    d[axis] = 0.0;
                    let ray = Ray::infinite(to_world.point(o), to_world.vector(d));
                    compare(&small, &bvh, &ray, &mut stats);
                }
            }
        }
    }
    // Along the walls: origins on a wall plane (x, y or z = ±1), directions in the plane,
    // including axis-aligned ones with signed zeros.
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            for k in 0..600 {
                let mut o = Vec3A::new(
                    rng.gen_range(-0.99..0.99),
                    rng.gen_range(-0.99..0.99),
                    rng.gen_range(-0.99..0.99),
                );
                o[axis] = side;
                let mut d = if k % 4 == 0 {
                    let mut e = Vec3A::ZERO;
                    e[(axis + 1 + k % 2) % 3] = if k % 8 == 0 { 1.0 } else { -1.0 };
                    e
                } else {
                    random_unit(&mut rng)
                };
                d[axis] = if k % 3 == 0 { -0.0 } else { 0.0 };
                compare(&small, &bvh, &Ray::infinite(o, d), &mut stats);
            }
        }
    }
    eprintln!("{stats:?}");
    assert!(stats.rays > 7_000, "{stats:?}");
}

#[test]
fn small_scene_threshold_counts_leaves() {
    // 6 rectangles + k cuboids of 12 triangles: small up to the threshold, a BVH above.
    for k in 0..13 {
        let mut b = GeometryBuilder::new();
        for i in 0..6 {
            b.add_instance(
                Shape::Rectangle(Rectangle {
                    half_width_m: 1.0,
                    half_height_m: 1.0,
                }),
                Transform::translate(Vec3A::new(0.0, 0.0, i as f32)),
                None,
            );
        }
        let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.1)));
        for i in 0..k {
            b.add_instance(
                Shape::Mesh(cube),
                Transform::translate(Vec3A::new(i as f32 * 0.3, 0.0, 0.5)),
                None,
            );
        }
        let g = b.build_with(BuildOptions::default());
        let leaves = 6 + 12 * k;
        assert_eq!(
            g.is_small_scene(),
            leaves <= SMALL_SCENE_MAX_LEAVES,
            "{leaves} leaves"
        );
    }
}

/// Rays leaving points 10 µm (and 1 µm) in front of a wall find it through the BVH as
/// through the small path: obvhs' node test clamped every child's entry distance to
/// ≥ 10⁻⁴ whatever the ray's `t_min` and lost these hits; Prism's own node test
/// (`triangle_bvh::node_hits`) bounds it by `t_min`.
#[test]
fn hits_micrometres_from_the_origin_are_found_through_the_bvh() {
    let (small, bvh) = both(|b: &mut GeometryBuilder| drop(cornell(b)));
    let mut rng = Pcg64::seed_from_u64(5);
    let mut found = 0;
    for gap_m in [1e-5f32, 1e-6] {
        for _ in 0..2_000 {
            // A random direction towards the back wall (the plane z = −1), from a point
            // `gap_m` in front of it along that direction, above the boxes.
            let d =
                Vec3A::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), -1.0).normalize();
            let p = Vec3A::new(rng.gen_range(-0.8..0.8), rng.gen_range(0.4..0.9), -1.0);
            let origin = p - d * gap_m;
            let ray = Ray::new(origin, d, 0.0, f32::INFINITY);
            let (a, b) = (small.intersect(&ray), bvh.intersect(&ray));
            let b = b.unwrap_or_else(|| panic!("the BVH lost the wall {gap_m} m ahead: {ray:?}"));
            assert_eq!(a.map(|h| h.t), Some(b.t), "{ray:?}");
            assert!((b.t - gap_m).abs() < 1e-6, "{ray:?}: t {}", b.t);
            assert!(bvh.occluded(&ray), "{ray:?}");
            found += 1;
        }
    }
    assert_eq!(found, 4_000);
}
