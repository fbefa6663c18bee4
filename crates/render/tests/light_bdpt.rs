//! `light` and `bdpt` against `path`: the three methods estimate the same image, so their
//! per-channel means agree within the Monte Carlo noise (4 standard errors, measured over
//! independent seeds); BDPT's strategies sum to its image; each unweighted strategy
//! converges to the path tracer's image of its path length.

use glam::UVec2;
use prism_render::integrator::{Bdpt, BdptStrategy, LightTracer, PathTracer};
use prism_render::{render_plan, Integrator, RenderScene, RenderSettings};
use prism_scene::MisHeuristic;

fn scene(name: &str, resolution: UVec2) -> RenderScene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let description = prism_scene::load_scene(root.join(name)).unwrap();
    RenderScene::build(&description, Some(resolution)).unwrap()
}

fn settings(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        spp,
        seed,
        sampler: prism_render::SamplerKind::Independent,
        ..RenderSettings::default()
    }
}

/// Linear Rec.709 pixels of one render with `integrator`.
fn render_with(
    scene: &mut RenderScene,
    integrator: Integrator,
    spp: u32,
    seed: u64,
) -> Vec<[f64; 3]> {
    scene.integrator = integrator;
    let plan = prism_bandwidth::SamplePlan::uniform(scene.resolution, spp).unwrap();
    let (film, stats) = render_plan(scene, &settings(spp, seed), &plan, &|_| {}).unwrap();
    assert_eq!(stats.non_finite_samples, 0, "{}", integrator.name());
    film.rgb.iter().map(|p| p.map(f64::from)).collect()
}

/// Per-channel mean over `mask`ed pixels and its standard error over `seeds` renders.
fn channel_means(
    scene: &mut RenderScene,
    integrator: Integrator,
    spp: u32,
    seeds: &[u64],
    mask: &[bool],
) -> [(f64, f64); 3] {
    let per_seed: Vec<[f64; 3]> = seeds
        .iter()
        .map(|&seed| {
            let image = render_with(scene, integrator, spp, seed);
            let n = mask.iter().filter(|&&m| m).count() as f64;
            let mut sum = [0.0; 3];
            for (p, _) in image.iter().zip(mask).filter(|(_, &m)| m) {
                for c in 0..3 {
                    sum[c] += p[c];
                }
            }
            sum.map(|s| s / n)
        })
        .collect();
    let k = per_seed.len() as f64;
    std::array::from_fn(|c| {
        let mean = per_seed.iter().map(|m| m[c]).sum::<f64>() / k;
        let var = per_seed.iter().map(|m| (m[c] - mean).powi(2)).sum::<f64>() / (k - 1.0);
        (mean, (var / k).sqrt())
    })
}

fn assert_agree(what: &str, a: [(f64, f64); 3], b: [(f64, f64); 3]) {
    for c in 0..3 {
        let ((ma, sa), (mb, sb)) = (a[c], b[c]);
        let se = (sa * sa + sb * sb).sqrt();
        eprintln!(
            "{what} channel {c}: {ma:.6} ± {sa:.6} vs {mb:.6} ± {sb:.6} ({:+.2} s.e.)",
            (ma - mb) / se.max(1e-30)
        );
        assert!(
            (ma - mb).abs() <= 4.0 * se.max(1e-6 * mb.abs()),
            "{what} channel {c}: {ma} vs {mb} differ by more than 4 s.e. ({se})"
        );
    }
}

