//! Test d of the predictor (docs/bandwidth.md): does V̂_p rank pixels as their measured
//! per-sample variance does? The three benchmark scenes at 64×64; V̂_p's luminance part
//! (less the colour term's X and Z noise, which `variance.Y` does not hold) from the
//! predictor's defaults against `variance.Y` (per-pixel sample variance of luminance) of a
//! 1024-spp render: Spearman's ρ ≥ 0.7 with direct light only (max_depth 1) and ≥ 0.5 with the
//! scene's depth, and under-prediction (V̂/median V̂ < ½·V/median V) in ≤ 10 % of the
//! direct-only pixels that see a surface. Minutes of rendering: `--ignored`
//!
//!     cargo test -p prism-render --test predictor_variance -- --ignored --nocapture

use std::path::Path;

use prism_bandwidth::VarianceBandwidth;
use prism_render::predictor::{predict, PredictorSettings};
use prism_render::{render, RenderScene, RenderSettings};
use prism_scene::{load_scene, Integrator};
use prism_testkit::rank_correlation::spearman;

const SPP: u32 = 1024;

fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The share of pixels with V̂/median V̂ < ½·V/median V.
fn under_predicted_share(predicted: &[f64], measured: &[f64]) -> f64 {
    let (mp, mm) = (median(predicted), median(measured));
    let under = predicted
        .iter()
        .zip(measured)
        .filter(|(p, m)| *p / mp < 0.5 * *m / mm)
        .count();
    under as f64 / predicted.len() as f64
}

struct Agreement {
    spearman: f64,
    under_predicted_share: f64,
    predicted_over_measured_median: f64,
}

/// V̂_p against `variance.Y` over the pixels whose centre ray hits a surface.
fn agreement(scene_file: &str, direct_only: bool) -> Agreement {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(scene_file);
    let mut description = load_scene(&path).expect("benchmark scene loads");
    if direct_only {
        match &mut description.integrator {
            Integrator::Path { max_depth, .. } => *max_depth = 1,
            other => panic!("{scene_file}: a path scene expected, found {other:?}"),
        }
    }
    let resolution = glam::UVec2::new(64, 64);
    let scene = RenderScene::build(&description, Some(resolution)).expect("scene builds");
    let prediction = predict(&scene, &PredictorSettings::defaults(64.0, 1), 1).unwrap();
    let settings = RenderSettings {
        spp: SPP,
        seed: 11,
        variance_aov: true,
        ..RenderSettings::default()
    };
    let (image, _) = render(&scene, &settings, &|_| {});
    let measured = &image.aov("variance.Y").expect("variance.Y layer").values;
    let depth = &image.aov("depth.Z").expect("depth.Z layer").values;
    let (mut predicted_v, mut measured_v) = (Vec::new(), Vec::new());
    // Eq. 9 (`--plan-variance eq9`) for comparison: its luminance part.
    let eq9 = predict(
        &scene,
        &PredictorSettings {
            variance_bandwidth: VarianceBandwidth::Incident,
            ..PredictorSettings::defaults(64.0, 1)
        },
        1,
    )
    .unwrap();
    let mut candidates: Vec<(&str, Vec<f64>)> = vec![
        ("V̂_p with the colour term", Vec::new()),
        ("eq. 9 (--plan-variance eq9), luminance part", Vec::new()),
        ("probe-measured per pixel, unpooled", Vec::new()),
        ("colour term alone", Vec::new()),
    ];
    for (i, p) in prediction.pixels.iter().enumerate() {
        if depth[i].is_finite() && depth[i] > 0.0 {
            predicted_v.push(f64::from(p.luminance_variance));
            measured_v.push(f64::from(measured[i]));
            candidates[0].1.push(f64::from(p.variance));
            candidates[1]
                .1
                .push(f64::from(eq9.pixels[i].luminance_variance));
            candidates[2].1.push(f64::from(p.measured_variance));
            candidates[3].1.push(f64::from(p.colour_variance));
        }
    }
    for (name, v) in &candidates {
        println!(
            "    {scene_file} direct_only={direct_only}: {name}: Spearman {:.3}, under-predicted {:.1} %",
            spearman(v, &measured_v),
            100.0 * under_predicted_share(v, &measured_v)
        );
    }
    let mp = median(&predicted_v);
    let mm = median(&measured_v);
    Agreement {
        spearman: spearman(&predicted_v, &measured_v),
        under_predicted_share: under_predicted_share(&predicted_v, &measured_v),
        predicted_over_measured_median: mp / mm,
    }
}

#[test]
#[ignore = "minutes of rendering; run with --ignored (test d of docs/bandwidth.md)"]
fn predicted_variance_ranks_pixels_as_the_measured_variance_does() {
    let mut failures = Vec::new();
    for scene in [
        "scenes/bandwidth/fig9-spheres.json",
        "scenes/bandwidth/fig17-curved-area.json",
        "scenes/glossy-env.json",
    ] {
        for direct_only in [true, false] {
            let a = agreement(scene, direct_only);
            let label = if direct_only { "direct only" } else { "full" };
            println!(
                "{scene} ({label}): Spearman {:.3}, under-predicted {:.1} %, median V̂ / median V {:.3}",
                a.spearman,
                100.0 * a.under_predicted_share,
                a.predicted_over_measured_median
            );
            let spearman_min = if direct_only { 0.7 } else { 0.5 };
            if a.spearman < spearman_min {
                failures.push(format!(
                    "{scene} ({label}): Spearman {:.3} < {spearman_min}",
                    a.spearman
                ));
            }
            if direct_only && a.under_predicted_share > 0.10 {
                failures.push(format!(
                    "{scene} ({label}): {:.1} % under-predicted > 10 %",
                    100.0 * a.under_predicted_share
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
