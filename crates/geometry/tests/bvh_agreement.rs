//! The BVH's closest-hit and occlusion queries agree with brute force over every triangle, and
//! closed meshes never leak rays aimed exactly at their shared edges and vertices
//! (Woop, Benthin & Wald 2013).

use glam::Vec3A;
use prism_geometry::{
    BuildOptions, BuildQuality, Geometry, GeometryBuilder, Hit, Ray, Shape, Transform,
    TriangleMesh, WatertightRay, SMALL_SCENE_MAX_LEAVES,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

mod support;
use support::{edge_and_vertex_targets, random_unit, triangle_soup};

fn single(mesh: &TriangleMesh, quality: BuildQuality) -> Geometry {
    let mut b = GeometryBuilder::new();
    let id = b.add_mesh(mesh.clone());
    b.add_instance(Shape::Mesh(id), Transform::IDENTITY, None)
        .unwrap();
    b.build(quality)
}

/// Closest t over all triangles with the same watertight test.
fn brute_force(mesh: &TriangleMesh, ray: &Ray) -> Option<(f32, usize)> {
    let wt = WatertightRay::new(ray.origin, ray.direction, ray.t_min);
    let mut best: Option<(f32, usize)> = None;
    for i in 0..mesh.triangle_count() {
        let [a, b, c] = mesh.triangle(i);
        let t_max = best.map_or(ray.t_max, |(t, _)| t);
        if let Some(h) = wt.intersect(a, b, c, t_max) {
            best = Some((h.t, i));
        }
    }
    best
}

fn test_meshes() -> Vec<(&'static str, TriangleMesh)> {
    let mut rng = Pcg64::seed_from_u64(7);
    vec![
        ("icosphere", TriangleMesh::icosphere(1.0, 3)),
        ("uv_sphere", TriangleMesh::uv_sphere(1.2, 16, 32)),
        ("cube", TriangleMesh::cuboid(Vec3A::new(1.0, 0.6, 0.8))),
        ("soup", triangle_soup(600, 1.5, 0.02..0.4, &mut rng)),
        (
            "soup with duplicates",
            with_duplicates(triangle_soup(600, 1.5, 0.02..0.4, &mut rng)),
        ),
    ]
}

/// `mesh` with 100 copies of each of its first five triangles spread through it and 100
/// triangles collapsed onto one vertex: groups the build takes apart from PLOC
/// (`prism_geometry::coincident_boxes`).
fn with_duplicates(mut mesh: TriangleMesh) -> TriangleMesh {
    let originals = mesh.indices.clone();
    let mut indices = Vec::new();
    for (i, tri) in originals.iter().enumerate() {
        indices.push(*tri);
        if i % 6 == 0 {
            indices.extend((0..5).map(|k| originals[k]));
        }
    }
    let collapsed = originals[7][0];
    indices.extend(std::iter::repeat_n([collapsed; 3], 100));
    mesh.indices = indices;
    TriangleMesh::new(mesh.positions, mesh.indices)
}

#[test]
fn closest_and_any_hit_agree_with_brute_force_on_random_rays() {
    let mut rng = Pcg64::seed_from_u64(2024);
    let mut total = 0;
    for (name, mesh) in test_meshes() {
        for quality in [BuildQuality::Fastest, BuildQuality::Fast] {
            let geometry = single(&mesh, quality);
            for i in 0..13_000 {
                let origin = Vec3A::new(
                    rng.gen_range(-2.5..2.5),
                    rng.gen_range(-2.5..2.5),
                    rng.gen_range(-2.5..2.5),
                );
                let dir = random_unit(&mut rng) * rng.gen_range(0.5..2.0);
                // A third of the rays are segments (shadow-ray style), the rest unbounded.
                let t_max = if i % 3 == 0 {
                    rng.gen_range(0.1..3.0)
                } else {
                    f32::INFINITY
                };
                let ray = Ray::new(origin, dir, 1e-4, t_max);
                let expected = brute_force(&mesh, &ray);
                let got = geometry.intersect(&ray);
                match (expected, got) {
                    (None, None) => {}
                    (Some((t, tri)), Some(h)) => {
                        assert_eq!(h.t, t, "{name}: closest t differs for {ray:?}");
                        if h.primitive_id as usize != tri {
                            // Only a tie (shared edge/vertex) may pick another triangle.
                            let [a, b, c] = mesh.triangle(h.primitive_id as usize);
                            let wt = WatertightRay::new(ray.origin, ray.direction, ray.t_min);
                            assert_eq!(
                                wt.intersect(a, b, c, ray.t_max).map(|x| x.t),
                                Some(t),
                                "{name}"
                            );
                        }
                    }
                    (e, g) => panic!("{name}: brute force {e:?} vs BVH {g:?} for {ray:?}"),
                }
                assert_eq!(
                    geometry.occluded(&ray),
                    expected.is_some(),
                    "{name}: occlusion for {ray:?}"
                );
                total += 1;
            }
        }
    }
    assert!(total >= 100_000);
}

#[test]
fn rays_at_shared_edges_and_vertices_never_leak_out_of_closed_meshes() {
    let mut rng = Pcg64::seed_from_u64(99);
    let mut rays = 0;
    for mesh in [
        TriangleMesh::icosphere(1.0, 2),
        TriangleMesh::cuboid(Vec3A::new(1.0, 0.5, 2.0)),
        TriangleMesh::uv_sphere(1.0, 12, 24),
    ] {
        let geometry = single(&mesh, BuildQuality::Fast);
        let targets = edge_and_vertex_targets(&mesh);
        let mut origins = vec![Vec3A::ZERO];
        origins.extend((0..12).map(|_| random_unit(&mut rng) * rng.gen_range(0.0..0.45)));
        for &o in &origins {
            for &target in &targets {
                let ray = Ray::new(o, target - o, 0.0, f32::INFINITY);
                let hit = geometry.intersect(&ray);
                assert!(
                    hit.is_some(),
                    "leak from inside: {ray:?} aimed at {target:?}"
                );
                assert!(geometry.occluded(&ray), "occlusion leak: {ray:?}");
                // Every exit point is at (or within rounding of) the target's distance.
                assert!(
                    (hit.unwrap().t - 1.0).abs() < 1e-3,
                    "{ray:?} t = {}",
                    hit.unwrap().t
                );
                // From outside, aimed at the same point: the near side must be hit.
                let outside = target + (target - o).normalize() * 3.0;
                let back = Ray::new(outside, target - outside, 0.0, f32::INFINITY);
                assert!(
                    geometry.intersect(&back).is_some(),
                    "leak from outside: {back:?}"
                );
                rays += 2;
            }
        }
    }
    assert!(rays > 50_000, "{rays}");
}

#[test]
fn scene_of_many_instances_agrees_with_brute_force_in_world_space() {
    let mut rng = Pcg64::seed_from_u64(5);
    let sphere = TriangleMesh::icosphere(0.5, 2);
    let cube = TriangleMesh::cuboid(Vec3A::splat(0.4));
    let mut b = GeometryBuilder::new();
    let ids = [b.add_mesh(sphere.clone()), b.add_mesh(cube.clone())];
    let mut placed = Vec::new();
    for k in 0..20 {
        let t = Transform::translate(Vec3A::new(
            rng.gen_range(-3.0..3.0),
            rng.gen_range(-3.0..3.0),
            rng.gen_range(-3.0..3.0),
        ))
        .compose(&Transform::rotate(random_unit(&mut rng), rng.gen_range(0.0..6.0)).unwrap())
        .compose(
            &Transform::scale(Vec3A::new(
                rng.gen_range(0.5..1.5),
                rng.gen_range(0.5..1.5),
                1.0,
            ))
            .unwrap(),
        );
        let m = ids[k % 2];
        b.add_instance(Shape::Mesh(m), t, None).unwrap();
        placed.push((if k % 2 == 0 { &sphere } else { &cube }, t));
    }
    let geometry = b.build(BuildQuality::Medium);
    for _ in 0..5_000 {
        let ray = Ray::new(
            Vec3A::new(rng.gen_range(-5.0..5.0), rng.gen_range(-5.0..5.0), 6.0),
            random_unit(&mut rng),
            1e-4,
            f32::INFINITY,
        );
        let mut expected: Option<(f32, usize)> = None;
        for (k, (mesh, t)) in placed.iter().enumerate() {
            let local = t.inverse_ray(&ray);
            if let Some((tt, _)) = brute_force(mesh, &local) {
                if expected.is_none_or(|(best, _)| tt < best) {
                    expected = Some((tt, k));
                }
            }
        }
        let got = geometry.intersect(&ray);
        assert_eq!(got.map(|h| h.t), expected.map(|e| e.0), "{ray:?}");
        if let (Some(h), Some((_, k))) = (got, expected) {
            assert_eq!(h.instance_id as usize, k);
            let si = geometry.interaction(&ray, &h);
            assert!(
                (si.p - ray.at(h.t)).length() < 1e-4,
                "{:?} vs {:?}",
                si.p,
                ray.at(h.t)
            );
        }
        assert_eq!(geometry.occluded(&ray), expected.is_some());
    }
}

/// The scene BVH's traversal compiled for each ISA the CPU runs (`Geometry::with_simd`)
/// returns the same hits, bit for bit, as the baseline build: the wider builds change the
/// instructions, never the arithmetic. The scene mixes baked triangles (a soup and a
/// sphere placed once) with instance leaves (an analytic sphere), and the rays include
/// ones leaving a surface with a tiny `t_min`. Built again without flattening, every
/// instance is a leaf, so the meshes' own BVHs under the scene BVH are traversed too; and
/// once more as a small scene, whose instance leaves are tested without the scene BVH.
#[test]
fn every_isa_traverses_the_scene_bvh_to_the_same_bits() {
    for (flatten, small) in [(true, false), (false, false), (false, true)] {
        every_isa_traverses_to_the_same_bits(flatten, small);
    }
}

fn every_isa_traverses_to_the_same_bits(flatten: bool, small: bool) {
    let mut rng = Pcg64::seed_from_u64(11);
    let mut b = GeometryBuilder::new();
    let soup = b.add_mesh(triangle_soup(4_000, 2.0, 0.02..0.3, &mut rng));
    b.add_instance(Shape::Mesh(soup), Transform::IDENTITY, None)
        .unwrap();
    let ball = b.add_mesh(TriangleMesh::icosphere(0.7, 3));
    b.add_instance(
        Shape::Mesh(ball),
        Transform::translate(Vec3A::new(0.5, -0.3, 0.2)),
        None,
    )
    .unwrap();
    b.add_instance(
        Shape::Sphere(prism_geometry::Sphere { radius_m: 0.4 }),
        Transform::translate(Vec3A::new(-1.0, 0.8, 0.0)),
        None,
    )
    .unwrap();
    let mut geometry = b.build_with(BuildOptions {
        quality: BuildQuality::Fast,
        flatten,
        small_scene_max_leaves: if small { SMALL_SCENE_MAX_LEAVES } else { 0 },
    });
    // The premise: instance leaves under the scene BVH (the sphere alone when flattened,
    // all three otherwise), or in the small-scene batches.
    let instance_leaves = if flatten { 1 } else { 3 };
    assert_eq!(geometry.is_small_scene(), small);
    assert_eq!(geometry.instance_leaf_count(), instance_leaves);
    let rays: Vec<Ray> = (0..20_000)
        .map(|i| {
            let origin = Vec3A::new(
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
            );
            let t_min = if i % 4 == 0 { 1e-5 } else { 0.0 };
            Ray::new(origin, random_unit(&mut rng), t_min, f32::INFINITY)
        })
        .collect();
    let trace = |g: &Geometry| -> Vec<(Option<[u32; 5]>, bool)> {
        rays.iter()
            .map(|r| {
                let hit = g.intersect(r).map(hit_bits);
                (hit, g.occluded(r))
            })
            .collect()
    };
    geometry = geometry.with_simd(prism_cpu::Simd::SCALAR);
    let baseline = trace(&geometry);
    assert!(baseline.iter().filter(|(h, _)| h.is_some()).count() > 5_000);
    for simd in prism_cpu::each_isa() {
        geometry = geometry.with_simd(simd);
        let got = trace(&geometry);
        for (i, (want, have)) in baseline.iter().zip(&got).enumerate() {
            assert_eq!(
                want,
                have,
                "flatten {flatten}, {} ray {i}: {:?}",
                simd.isa(),
                rays[i]
            );
        }
        // The same rays as one stream (interleaved traversals under the scene BVH; one by
        // one in the small scene): the same bits.
        let streamed = stream_hits(&geometry, &rays);
        for (i, (want, have)) in baseline.iter().zip(&streamed).enumerate() {
            assert_eq!(
                want.0,
                *have,
                "stream, flatten {flatten}, small {small}, {} ray {i}: {:?}",
                simd.isa(),
                rays[i]
            );
        }
    }
}

/// `Geometry::intersect_stream` of `rays`, each hit as its bits.
fn stream_hits(geometry: &Geometry, rays: &[Ray]) -> Vec<Option<[u32; 5]>> {
    let mut hits = vec![None; rays.len()];
    geometry.intersect_stream(rays, &mut hits);
    hits.iter().map(|h| h.map(hit_bits)).collect()
}

/// A hit's fields as bits (t, instance, primitive, b1, b2).
fn hit_bits(h: Hit) -> [u32; 5] {
    [
        h.t.to_bits(),
        h.instance_id,
        h.primitive_id,
        h.b1.to_bits(),
        h.b2.to_bits(),
    ]
}

/// A ray stream over one mesh instance (the mesh's own BVH, interleaved) finds each ray's
/// one-ray hit, bit for bit, at every ISA: rays from inside and outside a soup of 20 000
/// triangles, bounded and unbounded, and rays leaving a wall 10 µm in front of it with
/// `t_min` 10⁻⁵ m, which must hit it (no entry distance is clamped above `t_min`).
#[test]
fn ray_streams_find_the_one_ray_hits_in_a_mesh() {
    let mut rng = Pcg64::seed_from_u64(23);
    let soup = triangle_soup(20_000, 2.0, 0.02..0.2, &mut rng);
    // A wall at z = −2.5 facing +z, two triangles 6 m wide.
    let mut positions = soup.positions.clone();
    let mut indices = soup.indices.clone();
    let base = positions.len() as u32;
    positions.extend([
        Vec3A::new(-3.0, -3.0, -2.5),
        Vec3A::new(3.0, -3.0, -2.5),
        Vec3A::new(3.0, 3.0, -2.5),
        Vec3A::new(-3.0, 3.0, -2.5),
    ]);
    indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    let soup = TriangleMesh::new(positions, indices);
    let wall = [soup.triangle_count() - 2, soup.triangle_count() - 1];
    let mut geometry = single(&soup, BuildQuality::Fast);
    let mut rays: Vec<Ray> = (0..30_000)
        .map(|i| {
            let origin = Vec3A::new(
                rng.gen_range(-3.5..3.5),
                rng.gen_range(-3.5..3.5),
                rng.gen_range(-3.5..3.5),
            );
            let t_max = if i % 3 == 0 { 1.5 } else { f32::INFINITY };
            Ray::new(origin, random_unit(&mut rng), 0.0, t_max)
        })
        .collect();
    let near_wall = 2_000;
    for _ in 0..near_wall {
        let origin = Vec3A::new(
            rng.gen_range(-2.9..2.9),
            rng.gen_range(-2.9..2.9),
            -2.5 + 1e-5,
        );
        let mut d = random_unit(&mut rng);
        d.z = -d.z.abs().max(0.1);
        rays.push(Ray::new(origin, d.normalize(), 1e-5, f32::INFINITY));
    }
    for simd in std::iter::once(prism_cpu::Simd::SCALAR).chain(prism_cpu::each_isa()) {
        geometry = geometry.with_simd(simd);
        let streamed = stream_hits(&geometry, &rays);
        let mut hits = 0;
        for (i, (ray, have)) in rays.iter().zip(&streamed).enumerate() {
            let want = geometry.intersect(ray).map(hit_bits);
            assert_eq!(want, *have, "{} ray {i}: {ray:?}", simd.isa());
            hits += usize::from(have.is_some());
        }
        assert!(hits > 10_000, "{hits} hits");
        // Every ray leaving the wall 10 µm in front of it hits the wall.
        for (ray, have) in rays.iter().zip(&streamed).skip(rays.len() - near_wall) {
            let hit = have.unwrap_or_else(|| panic!("{ray:?} missed the wall"));
            assert!(wall.contains(&(hit[2] as usize)), "{ray:?}: {hit:?}");
        }
    }
}

/// Camera rays of a pinhole grid over a uv sphere meet the edges its triangles share (both
/// triangles hit, at the same `t` or one ulp apart, and the visiting order decides which is
/// kept): a stream keeps the triangle one ray keeps, at every ISA.
#[test]
fn ray_streams_keep_one_rays_triangle_where_rays_meet_shared_edges() {
    let sphere = TriangleMesh::uv_sphere(1.0, 101, 200);
    let mut geometry = single(&sphere, BuildQuality::Fast);
    let side = 384;
    let eye = Vec3A::new(0.0, 0.0, 3.0);
    let rays: Vec<Ray> = (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f32, (i / side) as f32);
            let sx = (2.0 * x / (side - 1) as f32 - 1.0) * 0.4;
            let sy = (1.0 - 2.0 * y / (side - 1) as f32) * 0.4;
            Ray::new(
                eye,
                Vec3A::new(sx, sy, -1.0).normalize(),
                0.0,
                f32::INFINITY,
            )
        })
        .collect();
    for simd in std::iter::once(prism_cpu::Simd::SCALAR).chain(prism_cpu::each_isa()) {
        geometry = geometry.with_simd(simd);
        let streamed = stream_hits(&geometry, &rays);
        let mut on_edges = 0;
        for (i, (ray, have)) in rays.iter().zip(&streamed).enumerate() {
            let want = geometry.intersect(ray);
            if let Some(h) = want {
                on_edges += usize::from(h.b1 == 0.0 || h.b2 == 0.0 || h.b1 + h.b2 == 1.0);
            }
            assert_eq!(want.map(hit_bits), *have, "{} ray {i}: {ray:?}", simd.isa());
        }
        // The premise: rays that meet shared edges exactly.
        assert!(on_edges > 100, "{on_edges} rays met an edge");
    }
}