/// Pixels whose first hits over the whole filter footprint are non-specular surfaces:
/// where a pinhole light tracer reaches.
fn non_specular_first_hits(scene: &RenderScene) -> Vec<bool> {
    let (w, h) = (scene.resolution.x, scene.resolution.y);
    let radius = scene.new_film().filter().radius_px();
    let wavelengths = prism_spectrum::SampledWavelengths::sample_visible(0.5);
    let mut mask = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let mut ok = true;
            for j in 0..5 {
                for i in 0..5 {
                    let offset = glam::Vec2::new(i as f32, j as f32) / 4.0 * 2.0 - 1.0;
                    let film =
                        glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + offset * (radius + 0.5);
                    let Some(ray) = scene.camera.generate_ray_only(film, glam::Vec2::splat(0.5))
                    else {
                        ok = false;
                        continue;
                    };
                    match scene.geometry.intersect(&ray) {
                        None => ok = false,
                        Some(hit) => {
                            let si = scene.geometry.shading_interaction(&ray, &hit);
                            let bsdf = scene.material(si.material_id).bsdf(&si, &wavelengths);
                            ok &= !bsdf.has_specular();
                        }
                    }
                }
            }
            mask.push(ok);
        }
    }
    mask
}

fn path_of(scene: &RenderScene) -> PathTracer {
    match scene.integrator {
        Integrator::Path(p) => p,
        other => panic!("expected a path-traced example scene, got {}", other.name()),
    }
}

fn light_of(p: PathTracer) -> Integrator {
    Integrator::Light(LightTracer {
        max_depth: p.max_depth,
        rr_depth: p.rr_depth,
    })
}

fn bdpt_of(p: PathTracer, strategy: Option<BdptStrategy>) -> Integrator {
    Integrator::Bdpt(Bdpt {
        max_depth: p.max_depth,
        rr_depth: p.rr_depth,
        mis: p.mis,
        strategy,
    })
}

fn methods_agree(name: &str, resolution: UVec2, spp: u32, seeds: usize) {
    methods_agree_on(scene(name, resolution), name, spp, seeds);
}

/// A scene from scenes/, its JSON edited by `edit` (parsed as if it were that file, so
/// assets resolve), with the path tracer (max depth 5) as its integrator.
fn edited_scene(
    name: &str,
    resolution: UVec2,
    edit: impl Fn(&mut serde_json::Value),
) -> RenderScene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    json["integrator"] = serde_json::json!({"type": "path", "max_depth": 5, "rr_depth": 3});
    edit(&mut json);
    let description = prism_scene::parse_scene_str(&json.to_string(), &path).unwrap();
    RenderScene::build(&description, Some(resolution)).unwrap()
}

fn methods_agree_on(mut scene: RenderScene, name: &str, spp: u32, seeds: usize) {
    let resolution = scene.resolution;
    let path = path_of(&scene);
    let seeds: Vec<u64> = (0..seeds as u64).map(|k| 1000 + 17 * k).collect();
    // The path tracer's own seeds: the methods share sample dimensions (camera sample,
    // vertex blocks), so equal seeds would correlate their noise and hide a difference.
    let path_seeds: Vec<u64> = seeds.iter().map(|s| s + 50_000).collect();
    let everywhere = vec![true; (resolution.x * resolution.y) as usize];
    let reachable = non_specular_first_hits(&scene);
    assert!(
        reachable.iter().filter(|&&m| m).count() > 16,
        "{name}: too few pixels"
    );
    let p_all = channel_means(
        &mut scene,
        Integrator::Path(path),
        spp,
        &path_seeds,
        &everywhere,
    );
    let b_all = channel_means(&mut scene, bdpt_of(path, None), spp, &seeds, &everywhere);
    assert_agree(&format!("{name}: bdpt vs path"), b_all, p_all);
    let p_reach = channel_means(
        &mut scene,
        Integrator::Path(path),
        spp,
        &path_seeds,
        &reachable,
    );
    let l_reach = channel_means(&mut scene, light_of(path), spp, &seeds, &reachable);
    assert_agree(&format!("{name}: light vs path"), l_reach, p_reach);
}

#[test]
fn light_bdpt_and_path_agree_on_the_cornell_box() {
    methods_agree("cornell-box.json", UVec2::new(32, 32), 16, 8);
}

#[test]
fn light_bdpt_and_path_agree_on_glossy_env() {
    methods_agree("glossy-env.json", UVec2::new(48, 27), 16, 8);
}

