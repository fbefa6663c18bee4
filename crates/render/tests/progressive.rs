//! Progressive rendering (`render_pass`, used by `prism converge`): passes that continue the
//! per-pixel sample sequence add up to one render of the total sample count, for both
//! samplers and both reconstructions (filter importance sampling and splatting).

use prism_bandwidth::SamplePlan;
use prism_render::{
    film_for, render, render_pass, FilmImage, RenderScene, RenderSettings, SamplerKind,
};
use prism_scene::parse_scene_str;

fn scene(reconstruction: &str) -> RenderScene {
    // A small lit box corner: diffuse inter-reflection, an area light, MIS.
    let json = format!(
        r#"{{
      "camera": {{"type": "pinhole", "fov_deg": 50, "transform": {{"look_at": {{"eye": [0, 1, 3], "target": [0, 0.5, 0]}}}}}},
      "film": {{"resolution": [20, 14], "reconstruction": "{reconstruction}",
               "filter": {{"type": "gaussian", "radius_px": 1.5, "sigma_px": 0.5}}}},
      "integrator": {{"type": "path", "max_depth": 5}},
      "materials": {{"white": {{"type": "lambert", "reflectance": 0.7}},
                    "red": {{"type": "lambert", "reflectance": {{"rgb": [0.7, 0.1, 0.1]}}}}}},
      "shapes": [
        {{"type": "rectangle", "size_m": [4, 4], "material": "white",
          "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
        {{"type": "rectangle", "size_m": [4, 4], "material": "red",
          "transform": {{"translate": [0, 0, -1]}}}},
        {{"type": "sphere", "radius_m": 0.4, "material": "white", "transform": {{"translate": [0.3, 0.4, 0]}}}},
        {{"type": "rectangle", "name": "lamp", "size_m": [0.6, 0.6], "material": "white",
          "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, 2, 0]}}]}}
      ],
      "lights": [{{"type": "area", "shape": "lamp", "spectrum": "D65", "scale": 5}}]
    }}"#
    );
    let description = parse_scene_str(&json, "progressive.json").expect("test scene parses");
    RenderScene::build(&description, None).expect("test scene builds")
}

/// Largest relative difference of two images' XYZ (absolute below 1e-9).
fn max_relative_difference(a: &FilmImage, b: &FilmImage) -> f64 {
    a.xyz
        .iter()
        .flatten()
        .zip(b.xyz.iter().flatten())
        .map(|(&x, &y)| {
            let (x, y) = (f64::from(x), f64::from(y));
            (x - y).abs() / x.abs().max(y.abs()).max(1e-9)
        })
        .fold(0.0, f64::max)
}

#[test]
fn passes_continuing_the_sequence_equal_one_render_of_the_total() {
    for reconstruction in ["importance", "splat"] {
        let scene = scene(reconstruction);
        for sampler in [SamplerKind::Sobol, SamplerKind::Independent] {
            let settings = RenderSettings {
                spp: 13,
                seed: 5,
                sampler,
                ..RenderSettings::default()
            };
            let (single, single_stats) = render(&scene, &settings, &|_| {});
            // Passes of 1, 4 and 8 samples: [0, 1), [1, 5), [5, 13).
            let mut film = film_for(&scene, &settings);
            let mut first = 0;
            let mut samples = 0;
            for pass in [1, 4, 8] {
                let plan = SamplePlan::uniform(scene.resolution, pass).unwrap();
                let stats = render_pass(&scene, &settings, &plan, &mut film, first, &|_| {})
                    .expect("plan and film fit the scene");
                samples += stats.samples;
                first += pass;
            }
            assert_eq!(samples, single_stats.samples);
            let passes = film.finish();
            // f32 images from f64 sums that differ only in the order of additions.
            let d = max_relative_difference(&single, &passes);
            assert!(
                d < 1e-5,
                "{reconstruction} {sampler:?}: max rel. difference {d}"
            );
            assert_eq!(
                single.aov("spp.Y").unwrap().values,
                passes.aov("spp.Y").unwrap().values
            );
            // What converge's render thread copies at a checkpoint (the colour sums only)
            // gives the finished image's RGB bit for bit.
            assert_eq!(film.rgb(), passes.rgb);
            assert_eq!(film.colour_snapshot().rgb(), passes.rgb);
            // And a pass that repeats samples [0, 8) instead is a different image.
            let mut film = film_for(&scene, &settings);
            for _ in 0..2 {
                let plan = SamplePlan::uniform(scene.resolution, 8).unwrap();
                render_pass(&scene, &settings, &plan, &mut film, 0, &|_| {}).unwrap();
            }
            let settings16 = RenderSettings {
                spp: 16,
                ..settings
            };
            let (sixteen, _) = render(&scene, &settings16, &|_| {});
            assert!(max_relative_difference(&sixteen, &film.finish()) > 1e-3);
        }
    }
}

#[test]
fn a_pass_rejects_a_film_of_another_resolution() {
    let scene = scene("importance");
    let settings = RenderSettings::default();
    let small = RenderScene::build(
        &parse_scene_str(
            r#"{"camera": {"type": "pinhole", "fov_deg": 40}, "film": {"resolution": [4, 4]}}"#,
            "small.json",
        )
        .unwrap(),
        None,
    )
    .unwrap();
    let mut film = film_for(&small, &settings);
    let plan = SamplePlan::uniform(scene.resolution, 1).unwrap();
    let e = render_pass(&scene, &settings, &plan, &mut film, 0, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("20×14"), "{e}");
}

/// A plan whose pixels start at their own sample index (`SamplePlan::with_first_samples`,
/// what predicted and adaptive plans need): passes of per-pixel counts equal one render of
/// the summed counts, through the packet tracer and the scalar one; two films holding
/// different samples merge into that render too (`Film::merge_film`).
#[test]
fn per_pixel_passes_equal_one_render_of_the_summed_counts() {
    let mut scene = scene("importance");
    let n = (scene.resolution.x * scene.resolution.y) as usize;
    let first: Vec<u32> = (0..n).map(|i| (i % 5) as u32).collect();
    let second: Vec<u32> = (0..n).map(|i| ((i * 7) % 4) as u32).collect();
    let total: Vec<u32> = first.iter().zip(&second).map(|(a, b)| a + b).collect();
    for packet in [true, false] {
        scene.set_packet_tracing(packet);
        let settings = RenderSettings {
            seed: 3,
            sampler: SamplerKind::Sobol,
            ..RenderSettings::default()
        };
        let plan_of = |counts: &[u32]| {
            SamplePlan::from_counts(scene.resolution, counts.to_vec(), vec![1; n]).unwrap()
        };
        let (single, _) =
            prism_render::render_plan(&scene, &settings, &plan_of(&total), &|_| {}).unwrap();
        let mut film = film_for(&scene, &settings);
        render_pass(&scene, &settings, &plan_of(&first), &mut film, 0, &|_| {}).unwrap();
        let continued = plan_of(&second).with_first_samples(first.clone()).unwrap();
        render_pass(&scene, &settings, &continued, &mut film, 0, &|_| {}).unwrap();
        let passes = film.finish();
        let d = max_relative_difference(&single, &passes);
        assert!(d < 1e-5, "packet {packet}: max rel. difference {d}");
        assert_eq!(
            single.aov("spp.Y").unwrap().values,
            passes.aov("spp.Y").unwrap().values
        );
        // The second pass in a film of its own, merged afterwards.
        let mut a = film_for(&scene, &settings);
        render_pass(&scene, &settings, &plan_of(&first), &mut a, 0, &|_| {}).unwrap();
        let mut b = film_for(&scene, &settings);
        render_pass(&scene, &settings, &continued, &mut b, 0, &|_| {}).unwrap();
        a.merge_film(&b).unwrap();
        let d = max_relative_difference(&single, &a.finish());
        assert!(d < 1e-5, "merged films, packet {packet}: {d}");
        // Without the first samples the second pass repeats the first's samples.
        let mut repeat = film_for(&scene, &settings);
        render_pass(&scene, &settings, &plan_of(&first), &mut repeat, 0, &|_| {}).unwrap();
        render_pass(
            &scene,
            &settings,
            &plan_of(&second),
            &mut repeat,
            0,
            &|_| {},
        )
        .unwrap();
        assert!(max_relative_difference(&single, &repeat.finish()) > 1e-3);
    }
}

/// Adaptive sampling spends the budget (up to the rounding of its last pass) and records
/// how many samples each pixel got; the pixels did not all get the same.
#[test]
fn adaptive_render_spends_the_budget_unevenly() {
    let scene = scene("importance");
    let n = (scene.resolution.x * scene.resolution.y) as f64;
    let settings = RenderSettings {
        seed: 3,
        ..RenderSettings::default()
    };
    let (image, stats) =
        prism_render::adaptive::render_adaptive(&scene, &settings, 32, &|_| {}).unwrap();
    let spp = &image.aov("plan.spp").unwrap().values;
    let total: f64 = spp.iter().map(|&s| f64::from(s)).sum();
    assert_eq!(total as u64, stats.samples);
    // Each pass rounds every pixel's share stochastically (variance ≤ ¼ per pixel and pass,
    // 9 passes): 4 standard errors of the mean.
    let tolerance = 4.0 * (9.0 * 0.25 / n).sqrt();
    assert!(
        (total / n - 32.0).abs() < tolerance,
        "mean spp {}",
        total / n
    );
    assert_eq!(spp, &image.aov("spp.Y").unwrap().values);
    let (lo, hi) = spp
        .iter()
        .fold((f32::MAX, 0.0f32), |(l, h), &s| (l.min(s), h.max(s)));
    assert!(lo >= 4.0 && hi > 2.0 * lo, "spp from {lo} to {hi}");
}
