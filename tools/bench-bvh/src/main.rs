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
    let mut keyed: Vec<(u64, Ray)> = rays.par_iter().map(|r| (key(r), *r)).collect();
    keyed.par_sort_unstable_by_key(|(k, _)| *k);
    for (dst, (_, r)) in rays.iter_mut().zip(keyed) {
        *dst = r;
    }
}

thread_local! {
    /// One long-lived pool per thread count, so that CPU accounting sees the same threads
    /// before and after each measurement.
    static POOLS: [std::sync::Arc<rayon::ThreadPool>; 2] =
        [std::sync::Arc::new(pool(1)), std::sync::Arc::new(pool(2))];
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// CPU time (ns) used so far by each thread of this process, from
/// `/proc/self/task/*/schedstat` (ns resolution); `None` off Linux.
fn thread_cpu_ns() -> Option<std::collections::HashMap<String, u64>> {
    let mut out = std::collections::HashMap::new();
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let entry = entry.ok()?;
        let text = std::fs::read_to_string(entry.path().join("schedstat")).ok()?;
        let ns = text.split_whitespace().next()?.parse::<u64>().ok()?;
        out.insert(entry.file_name().to_string_lossy().into_owned(), ns);
    }
    Some(out)
}

/// CPU seconds spent between two snapshots by threads alive at both.
fn cpu_s_between(
    a: &std::collections::HashMap<String, u64>,
    b: &std::collections::HashMap<String, u64>,
) -> f64 {
    a.iter()
        .filter_map(|(tid, &t0)| b.get(tid).map(|&t1| t1.saturating_sub(t0)))
        .sum::<u64>() as f64
        * 1e-9
}

/// Throughput of one measurement: wall-clock rays/s, rays per CPU-second (robust to other
/// processes sharing the cores) and hit fraction.
struct Throughput {
    rays_per_s: f64,
    rays_per_cpu_s: Option<f64>,
    hit_fraction: f64,
}

impl Throughput {
    fn json(&self) -> Value {
        json!({
            "mrays_s": mrays(self.rays_per_s),
            "mrays_per_cpu_s": self.rays_per_cpu_s.map(mrays),
        })
    }

    fn show(&self) -> String {
        format!(
            "{:.2} Mrays/s ({:.2} per CPU-s)",
            self.rays_per_s / 1e6,
            self.rays_per_cpu_s.unwrap_or(f64::NAN) / 1e6
        )
    }
}

/// Best of 3 runs of `f` over `rays` on `threads` threads.
fn trace(rays: &[Ray], threads: usize, f: &(dyn Fn(&Ray) -> bool + Sync)) -> Throughput {
    let p = &POOLS.with(|p| p[threads - 1].clone());
    let mut best = (f64::INFINITY, None);
    let mut hits = 0usize;
    for _ in 0..3 {
        let cpu0 = thread_cpu_ns();
        let start = Instant::now();
        hits = p.install(|| {
            rays.par_chunks(CHUNK)
                .map(|c| c.iter().filter(|r| f(r)).count())
                .sum()
        });
        let wall = start.elapsed().as_secs_f64();
        let cpu = cpu0
            .zip(thread_cpu_ns())
            .map(|(a, b)| cpu_s_between(&a, &b));
        if wall < best.0 {
            best = (wall, cpu);
        }
    }
    let n = rays.len() as f64;
    Throughput {
        rays_per_s: n / best.0,
        rays_per_cpu_s: best.1.map(|c| n / c),
        hit_fraction: hits as f64 / n,
    }
}

