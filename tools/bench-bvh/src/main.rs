//! BVH benchmark for prism-geometry: builds a procedurally displaced sphere of 10⁶ triangles
//! with every obvhs preset and traces coherent (pinhole grid) and incoherent (random) rays,
//! closest hit and occlusion, on 1 and 2 threads. Prints JSON on stdout.
//!
//! Run: `cargo run --release -p bench-bvh` (numbers recorded in docs/geometry.md).

use std::time::Instant;

use glam::Vec3A;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use prism_geometry::{
    BuildQuality, Geometry, GeometryBuilder, Ray, Shape, Transform, TriangleMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use serde_json::{json, Value};

const RADIUS_M: f32 = 1.0;
const RAY_COUNT: usize = 1 << 20;
const CHUNK: usize = 1024;

/// Sphere of 501 rings × 1000 segments = exactly 10⁶ triangles, radially displaced by a few
/// per cent with a smooth pattern so that it is not a perfect sphere.
fn bench_mesh() -> TriangleMesh {
    let mut mesh = TriangleMesh::uv_sphere(RADIUS_M, 501, 1000);
    mesh.map_positions(|p| {
        let n = p / RADIUS_M;
        p * (1.0 + 0.03 * (13.0 * n.x).sin() * (11.0 * n.y).sin() * (7.0 * n.z).cos())
    });
    mesh
}

fn primary_rays() -> Vec<Ray> {
    let side = (RAY_COUNT as f64).sqrt() as usize;
    let eye = Vec3A::new(0.0, 0.0, 3.0 * RADIUS_M);
    let half_fov = 0.4f32;
    (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f32, (i / side) as f32);
            let sx = (2.0 * (x + 0.5) / side as f32 - 1.0) * half_fov.tan();
            let sy = (1.0 - 2.0 * (y + 0.5) / side as f32) * half_fov.tan();
            Ray::infinite(eye, Vec3A::new(sx, sy, -1.0).normalize())
        })
        .collect()
}

/// Origins uniform in a cube 3 r wide around the mesh, directions uniform on the sphere.
fn random_rays(seed: u64) -> Vec<Ray> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..RAY_COUNT)
        .map(|_| {
            let o = Vec3A::new(
                rng.gen_range(-1.5..1.5),
                rng.gen_range(-1.5..1.5),
                rng.gen_range(-1.5..1.5),
            ) * RADIUS_M;
            let d = loop {
                let v = Vec3A::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                );
                let l2 = v.length_squared();
                if l2 > 1e-6 && l2 <= 1.0 {
                    break v / l2.sqrt();
                }
            };
            Ray::infinite(o, d)
        })
        .collect()
}

/// Sort rays by direction octant, then by a 30-bit Morton code of the origin (a cheap
/// coherence lever; Garanzha & Loop 2010 use a similar key).
fn sort_rays(rays: &mut [Ray]) {
    let key = |r: &Ray| -> u64 {
        let oct = ((r.direction.x < 0.0) as u64)
            | (((r.direction.y < 0.0) as u64) << 1)
            | (((r.direction.z < 0.0) as u64) << 2);
        let q = ((r.origin / RADIUS_M + Vec3A::splat(1.5)) / 3.0 * 1023.0)
            .clamp(Vec3A::ZERO, Vec3A::splat(1023.0));
        let spread = |v: u64| {
            let mut x = v & 0x3ff;
            x = (x | (x << 16)) & 0x30000ff;
            x = (x | (x << 8)) & 0x300f00f;
            x = (x | (x << 4)) & 0x30c30c3;
            (x | (x << 2)) & 0x9249249
        };
        (oct << 30) | spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2)
    };
    rays.par_sort_unstable_by_key(key);
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// Rays per second and hit fraction of `f` over `rays` on `threads` threads (best of 3).
fn trace(rays: &[Ray], threads: usize, f: &(dyn Fn(&Ray) -> bool + Sync)) -> (f64, f64) {
    let p = pool(threads);
    let mut best = f64::INFINITY;
    let mut hits = 0usize;
    for _ in 0..3 {
        let start = Instant::now();
        hits = p.install(|| {
            rays.par_chunks(CHUNK)
                .map(|c| c.iter().filter(|r| f(r)).count())
                .sum()
        });
        best = best.min(start.elapsed().as_secs_f64());
    }
    (rays.len() as f64 / best, hits as f64 / rays.len() as f64)
}

