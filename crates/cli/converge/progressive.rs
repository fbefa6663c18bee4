//! Progressive rendering with error checkpoints (`prism converge`).
//!
//! A method renders in passes; pass k adds the samples [sₖ₋₁, sₖ) of every pixel's sequence
//! (`render_pass`), so the film after pass k is the film of one render of sₖ samples. After
//! each pass the render thread only copies the film's colour sums (a memcpy,
//! `Film::colour_snapshot`) and hands the copy to a metric thread, which normalises it and
//! computes the errors against the reference — prepared once (`PreparedReference`: clean
//! pixels, CIELAB, peaks), so a checkpoint costs one fused pass over the test pixels —
//! while the next pass renders (issue 6: "checkpoints must not stall the render"). The
//! metric thread runs its own one-thread rayon pool, so it never queues work on the render
//! threads.
//!
//! The checkpoint schedule spaces the sample counts geometrically (even steps on the
//! chart's log axis) from 1 spp to the final count: `max_spp` when only a sample budget is
//! given (deterministic), else the count the measured rate reaches within the time budget
//! (re-estimated after every pass).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use std::sync::Arc;

use prism_bandwidth::Upsampling;
use prism_image::Image;
use prism_post::metrics::{CompareOptions, Comparison, PreparedReference};
use prism_render::adaptive::ADAPTIVE_FIRST_PASS_SPP;
use prism_render::{Film, RenderScene, RenderSettings, RenderStats};
use prism_spectrum::rgb_space::RgbColorSpace;

use prism_cpu::clock::{process_cpu_s, thread_cpu_s};

use super::method::PlanKind;
use super::pass_planner::{PassPlanner, PlanInputs};

/// How long a method may render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Seconds per method (∞: no time limit), on the wall clock or, with `cpu_clock`, on
    /// the render threads' CPU clock.
    pub time_s: f64,
    /// Count `time_s` in render-thread CPU time (`--clock cpu`).
    pub cpu_clock: bool,
    /// Samples per pixel at most (`None`: no sample limit).
    pub max_spp: Option<u32>,
    /// Checkpoints at most (≥ 2).
    pub checkpoints: u32,
}

/// The sample count after checkpoint `k` (0-based), given `spp_done` samples in
/// `elapsed_s`; `None` when the render is done.
pub fn next_target(k: u32, spp_done: u32, elapsed_s: f64, budget: &Budget) -> Option<u32> {
    let max_spp = budget.max_spp.unwrap_or(u32::MAX / 2);
    if k >= budget.checkpoints || spp_done >= max_spp || elapsed_s >= budget.time_s {
        return None;
    }
    if k == 0 {
        return Some(1);
    }
    let reachable = if budget.time_s.is_finite() {
        f64::from(spp_done) / elapsed_s.max(1e-9) * budget.time_s
    } else {
        f64::INFINITY
    };
    let final_spp = reachable.min(f64::from(max_spp));
    if final_spp < f64::from(spp_done) + 1.0 {
        return None;
    }
    let remaining = f64::from(budget.checkpoints - k);
    let ratio = (final_spp / f64::from(spp_done)).powf(1.0 / remaining);
    let target = (f64::from(spp_done) * ratio).round() as u32;
    Some(target.max(spp_done + 1).min(max_spp))
}

/// One checkpoint of a method.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    /// Wall time since the method's first pass started, s.
    pub time_s: f64,
    /// CPU time of the render threads since the first pass started, s: the process's CPU
    /// time less the metric thread's (`None` without a process clock). On a shared machine
    /// this is the fairer clock: other processes stretch wall time, not CPU time.
    pub cpu_time_s: Option<f64>,
    /// Samples per pixel so far.
    pub spp: u32,
    /// Camera samples so far (all pixels).
    pub samples: u64,
    pub comparison: Comparison,
}

/// What one method's progressive render produced.
pub struct MethodRun {
    pub checkpoints: Vec<Checkpoint>,
    pub stats: RenderStats,
    /// Wall time of the render loop (passes + film copies), s.
    pub render_wall_s: f64,
    /// Process CPU time from the first pass until the metric thread finished, s (all threads:
    /// render, copies and metrics). `None` where the platform has no process clock.
    pub cpu_s: Option<f64>,
    /// The film after the last pass.
    pub film: Film,
    /// CPU time the metric thread spent computing errors, s (the main cost converge adds;
    /// it runs beside the render, so on a machine with idle cores it adds no wall time).
    pub metric_cpu_s: f64,
    /// Wall time the render thread spent copying the film at checkpoints, s.
    pub snapshot_wall_s: f64,
    /// `predicted-hier`: how the film's pixels without samples are filled.
    pub upsampling: Option<Arc<Upsampling>>,
    /// The predictor's CPU time (`predicted` plans; inside the method's clock).
    pub predictor_cpu: Option<crate::predictor_time::PredictorCpu>,
}

