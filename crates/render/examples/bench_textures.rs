//! Texture speed: ns per lookup (nearest, bilinear, trilinear, trilinear + RGB → spectrum,
//! checkerboard, fBm) on one thread, and the render-time overhead of textures on a small
//! scene (the same scene with constant materials vs image textures + a normal map).
//! Prints JSON, and writes it to OUT.json if given (the latest run is kept as
//! tools/bench-results/bench-textures.json):
//!
//!     cargo run -p prism-render --example bench_textures -- [OUT.json]
//!
//! Times are CPU time (Linux `/proc/…/schedstat`: nanoseconds on a CPU, summed over the
//! process's threads for renders), so a loaded machine does not stretch them; each is the
//! minimum over 5 repetitions. Lookups are timed for random points over a 1024² texture
//! (16 MB: mostly cache misses, the worst case) and for coherent points (a scanline walk,
//! ~0.4 texel apart, as neighbouring pixels of a render are). The render comparison
//! alternates the two scenes.

use std::hint::black_box;
use std::time::Instant;

use glam::{Vec2, Vec3A};
use prism_render::texture::{
    checkerboard_weight, eval_spectrum, MipMap, Octaves, RgbUse, TexelValue, TextureContext,
};
use prism_render::{render, RenderScene, RenderSettings};
use prism_scene::WrapMode;
use prism_spectrum::SampledWavelengths;

struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// CPU nanoseconds of the calling thread (falls back to wall time off Linux).
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// CPU nanoseconds of all the process's threads.
fn process_cpu_ns() -> Option<u64> {
    let mut total = 0u64;
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let path = entry.ok()?.path().join("schedstat");
        let s = std::fs::read_to_string(path).ok()?;
        total += s.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total)
}

/// Minimum over `reps` runs of `f`'s CPU time per call, in ns.
fn time_ns(n: usize, reps: usize, mut f: impl FnMut() -> f32) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let (c, t) = (thread_cpu_ns(), Instant::now());
        let mut acc = 0.0f32;
        for _ in 0..n {
            acc += f();
        }
        black_box(acc);
        let ns = match (c, thread_cpu_ns()) {
            (Some(a), Some(b)) => (b - a) as f64,
            _ => t.elapsed().as_secs_f64() * 1e9,
        };
        best = best.min(ns / n as f64);
    }
    best
}

/// CPU seconds (all threads) of one call of `f`.
fn cpu_seconds(f: impl FnOnce()) -> f64 {
    let (c, t) = (process_cpu_ns(), Instant::now());
    f();
    match (c, process_cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
        _ => t.elapsed().as_secs_f64(),
    }
}

