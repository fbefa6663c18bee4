//! Flattening (small or single-use meshes baked into world-space triangles that share one
//! BVH with the remaining instances) answers every query as the unflattened instanced path
//! does: same closest hit (instance, primitive, t, b1, b2), same occlusion, same interaction
//! records; it bakes what the thresholds say; closed meshes stay closed under rotation,
//! non-uniform scale and mirroring; far-translated objects lose nothing relevant.

use glam::Vec3A;
use prism_geometry::{
    BuildOptions, BuildQuality, Disk, Geometry, GeometryBuilder, Hit, Ray, Rectangle, Shape,
    Sphere, Transform, TriangleMesh, FLATTEN_MAX_SHARED_MESH_TRIANGLES,
    FLATTEN_SHARED_TRIANGLE_BUDGET,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

mod support;
use support::{edge_and_vertex_targets, random_unit, triangle_soup};

/// Translation in `[-spread, spread]³` ∘ random rotation ∘ non-uniform scale in
/// [0.4, 1.6] per axis, mirrored (one negative factor) when `mirror`.
fn random_transform(rng: &mut Pcg64, spread: f32, mirror: bool) -> Transform {
    let mut s = Vec3A::new(
        rng.gen_range(0.4..1.6),
        rng.gen_range(0.4..1.6),
        rng.gen_range(0.4..1.6),
    );
    if mirror {
        s[rng.gen_range(0..3)] *= -1.0;
    }
    let offset = if spread > 0.0 {
        Vec3A::new(
            rng.gen_range(-spread..spread),
            rng.gen_range(-spread..spread),
            rng.gen_range(-spread..spread),
        )
    } else {
        Vec3A::ZERO
    };
    Transform::translate(offset)
        .compose(&Transform::rotate(random_unit(rng), rng.gen_range(0.0..6.3)).unwrap())
        .compose(&Transform::scale(s).unwrap())
}

/// A strip of exactly `n` triangles over a zig-zag of vertices (shared edges).
fn strip(n: usize) -> TriangleMesh {
    let positions = (0..n + 2)
        .map(|i| Vec3A::new(i as f32 * 0.01, (i % 2) as f32 * 0.01, 0.0))
        .collect();
    let indices = (0..n as u32).map(|i| [i, i + 1, i + 2]).collect();
    TriangleMesh::new(positions, indices)
}

/// What the mixed scene holds, for the counts it must flatten into.
struct MixedCounts {
    flattened_triangles: usize,
    top_level: usize,
}

/// Rectangles, cuboids (one shared 12-triangle mesh), a shared 320-triangle icosphere, a
/// shared uv sphere above the sharing threshold, a single-use 5120-triangle icosphere, a
/// single-use open soup, one identity-placed cuboid, analytic spheres and disks — under
/// translations, rotations, non-uniform scales and mirrors.
fn mixed_scene(seed: u64) -> (GeometryBuilder, MixedCounts) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut b = GeometryBuilder::new();
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    let ico = b.add_mesh(TriangleMesh::icosphere(0.5, 2));
    let big_mesh = TriangleMesh::uv_sphere(0.6, 48, 96);
    let big_triangles = big_mesh.triangle_count();
    assert!(big_triangles > FLATTEN_MAX_SHARED_MESH_TRIANGLES);
    let big = b.add_mesh(big_mesh);
    let single = b.add_mesh(TriangleMesh::icosphere(0.7, 4));
    let soup = b.add_mesh(triangle_soup(300, 1.0, 0.05..0.4, &mut rng));
    let identity_cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::new(0.3, 0.2, 0.4)));
    let mut flattened_triangles = 0;
    let mut top_level = 0;
    for k in 0..8 {
        let t = random_transform(&mut rng, 4.0, k % 3 == 0);
        let r = Rectangle {
            half_width_m: rng.gen_range(0.3..1.5),
            half_height_m: rng.gen_range(0.3..1.5),
        };
        b.add_instance(Shape::Rectangle(r), t, Some(k)).unwrap();
        top_level += 1;
    }
    for k in 0..10 {
        let t = random_transform(&mut rng, 4.0, k % 3 == 1);
        b.add_instance(Shape::Mesh(cube), t, None).unwrap();
        flattened_triangles += 12;
    }
    for k in 0..6 {
        let t = random_transform(&mut rng, 4.0, k % 2 == 0);
        b.add_instance(Shape::Mesh(ico), t, None).unwrap();
        flattened_triangles += 320;
    }
    for k in 0..3 {
        let t = random_transform(&mut rng, 4.0, k == 1);
        b.add_instance(Shape::Mesh(big), t, None).unwrap();
        top_level += 1;
    }
    let t = random_transform(&mut rng, 3.0, true);
    b.add_instance(Shape::Mesh(single), t, None).unwrap();
    flattened_triangles += 5120;
    let t = random_transform(&mut rng, 3.0, false);
    b.add_instance(Shape::Mesh(soup), t, None).unwrap();
    flattened_triangles += 300;
    b.add_instance(Shape::Mesh(identity_cube), Transform::IDENTITY, None)
        .unwrap();
    flattened_triangles += 12;
    for k in 0..4 {
        let t = random_transform(&mut rng, 4.0, k == 2);
        let s = Sphere {
            radius_m: rng.gen_range(0.2..0.8),
        };
        b.add_instance(Shape::Sphere(s), t, None).unwrap();
        let t = random_transform(&mut rng, 4.0, k == 3);
        let d = Disk {
            radius_m: rng.gen_range(0.3..1.2),
        };
        b.add_instance(Shape::Disk(d), t, None).unwrap();
        top_level += 2;
    }
    (
        b,
        MixedCounts {
            flattened_triangles,
            top_level,
        },
    )
}