/// The film's image as prism-post sees it (linear Rec.709, like `prism render`'s EXR),
/// with a hierarchical plan's interpolated pixels filled.
pub fn film_to_image(film: &Film, upsampling: Option<&Upsampling>) -> Result<Image, String> {
    let resolution = film.resolution();
    let mut rgb = film.rgb();
    if let Some(u) = upsampling {
        u.apply(&mut rgb).map_err(|e| e.to_string())?;
    }
    Image::new(
        resolution.x as usize,
        resolution.y as usize,
        rgb,
        RgbColorSpace::srgb(),
    )
    .map_err(|e| e.to_string())
}

fn add_stats(a: &mut RenderStats, b: &RenderStats) {
    a.rays_traced += b.rays_traced;
    a.samples += b.samples;
    a.non_finite_samples += b.non_finite_samples;
    a.bounces += b.bounces;
    a.roulette_terminations += b.roulette_terminations;
    a.non_finite_contributions += b.non_finite_contributions;
}

/// Renders `scene` progressively on `pool` and measures the error of every checkpoint
/// against `reference` (prepared once for all checkpoints and methods) on a separate
/// thread.
pub fn run_method(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: PlanKind,
    reference: &PreparedReference,
    budget: &Budget,
    pool: &rayon::ThreadPool,
    inputs: PlanInputs<'_>,
) -> Result<MethodRun, String> {
    type Snapshot = (f64, Option<f64>, u32, u64, Film, Option<Arc<Upsampling>>);
    let (sender, receiver) = mpsc::channel::<Snapshot>();
    // CPU time the metric thread has spent, ns (subtracted from the process's CPU time).
    let metric_cpu_ns = AtomicU64::new(0);
    let metric_cpu_ns = &metric_cpu_ns;
    std::thread::scope(|scope| {
        let metrics = scope.spawn(move || -> Result<Vec<Checkpoint>, String> {
            let thread_start = thread_cpu_s();
            let metric_pool = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .map_err(|e| format!("cannot start the metric thread: {e}"))?;
            let mut out = Vec::new();
            for (time_s, cpu_time_s, spp, samples, film, upsampling) in receiver {
                let comparison = metric_pool.install(|| {
                    let image = film_to_image(&film, upsampling.as_deref())?;
                    reference
                        .compare(
                            &image,
                            // FLIP is not a convergence metric here: it would cost the
                            // render more time than every other metric together.
                            &CompareOptions {
                                ssim: false,
                                flip_ppd: None,
                                delta_e2000_map: false,
                            },
                        )
                        .map_err(|e| e.to_string())
                })?;
                // The pool's worker did the work; the metric thread itself only waited.
                let worker_cpu = metric_pool.install(thread_cpu_s);
                let own_cpu = match (thread_start, thread_cpu_s()) {
                    (Some(a), Some(b)) => b - a,
                    _ => 0.0,
                };
                let spent = worker_cpu.unwrap_or(0.0) + own_cpu;
                metric_cpu_ns.store((spent * 1e9) as u64, Ordering::Relaxed);
                out.push(Checkpoint {
                    time_s,
                    cpu_time_s,
                    spp,
                    samples,
                    comparison,
                });
            }
            Ok(out)
        });

        let cpu_start = process_cpu_s();
        let start = Instant::now();
        // A predicted plan's predictor runs here: its time is the method's.
        let mut planner = pool.install(|| PassPlanner::new(plan, scene, settings, inputs))?;
        let mut stats = RenderStats::default();
        let mut spp_done = 0u32;
        let mut k = 0u32;
        let mut render_wall_s = 0.0;
        let mut snapshot_wall_s = 0.0;
        let mut render_cpu_s: Option<f64> = Some(0.0);
        let elapsed = |render_cpu_s: Option<f64>| match (budget.cpu_clock, render_cpu_s) {
            (true, Some(cpu)) => cpu,
            _ => start.elapsed().as_secs_f64(),
        };
        while let Some(target) = next_target(k, spp_done, elapsed(render_cpu_s), budget) {
            let pass_stats =
                pool.install(|| planner.render_pass(scene, settings, spp_done, target))?;
            add_stats(&mut stats, &pass_stats);
            spp_done = target;
            k += 1;
            let copy_start = Instant::now();
            let snapshot = planner.snapshot();
            snapshot_wall_s += copy_start.elapsed().as_secs_f64();
            render_wall_s = start.elapsed().as_secs_f64();
            render_cpu_s = match (cpu_start, process_cpu_s()) {
                (Some(a), Some(b)) => {
                    Some(b - a - metric_cpu_ns.load(Ordering::Relaxed) as f64 * 1e-9)
                }
                _ => None,
            };
            // The receiver lives until every snapshot is consumed; a send error means the
            // metric thread failed, and joining it below reports why.
            if sender
                .send((
                    render_wall_s,
                    render_cpu_s,
                    spp_done,
                    stats.samples,
                    snapshot,
                    planner.upsampling.clone(),
                ))
                .is_err()
            {
                break;
            }
        }
        drop(sender);
        let checkpoints = metrics
            .join()
            .map_err(|_| "the metric thread panicked".to_string())??;
        let cpu_s = match (cpu_start, process_cpu_s()) {
            (Some(a), Some(b)) => Some(b - a),
            _ => None,
        };
        let predictor_cpu = planner.predictor_cpu;
        let upsampling = planner.upsampling.clone();
        Ok(MethodRun {
            upsampling,
            checkpoints,
            stats,
            render_wall_s,
            cpu_s,
            predictor_cpu,
            film: planner.into_film(),
            metric_cpu_s: metric_cpu_ns.load(Ordering::Relaxed) as f64 * 1e-9,
            snapshot_wall_s,
        })
    })
}

