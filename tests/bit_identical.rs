//! Features that a scene does not use cost it nothing, not even a different random number:
//! every example scene renders bit for bit as recorded in
//! `tests/fixtures/bit_identical_hashes.txt`, through the packet tracer (where the scene
//! allows it) and through the scalar tracer. Participating media and fluorescence reserve
//! their sample dimensions only in scenes that have them, so adding them must leave these
//! hashes alone; a change that moves them on purpose re-records them:
//!
//! ```text
//! PRISM_BLESS_HASHES=1 cargo test --test bit_identical
//! ```
//!
//! and says why in its commit message. The vector kernels run as `PRISM_SIMD=scalar` (the
//! baseline SSE2 kernels; AVX2 and AVX-512 render the same bits, the film's sums being
//! exact), so the hashes hold on any x86-64 machine.

use std::collections::BTreeMap;
use std::hash::Hasher;
use std::path::{Path, PathBuf};

use glam::UVec2;
use prism_render::{render_plan, FilmImage, RenderScene, RenderSettings};

const WIDTH_PX: u32 = 32;
const SPP: u32 = 2;
const SEED: u64 = 11;
const FIXTURE: &str = "tests/fixtures/bit_identical_hashes.txt";

/// FNV-1a over the bytes of every film plane: any changed bit changes the hash.
struct Fnv1a(u64);

impl Hasher for Fnv1a {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn film_hash(film: &FilmImage) -> u64 {
    let mut h = Fnv1a(0xcbf2_9ce4_8422_2325);
    let mut floats = |v: &[f32]| {
        for x in v {
            h.write(&x.to_bits().to_le_bytes());
        }
    };
    floats(film.xyz.as_flattened());
    floats(film.rgb.as_flattened());
    floats(&film.y);
    for plane in &film.aovs {
        floats(&plane.values);
    }
    h.finish()
}

/// Every scene file under scenes/ (one and two levels deep), sorted; hidden files (the
/// temporary copies tools/radiosity_stress.py writes next to a scene) left out.
fn example_scenes(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![(root.join("scenes"), 0)];
    while let Some((dir, depth)) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
            {
                continue;
            }
            if path.is_dir() && depth == 0 {
                dirs.push((path, depth + 1));
            } else if path.extension().is_some_and(|e| e == "json") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// "scene variant" → hash, for every scene that loads and renders.
fn current_hashes(root: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for path in example_scenes(root) {
        let name = path
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .into_owned();
        // Scene fragments and scenes this build refuses are not what this test guards.
        let Ok(description) = prism_scene::load_scene(&path) else {
            continue;
        };
        let [w, h] = description.film.resolution;
        let resolution = UVec2::new(WIDTH_PX, (WIDTH_PX * h / w).max(1));
        let Ok(mut scene) = RenderScene::build(&description, Some(resolution)) else {
            continue;
        };
        let mut settings = RenderSettings {
            spp: SPP,
            seed: SEED,
            ..RenderSettings::default()
        };
        if let prism_scene::Integrator::Path { sampler, .. } = description.integrator {
            settings.sampler = sampler;
        }
        let plan = prism_bandwidth::SamplePlan::uniform(resolution, SPP).unwrap();
        for (variant, packet) in [("packet", true), ("scalar", false)] {
            scene.set_packet_tracing(packet);
            let Ok((film, _)) = render_plan(&scene, &settings, &plan, &|_| {}) else {
                continue;
            };
            out.insert(
                format!("{name} {variant}"),
                format!("{:016x}", film_hash(&film)),
            );
        }
    }
    out
}

#[test]
fn scenes_render_the_recorded_bits() {
    // Before any kernel is chosen: the portable kernels (see the module comment). This is
    // the only test in this binary, so no other thread reads the environment meanwhile.
    std::env::set_var(prism_cpu::ENV_VAR, "scalar");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let current = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| current_hashes(root));
    let fixture = root.join(FIXTURE);
    if std::env::var_os("PRISM_BLESS_HASHES").is_some() {
        let mut text = String::from(
            "# tests/bit_identical.rs: \"scene variant hash\", FNV-1a of the film planes\n\
             # (32 px wide, 2 spp, seed 11, PRISM_SIMD=scalar). Re-record with\n\
             # PRISM_BLESS_HASHES=1 cargo test --test bit_identical\n",
        );
        for (key, hash) in &current {
            text += &format!("{key} {hash}\n");
        }
        std::fs::write(&fixture, text).unwrap();
        return;
    }
    let recorded = std::fs::read_to_string(&fixture).unwrap();
    let mut differing = Vec::new();
    let mut checked = 0;
    let mut keys = std::collections::BTreeSet::new();
    for line in recorded.lines().filter(|l| !l.starts_with('#')) {
        let (key, hash) = line.rsplit_once(' ').unwrap();
        keys.insert(key);
        match current.get(key) {
            Some(now) if now == hash => checked += 1,
            Some(now) => differing.push(format!("{key}: recorded {hash}, now {now}")),
            None => differing.push(format!("{key}: recorded {hash}, no longer renders")),
        }
    }
    // A scene added without re-recording would go unchecked.
    for (key, now) in &current {
        if !keys.contains(key.as_str()) {
            differing.push(format!("{key}: renders ({now}) but is not recorded"));
        }
    }
    assert!(
        differing.is_empty(),
        "{} of {} renders changed:\n{}",
        differing.len(),
        checked + differing.len(),
        differing.join("\n")
    );
    assert!(checked >= 40, "only {checked} renders checked");
}
