//! The estimator contract: what the driver calls, for every rendering method alike.
//!
//! A render is one or more passes over the film (`prism converge` runs many; `prism
//! render` one). Before each pass the driver calls `prepare`, whose state persists across
//! passes: a pre-pass such as photon shooting or the bandwidth predictor's G-buffer goes
//! there, computed once. Then it calls `render_tile` for every work item: the camera
//! samples of one film tile (or, for estimators that trace light paths, a range of their
//! sample indices), in parallel. Camera-side contributions go into the tile; light-side
//! ones (a light-path vertex connected to the camera) into the item's `LightSplats`, which
//! the driver merges in work-item order — one deterministic path for every method.

use std::ops::Range;

use glam::UVec2;
use prism_bandwidth::SamplePlan;

use super::driver::{RenderSettings, RenderStats};
use crate::film::{FilmTile, LightSplats};
use crate::sampler::PixelSampler;
use crate::scene_build::RenderScene;

/// One pass of a render.
#[derive(Clone, Copy, Debug)]
pub struct Pass<'a> {
    /// 0 for a render's first pass.
    pub index: u32,
    pub settings: &'a RenderSettings,
    /// Camera samples per pixel (and light samples per hit).
    pub plan: &'a SamplePlan,
    /// Sample index of each pixel's first sample in this pass (plus the plan's own
    /// per-pixel start, `SamplePlan::first_sample`).
    pub first_sample: u32,
    /// When this pass is one sample range of a longer render (`prism render --samples`,
    /// a resumed range): that render's plan. A sample's ray footprint (texture filtering)
    /// follows the samples its pixel gets in the whole render, so that the range's samples
    /// are the whole render's. `None`: the pass's own plan (a progressive pass scales by
    /// its own count).
    pub footprint_plan: Option<&'a SamplePlan>,
}

impl Pass<'_> {
    /// The sample count a pixel's ray footprints are scaled for (see `footprint_plan`).
    #[inline]
    pub fn footprint_samples(&self, pixel: UVec2) -> u32 {
        self.footprint_plan
            .unwrap_or(self.plan)
            .camera_samples(pixel)
    }

    /// The factor a camera ray's differentials are scaled by in `pixel`: several samples
    /// share the pixel, each one's differential covers a fraction of it (pbrt-v4
    /// `GetCameraSample`/`ScaleDifferentials`: max(1/8, 1/√spp) of `footprint_samples`).
    #[inline]
    pub fn differential_scale(&self, pixel: UVec2) -> f32 {
        (1.0 / (self.footprint_samples(pixel).max(1) as f32).sqrt()).max(0.125)
    }
}

/// One work item: the camera samples of a tile that the item renders.
#[derive(Clone, Debug)]
pub struct TileWork<'a> {
    pub pass: &'a Pass<'a>,
    pub sampler: &'a PixelSampler,
    /// The sample indices of this item: a pixel renders those of its own range
    /// [first_sample, first_sample + plan.camera_samples(pixel)) that fall in here.
    pub sample_indices: Range<u32>,
    /// The camera reads its lens variate (thin lens).
    pub uses_lens: bool,
}

impl TileWork<'_> {
    /// The sample indices pixel `pixel` renders in this item.
    #[inline]
    pub fn samples_of(&self, pixel: UVec2) -> Range<u32> {
        let first = self.pass.first_sample + self.pass.plan.first_sample(pixel);
        let own_end = first.saturating_add(self.pass.plan.camera_samples(pixel));
        let start = first.max(self.sample_indices.start);
        let end = own_end.min(self.sample_indices.end);
        start..end.max(start)
    }

    /// Light samples per hit of `pixel` (the plan's).
    #[inline]
    pub fn light_samples(&self, pixel: UVec2) -> u32 {
        self.pass.plan.light_samples(pixel)
    }
}

/// A rendering method. `Send`: a render that spans several calls of the driver (`prism
/// converge`'s passes) keeps one estimator, and with it the state its passes build up.
pub trait Estimator: Send + Sync {
    /// The name used in scene files, `--method` and statistics.
    fn name(&self) -> &'static str;

    /// Called before every pass; an error ends the render with that message (e.g. a camera
    /// a light-path method cannot connect to).
    fn prepare(&mut self, scene: &RenderScene, pass: &Pass) -> Result<(), String>;

    /// True when `render_tile` traces light paths and splats: the driver then cuts tiles
    /// into sample ranges so that each item's splat list stays small.
    fn splats_light_paths(&self) -> bool;

    /// `Some(n)`: `prepare` must run before every n sample indices, which must be the same
    /// in every pixel — the driver then cuts each pass into passes of at most n indices
    /// (a photon integrator shoots one photon pass per sample index). `None`: one
    /// `prepare` per pass, however many samples it holds.
    fn sample_indices_per_prepare(&self) -> Option<u32>;

    /// Renders the work item into `tile` (camera side) and `splats` (light side); returns
    /// what it did.
    fn render_tile(
        &self,
        scene: &RenderScene,
        work: &TileWork,
        tile: &mut FilmTile,
        splats: &mut LightSplats,
    ) -> RenderStats;
}