/// The same total work without checkpoints: one pass of `spp` samples, no film copies, no
/// metric thread. (wall s, CPU s) — the peer that `--overhead` compares against.
pub fn run_plain(
    scene: &RenderScene,
    settings: &RenderSettings,
    plan: PlanKind,
    spp: u32,
    pool: &rayon::ThreadPool,
    inputs: PlanInputs<'_>,
) -> Result<(f64, Option<f64>), String> {
    let cpu_start = process_cpu_s();
    let start = Instant::now();
    pool.install(|| -> Result<(), String> {
        let mut planner = PassPlanner::new(plan, scene, settings, inputs)?;
        // Adaptive sampling needs its error passes; the others render in one pass.
        match plan {
            PlanKind::Adaptive => {
                let mut done = 0;
                for target in [ADAPTIVE_FIRST_PASS_SPP.min(spp), spp] {
                    if target > done {
                        planner.render_pass(scene, settings, done, target)?;
                        done = target;
                    }
                }
            }
            PlanKind::Uniform
            | PlanKind::Predicted
            | PlanKind::PredictedHier
            | PlanKind::Oracle => {
                planner.render_pass(scene, settings, 0, spp)?;
            }
        }
        Ok(())
    })?;
    let wall = start.elapsed().as_secs_f64();
    let cpu = match (cpu_start, process_cpu_s()) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    Ok((wall, cpu))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schedule(budget: &Budget, rate_spp_per_s: f64) -> Vec<u32> {
        let (mut out, mut spp, mut k) = (Vec::new(), 0u32, 0u32);
        while let Some(t) = next_target(k, spp, f64::from(spp) / rate_spp_per_s, budget) {
            assert!(t > spp, "targets increase");
            out.push(t);
            spp = t;
            k += 1;
        }
        out
    }

    #[test]
    fn a_sample_budget_gives_a_geometric_deterministic_schedule() {
        let b = Budget {
            time_s: f64::INFINITY,
            cpu_clock: false,
            max_spp: Some(256),
            checkpoints: 9,
        };
        // 1 → 256 in 8 steps of ×2.
        assert_eq!(schedule(&b, 100.0), vec![1, 2, 4, 8, 16, 32, 64, 128, 256]);
        let few = Budget {
            checkpoints: 3,
            ..b
        };
        assert_eq!(schedule(&few, 1.0), vec![1, 16, 256]);
    }

    #[test]
    fn a_time_budget_ends_near_rate_times_budget() {
        let b = Budget {
            time_s: 10.0,
            cpu_clock: false,
            max_spp: None,
            checkpoints: 12,
        };
        let s = schedule(&b, 50.0);
        assert!(s.len() <= 12);
        let last = *s.last().unwrap();
        assert!((495..=500).contains(&last), "{s:?}");
        // Both limits: the sample limit wins when it comes first.
        let both = Budget {
            max_spp: Some(64),
            ..b
        };
        assert_eq!(*schedule(&both, 50.0).last().unwrap(), 64);
    }
}