fn build(b: GeometryBuilder, flatten: bool) -> Geometry {
    b.build_with(BuildOptions {
        quality: BuildQuality::Fast,
        flatten,
        ..BuildOptions::default()
    })
}

/// Whether a hit lies on (within `tol`, in barycentric or uv units) the boundary of what it
/// hit: the only place where the world-space triangles and the object-space test may round
/// a hit/miss decision differently.
fn at_an_edge(g: &Geometry, ray: &Ray, hit: &Hit, tol: f32) -> bool {
    let inst = &g.instances()[hit.instance_id as usize];
    match inst.shape {
        Shape::Mesh(_) => {
            let b0 = 1.0 - hit.b1 - hit.b2;
            b0.min(hit.b1).min(hit.b2) < tol
        }
        Shape::Rectangle(_) => {
            let uv = g.interaction(ray, hit).uv;
            uv.x.min(uv.y).min(1.0 - uv.x).min(1.0 - uv.y) < tol
        }
        // Analytic shapes take the same path in both builds.
        _ => false,
    }
}

#[derive(Debug, Default)]
struct Agreement {
    rays: usize,
    hits: usize,
    /// Identical `Hit` (every field bit for bit).
    identical: usize,
    /// Same instance and primitive, t/b1/b2 within tolerance (the object-space re-test
    /// rounded to a miss at an edge, so the world-space values were kept).
    same_primitive: usize,
    /// Another primitive at (nearly) the same t: a tie at a shared edge or vertex.
    ties: usize,
    /// A hit (at an edge of it) that the other build misses, nearer than what that build
    /// reports if anything.
    edge_disagreements: usize,
}

/// Compare the two builds on one ray; panics on any difference that is not an edge case.
fn compare(reference: &Geometry, flat: &Geometry, ray: &Ray, stats: &mut Agreement) {
    let (a, b) = (reference.intersect(ray), flat.intersect(ray));
    stats.rays += 1;
    // Each build's any-hit query agrees with its own closest-hit query exactly.
    assert_eq!(reference.occluded(ray), a.is_some(), "reference {ray:?}");
    assert_eq!(flat.occluded(ray), b.is_some(), "flattened {ray:?}");
    let scale = ray.direction.length();
    let t_tol = |t: f32| 4e-6 * (t * scale + ray.origin.abs().max_element() + 1.0) / scale;
    match (a, b) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            stats.hits += 1;
            if a == b {
                stats.identical += 1;
                // Same hit in, same record out.
                assert_eq!(reference.interaction(ray, &a), flat.interaction(ray, &b));
            } else if (a.instance_id, a.primitive_id) == (b.instance_id, b.primitive_id) {
                assert!(
                    (a.t - b.t).abs() <= t_tol(a.t),
                    "{a:?} vs {b:?} for {ray:?}"
                );
                assert!(
                    (a.b1 - b.b1).abs() < 1e-4 && (a.b2 - b.b2).abs() < 1e-4,
                    "{a:?} vs {b:?}"
                );
                assert!(
                    at_an_edge(flat, ray, &b, 1e-4),
                    "{a:?} vs {b:?} for {ray:?}"
                );
                stats.same_primitive += 1;
            } else if (a.t - b.t).abs() <= t_tol(a.t) {
                // Another primitive at the same t: a shared edge or vertex.
                stats.ties += 1;
            } else {
                // One build found a nearer hit the other missed: only at an edge of it.
                let (g, nearer) = if a.t < b.t { (reference, a) } else { (flat, b) };
                assert!(
                    at_an_edge(g, ray, &nearer, 1e-4),
                    "different closest hits {a:?} vs {b:?} for {ray:?}"
                );
                stats.edge_disagreements += 1;
            }
        }
        (Some(h), None) => {
            assert!(
                at_an_edge(reference, ray, &h, 1e-4),
                "flattened misses {h:?} of {ray:?}"
            );
            stats.edge_disagreements += 1;
        }
        (None, Some(h)) => {
            assert!(
                at_an_edge(flat, ray, &h, 1e-4),
                "flattened adds {h:?} for {ray:?}"
            );
            stats.edge_disagreements += 1;
        }
    }
}

