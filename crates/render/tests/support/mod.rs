//! Shared by the render crate's scene tests: each test file declares `mod support;`.
#![allow(dead_code)]

use std::path::PathBuf;

use glam::UVec2;
use prism_bandwidth::SamplePlan;
use prism_render::integrator::Pass;
use prism_render::{film_for, render_pass_with, RenderScene, RenderSettings};
use prism_scene::load_scene;

/// A test's own scene folder (removed when dropped): scene JSON and its data files.
pub struct Dir(pub PathBuf);

impl Dir {
    /// `prefix` names the test file, `test` the test.
    pub fn new(prefix: &str, test: &str) -> Dir {
        let dir =
            std::env::temp_dir().join(format!("prism-{prefix}-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Dir(dir)
    }
    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
    /// The repository's scene `name` (under scenes/) as JSON, with its data files `files`
    /// (paths relative to the scene's folder) copied into this folder at the same paths.
    pub fn repository_json(&self, name: &str, files: &[&str]) -> serde_json::Value {
        let scene = scenes_dir().join(name);
        let folder = scene.parent().unwrap();
        for file in files {
            let to = self.0.join(file);
            std::fs::create_dir_all(to.parent().unwrap()).unwrap();
            std::fs::copy(folder.join(file), to).unwrap();
        }
        serde_json::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap()
    }
    pub fn scene(&self, json: &str) -> RenderScene {
        self.scene_at(json, None)
    }
    /// `json` written as `scene.json` and built at `resolution` (`None`: its film's).
    pub fn scene_at(&self, json: &str, resolution: Option<u32>) -> RenderScene {
        let path = self.write("scene.json", json.as_bytes());
        let description = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        RenderScene::build(&description, resolution.map(UVec2::splat))
            .unwrap_or_else(|e| panic!("{e}"))
    }
    pub fn build_error(&self, json: &str) -> String {
        let path = self.write("scene.json", json.as_bytes());
        let description = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        match RenderScene::build(&description, None) {
            Ok(_) => panic!("built a scene that should be refused: {json}"),
            Err(e) => e.to_string().replace(&self.0.display().to_string(), "DIR"),
        }
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A Mitsuba `.vol` (version 3, float32, 1 channel) of `values` (x fastest) over the box.
#[allow(dead_code)] // not every test binary that shares this module writes grids
pub fn vol_bytes(res: [i32; 3], min: [f32; 3], max: [f32; 3], values: &[f32]) -> Vec<u8> {
    let mut b = b"VOL".to_vec();
    b.push(3);
    b.extend_from_slice(&1i32.to_le_bytes());
    for r in res {
        b.extend_from_slice(&r.to_le_bytes());
    }
    b.extend_from_slice(&1i32.to_le_bytes());
    for x in min.iter().chain(max.iter()) {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

/// The mean Y over `window` (x0, y0, x1, y1; exclusive ends) of each of the first
/// `passes` passes (sample indices 0, 1, …; one sample a pixel each, a photon pass being
/// one sample index), each in its own film, all rendered by one estimator in order.
pub fn pass_means(
    scene: &RenderScene,
    passes: u32,
    seed: u64,
    window: (u32, u32, u32, u32),
) -> Vec<f64> {
    let width = scene.resolution.x;
    pass_images(scene, passes, seed)
        .iter()
        .map(|y| window_mean(y, width, window))
        .collect()
}

/// The Y image of each of the first `passes` passes, as `pass_means` renders them.
pub fn pass_images(scene: &RenderScene, passes: u32, seed: u64) -> Vec<Vec<f32>> {
    let settings = RenderSettings {
        spp: 1,
        seed,
        ..RenderSettings::default()
    };
    let plan = SamplePlan::uniform(scene.resolution, 1).unwrap();
    let mut estimator = scene.integrator.estimator();
    (0..passes)
        .map(|i| {
            let mut film = film_for(scene, &settings);
            let pass = Pass {
                index: i,
                settings: &settings,
                plan: &plan,
                first_sample: i,
                footprint_plan: None,
            };
            render_pass_with(estimator.as_mut(), scene, &pass, &mut film, &|_| {}).unwrap();
            film.finish().y
        })
        .collect()
}

pub fn window_mean(y: &[f32], width: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> f64 {
    let mut sum = 0.0;
    for py in y0..y1 {
        for px in x0..x1 {
            sum += f64::from(y[(py * width + px) as usize]);
        }
    }
    sum / f64::from((x1 - x0) * (y1 - y0))
}

/// Mean and standard error of independent samples.
pub fn mean_se(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

pub fn assert_close(
    what: &str,
    (mean, se): (f64, f64),
    expected: f64,
    expected_se: f64,
    floor: f64,
) {
    let se = (se * se + expected_se * expected_se).sqrt();
    eprintln!("{what}: {mean:.5} vs {expected:.5}, s.e. {se:.2e}, floor {floor:.2e}");
    assert!(
        (mean - expected).abs() <= 4.0 * se + floor,
        "{what}: {mean} vs {expected} (s.e. {se}, floor {floor})"
    );
}

/// The repository's scene `name` at `resolution` × `resolution`.
pub fn repository_scene(name: &str, resolution: u32) -> RenderScene {
    repository_scene_at(name, UVec2::splat(resolution))
}

/// The repository's scenes/ folder.
pub fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The repository's scene `name` (under scenes/) at `resolution` (width, height).
pub fn repository_scene_at(name: &str, resolution: UVec2) -> RenderScene {
    let path = scenes_dir().join(name);
    let description = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    RenderScene::build(&description, Some(resolution)).unwrap_or_else(|e| panic!("{e}"))
}

pub fn with_integrator(
    mut scene: RenderScene,
    description: prism_scene::Integrator,
) -> RenderScene {
    scene.integrator = prism_render::Integrator::from_description(&description).unwrap();
    scene
}

/// Illuminance and its standard error at every point of every sensor of the scene written
/// as `scene.json` in `dir`, measured on `scene` with `seed`.
pub fn sensor_lux(scene: &RenderScene, dir: &Dir, seed: u64) -> Vec<(f64, f64)> {
    let description = load_scene(dir.0.join("scene.json")).unwrap();
    let (readings, _) =
        prism_render::sensor::measure_sensors(scene, &description.sensors, seed, &|_| {});
    readings
        .iter()
        .flat_map(|r| r.points.iter().map(|p| (p.illuminance_lx, p.std_error_lx)))
        .collect()
}

/// The points where radiosity's reading `got` differs from path's `expected` by more than
/// 2 % + 4 combined s.e. (each printed, with its relative difference).
pub fn lux_disagreements(expected: &[(f64, f64)], got: &[(f64, f64)]) -> usize {
    lux_disagreements_within(expected, got, 0.02)
}

/// As [`lux_disagreements`] with `relative` in place of 2 %.
pub fn lux_disagreements_within(
    expected: &[(f64, f64)],
    got: &[(f64, f64)],
    relative: f64,
) -> usize {
    let mut failures = 0;
    for (i, (&(e, e_se), &(g, g_se))) in expected.iter().zip(got).enumerate() {
        let se = (e_se * e_se + g_se * g_se).sqrt();
        eprintln!(
            "point {i}: radiosity {g:.3} lx, path {e:.3} lx ({:+.2} %), s.e. {se:.3}",
            100.0 * (g / e - 1.0)
        );
        failures += usize::from((g - e).abs() > relative * e + 4.0 * se);
    }
    failures
}
