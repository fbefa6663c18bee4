//! The Cornell box filled with fog (scenes/cornell-box-fog.json) against Mitsuba 3.6.4's
//! `volpathmis` (tests/fixtures/cornell_fog_mitsuba_reference.exr; version, scene and call
//! in its .json). Both are written by tools/mitsuba/cornell_fog.py from the same dict:
//! `mi.cornell_box()` at 128 × 128 px plus a homogeneous medium (σt and albedo spectra,
//! Henyey–Greenstein g 0.3) inside a cube scaled by 1.001 with Mitsuba's `null` BSDF, which
//! is Prism's `interface` material (docs/mitsuba.md, "The Cornell box in fog").
//!
//! Issue 20, test 8, on two Prism renders of 64 spp (Owen-scrambled Sobol: the directly
//! visible light holds half of the image's mean, and its wavelength noise at the independent
//! sampler moves a channel's mean by ±1 % at this budget): the mean of each RGB channel
//! within 1 % of Mitsuba's (the reference
//! divided by Mitsuba's film factor first, as for the fog-free box), and the relMSE against
//! Mitsuba no larger than Prism's own noise explains: two independent Prism renders A and B
//! differ by relMSE(A, B) ≈ 2 × the noise of one, so an unbiased A sits at relMSE(A, Mitsuba)
//! ≈ relMSE(A, B) / 2 + the reference's noise; a bias adds to it.

use prism_image::io::exr::read_exr;
use prism_image::Image;
use prism_render::{render, FilmImage, RenderScene, RenderSettings};
use prism_spectrum::rgb_space::RgbColorSpace;

const MITSUBA_FILM_FACTOR: f64 = 106.857 / 106.750_259_4;
const SPP: u32 = 64;

fn image(rgb: Vec<[f32; 3]>, size: usize) -> Image {
    Image::new(size, size, rgb, RgbColorSpace::srgb()).unwrap()
}

fn render_fog(scene: &RenderScene, seed: u64) -> FilmImage {
    let settings = RenderSettings {
        spp: SPP,
        seed,
        sampler: prism_render::SamplerKind::Sobol,
        ..RenderSettings::default()
    };
    let (film, stats) = render(scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    assert_eq!(stats.non_finite_contributions, 0);
    // The fog box is closed and unnested, yet 2–11 paths in 10⁶ meet it from the side
    // they are not in (seeds 1–8, 64 spp, 2026-12-02): rays entering near a cube edge
    // (docs/mitsuba.md, "The Cornell box in fog").
    // Tolerated here, bounded 10× above the worst seed so that a systematic one fails.
    assert!(
        stats.medium_mismatches * 10_000 < stats.samples,
        "{} medium mismatches in {} samples",
        stats.medium_mismatches,
        stats.samples
    );
    film
}

#[test]
fn foggy_cornell_box_matches_mitsuba_volpathmis() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let description = prism_scene::load_scene(root.join("scenes/cornell-box-fog.json")).unwrap();
    let scene = RenderScene::build(&description, None).unwrap();
    let a = render_fog(&scene, 1);
    let b = render_fog(&scene, 2);
    let reference =
        read_exr(&root.join("tests/fixtures/cornell_fog_mitsuba_reference.exr")).unwrap();
    let size = a.width as usize;
    assert_eq!(
        (reference.width(), reference.height()),
        (size, a.height as usize)
    );
    let reference: Vec<[f32; 3]> = reference
        .pixels()
        .iter()
        .map(|p| p.map(|c| (f64::from(c) / MITSUBA_FILM_FACTOR) as f32))
        .collect();
    let n = reference.len() as f64;
    for c in 0..3 {
        let mean = |img: &[[f32; 3]]| img.iter().map(|p| f64::from(p[c])).sum::<f64>() / n;
        let (ours, theirs) = ((mean(&a.rgb) + mean(&b.rgb)) / 2.0, mean(&reference));
        let rel = (ours - theirs) / theirs;
        eprintln!(
            "channel {c}: Prism {ours:.6}, Mitsuba {theirs:.6}, relative difference {rel:+.4}"
        );
        assert!(rel.abs() <= 0.01, "channel {c}: {rel:+.4} (limit ±1 %)");
    }
    let mitsuba = image(reference, size);
    let (ia, ib) = (image(a.rgb.clone(), size), image(b.rgb.clone(), size));
    // Symmetric in the two renders: heavy-tailed noise (a few bright paths) moves either
    // relMSE(·, Mitsuba) alone by ±10 %.
    let against_mitsuba = (prism_post::compare(&ia, &mitsuba).unwrap().relmse
        + prism_post::compare(&ib, &mitsuba).unwrap().relmse)
        / 2.0;
    let between_seeds = prism_post::compare(&ia, &ib).unwrap().relmse;
    let ratio = against_mitsuba / (between_seeds / 2.0);
    eprintln!(
        "relMSE at {SPP} spp: against Mitsuba {against_mitsuba:.4e} (mean of both renders), \
         between the two Prism renders {between_seeds:.4e}; ratio to Prism's own noise {ratio:.3}"
    );
    // The reference (4096 spp) adds ≈ SPP/4096 of the noise; the rest of the margin covers
    // the spread of a relMSE estimate of heavy-tailed noise (measured 1.11–1.27 over five
    // seed pairs; the fog-free box at 256 × 256, independent sampler, gives 1.01).
    assert!(
        ratio < 1.35,
        "relMSE against Mitsuba is {ratio:.3}× Prism's own noise"
    );
}