#[test]
fn flattened_geometry_matches_the_instanced_geometry_on_random_rays() {
    let (b, counts) = mixed_scene(11);
    let flat = build(b, true);
    let reference = build(mixed_scene(11).0, false);
    assert_eq!(flat.flattened_triangle_count(), counts.flattened_triangles);
    assert_eq!(flat.instance_leaf_count(), counts.top_level);
    assert_eq!(reference.flattened_triangle_count(), 0);
    assert_eq!(reference.instance_leaf_count(), reference.instances().len());

    let mut rng = Pcg64::seed_from_u64(3);
    let mut stats = Agreement::default();
    for i in 0..120_000 {
        let origin = Vec3A::new(
            rng.gen_range(-6.0..6.0),
            rng.gen_range(-6.0..6.0),
            rng.gen_range(-6.0..6.0),
        );
        // Directions are not unit length: t is in units of the direction in both builds.
        let dir = random_unit(&mut rng) * rng.gen_range(0.3..3.0);
        let (t_min, t_max) = match i % 3 {
            0 => (0.0, f32::INFINITY),
            1 => (1e-4, f32::INFINITY),
            _ => (1e-4, rng.gen_range(0.5..6.0)),
        };
        compare(
            &reference,
            &flat,
            &Ray::new(origin, dir, t_min, t_max),
            &mut stats,
        );
    }
    eprintln!("random rays: {stats:?}");
    assert!(stats.rays == 120_000 && stats.hits > 15_000, "{stats:?}");
    // The object-space re-test gives bit-identical hits except at edges and ties.
    let others = stats.same_primitive + stats.ties + stats.edge_disagreements;
    assert!(others * 1000 < stats.hits, "{stats:?}");

    // Rays aimed at the flattened shapes' vertices and corners, where rounding differences
    // concentrate: ties between the triangles sharing a vertex are the rule there.
    let mut stats = Agreement::default();
    for inst in 0..flat.instances().len() {
        let instance = flat.instances()[inst];
        let targets: Vec<Vec3A> = match instance.shape {
            Shape::Mesh(m) => flat.mesh(m).positions.iter().step_by(7).copied().collect(),
            Shape::Rectangle(r) => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, y)| Vec3A::new(x * r.half_width_m, y * r.half_height_m, 0.0))
                .to_vec(),
            _ => Vec::new(),
        };
        for target in targets {
            let target = instance.to_world.point(target);
            let origin = target + random_unit(&mut rng) * rng.gen_range(1.0..5.0);
            compare(
                &reference,
                &flat,
                &Ray::new(origin, target - origin, 0.0, f32::INFINITY),
                &mut stats,
            );
        }
    }
    eprintln!("rays at vertices: {stats:?}");
    assert!(stats.rays > 1_000, "{stats:?}");
}

