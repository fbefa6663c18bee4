//! Variance-driven adaptive sampling, the baseline the bandwidth predictor is measured
//! against (`--plan adaptive`, `path+adaptive`; Cycles kernel/film/adaptive_sampling.h after
//! Dammertz et al. 2010). The samples of every pass are split per pixel between two films:
//! A gets the first half of each pixel's pass, B the rest, so A holds about half of all
//! samples and |I − A| (I = A + B) estimates the error of the full image
//! (prism-bandwidth's `adaptive_error`). After a uniform first pass of 4 spp, each pass
//! spends what a uniform pass would, spread ∝ that error.

use glam::UVec2;
use prism_bandwidth::{adaptive_error, adaptive_pass_counts, SamplePlan};

use crate::film::{AovPlane, Film, FilmImage};
use crate::integrator::{Estimator, Pass};
use crate::scene_build::RenderScene;
use crate::{film_for, render_pass_with, RenderError, RenderSettings, RenderStats};

/// Samples per pixel of the uniform first pass (Cycles' default minimum before adapting).
pub const ADAPTIVE_FIRST_PASS_SPP: u32 = 4;

/// Passes after the first, at most: each spends (budget − first pass) / this, so the error
/// map is refreshed often enough to follow the noise while a pass's overhead (one error
/// map, O(pixels)) stays negligible.
pub const ADAPTIVE_PASSES: u32 = 8;

/// A render whose passes give each pixel its own count of samples, each pixel continuing
/// its own sample sequence (`SamplePlan::with_first_samples`), so the passes add up to one
/// render of the summed counts. Split (adaptive sampling): the first ⌈c/2⌉ of a pixel's c
/// samples in a pass go to film A, the rest to film B, and |I − A| (I = A + B) estimates
/// the error. Used by `render_adaptive` and by `prism converge`'s per-pixel plans. One
/// estimator renders every pass, so state that passes build on (`photon_progressive`'s
/// per-pixel statistics) carries from one to the next.
pub struct PerPixelPasses {
    estimator: Box<dyn Estimator>,
    done: Vec<u32>,
    /// Film B (or the only film when not split).
    film: Film,
    /// Film A, when split.
    half: Option<Film>,
    /// `with_relative_density`; `None`: every sample weighs 1 on a splatting film.
    relative_density: Option<Vec<f32>>,
}

impl PerPixelPasses {
    pub fn new(scene: &RenderScene, settings: &RenderSettings, split: bool) -> Self {
        let n = scene.resolution.x as usize * scene.resolution.y as usize;
        Self {
            estimator: scene.integrator.estimator(),
            done: vec![0; n],
            film: film_for(scene, settings),
            half: split.then(|| film_for(scene, settings)),
            relative_density: None,
        }
    }

    /// The plan's relative sample density per pixel (`Allocated::relative_density`),
    /// which a splatting film weights samples by (`SamplePlan::with_relative_density`).
    pub fn with_relative_density(mut self, density: Vec<f32>) -> Self {
        self.relative_density = Some(density);
        self
    }

    /// Samples each pixel has so far (row-major).
    pub fn done(&self) -> &[u32] {
        &self.done
    }

    /// Renders `counts[p]` more samples of every pixel p.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        settings: &RenderSettings,
        counts: &[u32],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RenderStats, RenderError> {
        let n = self.done.len();
        let (to_half, to_film): (Vec<u32>, Vec<u32>) = match self.half {
            Some(_) => counts.iter().map(|c| (c.div_ceil(2), c / 2)).unzip(),
            None => (vec![0; n], counts.to_vec()),
        };
        let film_start: Vec<u32> = self.done.iter().zip(&to_half).map(|(d, a)| d + a).collect();
        let mut stats = RenderStats::default();
        for (count, start, into_half) in [
            (to_half, self.done.clone(), true),
            (to_film, film_start, false),
        ] {
            if count.iter().all(|&c| c == 0) {
                continue;
            }
            // Pixels that all start at one index are an ordinary pass from there for the
            // light-path estimators (the driver's `uniform_first_sample`).
            let mut plan = SamplePlan::from_counts(scene.resolution, count, vec![1; n])?
                .with_first_samples(start)?;
            if let Some(density) = &self.relative_density {
                plan = plan.with_relative_density(density)?;
            }
            let film = match (&mut self.half, into_half) {
                (Some(half), true) => half,
                _ => &mut self.film,
            };
            // As `render_pass` with first sample 0: the plan carries each pixel's start.
            let pass = Pass {
                index: 0,
                settings,
                plan: &plan,
                first_sample: 0,
                footprint_plan: None,
            };
            stats.add(&render_pass_with(
                self.estimator.as_mut(),
                scene,
                &pass,
                film,
                progress,
            )?);
        }
        for (d, c) in self.done.iter_mut().zip(counts) {
            *d += c;
        }
        Ok(stats)
    }

    /// The colour sums of every sample so far (both films when split).
    pub fn snapshot(&self) -> Film {
        let mut out = self.film.colour_snapshot();
        if let Some(half) = &self.half {
            out.merge_film(&half.colour_snapshot())
                .expect("two films of one render");
        }
        out
    }

    /// Per-pixel error of the image so far (`adaptive_error`; `None` unless split).
    pub fn adaptive_error(&self, resolution: UVec2) -> Option<Result<Vec<f32>, RenderError>> {
        let half = self.half.as_ref()?;
        Some(adaptive_error(resolution, &self.snapshot().rgb(), &half.rgb()).map_err(Into::into))
    }

    /// The finished film (both films merged when split).
    pub fn into_film(mut self) -> Film {
        if let Some(half) = &self.half {
            self.film.merge_film(half).expect("two films of one render");
        }
        self.film
    }
}

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
    let mut passes = PerPixelPasses::new(scene, settings, true);
    let mut stats = RenderStats::default();
    let first = ADAPTIVE_FIRST_PASS_SPP.min(mean_spp.max(1));
    let mut counts = vec![first; n];
    let pass_total = (budget - u64::from(first) * n as u64).div_ceil(u64::from(ADAPTIVE_PASSES));
    let mut spent = 0u64;
    let mut pass = 0u32;
    loop {
        stats.add(&passes.render(scene, settings, &counts, progress)?);
        spent += counts.iter().map(|&c| u64::from(c)).sum::<u64>();
        // The pass count bounds the loop when stochastic rounding leaves the last few
        // samples of the budget unspent.
        if spent >= budget || pass_total == 0 || pass >= 2 * ADAPTIVE_PASSES {
            break;
        }
        let errors = passes
            .adaptive_error(resolution)
            .expect("the passes are split")?;
        counts = adaptive_pass_counts(&errors, pass_total.min(budget - spent), settings.seed, pass);
        pass += 1;
    }
    let done: Vec<f32> = passes.done().iter().map(|&d| d as f32).collect();
    let mut image = passes.into_film().finish();
    image.aovs.push(AovPlane {
        name: "plan.spp".into(),
        values: done,
    });
    Ok((image, stats))
}