/// Build on a 2-thread pool (the target machine has 2 cores); the time covers box
/// computation, the obvhs build and the leaf-order triangle copy.
fn build(mesh: &TriangleMesh, quality: BuildQuality) -> (Geometry, f64, Option<f64>) {
    let mut b = GeometryBuilder::new();
    let id = b.add_mesh(mesh.clone());
    b.add_instance(Shape::Mesh(id), Transform::IDENTITY, None)
        .expect("mesh was added");
    let p = POOLS.with(|p| p[1].clone());
    let cpu0 = thread_cpu_ns();
    let start = Instant::now();
    let g = p.install(|| b.build(quality));
    let wall = start.elapsed().as_secs_f64();
    let cpu = cpu0
        .zip(thread_cpu_ns())
        .map(|(a, b)| cpu_s_between(&a, &b));
    (g, wall, cpu)
}

/// 1-minute load average, to judge whether other processes shared the cores during the run.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn mrays(x: f64) -> Value {
    json!((x / 1e4).round() / 100.0)
}

fn main() {
    let load_at_start = load_average();
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
        let (g, build_s, build_cpu_s) = build(&mesh, q);
        let t1 = trace(&random, 1, &|r| g.intersect(r).is_some());
        let t2 = trace(&random, 2, &|r| g.intersect(r).is_some());
        eprintln!(
            "{}: build {build_s:.3} s ({:.3} CPU-s), incoherent closest 1t {} 2t {}",
            q.name(),
            build_cpu_s.unwrap_or(f64::NAN),
            t1.show(),
            t2.show()
        );
        presets.push(json!({
            "preset": q.name(),
            "build_s": (build_s * 1000.0).round() / 1000.0,
            "build_cpu_s": build_cpu_s.map(|c| (c * 1000.0).round() / 1000.0),
            "incoherent_closest_1t": t1.json(),
            "incoherent_closest_2t": t2.json(),
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
            let closest = trace(rays, threads, &|r| g.intersect(r).is_some());
            let any = trace(rays, threads, &|r| g.occluded(r));
            eprintln!(
                "{name} {threads}t: closest {}, any hit {}, hit fraction {:.3}",
                closest.show(),
                any.show(),
                closest.hit_fraction
            );
            traversal.push(json!({
                "rays": name,
                "threads": threads,
                "closest": closest.json(),
                "any_hit": any.json(),
                "hit_fraction": (closest.hit_fraction * 1000.0).round() / 1000.0,
            }));
        }
    }

    // Reference: obvhs alone — its triangle builder and its own (non-watertight,
    // Möller–Trumbore) triangle test, same preset and rays.
    let tris: Vec<Triangle> = (0..mesh.triangle_count())
        .map(|i| {
            let [v0, v1, v2] = mesh.triangle(i);
            Triangle { v0, v1, v2 }
        })
        .collect();
    let start = Instant::now();
    let cw = pool(2).install(|| {
        build_cwbvh_from_tris(
            &tris,
            BuildQuality::default().params(),
            &mut Default::default(),
        )
    });
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
    let ob1 = trace(&random, 1, &ob);
    let ob2 = trace(&random, 2, &ob);
    eprintln!(
        "obvhs reference: build {ob_build_s:.3} s, incoherent closest 1t {} 2t {}",
        ob1.show(),
        ob2.show()
    );

    let out = json!({
        "command": "cargo run --release -p bench-bvh",
        "load_average_1min_at_start": load_at_start,
        "load_average_1min_at_end": load_average(),
        "mesh": { "triangles": mesh.triangle_count(), "kind": "displaced uv sphere, 501 x 1000" },
        "ray_count": RAY_COUNT,
        "threads_available": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "units": "mrays_s: million rays per wall-clock second; mrays_per_cpu_s: million rays per CPU-second of this process (all threads)",
        "default_preset": BuildQuality::default().name(),
        "presets": presets,
        "traversal_default_preset": traversal,
        "incoherent_sort_s": (sort_s * 1000.0).round() / 1000.0,
        "obvhs_reference": {
            "build_s": (ob_build_s * 1000.0).round() / 1000.0,
            "incoherent_closest_1t": ob1.json(),
            "incoherent_closest_2t": ob2.json(),
        },
    });
    println!("{}", serde_json::to_string_pretty(&out).expect("json"));
}