#[test]
fn flattening_bakes_small_or_single_use_meshes_and_keeps_analytic_shapes() {
    // The mixed scene: see `mixed_scene` for the expected split.
    let (b, counts) = mixed_scene(5);
    let g = build(b, true);
    assert_eq!(g.flattened_triangle_count(), counts.flattened_triangles);
    assert_eq!(g.instance_leaf_count(), counts.top_level);
    assert_eq!(
        g.mesh_count(),
        6,
        "meshes stay stored for the interaction records"
    );

    // A shared mesh of exactly the threshold is baked, one triangle more is not; a
    // single-use mesh of any size is.
    let mut b = GeometryBuilder::new();
    let at = b.add_mesh(strip(FLATTEN_MAX_SHARED_MESH_TRIANGLES));
    let above = b.add_mesh(strip(FLATTEN_MAX_SHARED_MESH_TRIANGLES + 1));
    let once = b.add_mesh(strip(3 * FLATTEN_MAX_SHARED_MESH_TRIANGLES));
    for (k, m) in [at, at, above, above, once].into_iter().enumerate() {
        b.add_instance(
            Shape::Mesh(m),
            Transform::translate(Vec3A::new(0.0, k as f32, 1.0)),
            None,
        )
        .unwrap();
    }
    let g = build(b, true);
    assert_eq!(
        g.flattened_triangle_count(),
        5 * FLATTEN_MAX_SHARED_MESH_TRIANGLES
    );
    assert_eq!(g.instance_leaf_count(), 2);

    // Copies of shared meshes stop at the budget, smallest meshes first.
    let mut b = GeometryBuilder::new();
    let small = b.add_mesh(strip(16));
    let large = b.add_mesh(strip(FLATTEN_MAX_SHARED_MESH_TRIANGLES));
    let copies = FLATTEN_SHARED_TRIANGLE_BUDGET / FLATTEN_MAX_SHARED_MESH_TRIANGLES;
    let place = |k: usize| Transform::translate(Vec3A::new(0.0, k as f32 * 0.1, 0.0));
    for k in 0..copies {
        b.add_instance(Shape::Mesh(large), place(k), None).unwrap();
    }
    for k in 0..4 {
        b.add_instance(Shape::Mesh(small), place(k), None).unwrap();
    }
    let g = build(b, true);
    assert_eq!(g.flattened_triangle_count(), 4 * 16);
    assert_eq!(g.instance_leaf_count(), copies);

    // Analytic shapes are never baked: they stay exact leaves of the one BVH.
    let mut b = GeometryBuilder::new();
    let rect = Rectangle {
        half_width_m: 1.0,
        half_height_m: 0.5,
    };
    b.add_instance(Shape::Rectangle(rect), Transform::IDENTITY, None);
    b.add_instance(
        Shape::Sphere(Sphere { radius_m: 0.25 }),
        Transform::translate(Vec3A::new(0.0, 0.0, -1.0)),
        None,
    );
    b.add_instance(
        Shape::Disk(Disk { radius_m: 1.0 }),
        Transform::translate(Vec3A::new(0.0, 0.0, -2.0)),
        None,
    );
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    b.add_instance(
        Shape::Mesh(cube),
        Transform::translate(Vec3A::new(0.0, 0.0, -4.0)),
        None,
    );
    let g = build(b, true);
    assert_eq!(g.flattened_triangle_count(), 12);
    assert_eq!(g.instance_leaf_count(), 3);
    let ray = Ray::infinite(Vec3A::new(0.0, 0.0, 3.0), -Vec3A::Z);
    let hit = Hit {
        t: 3.0,
        instance_id: 0,
        primitive_id: 0,
        b1: 0.0,
        b2: 0.0,
    };
    assert_eq!(g.intersect(&ray), Some(hit));
    assert!(g.occluded(&ray));
    for (t_min, instance, t) in [(3.5, 1, 3.75), (4.5, 2, 5.0), (5.5, 3, 6.5)] {
        let r = Ray::new(ray.origin, ray.direction, t_min, f32::INFINITY);
        let h = g.intersect(&r).unwrap();
        assert_eq!((h.instance_id, h.t), (instance, t));
        assert!(g.occluded(&r));
        assert!(!g.occluded(&Ray::new(ray.origin, ray.direction, t_min, t - 0.01)));
    }
    assert!(!g.occluded(&Ray::new(ray.origin, ray.direction, 7.6, f32::INFINITY)));

    // A single sphere: traced without a BVH.
    let mut b = GeometryBuilder::new();
    b.add_instance(
        Shape::Sphere(Sphere { radius_m: 1.0 }),
        Transform::IDENTITY,
        None,
    );
    let g = build(b, true);
    assert_eq!(g.instance_leaf_count(), 1);
    assert_eq!(g.intersect(&ray).map(|h| h.t), Some(2.0));
}