fn build(mesh: &TriangleMesh, quality: BuildQuality) -> (Geometry, f64) {
    let start = Instant::now();
    let mut b = GeometryBuilder::new();
    let id = b.add_mesh(mesh.clone());
    b.add_instance(Shape::Mesh(id), Transform::IDENTITY, None)
        .unwrap();
    let clone_s = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let g = b.build(quality);
    let _ = clone_s;
    (g, start.elapsed().as_secs_f64())
}

fn mrays(x: f64) -> Value {
    json!((x / 1e4).round() / 100.0)
}

fn main() {
    let mesh = bench_mesh();
    let primary = primary_rays();
    let random = random_rays(1);
    let mut sorted = random.clone();
    let sort_start = Instant::now();
    sort_rays(&mut sorted);
    let sort_s = sort_start.elapsed().as_secs_f64();

    let mut presets = Vec::new();
    let mut default_geometry = None;
    for q in BuildQuality::ALL {
        let (g, build_s) = build(&mesh, q);
        let (closest, _) = trace(&random, 1, &|r| g.intersect(r).is_some());
        let (closest2, _) = trace(&random, 2, &|r| g.intersect(r).is_some());
        eprintln!(
            "{}: build {build_s:.3} s, incoherent closest {:.2} / {:.2} Mrays/s (1/2 threads)",
            q.name(),
            closest / 1e6,
            closest2 / 1e6
        );
        presets.push(json!({
            "preset": q.name(),
            "build_s": (build_s * 1000.0).round() / 1000.0,
            "incoherent_closest_mrays_s_1t": mrays(closest),
            "incoherent_closest_mrays_s_2t": mrays(closest2),
        }));
        if q == BuildQuality::default() {
            default_geometry = Some(g);
        }
    }
    let g = default_geometry.expect("default preset is in ALL");

    let mut traversal = Vec::new();
    for (name, rays) in [
        ("coherent_primary", &primary),
        ("incoherent_random", &random),
        ("incoherent_sorted", &sorted),
    ] {
        for threads in [1, 2] {
            let (closest, hit_fraction) = trace(rays, threads, &|r| g.intersect(r).is_some());
            let (any, _) = trace(rays, threads, &|r| g.occluded(r));
            eprintln!("{name} {threads}t: closest {:.2}, any {:.2} Mrays/s, hit fraction {hit_fraction:.3}", closest / 1e6, any / 1e6);
            traversal.push(json!({
                "rays": name,
                "threads": threads,
                "closest_mrays_s": mrays(closest),
                "any_hit_mrays_s": mrays(any),
                "hit_fraction": (hit_fraction * 1000.0).round() / 1000.0,
            }));
        }
    }

    // Reference: obvhs alone, its own (non-watertight, Möller–Trumbore) triangle test over its
    // triangle builder, same preset and rays, single- and two-threaded.
    let tris: Vec<Triangle> = (0..mesh.triangle_count())
        .map(|i| {
            let [v0, v1, v2] = mesh.triangle(i);
            Triangle { v0, v1, v2 }
        })
        .collect();
    let start = Instant::now();
    let cw = build_cwbvh_from_tris(
        &tris,
        BuildQuality::default().params(),
        &mut Default::default(),
    );
    let ob_build_s = start.elapsed().as_secs_f64();
    let leaf: Vec<Triangle> = cw
        .primitive_indices
        .iter()
        .map(|&i| tris[i as usize])
        .collect();
    let ob = |r: &Ray| {
        let mut hit = RayHit::none();
        cw.ray_traverse(
            obvhs::ray::Ray::new(r.origin, r.direction, r.t_min, r.t_max),
            &mut hit,
            |ray, id| leaf[id].intersect(ray),
        )
    };
    let (ob1, _) = trace(&random, 1, &ob);
    let (ob2, _) = trace(&random, 2, &ob);
    eprintln!(
        "obvhs reference: build {ob_build_s:.3} s, incoherent closest {:.2} / {:.2}",
        ob1 / 1e6,
        ob2 / 1e6
    );

    let out = json!({
        "mesh": { "triangles": mesh.triangle_count(), "kind": "displaced uv sphere, 501 x 1000" },
        "ray_count": RAY_COUNT,
        "threads_available": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "default_preset": BuildQuality::default().name(),
        "presets": presets,
        "traversal_default_preset": traversal,
        "incoherent_sort_s": (sort_s * 1000.0).round() / 1000.0,
        "obvhs_reference": {
            "build_s": (ob_build_s * 1000.0).round() / 1000.0,
            "incoherent_closest_mrays_s_1t": mrays(ob1),
            "incoherent_closest_mrays_s_2t": mrays(ob2),
        },
    });
    println!("{}", serde_json::to_string_pretty(&out).expect("json"));
}
