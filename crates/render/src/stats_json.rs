//! The object `prism render --stats-json` writes, and the Python package's `Render.stats`:
//! one definition so that both report the same keys.

use crate::{RenderScene, RenderSettings, RenderStats};

/// `--stats-json`'s object for a render of `scene` with `settings` on `threads` threads that
/// took `wall_time_s` (without the sample ranges of partial renders, which the CLI adds).
pub fn stats_json(
    scene: &RenderScene,
    settings: &RenderSettings,
    threads: usize,
    wall_time_s: f64,
    stats: &RenderStats,
) -> serde_json::Value {
    serde_json::json!({
        "wall_time_s": wall_time_s,
        "rays_traced": stats.rays_traced,
        "rays_per_second": stats.rays_traced as f64 / wall_time_s.max(1e-9),
        "samples": stats.samples,
        "peak_memory_bytes": peak_memory_bytes(),
        "resolution": [scene.resolution.x, scene.resolution.y],
        "spp": settings.spp,
        "threads": threads,
        "integrator": scene.integrator.name(),
        "non_finite_samples": stats.non_finite_samples,
        "non_finite_contributions": stats.non_finite_contributions,
        "bounces": stats.bounces,
        "roulette_terminations": stats.roulette_terminations,
        "light_paths": stats.light_paths,
        "medium_mismatches": stats.medium_mismatches,
        // The fast paths' ISA (`--explain` says why).
        "simd": prism_cpu::active().isa().name(),
    })
}

/// This process's peak resident memory (`VmHWM`), bytes; `None` without /proc.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
