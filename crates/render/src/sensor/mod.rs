//! Illuminance sensors: points, lists and grids of points (prism-scene `Sensor`), each
//! measured as E = ∫ L cos θ dω in lux with its standard error (`illuminance`), to a fixed
//! sample count or until a requested standard error; per sensor the uniformity ratios
//! E_min/E_avg and E_min/E_max (docs/lighting.md).
//!
//! Sampling: randomised quasi-Monte Carlo, the samples of a point split over independent
//! Owen-scrambled Sobol replicates whose spread gives the standard error (`replicates`).
//!
//! Determinism: sample k of replicate r of point i of sensor s draws from the stream
//! (seed, s, r, (i, s), k), never from a thread's state, so the readings are the same for
//! any thread count.

mod illuminance;
mod replicates;

pub use illuminance::sample_illuminance_lx;
pub use replicates::{
    replicate_count, replicate_sampler, replicates_for, ReplicateStats, SENSOR_REPLICATES,
};

use glam::{DVec3, UVec2, Vec3A};
use prism_scene::{Sensor, SensorSampling};
use rayon::prelude::*;

use crate::film::FixedSum;
use crate::integrator::{PathCounters, PathTracer};
use crate::sampler::PixelSampler;
use crate::scene_build::RenderScene;

/// Samples per work item: the unit of parallel work within one point.
const CHUNK_SAMPLES: u32 = 256;

/// Streaming mean and sum of squared deviations (Welford 1962; Chan, Golub & LeVeque 1979
/// for merging two sets).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunningStats {
    pub n: u64,
    pub mean: f64,
    pub m2: f64,
}

impl RunningStats {
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    pub fn merge(&mut self, o: &RunningStats) {
        if o.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *o;
            return;
        }
        let n = self.n + o.n;
        let d = o.mean - self.mean;
        self.mean += d * o.n as f64 / n as f64;
        self.m2 += o.m2 + d * d * (self.n as f64 * o.n as f64) / n as f64;
        self.n = n;
    }

    /// Standard error of the mean, s/√n (0 with fewer than 2 samples).
    pub fn std_error(&self) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        (self.m2.max(0.0) / (self.n - 1) as f64 / self.n as f64).sqrt()
    }
}

/// One measuring point's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointReading {
    /// Position, metres (world).
    pub position_m: [f64; 3],
    /// Unit normal of the receiving surface.
    pub normal: [f64; 3],
    /// Mean illuminance, lx.
    pub illuminance_lx: f64,
    /// Standard error of `illuminance_lx`, lx.
    pub std_error_lx: f64,
    /// Samples taken.
    pub samples: u64,
}

/// Uniformity of a set of illuminances (EN 12464-1 U₀ = E_min/E_avg; E_min/E_max).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniformity {
    pub min_lx: f64,
    pub max_lx: f64,
    pub average_lx: f64,
    /// E_min / E_avg (0 when E_avg = 0).
    pub min_over_average: f64,
    /// E_min / E_max (0 when E_max = 0).
    pub min_over_max: f64,
}

impl Uniformity {
    /// `None` for an empty set.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Self> {
        let (mut min, mut max, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
        for v in values {
            min = min.min(v);
            max = max.max(v);
            sum += v;
            n += 1;
        }
        if n == 0 {
            return None;
        }
        let average = sum / n as f64;
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        Some(Self {
            min_lx: min,
            max_lx: max,
            average_lx: average,
            min_over_average: ratio(min, average),
            min_over_max: ratio(min, max),
        })
    }
}

/// One sensor's readings.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorReading {
    pub name: String,
    /// `[nu, nv]` for grids (points are row-major, u fastest); `None` for point lists.
    pub grid_resolution: Option<[u32; 2]>,
    pub points: Vec<PointReading>,
}

impl SensorReading {
    pub fn uniformity(&self) -> Uniformity {
        Uniformity::of(self.points.iter().map(|p| p.illuminance_lx))
            .expect("a sensor has at least one point")
    }
}

/// Totals of a measurement.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensorStats {
    pub samples: u64,
    pub rays_traced: u64,
    pub non_finite_contributions: u64,
}

/// What measures the sensors: a path tracer and, for `radiosity`, the solution its paths
/// end on.
pub struct SensorTracer {
    pub path: PathTracer,
    pub gather: Option<std::sync::Arc<crate::integrator::radiosity::SolvedScene>>,
}