#[test]
fn baked_closed_meshes_stay_closed_under_rotation_scale_and_mirror() {
    let mut rng = Pcg64::seed_from_u64(17);
    let mut rays = 0;
    for mesh in [
        TriangleMesh::cuboid(Vec3A::new(1.0, 0.5, 2.0)),
        TriangleMesh::icosphere(1.0, 2),
    ] {
        for (k, spread) in [4.0f32, 4.0, 1000.0].into_iter().enumerate() {
            let to_world = random_transform(&mut rng, spread, k != 1);
            let mut b = GeometryBuilder::new();
            let id = b.add_mesh(mesh.clone());
            // Two instances: a shared mesh, baked as two copies.
            b.add_instance(Shape::Mesh(id), to_world, None).unwrap();
            b.add_instance(
                Shape::Mesh(id),
                to_world.compose(&Transform::translate(Vec3A::new(0.0, 0.0, 50.0))),
                None,
            )
            .unwrap();
            let g = b.build(BuildQuality::Fast);
            assert_eq!(g.flattened_triangle_count(), 2 * mesh.triangle_count());
            // World targets through the baked vertices: exactly the soup's vertex bits, and
            // edge points between them.
            let world: Vec<Vec3A> = mesh.positions.iter().map(|&p| to_world.point(p)).collect();
            let world_mesh = TriangleMesh::new(world, mesh.indices.clone());
            let targets = edge_and_vertex_targets(&world_mesh);
            let mut origins = vec![to_world.point(Vec3A::ZERO)];
            origins.extend(
                (0..8).map(|_| to_world.point(random_unit(&mut rng) * rng.gen_range(0.0..0.45))),
            );
            for &o in &origins {
                for &target in &targets {
                    let ray = Ray::new(o, target - o, 0.0, f32::INFINITY);
                    let hit = g.intersect(&ray);
                    assert!(hit.is_some(), "leak from inside: {ray:?} at {target:?}");
                    assert_eq!(hit.unwrap().instance_id, 0);
                    assert!(g.occluded(&ray), "occlusion leak: {ray:?}");
                    assert!((hit.unwrap().t - 1.0).abs() < 1e-3, "{ray:?} {hit:?}");
                    let outside = target + (target - o) * 2.0;
                    let back = Ray::new(outside, target - outside, 0.0, f32::INFINITY);
                    assert!(g.intersect(&back).is_some(), "leak from outside: {back:?}");
                    rays += 2;
                }
            }
        }
    }
    assert!(rays > 30_000, "{rays}");
}

