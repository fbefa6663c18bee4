//! The Cornell box (scenes/cornell-box.json, Mitsuba 3's `mi.cornell_box()` translated by
//! tools/mitsuba/export_cornell_scene.py) against Mitsuba 3.6.4's 4096-spp render
//! (tests/fixtures/cornell_mitsuba_reference.exr; call and version in its .json).
//!
//! Issue 4's criterion: the mean of each RGB channel within 1 % of Mitsuba's. Mitsuba
//! normalises XYZ by 1/106.7502594 where Prism divides by ∫ȳ = 106.857 (docs/mitsuba.md),
//! so the reference is divided by 1.0010003 first. As a check of the spatial distribution
//! too, 16 × 16 blocks of 16 × 16 pixels must agree within their Monte Carlo noise (the
//! spread of the block differences; the light's blocks excluded, since they are dominated
//! by the saturated, directly visible emitter).

use prism_image::io::exr::read_exr;
use prism_render::integrator::{Bdpt, LightTracer};
use prism_render::{render, Integrator, RenderScene, RenderSettings};

const MITSUBA_FILM_FACTOR: f64 = 106.857 / 106.750_259_4;

#[test]
fn cornell_box_matches_mitsuba_within_one_percent_per_channel() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let description = prism_scene::load_scene(root.join("scenes/cornell-box.json")).unwrap();
    let scene = RenderScene::build(&description, None).unwrap();
    // The scene's sampler (independent, as Mitsuba's) and its splatting film.
    let sampler = match description.integrator {
        prism_scene::Integrator::Path { sampler, .. } => sampler,
        _ => unreachable!("the Cornell box uses the path tracer"),
    };
    let settings = RenderSettings {
        spp: 64,
        seed: 1,
        sampler,
        ..RenderSettings::default()
    };
    let (film, stats) = render(&scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    assert_eq!(stats.non_finite_contributions, 0);
    let reference = read_exr(&root.join("tests/fixtures/cornell_mitsuba_reference.exr")).unwrap();
    assert_eq!(
        (reference.width(), reference.height()),
        (film.width as usize, film.height as usize)
    );
    let reference: Vec<[f64; 3]> = reference
        .pixels()
        .iter()
        .map(|p| p.map(|c| f64::from(c) / MITSUBA_FILM_FACTOR))
        .collect();
    let ours: Vec<[f64; 3]> = film.rgb.iter().map(|p| p.map(f64::from)).collect();
    let n = ours.len() as f64;
    for c in 0..3 {
        let a: f64 = ours.iter().map(|p| p[c]).sum::<f64>() / n;
        let b: f64 = reference.iter().map(|p| p[c]).sum::<f64>() / n;
        let rel = (a - b) / b;
        eprintln!("channel {c}: Prism {a:.6}, Mitsuba {b:.6}, relative difference {rel:+.4}");
        assert!(rel.abs() <= 0.01, "channel {c}: {rel:+.4} (limit ±1 %)");
    }
    // Blocks: relative difference of block means (all three channels summed).
    let (w, block) = (film.width as usize, 16usize);
    let mut diffs = Vec::new();
    for by in 0..film.height as usize / block {
        for bx in 0..w / block {
            let (mut sa, mut sb, mut emitter) = (0.0, 0.0, false);
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    let i = y * w + x;
                    sa += ours[i].iter().sum::<f64>();
                    sb += reference[i].iter().sum::<f64>();
                    // Any pixel brighter than every wall sees the emitter (or its edge,
                    // where 64 spp of a 0/1 coverage are far noisier than the walls).
                    emitter |= reference[i].iter().sum::<f64>() > 3.0;
                }
            }
            if emitter {
                continue;
            }
            diffs.push((sa - sb) / sb);
        }
    }
    let m = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / m;
    let sigma = (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt();
    let worst = diffs.iter().fold(0.0f64, |w, d| w.max((d - mean).abs()));
    eprintln!("blocks: {m} compared, mean {mean:+.4}, σ {sigma:.4}, worst {worst:.4}");
    assert!(sigma < 0.05, "block noise σ = {sigma}");
    assert!(
        worst < 6.0 * sigma,
        "a block differs by {worst} (σ {sigma})"
    );
}

/// Mitsuba's reference, divided by the film factor (see the module docs).
fn mitsuba_reference(root: &std::path::Path) -> Vec<[f64; 3]> {
    read_exr(&root.join("tests/fixtures/cornell_mitsuba_reference.exr"))
        .unwrap()
        .pixels()
        .iter()
        .map(|p| p.map(|c| f64::from(c) / MITSUBA_FILM_FACTOR))
        .collect()
}

/// The Cornell box rendered with `integrator` (the scene's depth, roulette and MIS), each
/// channel's mean within 1 % of Mitsuba 3's.
fn method_matches_mitsuba(make: impl Fn(prism_render::integrator::PathTracer) -> Integrator) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let description = prism_scene::load_scene(root.join("scenes/cornell-box.json")).unwrap();
    let mut scene = RenderScene::build(&description, None).unwrap();
    let Integrator::Path(path) = scene.integrator else {
        unreachable!("the Cornell box uses the path tracer")
    };
    scene.integrator = make(path);
    let settings = RenderSettings {
        spp: 16,
        seed: 3,
        sampler: prism_render::SamplerKind::Independent,
        ..RenderSettings::default()
    };
    let (film, stats) = render(&scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    let reference = mitsuba_reference(root);
    let ours: Vec<[f64; 3]> = film.rgb.iter().map(|p| p.map(f64::from)).collect();
    let n = ours.len() as f64;
    for c in 0..3 {
        let a: f64 = ours.iter().map(|p| p[c]).sum::<f64>() / n;
        let b: f64 = reference.iter().map(|p| p[c]).sum::<f64>() / n;
        let rel = (a - b) / b;
        eprintln!(
            "{}: channel {c}: Prism {a:.6}, Mitsuba {b:.6}, relative difference {rel:+.4}",
            scene.integrator.name()
        );
        assert!(rel.abs() <= 0.01, "channel {c}: {rel:+.4} (limit ±1 %)");
    }
}

#[test]
fn cornell_box_with_bdpt_matches_mitsuba_within_one_percent_per_channel() {
    method_matches_mitsuba(|p| {
        Integrator::Bdpt(Bdpt {
            max_depth: p.max_depth,
            rr_depth: p.rr_depth,
            mis: p.mis,
            strategy: None,
        })
    });
}

#[test]
fn cornell_box_with_light_tracing_matches_mitsuba_within_one_percent_per_channel() {
    method_matches_mitsuba(|p| {
        Integrator::Light(LightTracer {
            max_depth: p.max_depth,
            rr_depth: p.rr_depth,
        })
    });
}
