//! The bandwidth predictor run and timed as `prism render --plan predicted` and `prism
//! converge`'s predicted methods both run it: the BSDF angular tables (built, or read from
//! `--cache-dir`), then the prediction and, for `predicted-hier`, its hierarchical plan,
//! each phase in process CPU seconds and wall seconds.

use std::time::Instant;

use prism_bandwidth::Upsampling;
use prism_render::bsdf_table_cache::AngularTableCache;
use prism_render::predictor::{predict_with_probe, Prediction, PredictorSettings};
use prism_render::probe::RenderProbe;
use prism_render::RenderScene;
use serde_json::json;

use prism_cpu::clock::process_cpu_s;

/// A moment on the wall clock and on the process's CPU clock (all threads).
#[derive(Clone, Copy, Debug)]
struct Moment {
    wall: Instant,
    cpu_s: Option<f64>,
}

impl Moment {
    fn now() -> Self {
        Self {
            wall: Instant::now(),
            cpu_s: process_cpu_s(),
        }
    }
}

/// Process CPU time of the two phases, s (the "tables apart, cached").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictorCpu {
    pub tables_cpu_s: f64,
    pub predict_cpu_s: f64,
}

/// When each phase began and ended.
#[derive(Clone, Copy, Debug)]
pub struct PredictorTime {
    started: Moment,
    tables_done: Moment,
    finished: Moment,
}

impl PredictorTime {
    /// The CPU time of each phase; `None` where the platform has no process clock.
    pub fn cpu(&self) -> Option<PredictorCpu> {
        match (
            self.started.cpu_s,
            self.tables_done.cpu_s,
            self.finished.cpu_s,
        ) {
            (Some(a), Some(b), Some(c)) => Some(PredictorCpu {
                tables_cpu_s: b - a,
                predict_cpu_s: c - b,
            }),
            _ => None,
        }
    }

    /// `--stats-json`'s `predictor` object: both phases' CPU seconds (null without a
    /// process clock) and wall seconds.
    pub fn json(&self) -> serde_json::Value {
        let cpu = self.cpu();
        let wall = |a: Moment, b: Moment| (b.wall - a.wall).as_secs_f64();
        json!({
            "tables_cpu_s": cpu.map(|c| c.tables_cpu_s),
            "predict_cpu_s": cpu.map(|c| c.predict_cpu_s),
            "tables_wall_s": wall(self.started, self.tables_done),
            "predict_wall_s": wall(self.tables_done, self.finished),
        })
    }
}

/// Builds the probe's tables for `scene` (through `table_cache`), predicts with
/// `predictor` and, where it asks for hierarchical shading, makes the hierarchical plan
/// (at the allocation's mean spp and seed) inside the same clock: the prediction, the
/// up-sampling of `predicted-hier` and the time of both phases.
pub fn predict_timed(
    scene: &RenderScene,
    predictor: &PredictorSettings,
    seed: u64,
    table_cache: Option<&AngularTableCache>,
) -> Result<(Prediction, Option<Upsampling>, PredictorTime), String> {
    let started = Moment::now();
    let probe = RenderProbe::new(scene, seed).with_bandwidth_tables_cached(table_cache)?;
    let tables_done = Moment::now();
    let mut prediction = predict_with_probe(scene, predictor, probe)?;
    let upsampling = predictor
        .hierarchical_max_level
        .map(|max_level| {
            prediction.make_hierarchical(
                max_level,
                predictor.allocation.mean_spp,
                predictor.allocation.seed,
            )
        })
        .transpose()?;
    let time = PredictorTime {
        started,
        tables_done,
        finished: Moment::now(),
    };
    Ok((prediction, upsampling, time))
}