fn main() {
    let out = std::env::args().nth(1);
    let size = 1024usize;
    let mut rng = Lcg(7);
    let texels: Vec<[f32; 4]> = (0..size * size)
        .map(|_| [rng.next(), rng.next(), rng.next(), 1.0])
        .collect();
    let mip = MipMap::new(size, size, texels, WrapMode::Repeat);
    // Random points and footprints (0 to 16 texels): precomputed so the RNG is not timed.
    let n = 1 << 20;
    let queries: Vec<(Vec2, Vec2, Vec2)> = (0..n)
        .map(|_| {
            let st = Vec2::new(rng.next(), rng.next());
            let w = rng.next() * 16.0 / size as f32;
            (st, Vec2::new(w, 0.0), Vec2::new(0.0, w * 0.5))
        })
        .collect();
    // Coherent: a scanline walk 0.4 texel per step, footprint 0.4–3 texels.
    let coherent: Vec<(Vec2, Vec2, Vec2)> = (0..n)
        .map(|k| {
            let x = (k % 2048) as f32 * 0.4 / size as f32;
            let y = (k / 2048) as f32 * 0.4 / size as f32;
            let w = (0.4 + 2.6 * (k % 2048) as f32 / 2048.0) / size as f32;
            (Vec2::new(x, y), Vec2::new(w, 0.0), Vec2::new(0.0, w))
        })
        .collect();
    let mut j = 0usize;
    let mut next_coherent = || {
        j = (j + 1) & (n - 1);
        coherent[j]
    };
    let reps = 5;
    let nearest_c = time_ns(n, reps, || mip.nearest(next_coherent().0)[0]);
    let bilinear_c = time_ns(n, reps, || mip.bilinear(0, next_coherent().0)[0]);
    let trilinear_c = time_ns(n, reps, || {
        let (st, a, b) = next_coherent();
        mip.trilinear(st, a, b)[0]
    });
    let mut i = 0usize;
    let mut next = || {
        i = (i + 1) & (n - 1);
        queries[i]
    };
    let nearest = time_ns(n, reps, || mip.nearest(next().0)[0]);
    let bilinear = time_ns(n, reps, || mip.bilinear(0, next().0)[0]);
    let trilinear = time_ns(n, reps, || {
        let (st, a, b) = next();
        mip.trilinear(st, a, b)[0]
    });
    let checker = time_ns(n, reps, || {
        let (st, a, b) = next();
        checkerboard_weight(st * 37.0, a * 37.0, b * 37.0)
    });
    let octaves = Octaves {
        max_octaves: 6,
        gain: 0.5,
        lacunarity: 2.0,
    };
    let fbm = time_ns(n / 4, reps, || {
        let (st, _, _) = next();
        octaves.fbm(Vec3A::new(st.x * 50.0, st.y * 50.0, 0.3), 0.0) as f32
    });
    // A full albedo-texture evaluation: trilinear RGB, then the sigmoid coefficients from
    // the table and four wavelengths (what a textured lambert costs per hit).
    let dir = tempfile_dir();
    let png = dir.join("bench.png");
    write_noise_png(&png, 512);
    let scene_json = format!(
        r#"{{"materials": {{"t": {{"type": "lambert", "reflectance": {{"texture": {{"type": "image", "file": "{}"}}}}}}}}}}"#,
        png.display()
    );
    let description = prism_scene::parse_scene_str(&scene_json, dir.join("s.json")).unwrap();
    let scene = RenderScene::build(&description, None).unwrap();
    let texture = match &scene.materials[0] {
        prism_render::material::Material::Surface(
            prism_render::material::SurfaceMaterial::Lambert {
                reflectance: prism_render::texture::TexturedSpectrum::Texture { texture, .. },
            },
        ) => texture.clone(),
        _ => unreachable!(),
    };
    let wavelengths = SampledWavelengths::sample_visible(0.37);
    let spectrum_lookup = time_ns(n, reps, || {
        let (st, a, b) = next_coherent();
        let ctx = TextureContext {
            uv: st,
            duvdx: a,
            duvdy: b,
            ..TextureContext::default()
        };
        eval_spectrum(&texture, RgbUse::Albedo, &ctx, &wavelengths)[0]
    });
    let rgb_lookup = time_ns(n, reps, || {
        let (st, a, b) = next_coherent();
        let ctx = TextureContext {
            uv: st,
            duvdx: a,
            duvdy: b,
            ..TextureContext::default()
        };
        match texture.value(&ctx) {
            TexelValue::Rgba(c) => c[0],
            TexelValue::Blend(t) => t,
        }
    });

    // Render overhead: the same scene, constant vs textured materials.
    let normal_png = dir.join("normal.png");
    write_flatish_normal_png(&normal_png, 256);
    let scene_for = |textured: bool| {
        let (floor, ball) = if textured {
            (
                format!(
                    r#"{{"type": "lambert", "reflectance": {{"texture": {{"type": "image", "file": "{}", "uv_scale": [8, 8]}}}}}}"#,
                    png.display()
                ),
                format!(
                    r#"{{"type": "normal_map", "material": "base", "texture": {{"type": "image", "file": "{}"}}}}"#,
                    normal_png.display()
                ),
            )
        } else {
            (
                r#"{"type": "lambert", "reflectance": 0.5}"#.to_string(),
                r#"{"type": "lambert", "reflectance": 0.5}"#.to_string(),
            )
        };
        let json = format!(
            r#"{{
          "camera": {{"type": "pinhole", "fov_deg": 50, "transform": {{"look_at": {{"eye": [0, 1.2, 4], "target": [0, 0.4, 0]}}}}}},
          "film": {{"resolution": [160, 90]}},
          "integrator": {{"type": "path", "max_depth": 5}},
          "materials": {{"base": {{"type": "lambert", "reflectance": 0.5}}, "floor": {floor}, "ball": {ball}}},
          "shapes": [
            {{"type": "rectangle", "size_m": [20, 20], "material": "floor", "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
            {{"type": "sphere", "radius_m": 0.5, "material": "ball", "transform": {{"translate": [0, 0.5, 0]}}}}
          ],
          "lights": [{{"type": "sky", "spectrum": 1.0, "scale": 1.0}}, {{"type": "directional", "direction": [0.3, -1, 0.2], "scale": 3}}]
        }}"#
        );
        let d = prism_scene::parse_scene_str(&json, dir.join("r.json")).unwrap();
        RenderScene::build(&d, None).unwrap()
    };
    let plain = scene_for(false);
    let textured = scene_for(true);
    let settings = RenderSettings {
        spp: 16,
        seed: 1,
        ..RenderSettings::default()
    };
    let (mut t_plain, mut t_textured) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        t_plain = t_plain.min(cpu_seconds(|| {
            black_box(render(&plain, &settings, &|_| {}));
        }));
        t_textured = t_textured.min(cpu_seconds(|| {
            black_box(render(&textured, &settings, &|_| {}));
        }));
    }
    let _ = std::fs::remove_dir_all(&dir);

    let json = format!(
        r#"{{
  "tool": "cargo run -p prism-render --example bench_textures (profile dev, opt-level 2)",
  "threads": {},
  "clock": "CPU time (/proc schedstat), minimum of 5",
  "lookup_cpu_ns": {{
    "texture_size": {size},
    "coherent_nearest": {nearest_c:.2},
    "coherent_bilinear": {bilinear_c:.2},
    "coherent_trilinear": {trilinear_c:.2},
    "random_nearest": {nearest:.2},
    "random_bilinear": {bilinear:.2},
    "random_trilinear": {trilinear:.2},
    "coherent_image_texture_rgb_trilinear_with_uv_mapping_512": {rgb_lookup:.2},
    "coherent_image_texture_albedo_spectrum_trilinear_512": {spectrum_lookup:.2},
    "checkerboard_box_filtered": {checker:.2},
    "fbm_6_octaves": {fbm:.2}
  }},
  "render": {{
    "scene": "160x90, 16 spp, floor + sphere, sky + sun, max_depth 5",
    "constant_materials_cpu_s": {t_plain:.4},
    "image_texture_floor_and_normal_mapped_sphere_cpu_s": {t_textured:.4},
    "overhead_ratio": {:.4}
  }}
}}"#,
        rayon::current_num_threads(),
        t_textured / t_plain
    );
    println!("{json}");
    if let Some(path) = out {
        std::fs::write(path, json + "\n").unwrap();
    }
}