#[test]
fn far_translated_small_objects_lose_nothing_relevant() {
    // Two 0.2 m cuboids (one shared mesh, baked) and a rectangle (analytic in both builds)
    // 20 km from the origin, seen from 2–10 m away: world-space baking rounds the cuboids'
    // vertices to f32 at 20 km (ulp ≈ 2 mm), the instanced path rounds the ray origin taken
    // to object space by the same amount; the two may disagree only within a few such ulps
    // of an edge (measured along the face, which a grazing ray stretches), and t agrees to
    // the same absolute precision.
    let mut rng = Pcg64::seed_from_u64(23);
    let far = Vec3A::new(1.2e4, -5.0e3, 2.0e4);
    let make = || {
        let mut rng = Pcg64::seed_from_u64(1);
        let mut b = GeometryBuilder::new();
        let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.1)));
        let t = Transform::translate(far).compose(&random_transform(&mut rng, 0.0, true));
        b.add_instance(Shape::Mesh(cube), t, None).unwrap();
        b.add_instance(
            Shape::Mesh(cube),
            t.compose(&Transform::translate(Vec3A::X)),
            None,
        )
        .unwrap();
        let r = Rectangle {
            half_width_m: 0.1,
            half_height_m: 0.1,
        };
        b.add_instance(
            Shape::Rectangle(r),
            Transform::translate(far + Vec3A::Y).compose(&random_transform(&mut rng, 0.0, false)),
            None,
        )
        .unwrap();
        b
    };
    let flat = build(make(), true);
    let reference = build(make(), false);
    assert_eq!(flat.instance_leaf_count(), 1, "the rectangle");
    let ulp = (far.abs().max_element() * f32::EPSILON).max(f32::MIN_POSITIVE);
    let centres: Vec<Vec3A> = flat
        .instances()
        .iter()
        .map(|inst| inst.to_world.point(Vec3A::ZERO))
        .collect();
    let mut hits = 0;
    let mut disagreements = 0;
    let mut max_edge_distance = 0.0f32;
    // Wrong answers (hit/miss or which object) against an f64 reference, per build.
    let (mut flat_wrong, mut reference_wrong) = (0, 0);
    for i in 0..30_000 {
        let centre = centres[i % 3];
        let target = centre + random_unit(&mut rng) * rng.gen_range(0.0..0.15);
        let origin = centre + random_unit(&mut rng) * rng.gen_range(2.0..10.0);
        let ray = Ray::new(origin, (target - origin).normalize(), 0.0, f32::INFINITY);
        let (a, b) = (reference.intersect(&ray), flat.intersect(&ray));
        hits += a.is_some() as usize;
        let truth = closest_in_f64(&flat, &ray);
        reference_wrong += (a.map(|h| h.instance_id) != truth) as usize;
        flat_wrong += (b.map(|h| h.instance_id) != truth) as usize;
        // The hit one build found nearer than the other did (if any), with that build.
        let nearer = match (a, b) {
            (None, None) => continue,
            (Some(a), Some(b))
                if (a.instance_id, a.primitive_id) == (b.instance_id, b.primitive_id) =>
            {
                // Unit direction: t in metres.
                assert!((a.t - b.t).abs() <= 8.0 * ulp, "{a:?} vs {b:?}");
                continue;
            }
            (Some(a), Some(b)) if (a.t - b.t).abs() <= 8.0 * ulp => continue,
            (Some(a), Some(b)) if b.t < a.t => (&flat, b),
            (Some(a), _) => (&reference, a),
            (None, Some(b)) => (&flat, b),
        };
        let (g, h) = nearer;
        // Distance of the hit to the nearest edge of its face, in object-space metres.
        let inst = &g.instances()[h.instance_id as usize];
        let p = inst.to_world.inverse_point(g.interaction(&ray, &h).p);
        let d = match inst.shape {
            Shape::Rectangle(_) => (0.1 - p.x.abs()).min(0.1 - p.y.abs()),
            _ => {
                // Cuboid: the largest |coordinate| is the face's, the next one the edge's.
                let mut c = p.abs().to_array();
                c.sort_by(f32::total_cmp);
                0.1 - c[1]
            }
        };
        // Object space is scaled by 0.4–1.6: 32 world ulps ≤ 80 object-space ulps.
        assert!(
            d.abs() <= 32.0 * ulp,
            "{ray:?}: {a:?} vs {b:?}, {d} m from an edge"
        );
        max_edge_distance = max_edge_distance.max(d.abs());
        disagreements += 1;
    }
    eprintln!(
        "far: {hits} hits, {disagreements} edge disagreements (at most {:.1} ulps from an \
         edge, ulp {ulp} m); wrong against f64: flattened {flat_wrong}, instanced \
         {reference_wrong}",
        max_edge_distance / ulp
    );
    assert!(
        hits > 5_000 && disagreements * 50 < hits,
        "{hits} {disagreements}"
    );
    // Baking is no less accurate than transforming the ray.
    assert!(
        flat_wrong <= 2 * reference_wrong + 10,
        "{flat_wrong} {reference_wrong}"
    );
}

/// Which of the far test's objects (cuboids and a rectangle of half size 0.1, each defined by
/// its f32 matrix) `ray` hits first, computed in f64.
fn closest_in_f64(g: &Geometry, ray: &Ray) -> Option<u32> {
    let mut best: Option<(f64, u32)> = None;
    for (k, inst) in g.instances().iter().enumerate() {
        let inv = inst.to_world.matrix().as_dmat4().inverse();
        let o = inv.transform_point3(ray.origin.as_dvec3());
        let d = inv.transform_vector3(ray.direction.as_dvec3());
        let t = match inst.shape {
            Shape::Rectangle(_) => {
                let t = -o.z / d.z;
                let p = o + t * d;
                (t > 0.0 && p.x.abs() <= 0.1 && p.y.abs() <= 0.1).then_some(t)
            }
            _ => {
                let (a, b) = ((-0.1 - o) / d, (0.1 - o) / d);
                let (t0, t1) = (a.min(b).max_element(), a.max(b).min_element());
                (t0 <= t1 && t1 > 0.0).then_some(if t0 > 0.0 { t0 } else { t1 })
            }
        };
        if let Some(t) = t {
            if best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, k as u32));
            }
        }
    }
    best.map(|(_, k)| k)
}