#[test]
fn light_bdpt_and_path_agree_on_the_daylight_room() {
    methods_agree("daylight-room.json", UVec2::new(40, 30), 16, 8);
}

/// Σ over strategies (s, t) of one length of the MIS-weighted strategy images is the full
/// image: the same random numbers (the strategy filter draws nothing), so equal up to the
/// order of float additions.
#[test]
fn bdpt_strategy_images_sum_to_the_full_image() {
    let mut scene = scene("cornell-box.json", UVec2::new(16, 16));
    let mut p = path_of(&scene);
    p.max_depth = 3;
    scene.integrator = Integrator::Path(p);
    let full = render_with(&mut scene, bdpt_of(p, None), 4, 5);
    let mut sum = vec![[0.0f64; 3]; full.len()];
    for depth in 0..=p.max_depth {
        for t in 1..=depth + 2 {
            let s = depth + 2 - t;
            if (s, t) == (1, 1) {
                continue;
            }
            let strategy = BdptStrategy {
                s,
                t,
                unweighted: false,
            };
            let image = render_with(&mut scene, bdpt_of(p, Some(strategy)), 4, 5);
            for (acc, px) in sum.iter_mut().zip(&image) {
                for c in 0..3 {
                    acc[c] += px[c];
                }
            }
        }
    }
    let total: f64 = full.iter().map(|p| p.iter().sum::<f64>()).sum();
    let mut worst = 0.0f64;
    for (a, b) in sum.iter().zip(&full) {
        for c in 0..3 {
            worst = worst.max((a[c] - b[c]).abs());
        }
    }
    let mean = total / (3 * full.len()) as f64;
    eprintln!("strategies' sum vs full image: worst pixel difference {worst:e} (mean {mean})");
    assert!(
        worst <= 1e-4 * mean,
        "worst difference {worst} vs mean pixel {mean}"
    );
}

/// Each strategy alone (weight 1) of paths with `depth` scattering events converges to
/// the path tracer's image of that length, path(max_depth = depth) − path(depth − 1): the
/// Cornell box is diffuse, so every strategy has full support.
#[test]
fn unweighted_bdpt_strategies_converge_to_the_path_tracers_image_of_their_length() {
    let mut scene = scene("cornell-box.json", UVec2::new(16, 16));
    let base = path_of(&scene);
    let seeds: Vec<u64> = (0..8).map(|k| 77 + k).collect();
    let everywhere = vec![true; 256];
    for depth in [1u32, 2] {
        let at = |max_depth: u32| PathTracer { max_depth, ..base };
        // The path tracer's length-`depth` image per seed: the difference of two renders
        // with the same random numbers.
        let per_seed: Vec<[f64; 3]> = seeds
            .iter()
            .map(|&seed| {
                // Seeds apart from the strategies' (shared sample dimensions).
                let seed = seed + 50_000;
                let hi = render_with(&mut scene, Integrator::Path(at(depth)), 64, seed);
                let lo = if depth == 0 {
                    vec![[0.0; 3]; hi.len()]
                } else {
                    render_with(&mut scene, Integrator::Path(at(depth - 1)), 64, seed)
                };
                let n = hi.len() as f64;
                std::array::from_fn(|c| {
                    hi.iter().zip(&lo).map(|(a, b)| a[c] - b[c]).sum::<f64>() / n
                })
            })
            .collect();
        let k = per_seed.len() as f64;
        let path_length: [(f64, f64); 3] = std::array::from_fn(|c| {
            let mean = per_seed.iter().map(|m| m[c]).sum::<f64>() / k;
            let var = per_seed.iter().map(|m| (m[c] - mean).powi(2)).sum::<f64>() / (k - 1.0);
            (mean, (var / k).sqrt())
        });
        for t in 1..=depth + 2 {
            let s = depth + 2 - t;
            if (s, t) == (1, 1) {
                continue;
            }
            let strategy = BdptStrategy {
                s,
                t,
                unweighted: true,
            };
            let b = channel_means(
                &mut scene,
                bdpt_of(at(depth), Some(strategy)),
                64,
                &seeds,
                &everywhere,
            );
            assert_agree(
                &format!("length {depth}, strategy ({s}, {t}) vs path"),
                b,
                path_length,
            );
        }
    }
}