fn tempfile_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-bench-textures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_png(path: &std::path::Path, size: usize, rgb: impl Fn(usize, usize) -> [f32; 3]) {
    let pixels: Vec<[f32; 3]> = (0..size * size).map(|i| rgb(i % size, i / size)).collect();
    let image = prism_image::Image::new(
        size,
        size,
        pixels,
        prism_spectrum::rgb_space::RgbColorSpace::srgb(),
    )
    .unwrap();
    prism_image::io::write_image(path, &image).unwrap();
}

fn write_noise_png(path: &std::path::Path, size: usize) {
    write_png(path, size, |x, y| {
        let h = ((x * 73856093) ^ (y * 19349663)) % 1000;
        let v = h as f32 / 1000.0;
        [v, 0.5 * v + 0.2, 1.0 - v]
    });
}

fn write_flatish_normal_png(path: &std::path::Path, size: usize) {
    // A PNG written through prism-image is sRGB-encoded from these linear values; read
    // back as a normal map it is taken as linear codes, which only changes the bumps.
    write_png(path, size, |x, y| {
        let t = std::f32::consts::TAU * 4.0 / size as f32;
        let n = Vec3A::new(0.4 * (t * x as f32).sin(), 0.4 * (t * y as f32).cos(), 1.0).normalize();
        [0.5 * (n.x + 1.0), 0.5 * (n.y + 1.0), 0.5 * (n.z + 1.0)]
    });
}
