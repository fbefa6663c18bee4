//! BVH benchmark for prism-geometry: builds a procedurally displaced sphere of 10⁶ triangles
//! with every obvhs preset and traces coherent (pinhole grid) and incoherent (random) rays,
//! closest hit and occlusion, on 1 and 2 threads. Prints JSON on stdout.
//!
//! Then, for scenes of many small instances (the Cornell box; a mixed scene of cuboids,
//! icospheres, rectangles and spheres; 64 instances of icospheres of growing size), it traces
//! the same rays against the flattened geometry (the default build) and against the
//! unflattened two-level geometry (`BuildOptions { flatten: false }`), alternating the two.
//!
//! Run: `cargo run --release -p bench-bvh > tools/bench-results/bench-bvh.json` (numbers in
//! docs/geometry.md);
//! `cargo run --release -p bench-bvh -- --instanced-only [--scene NAME_PART]` runs only the
//! instanced scenes (those whose name contains `NAME_PART`);
//! `-- --peer DIR` serves a peer comparison (`peer_mode`; tools/peers/embree_bvh.py).

use std::time::Instant;

use glam::{Mat4, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use prism_geometry::{
    BuildOptions, BuildQuality, Geometry, GeometryBuilder, Ray, Rectangle, Shape, Sphere,
    Transform, TriangleMesh,
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
    trace_runs(rays, threads, 3, f)
}

/// Best of `runs` runs of `f` over `rays` on `threads` threads.
fn trace_runs(
    rays: &[Ray],
    threads: usize,
    runs: usize,
    f: &(dyn Fn(&Ray) -> bool + Sync),
) -> Throughput {
    let p = &POOLS.with(|p| p[threads - 1].clone());
    let mut best = (f64::INFINITY, None);
    let mut hits = 0usize;
    for _ in 0..runs {
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

const UNITS: &str = "mrays_s: million rays per wall-clock second; mrays_per_cpu_s: million rays per CPU-second of this process (all threads)";

fn mrays(x: f64) -> Value {
    json!((x / 1e4).round() / 100.0)
}

/// `--peer DIR`: the workload of a peer comparison (tools/peers/embree_bvh.py). Writes the
/// benchmark mesh and the incoherent rays to DIR as raw little-endian arrays
/// (`vertices.f32`: x y z per vertex; `indices.u32`: three per triangle; `rays.f32`: origin
/// x y z, t_min, direction x y z, t_max per ray), builds the default BVH, prints one JSON line
/// and then, per stdin line, traces every ray for the closest hit on one thread and prints
/// one JSON line (seconds, hits): the driver alternates these runs with the peer's.
fn peer_mode(dir: &std::path::Path) {
    use std::io::{BufRead, Write};
    let mesh = bench_mesh();
    let rays = random_rays(1);
    std::fs::create_dir_all(dir).expect("peer directory");
    let write = |name: &str, bytes: Vec<u8>| {
        let tmp = dir.join(format!("{name}.tmp"));
        std::fs::write(&tmp, bytes).expect("write peer workload");
        std::fs::rename(&tmp, dir.join(name)).expect("rename peer workload");
    };
    let f32s = |v: &mut Vec<u8>, xs: &[f32]| xs.iter().for_each(|x| v.extend(x.to_le_bytes()));
    let mut vertices = Vec::new();
    mesh.positions
        .iter()
        .for_each(|p| f32s(&mut vertices, &p.to_array()));
    write("vertices.f32", vertices);
    let indices: Vec<u8> = mesh
        .indices
        .iter()
        .flat_map(|t| t.iter().flat_map(|i| i.to_le_bytes()))
        .collect();
    write("indices.u32", indices);
    let mut ray_bytes = Vec::new();
    for r in &rays {
        let o = r.origin.to_array();
        let d = r.direction.to_array();
        f32s(
            &mut ray_bytes,
            &[o[0], o[1], o[2], r.t_min, d[0], d[1], d[2], r.t_max],
        );
    }
    write("rays.f32", ray_bytes);
    let (g, build_s, _) = build(&mesh, BuildQuality::default());
    let ready = json!({"ready": true, "triangles": mesh.triangle_count(), "rays": rays.len(),
                       "preset": BuildQuality::default().name(), "build_s": build_s});
    println!("{ready}");
    std::io::stdout().flush().expect("stdout");
    let mut stream_hits = vec![None; rays.len()];
    for line in std::io::stdin().lock().lines() {
        if line.is_err() {
            break;
        }
        let start = Instant::now();
        let hits = rays.iter().filter(|r| g.intersect(r).is_some()).count();
        let seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        g.intersect_stream(&rays, &mut stream_hits);
        let stream_seconds = start.elapsed().as_secs_f64();
        let stream_same = stream_hits
            .iter()
            .zip(&rays)
            .all(|(h, r)| *h == g.intersect(r));
        println!(
            "{}",
            json!({"seconds": seconds, "hits": hits, "stream_seconds": stream_seconds,
                   "stream_hits": stream_hits.iter().filter(|h| h.is_some()).count(),
                   "stream_same_hits": stream_same})
        );
        std::io::stdout().flush().expect("stdout");
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(dir) = args
        .iter()
        .position(|a| a == "--peer")
        .and_then(|i| args.get(i + 1))
    {
        return peer_mode(std::path::Path::new(dir));
    }
    let instanced_only = args.iter().any(|a| a == "--instanced-only");
    let filter = args
        .iter()
        .position(|a| a == "--scene")
        .and_then(|i| args.get(i + 1))
        .map_or("", |s| s.as_str());
    let load_at_start = prism_cpu::clock::load_average_1m();
    let instanced = instanced_scenes(filter);
    if instanced_only {
        let out = json!({
            "command": format!("cargo run --release -p bench-bvh -- {}", args[1..].join(" ")),
            "load_average_1min_at_start": load_at_start,
            "load_average_1min_at_end": prism_cpu::clock::load_average_1m(),
            "units": UNITS,
            "instanced_scenes": instanced,
        });
        println!("{}", serde_json::to_string_pretty(&out).expect("json"));
        return;
    }
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
        "load_average_1min_at_end": prism_cpu::clock::load_average_1m(),
        "mesh": { "triangles": mesh.triangle_count(), "kind": "displaced uv sphere, 501 x 1000" },
        "ray_count": RAY_COUNT,
        "threads_available": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "units": UNITS,
        "default_preset": BuildQuality::default().name(),
        "presets": presets,
        "traversal_default_preset": traversal,
        "incoherent_sort_s": (sort_s * 1000.0).round() / 1000.0,
        "obvhs_reference": {
            "build_s": (ob_build_s * 1000.0).round() / 1000.0,
            "incoherent_closest_1t": ob1.json(),
            "incoherent_closest_2t": ob2.json(),
        },
        "instanced_scenes": instanced,
    });
    println!("{}", serde_json::to_string_pretty(&out).expect("json"));
}

/// Runs of each build per instanced-scene measurement, alternated.
const ALTERNATIONS: usize = 8;

/// Rays per instanced-scene measurement.
const INSTANCED_RAY_COUNT: usize = 1 << 19;

/// The Cornell box of scenes/cornell-box.json as prism-render builds it: six 2 m rectangles
/// (light, floor, ceiling, back, green and red walls) and two cuboids sharing one unit cube
/// (half size 0.5, scaled by the 2 m size, then placed), matrices copied from the scene file.
fn cornell_box(b: &mut GeometryBuilder) {
    let m = |rows: [[f32; 4]; 3]| {
        let mut all = [[0.0, 0.0, 0.0, 1.0]; 4];
        all[..3].copy_from_slice(&rows);
        Transform::from_matrix(Mat4::from_cols_array_2d(&all).transpose()).expect("invertible")
    };
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
    for rows in rectangles {
        let r = Rectangle {
            half_width_m: 1.0,
            half_height_m: 1.0,
        };
        b.add_instance(Shape::Rectangle(r), m(rows), None);
    }
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    let size = Transform::scale(Vec3A::splat(2.0)).expect("scale");
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
        b.add_instance(Shape::Mesh(cube), m(rows).compose(&size), None);
    }
}

/// Cornell box rays: the camera's pinhole grid (eye (0, 0, 3.9), 39.3° horizontal field),
/// bounce-like rays (origins uniform in the box, uniform directions) and shadow segments
/// from points in the box to points on the light.
fn cornell_rays() -> [(&'static str, Vec<Ray>); 3] {
    let side = (INSTANCED_RAY_COUNT as f64).sqrt() as usize;
    let tan = (0.5 * 39.3077f32.to_radians()).tan();
    let primary = (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f32, (i / side) as f32);
            let sx = (2.0 * (x + 0.5) / side as f32 - 1.0) * tan;
            let sy = (1.0 - 2.0 * (y + 0.5) / side as f32) * tan;
            Ray::infinite(
                Vec3A::new(0.0, 0.0, 3.9),
                Vec3A::new(sx, sy, -1.0).normalize(),
            )
        })
        .collect();
    let mut rng = Pcg64::seed_from_u64(2);
    let in_box = |rng: &mut Pcg64| {
        Vec3A::new(
            rng.gen_range(-0.99..0.99),
            rng.gen_range(-0.99..0.99),
            rng.gen_range(-0.99..0.99),
        )
    };
    let bounce = (0..INSTANCED_RAY_COUNT)
        .map(|_| {
            let o = in_box(&mut rng);
            Ray::spawn(o, random_direction(&mut rng))
        })
        .collect();
    let shadow = (0..INSTANCED_RAY_COUNT)
        .map(|_| {
            let o = in_box(&mut rng);
            let on_light = Vec3A::new(
                rng.gen_range(-0.23..0.23),
                0.99,
                0.01 + rng.gen_range(-0.19..0.19),
            );
            Ray::spawn_to(o, on_light)
        })
        .collect();
    [("primary", primary), ("bounce", bounce), ("shadow", shadow)]
}