/// The sensors' tracer: for `radiosity`, direct light by light sampling at the sensor and
/// the light arriving along the cosine-sampled ray from the solution at its hit (max depth
/// 0, then the solution); for the other methods their own path tracer
/// (`Integrator::sensor_tracer`: depth, roulette and MIS), or the default one (max depth 8,
/// roulette from depth 3, power heuristic) for a diagnostic integrator. A radiosity scene
/// whose solution cannot be built (the memory limit, which `prism render` reports before
/// measuring) is measured by path tracing.
pub fn sensor_tracer(scene: &RenderScene) -> SensorTracer {
    match scene.radiosity_solution() {
        Some(Ok(solved)) => SensorTracer {
            path: PathTracer {
                max_depth: 0,
                rr_depth: u32::MAX,
                ..PathTracer::default()
            },
            gather: Some(solved),
        },
        Some(Err(_)) | None => SensorTracer {
            path: scene.integrator.sensor_tracer(),
            gather: None,
        },
    }
}

/// Light samples per vertex for sensors: one per light up to 8 (stratified, so a few
/// equally bright lamps each get a shadow ray, as Radiance's direct calculation does).
pub fn sensor_light_samples(scene: &RenderScene) -> u32 {
    scene.lights.len().clamp(1, 8) as u32
}

/// Dimensions of a sensor sample drawn from scrambled Sobol points: the sample's own
/// (wavelength 1, direction 2, 3 per light sample; `sample_illuminance_lx`) and the first
/// path vertex's eight (`PathTracer::radiance_from`); the rest are independent. On the
/// furnished-room benchmark (docs/lighting.md "Speed") the variance per sample is the same
/// as with the renderer's 29 Sobol dimensions — later dimensions carry little of it — and
/// each scrambled value costs about four hashes against one.
pub fn sensor_sobol_dimensions(light_samples: u32) -> u32 {
    3 + 3 * light_samples.max(1) + 8
}