/// `light` refuses cameras without importance with the camera's reason, instead of
/// rendering black.
#[test]
fn light_and_bdpt_refuse_cameras_without_importance() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let description = prism_scene::load_scene(root.join("cameras/orthographic.json")).unwrap();
    let mut scene = RenderScene::build(&description, Some(UVec2::new(8, 8))).unwrap();
    for integrator in [
        light_of(PathTracer::default()),
        bdpt_of(PathTracer::default(), None),
    ] {
        scene.integrator = integrator;
        let plan = prism_bandwidth::SamplePlan::uniform(scene.resolution, 1).unwrap();
        let e = render_plan(&scene, &settings(1, 0), &plan, &|_| {}).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("orthographic"), "{text}");
        assert!(text.starts_with(integrator.name()), "{text}");
    }
}

/// The light tracer's film holds one light path per camera sample.
#[test]
fn light_traces_one_light_path_per_camera_sample() {
    let mut scene = scene("cornell-box.json", UVec2::new(8, 8));
    scene.integrator = light_of(path_of(&scene));
    let plan = prism_bandwidth::SamplePlan::uniform(scene.resolution, 3).unwrap();
    let (_, stats) = render_plan(&scene, &settings(3, 0), &plan, &|_| {}).unwrap();
    assert_eq!(stats.light_paths, 8 * 8 * 3);
    assert_eq!(stats.samples, 8 * 8 * 3);
}

#[test]
fn the_power_and_balance_heuristics_agree() {
    let mut scene = scene("cornell-box.json", UVec2::new(16, 16));
    let mut p = path_of(&scene);
    let seeds: Vec<u64> = (0..6).map(|k| 300 + k).collect();
    let everywhere = vec![true; 256];
    p.mis = MisHeuristic::Power;
    let power = channel_means(&mut scene, bdpt_of(p, None), 16, &seeds, &everywhere);
    p.mis = MisHeuristic::Balance;
    let other_seeds: Vec<u64> = seeds.iter().map(|s| s + 50_000).collect();
    let balance = channel_means(&mut scene, bdpt_of(p, None), 16, &other_seeds, &everywhere);
    assert_agree("bdpt power vs balance", power, balance);
}

/// Point, spot, goniometric (IES) and directional lights in the Cornell box (the light
/// sources a camera path can never hit: bdpt and light reach them only through their
/// emission sampling and s = 1 connections).
#[test]
fn light_bdpt_and_path_agree_with_point_spot_ies_and_directional_lights() {
    let scene = edited_scene("cornell-box.json", UVec2::new(24, 24), |json| {
        json["lights"] = serde_json::json!([
            {"type": "point", "position_m": [0.3, 0.7, 0.2], "power_lm": 60},
            {"type": "spot", "position_m": [-0.5, 0.9, -0.2], "target_m": [-0.2, -1, 0.1],
             "cone_angle_deg": 35, "falloff_start_deg": 20, "intensity_cd": 10},
            {"type": "luminaire", "file": "office/downlight.ies", "position_m": [0.4, 0.95, -0.4],
             "power_lm": 40},
            {"type": "directional", "direction": [0.2, -0.3, -1], "illuminance_lx": 40}
        ]);
    });
    methods_agree_on(
        scene,
        "cornell box with point, spot, IES and directional lights",
        16,
        8,
    );
}

/// Light paths connect to the lens of a thin-lens camera and to the point of a fisheye.
#[test]
fn light_bdpt_and_path_agree_with_thin_lens_and_fisheye_cameras() {
    for name in ["cameras/thin-lens.json", "cameras/fisheye-equidistant.json"] {
        let scene = edited_scene(name, UVec2::new(24, 24), |_| {});
        methods_agree_on(scene, name, 16, 8);
    }
}
