//! Light selection at shading points (issue 22): the light BVH (Conty Estevez & Kulla 2018)
//! against selection in proportion to power on scenes/many-lights/open-office.json (120
//! luminaires: 96 ceiling panels and 24 desk lamps).
//!
//! - Unbiased: the two images' channel means agree within 4 standard errors of their
//!   difference (8 independent renders each, different seeds: the standard error is that of
//!   the 8 image means);
//! - better: on the floor (the image's lower half) the per-pixel variance over those
//!   renders is at most a quarter of power's (measured: 6–17× lower per channel).

use std::path::PathBuf;

use prism_render::{render, RenderScene, RenderSettings};

const RUNS: u64 = 8;

fn open_office() -> prism_scene::SceneDescription {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/many-lights/open-office.json");
    prism_scene::load_scene(path).unwrap()
}

/// `RUNS` renders (seeds 1…RUNS) at 64 × 36 px, 32 spp: each an RGB image.
fn renders(bvh: bool) -> Vec<Vec<[f64; 3]>> {
    let description = open_office();
    let mut scene = RenderScene::build(&description, Some(glam::UVec2::new(64, 36))).unwrap();
    assert_eq!(scene.set_light_bvh(bvh), bvh);
    (1..=RUNS)
        .map(|seed| {
            let settings = RenderSettings {
                spp: 32,
                seed,
                ..RenderSettings::default()
            };
            let (film, stats) = render(&scene, &settings, &|_| {});
            assert_eq!(stats.non_finite_samples, 0);
            film.rgb.iter().map(|p| p.map(f64::from)).collect()
        })
        .collect()
}

fn mean_and_standard_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Mean over the pixels of the image's lower half (the floor: lit by the luminaires, no
/// edges of panels within a pixel) of the per-pixel variance of channel `c` across the
/// renders.
fn mean_pixel_variance(images: &[Vec<[f64; 3]>], c: usize) -> f64 {
    let n = images.len() as f64;
    let pixels = images[0].len();
    (pixels / 2..pixels)
        .map(|i| {
            let m = images.iter().map(|im| im[i][c]).sum::<f64>() / n;
            images.iter().map(|im| (im[i][c] - m).powi(2)).sum::<f64>() / (n - 1.0)
        })
        .sum::<f64>()
        / (pixels - pixels / 2) as f64
}

#[test]
fn the_light_bvh_is_unbiased_and_less_noisy_than_power_selection() {
    let bvh = renders(true);
    let power = renders(false);
    for c in 0..3 {
        let image_means = |images: &[Vec<[f64; 3]>]| -> Vec<f64> {
            images
                .iter()
                .map(|im| im.iter().map(|p| p[c]).sum::<f64>() / im.len() as f64)
                .collect()
        };
        let (mb, sb) = mean_and_standard_error(&image_means(&bvh));
        let (mp, sp) = mean_and_standard_error(&image_means(&power));
        let se = (sb * sb + sp * sp).sqrt();
        eprintln!(
            "channel {c}: BVH {mb:.5} ± {sb:.5}, power {mp:.5} ± {sp:.5}, difference {:+.5} \
             ({:.2} standard errors)",
            mb - mp,
            (mb - mp) / se
        );
        assert!(
            4.0 * se < 0.03 * mp,
            "channel {c}: too noisy to test (SE {se})"
        );
        assert!(
            (mb - mp).abs() <= 4.0 * se,
            "channel {c}: BVH {mb} vs power {mp}, beyond 4 standard errors ({se})"
        );
        let (vb, vp) = (mean_pixel_variance(&bvh, c), mean_pixel_variance(&power, c));
        eprintln!("channel {c}: mean pixel variance BVH {vb:.3e}, power {vp:.3e}");
        assert!(
            vb < 0.25 * vp,
            "channel {c}: BVH variance {vb} vs power {vp}"
        );
    }
}