fn random_direction(rng: &mut Pcg64) -> Vec3A {
    loop {
        let v = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-6 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

/// Translation in a `spread` cube, random rotation, non-uniform scale `[0.5, 1.5]·size`.
fn random_placement(rng: &mut Pcg64, spread: f32, size: f32) -> Transform {
    Transform::translate(Vec3A::new(
        rng.gen_range(-spread..spread),
        rng.gen_range(-spread..spread),
        rng.gen_range(-spread..spread),
    ))
    .compose(&Transform::rotate(random_direction(rng), rng.gen_range(0.0..6.3)).expect("axis"))
    .compose(
        &Transform::scale(Vec3A::new(
            rng.gen_range(0.5..1.5) * size,
            rng.gen_range(0.5..1.5) * size,
            rng.gen_range(0.5..1.5) * size,
        ))
        .expect("scale"),
    )
}

/// 400 cuboids (one shared mesh), 100 instances of a 320-triangle icosphere, 100 rectangles
/// and 50 spheres in a 10 m cube.
fn mixed_scene(b: &mut GeometryBuilder) {
    let mut rng = Pcg64::seed_from_u64(9);
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    let ico = b.add_mesh(TriangleMesh::icosphere(0.5, 2));
    for _ in 0..400 {
        b.add_instance(
            Shape::Mesh(cube),
            random_placement(&mut rng, 5.0, 0.4),
            None,
        );
    }
    for _ in 0..100 {
        b.add_instance(Shape::Mesh(ico), random_placement(&mut rng, 5.0, 0.5), None);
    }
    for _ in 0..100 {
        let r = Rectangle {
            half_width_m: 0.3,
            half_height_m: 0.3,
        };
        b.add_instance(
            Shape::Rectangle(r),
            random_placement(&mut rng, 5.0, 1.0),
            None,
        );
    }
    for _ in 0..50 {
        let s = Sphere { radius_m: 0.2 };
        b.add_instance(Shape::Sphere(s), random_placement(&mut rng, 5.0, 1.0), None);
    }
}

/// 64 icospheres of `subdivisions` (20·4ˢ triangles), each its own mesh (single use, so
/// always baked), in a 6 m cube.
fn icosphere_scene(b: &mut GeometryBuilder, subdivisions: u32) {
    let mut rng = Pcg64::seed_from_u64(4);
    for _ in 0..64 {
        let m = b.add_mesh(TriangleMesh::icosphere(0.5, subdivisions));
        b.add_instance(Shape::Mesh(m), random_placement(&mut rng, 3.0, 1.0), None);
    }
}

/// The Cornell box's six walls (2 m rectangles and a 0.4 m light) and `cuboids` randomly
/// placed 0.2–0.6 m cuboids inside (one shared 12-triangle mesh, baked): 6 + 12·`cuboids`
/// leaves, the sweep that sets `SMALL_SCENE_MAX_LEAVES`.
fn room_with_cuboids(b: &mut GeometryBuilder, cuboids: usize) {
    let mut rng = Pcg64::seed_from_u64(12);
    let quarter = std::f32::consts::FRAC_PI_2;
    let walls: [(Vec3A, Vec3A, f32); 6] = [
        (Vec3A::new(0.0, -1.0, 0.0), Vec3A::X, -quarter),
        (Vec3A::new(0.0, 1.0, 0.0), Vec3A::X, quarter),
        (Vec3A::new(0.0, 0.0, -1.0), Vec3A::X, 0.0),
        (Vec3A::new(-1.0, 0.0, 0.0), Vec3A::Y, quarter),
        (Vec3A::new(1.0, 0.0, 0.0), Vec3A::Y, -quarter),
        (Vec3A::new(0.0, 0.99, 0.0), Vec3A::X, quarter),
    ];
    for (i, (at, axis, angle)) in walls.into_iter().enumerate() {
        let half = if i == 5 { 0.2 } else { 1.0 };
        let r = Rectangle {
            half_width_m: half,
            half_height_m: half,
        };
        let t = Transform::translate(at).compose(&Transform::rotate(axis, angle).expect("axis"));
        b.add_instance(Shape::Rectangle(r), t, None);
    }
    let cube = b.add_mesh(TriangleMesh::cuboid(Vec3A::splat(0.5)));
    for _ in 0..cuboids {
        b.add_instance(
            Shape::Mesh(cube),
            random_placement(&mut rng, 0.6, 0.4),
            None,
        );
    }
}

/// Origins uniform in a `spread` cube, uniform directions.
fn rays_in_cube(spread: f32, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..INSTANCED_RAY_COUNT)
        .map(|_| {
            let o = Vec3A::new(
                rng.gen_range(-spread..spread),
                rng.gen_range(-spread..spread),
                rng.gen_range(-spread..spread),
            );
            Ray::infinite(o, random_direction(&mut rng))
        })
        .collect()
}

/// Closest-hit and any-hit throughput of the same rays against the unflattened and the
/// flattened build of a scene, 1 thread, the two builds alternated run by run (best of
/// [`ALTERNATIONS`] runs each), so that load from other processes affects both alike.
fn compare_builds(
    name: &str,
    scene: &dyn Fn(&mut GeometryBuilder),
    rays: &[(&str, Vec<Ray>)],
) -> Value {
    // The BVH in both builds: this compares flattening alone.
    let options = |flatten| BuildOptions {
        quality: BuildQuality::default(),
        flatten,
        small_scene_max_leaves: 0,
    };
    compare_options(
        name,
        scene,
        rays,
        [
            ("unflattened", options(false)),
            ("flattened", options(true)),
        ],
    )
}

/// The small-scene path (every leaf tested, 8 at a time, no BVH) against the flattened BVH
/// of the same scene.
fn compare_small(
    name: &str,
    scene: &dyn Fn(&mut GeometryBuilder),
    rays: &[(&str, Vec<Ray>)],
) -> Value {
    let options = |small_scene_max_leaves| BuildOptions {
        small_scene_max_leaves,
        ..BuildOptions::default()
    };
    compare_options(
        name,
        scene,
        rays,
        [("bvh", options(0)), ("small", options(usize::MAX))],
    )
}

/// Closest-hit and any-hit throughput of the same rays against two builds of a scene
/// (`[(label, options); 2]`), 1 thread, alternated run by run (best of [`ALTERNATIONS`]
/// runs each), so that load from other processes affects both alike.
fn compare_options(
    name: &str,
    scene: &dyn Fn(&mut GeometryBuilder),
    rays: &[(&str, Vec<Ray>)],
    variants: [(&str, BuildOptions); 2],
) -> Value {
    let build = |options: BuildOptions| {
        let mut b = GeometryBuilder::new();
        scene(&mut b);
        let p = POOLS.with(|p| p[1].clone());
        let start = Instant::now();
        let g = p.install(|| b.build_with(options));
        (g, start.elapsed().as_secs_f64())
    };
    let [(off_name, off_options), (on_name, on_options)] = variants;
    let (off, off_build_s) = build(off_options);
    let (on, on_build_s) = build(on_options);
    let mut sets = Vec::new();
    for (ray_name, rays) in rays {
        let mut best: [[Option<Throughput>; 2]; 2] = Default::default(); // [query][flatten]
        for _ in 0..ALTERNATIONS {
            for (k, g) in [&off, &on].into_iter().enumerate() {
                let closest = trace_runs(rays, 1, 1, &|r| g.intersect(r).is_some());
                let any = trace_runs(rays, 1, 1, &|r| g.occluded(r));
                for (q, t) in [closest, any].into_iter().enumerate() {
                    if best[q][k]
                        .as_ref()
                        .is_none_or(|b| t.rays_per_s > b.rays_per_s)
                    {
                        best[q][k] = Some(t);
                    }
                }
            }
        }
        let [[c_off, c_on], [a_off, a_on]] = best.map(|q| q.map(|t| t.expect("measured")));
        eprintln!(
            "{name}/{ray_name} ({off_name} -> {on_name}): closest {} -> {} ({:.2}x), any hit {} -> {} ({:.2}x), hit fraction {:.3}",
            c_off.show(),
            c_on.show(),
            c_on.rays_per_s / c_off.rays_per_s,
            a_off.show(),
            a_on.show(),
            a_on.rays_per_s / a_off.rays_per_s,
            c_on.hit_fraction
        );
        sets.push(json!({
            "rays": ray_name,
            "hit_fraction": (c_on.hit_fraction * 1000.0).round() / 1000.0,
            format!("closest_{off_name}"): c_off.json(),
            format!("closest_{on_name}"): c_on.json(),
            "closest_speedup": ((c_on.rays_per_s / c_off.rays_per_s) * 100.0).round() / 100.0,
            format!("any_hit_{off_name}"): a_off.json(),
            format!("any_hit_{on_name}"): a_on.json(),
            "any_hit_speedup": ((a_on.rays_per_s / a_off.rays_per_s) * 100.0).round() / 100.0,
        }));
    }
    json!({
        "scene": name,
        "instances": on.instances().len(),
        "flattened_triangles": on.flattened_triangle_count(),
        "instance_leaves_flattened": on.instance_leaf_count(),
        "compared": [off_name, on_name],
        format!("build_s_{off_name}"): (off_build_s * 1e4).round() / 1e4,
        format!("build_s_{on_name}"): (on_build_s * 1e4).round() / 1e4,
        "threads": 1,
        "ray_sets": sets,
    })
}

/// The instanced scenes whose name contains `filter` (all for an empty filter).
fn instanced_scenes(filter: &str) -> Vec<Value> {
    let mut out = Vec::new();
    let wanted = |name: &str| name.contains(filter);
    if wanted("cornell_box") {
        out.push(compare_builds("cornell_box", &cornell_box, &cornell_rays()));
    }
    if wanted("small_cornell_box") {
        out.push(compare_small(
            "small_cornell_box",
            &cornell_box,
            &cornell_rays(),
        ));
    }
    for cuboids in [1, 2, 3, 4, 5, 6, 8, 10, 14, 18, 22] {
        let name = format!("small_room_{}_leaves", 6 + 12 * cuboids);
        if wanted(&name) {
            out.push(compare_small(
                &name,
                &|b| room_with_cuboids(b, cuboids),
                &[("incoherent", rays_in_cube(0.95, 13))],
            ));
        }
    }
    if wanted("mixed_650_instances") {
        out.push(compare_builds(
            "mixed_650_instances",
            &mixed_scene,
            &[("incoherent", rays_in_cube(6.0, 5))],
        ));
    }
    for s in 1..=5 {
        let name = format!("64_icospheres_{}_triangles", 20 << (2 * s));
        if wanted(&name) {
            out.push(compare_builds(
                &name,
                &|b| icosphere_scene(b, s),
                &[("incoherent", rays_in_cube(4.0, 6))],
            ));
        }
    }
    out
}