/// Deterministic per-sensor seed.
fn sensor_seed(seed: u64, sensor: usize) -> u64 {
    // SplitMix64 finaliser (Steele et al. 2014).
    let mut z = seed ^ (sensor as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Samples of one point from `from` to `to` in total, spread over the replicates
/// (`replicates::replicate_count`), in parallel chunks merged in a fixed order.
#[allow(clippy::too_many_arguments)]
fn run_samples(
    tracer: &SensorTracer,
    scene: &RenderScene,
    samplers: &[PixelSampler],
    point: UVec2,
    p: Vec3A,
    n: Vec3A,
    from: u32,
    to: u32,
    stats: &mut ReplicateStats,
    counters: &mut PathCounters,
) {
    let replicates = samplers.len() as u32;
    let light_samples = sensor_light_samples(scene);
    let sobol_dimensions = sensor_sobol_dimensions(light_samples);
    let mut items = Vec::new();
    for r in 0..replicates {
        let start = replicate_count(from, replicates, r);
        let end = replicate_count(to, replicates, r);
        let mut c = start;
        while c < end {
            items.push((r, c, (c + CHUNK_SAMPLES).min(end)));
            c += CHUNK_SAMPLES;
        }
    }
    let chunks: Vec<(u32, FixedSum, u64, PathCounters)> = items
        .into_par_iter()
        .map(|(r, start, end)| {
            let mut sum = FixedSum::ZERO;
            let mut counters = PathCounters::default();
            for k in start..end {
                let mut stream = samplers[r as usize]
                    .stream(point, k)
                    .with_sobol_dimensions(sobol_dimensions);
                sum += FixedSum::from_f64(sample_illuminance_lx(
                    tracer,
                    scene,
                    p,
                    n,
                    light_samples,
                    &mut stream,
                    &mut counters,
                ));
            }
            (r, sum, u64::from(end - start), counters)
        })
        .collect();
    for (r, sum, count, c) in chunks {
        stats.add(r, sum, count);
        counters.rays += c.rays;
        counters.non_finite_contributions += c.non_finite_contributions;
    }
}

/// Measures one point under `sampling`: all its samples, or with `share` = (a, b, N) the
/// samples [⌊a·S/N⌋, ⌊b·S/N⌋) of its S fixed samples (a sample range of a render; an
/// adaptive point takes all its samples whatever `share` is: the caller refuses that).
#[allow(clippy::too_many_arguments)]
fn measure_point(
    tracer: &SensorTracer,
    scene: &RenderScene,
    seed: u64,
    index: UVec2,
    position_m: [f64; 3],
    normal: [f64; 3],
    sampling: SensorSampling,
    share: Option<SampleShare>,
) -> (PointReading, ReplicateStats, PathCounters) {
    let p = DVec3::from(position_m).as_vec3a();
    let n = DVec3::from(normal).normalize().as_vec3a();
    let mut counters = PathCounters::default();
    // Replicates: as many as the most samples this point may take allows.
    let most = match sampling {
        SensorSampling::Fixed { samples } => samples,
        SensorSampling::Adaptive { max_samples, .. } => max_samples,
    };
    let samplers: Vec<PixelSampler> = (0..replicates_for(most))
        .map(|r| replicate_sampler(seed, r))
        .collect();
    let replicates = samplers.len() as u32;
    let mut stats = ReplicateStats::new(replicates);
    let mut take = |stats: &mut ReplicateStats, from: u32, to: u32| {
        run_samples(
            tracer,
            scene,
            &samplers,
            index,
            p,
            n,
            from,
            to,
            stats,
            &mut counters,
        );
    };
    match sampling {
        SensorSampling::Fixed { samples } => match share {
            None => take(&mut stats, 0, samples),
            Some(share) => take(
                &mut stats,
                share.of(samples, true),
                share.of(samples, false),
            ),
        },
        SensorSampling::Adaptive {
            relative_error,
            absolute_error_lx,
            min_samples,
            max_samples,
        } => {
            let mut done = 0u32;
            // At least two samples per replicate before the first standard error.
            let mut next = min_samples.max(16 * replicates).min(max_samples);
            loop {
                take(&mut stats, done, next);
                done = next;
                let target = (relative_error * stats.mean().abs()).max(absolute_error_lx);
                let se = stats.std_error();
                // No sample has found light yet: a relative target cannot be judged (the
                // standard error of all zeros is 0, yet light that arrives by rare paths,
                // through a door ajar, is not there). Only an absolute target can stop it.
                let judged = stats.mean() != 0.0 || absolute_error_lx > 0.0;
                if (judged && se <= target) || done >= max_samples {
                    break;
                }
                // n · (se / target)² samples reach the target if the variance per sample
                // holds (scrambled nets do better, so this errs on the safe side); aim 10 %
                // beyond, never more than 4× the samples so far in one step.
                let wanted = if target > 0.0 {
                    (done as f64 * (se / target).powi(2) * 1.1).ceil()
                } else {
                    f64::INFINITY
                };
                let wanted = wanted
                    .min(4.0 * done as f64)
                    .max(done as f64 + f64::from(replicates));
                next = (wanted.min(f64::from(max_samples))) as u32;
            }
        }
    }
    (
        PointReading {
            position_m,
            normal: n.to_array().map(f64::from),
            illuminance_lx: stats.mean(),
            std_error_lx: stats.std_error(),
            samples: stats.samples(),
        },
        stats,
        counters,
    )
}

/// A sample range [start, end) of a render of `total` samples per pixel, applied to a
/// sensor point's own sample count S: [⌊start·S/total⌋, ⌊end·S/total⌋), so that the
/// ranges of any split of [0, total) take each of the S samples once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleShare {
    pub start: u32,
    pub end: u32,
    pub total: u32,
}

impl SampleShare {
    fn of(self, samples: u32, first: bool) -> u32 {
        let k = if first { self.start } else { self.end };
        (u64::from(k) * u64::from(samples) / u64::from(self.total.max(1))) as u32
    }
}

/// A point's replicate sums: the exact state of its measurement, which the sums of other
/// sample ranges of the same measurement can be added to.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSums {
    pub position_m: [f64; 3],
    pub normal: [f64; 3],
    pub replicates: ReplicateStats,
}

/// A sensor's point sums (see [`measure_sensor_share`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SensorSums {
    pub name: String,
    pub grid_resolution: Option<[u32; 2]>,
    pub points: Vec<PointSums>,
}

impl SensorSums {
    /// Adds the sums of another sample range of the same sensor; an error names what
    /// differs.
    pub fn add(&mut self, other: &SensorSums) -> Result<(), String> {
        if self.name != other.name || self.points.len() != other.points.len() {
            return Err(format!(
                "sensor {} ({} points) and sensor {} ({} points)",
                self.name,
                self.points.len(),
                other.name,
                other.points.len()
            ));
        }
        for (a, b) in self.points.iter_mut().zip(&other.points) {
            a.replicates.merge(&b.replicates).ok_or_else(|| {
                format!("sensor {}: the points have different replicates", self.name)
            })?;
        }
        Ok(())
    }

