//! Variance-driven adaptive sampling, the baseline the bandwidth predictor is measured
//! against (`--plan adaptive`, `path+adaptive`; Cycles kernel/film/adaptive_sampling.h after
//! Dammertz et al. 2010). The samples of every pass are split per pixel between two films:
//! A gets the first half of each pixel's pass, B the rest, so A holds about half of all
//! samples and |I − A| (I = A + B) estimates the error of the full image
//! (prism-bandwidth's `adaptive_error`). After a uniform first pass of 4 spp, each pass
//! spends what a uniform pass would, spread ∝ that error.

use prism_bandwidth::{adaptive_error, adaptive_pass_counts, SamplePlan};

use crate::film::{AovPlane, FilmImage};
use crate::scene_build::RenderScene;
use crate::{film_for, render_pass, RenderError, RenderSettings, RenderStats};

/// Samples per pixel of the uniform first pass (Cycles' default minimum before adapting).
pub const ADAPTIVE_FIRST_PASS_SPP: u32 = 4;

/// Passes after the first, at most: each spends (budget − first pass) / this, so the error
/// map is refreshed often enough to follow the noise while a pass's overhead (one error
/// map, O(pixels)) stays negligible.
pub const ADAPTIVE_PASSES: u32 = 8;

/// Renders `scene` with a mean of `mean_spp` camera samples per pixel placed adaptively;
/// returns the film (with a `plan.spp` layer: the samples each pixel got) and statistics.
pub fn render_adaptive(
    scene: &RenderScene,
    settings: &RenderSettings,
    mean_spp: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(FilmImage, RenderStats), RenderError> {
    let resolution = scene.resolution;
    let n = resolution.x as usize * resolution.y as usize;
    let budget = u64::from(mean_spp.max(1)) * n as u64;
    let mut film_a = film_for(scene, settings);
    let mut film_b = film_for(scene, settings);
    let mut done = vec![0u32; n];
    let mut stats = RenderStats::default();
    let first = ADAPTIVE_FIRST_PASS_SPP.min(mean_spp.max(1));
    let mut counts = vec![first; n];
    let pass_total = (budget - u64::from(first) * n as u64).div_ceil(u64::from(ADAPTIVE_PASSES));
    let mut spent = 0u64;
    let mut pass = 0u32;
    loop {
        // A: the first ⌈c/2⌉ samples of each pixel's pass, B: the rest.
        let half_a: Vec<u32> = counts.iter().map(|c| c.div_ceil(2)).collect();
        let half_b: Vec<u32> = counts.iter().zip(&half_a).map(|(c, a)| c - a).collect();
        let start_b: Vec<u32> = done.iter().zip(&half_a).map(|(d, a)| d + a).collect();
        for (film, count, start) in [
            (&mut film_a, half_a, done.clone()),
            (&mut film_b, half_b, start_b),
        ] {
            let plan = SamplePlan::from_counts(resolution, count, vec![1; n])?
                .with_first_samples(start)?;
            let s = render_pass(scene, settings, &plan, film, 0, progress)?;
            stats.add(&s);
        }
        for (d, c) in done.iter_mut().zip(&counts) {
            *d += c;
        }
        spent += counts.iter().map(|&c| u64::from(c)).sum::<u64>();
        // The pass count bounds the loop when stochastic rounding leaves the last few
        // samples of the budget unspent.
        if spent >= budget || pass_total == 0 || pass >= 2 * ADAPTIVE_PASSES {
            break;
        }
        let mut full = film_a.colour_snapshot();
        full.merge_film(&film_b.colour_snapshot())
            .expect("two films of one render");
        let errors = adaptive_error(resolution, &full.rgb(), &film_a.rgb())?;
        counts = adaptive_pass_counts(&errors, pass_total.min(budget - spent), settings.seed, pass);
        pass += 1;
    }
    film_a.merge_film(&film_b).expect("two films of one render");
    let mut image = film_a.finish();
    image.aovs.push(AovPlane {
        name: "plan.spp".into(),
        values: done.iter().map(|&d| d as f32).collect(),
    });
    Ok((image, stats))
}