    /// The readings of the samples held: the mean of the replicate means and its standard
    /// error, as a whole measurement gives them.
    pub fn reading(&self) -> SensorReading {
        SensorReading {
            name: self.name.clone(),
            grid_resolution: self.grid_resolution,
            points: self
                .points
                .iter()
                .map(|p| PointReading {
                    position_m: p.position_m,
                    normal: p.normal,
                    illuminance_lx: p.replicates.mean(),
                    std_error_lx: p.replicates.std_error(),
                    samples: p.replicates.samples(),
                })
                .collect(),
        }
    }
}

/// Measures `share` of the samples of every sensor (all of them fixed-count: an adaptive
/// sensor decides its count from its samples so far, which no range can; an error names
/// it), returning the sums to add to other ranges' (`prism render --samples`, `prism
/// merge`).
pub fn measure_sensor_share(
    scene: &RenderScene,
    sensors: &[Sensor],
    seed: u64,
    share: SampleShare,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Vec<SensorSums>, SensorStats), String> {
    if let Some(s) = sensors
        .iter()
        .find(|s| matches!(s.sampling, SensorSampling::Adaptive { .. }))
    {
        return Err(format!(
            "sensor {} stops when its standard error is reached (relative_error / \
             absolute_error_lx), which a sample range cannot decide: give it a fixed \
             `samples` count",
            s.name
        ));
    }
    let (all, stats) = measure_all(scene, sensors, seed, Some(share), progress);
    Ok((
        all.into_iter()
            .map(|(reading, replicates)| SensorSums {
                name: reading.name,
                grid_resolution: reading.grid_resolution,
                points: reading
                    .points
                    .iter()
                    .zip(replicates)
                    .map(|(p, replicates)| PointSums {
                        position_m: p.position_m,
                        normal: p.normal,
                        replicates,
                    })
                    .collect(),
            })
            .collect(),
        stats,
    ))
}

/// Measures every sensor of `sensors` in `scene` (points in parallel on the current rayon
/// pool). `progress` is called with the number of points finished.
pub fn measure_sensors(
    scene: &RenderScene,
    sensors: &[Sensor],
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> (Vec<SensorReading>, SensorStats) {
    let (all, stats) = measure_all(scene, sensors, seed, None, progress);
    (all.into_iter().map(|(r, _)| r).collect(), stats)
}

/// Every sensor's readings and each point's replicates.
#[allow(clippy::type_complexity)]
fn measure_all(
    scene: &RenderScene,
    sensors: &[Sensor],
    seed: u64,
    share: Option<SampleShare>,
    progress: &(dyn Fn(u64) + Sync),
) -> (Vec<(SensorReading, Vec<ReplicateStats>)>, SensorStats) {
    let tracer = sensor_tracer(scene);
    let mut readings = Vec::with_capacity(sensors.len());
    let mut stats = SensorStats::default();
    for (s, sensor) in sensors.iter().enumerate() {
        let sensor_seed = sensor_seed(seed, s);
        let results: Vec<(PointReading, ReplicateStats, PathCounters)> = (0..sensor.kind.len())
            .into_par_iter()
            .map(|i| {
                let (position_m, normal) = sensor.kind.point(i);
                let r = measure_point(
                    &tracer,
                    scene,
                    sensor_seed,
                    UVec2::new(i as u32, s as u32),
                    position_m,
                    normal,
                    sensor.sampling,
                    share,
                );
                progress(1);
                r
            })
            .collect();
        let mut points = Vec::with_capacity(results.len());
        let mut replicates = Vec::with_capacity(results.len());
        for (p, r, c) in results {
            stats.samples += p.samples;
            stats.rays_traced += c.rays;
            stats.non_finite_contributions += c.non_finite_contributions;
            points.push(p);
            replicates.push(r);
        }
        readings.push((
            SensorReading {
                name: sensor.name.clone(),
                grid_resolution: match sensor.kind {
                    prism_scene::SensorKind::Grid { resolution, .. } => Some(resolution),
                    _ => None,
                },
                points,
            },
            replicates,
        ));
    }
    (readings, stats)
}

/// Total measuring points of `sensors` (for progress bars).
pub fn total_points(sensors: &[Sensor]) -> u64 {
    sensors.iter().map(|s| s.kind.len() as u64).sum()
}

#[cfg(test)]
mod tests;
