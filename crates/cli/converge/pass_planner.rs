//! The samples of each progressive pass per method's sample plan (`prism converge`): uniform
//! passes add the same count everywhere; `predicted` runs the bandwidth predictor once and
//! each pass tops every pixel up to its share of the new mean (`Allocated::cumulative_counts`);
//! `adaptive` keeps two films (each pass's samples of a pixel split between them) and, after
//! 4 spp, spreads a uniform pass's total by the error between the full image and the half
//! (`prism_render::adaptive` is the same method for `prism render`).

use glam::UVec2;
use prism_bandwidth::{adaptive_error, adaptive_pass_counts, Allocated, SamplePlan};
use prism_render::adaptive::ADAPTIVE_FIRST_PASS_SPP;
use prism_render::predictor::{predict, PredictorSettings, DEFAULT_PROBE_SAMPLES};
use prism_render::{film_for, render_pass, Film, RenderScene, RenderSettings, RenderStats};

use super::method::PlanKind;

/// The mean spp the predicted plan's densities are computed for (its anti-aliasing
/// minimums depend on the budget; the densities are then scaled to each checkpoint).
const PREDICTED_PLAN_SPP: f64 = 64.0;

/// A method's films and the state its plan carries between passes.
pub struct PassPlanner {
    kind: PlanKind,
    resolution: UVec2,
    /// Samples each pixel has so far.
    done: Vec<u32>,
    /// The film every method has; for `adaptive`, half of each pass's samples.
    pub film: Film,
    /// `adaptive`: the other half.
    half: Option<Film>,
    allocated: Option<Allocated>,
    seed: u64,
    passes: u32,
}

impl PassPlanner {
    /// The planner of `kind`; `predicted` runs the predictor here (on the current rayon
    /// pool), so its time counts as the method's.
    pub fn new(
        kind: PlanKind,
        scene: &RenderScene,
        settings: &RenderSettings,
        oracle: Option<&Allocated>,
    ) -> Result<Self, String> {
        let n = (scene.resolution.x * scene.resolution.y) as usize;
        let allocated = match kind {
            PlanKind::Predicted => {
                let predictor = PredictorSettings {
                    probe_samples: DEFAULT_PROBE_SAMPLES,
                    allocation: prism_bandwidth::AllocationSettings {
                        mean_spp: PREDICTED_PLAN_SPP,
                        floor: prism_bandwidth::allocation::DEFAULT_FLOOR,
                        allocation: prism_bandwidth::Allocation::RelativeError,
                        seed: settings.seed,
                    },
                    variance_bandwidth: prism_bandwidth::VarianceBandwidth::Incident,
                    visibility: true,
                };
                Some(predict(scene, &predictor, settings.seed)?.allocated)
            }
            PlanKind::Oracle => Some(
                oracle
                    .ok_or("path+oracle needs --oracle-variance FILE.exr")?
                    .clone(),
            ),
            PlanKind::Uniform | PlanKind::Adaptive => None,
        };
        Ok(Self {
            kind,
            resolution: scene.resolution,
            done: vec![0; n],
            film: film_for(scene, settings),
            half: match kind {
                PlanKind::Adaptive => Some(film_for(scene, settings)),
                PlanKind::Uniform | PlanKind::Predicted | PlanKind::Oracle => None,
            },
            allocated,
            seed: settings.seed,
            passes: 0,
        })
    }

    /// Renders the pass that brings the mean from `spp_done` to `target` spp.
    pub fn render_pass(
        &mut self,
        scene: &RenderScene,
        settings: &RenderSettings,
        spp_done: u32,
        target: u32,
    ) -> Result<RenderStats, String> {
        let n = self.done.len();
        let pass = target - spp_done;
        let counts: Vec<u32> = match (self.kind, &self.allocated) {
            (PlanKind::Uniform, _) => {
                let plan = SamplePlan::uniform(self.resolution, pass).map_err(|e| e.to_string())?;
                self.passes += 1;
                return render_pass(scene, settings, &plan, &mut self.film, spp_done, &|_| {})
                    .map_err(|e| e.to_string());
            }
            (PlanKind::Predicted | PlanKind::Oracle, Some(allocated)) => allocated
                .cumulative_counts(f64::from(target), self.seed)
                .iter()
                .zip(&self.done)
                .map(|(c, d)| c.saturating_sub(*d))
                .collect(),
            (PlanKind::Predicted | PlanKind::Oracle, None) => {
                unreachable!("the predicted and oracle plans are made in `new`")
            }
            (PlanKind::Adaptive, _) if spp_done < ADAPTIVE_FIRST_PASS_SPP => vec![pass; n],
            (PlanKind::Adaptive, _) => {
                let half = self.half.as_ref().expect("adaptive keeps two films");
                let errors = adaptive_error(self.resolution, &self.snapshot().rgb(), &half.rgb())
                    .map_err(|e| e.to_string())?;
                adaptive_pass_counts(&errors, u64::from(pass) * n as u64, self.seed, self.passes)
            }
        };
        self.passes += 1;
        let mut stats = RenderStats::default();
        // `adaptive`: the first ⌈c/2⌉ of a pixel's pass into `half`, the rest into `film`.
        let (first_part, second_part): (Vec<u32>, Vec<u32>) = match self.half {
            Some(_) => counts.iter().map(|c| (c.div_ceil(2), c / 2)).unzip(),
            None => (counts.clone(), vec![0; n]),
        };
        let second_start: Vec<u32> = self
            .done
            .iter()
            .zip(&first_part)
            .map(|(d, a)| d + a)
            .collect();
        let parts = [
            (first_part, self.done.clone(), true),
            (second_part, second_start, false),
        ];
        for (count, start, first) in parts {
            if count.iter().all(|&c| c == 0) {
                continue;
            }
            let plan = SamplePlan::from_counts(self.resolution, count, vec![1; n])
                .and_then(|p| p.with_first_samples(start))
                .map_err(|e| e.to_string())?;
            let film = match (&mut self.half, first) {
                (Some(half), true) => half,
                _ => &mut self.film,
            };
            let s =
                render_pass(scene, settings, &plan, film, 0, &|_| {}).map_err(|e| e.to_string())?;
            stats.add(&s);
        }
        for (d, c) in self.done.iter_mut().zip(&counts) {
            *d += c;
        }
        Ok(stats)
    }

    /// The colour sums of every sample so far (both films for `adaptive`).
    pub fn snapshot(&self) -> Film {
        let mut out = self.film.colour_snapshot();
        if let Some(half) = &self.half {
            out.merge_film(&half.colour_snapshot())
                .expect("two films of one render");
        }
        out
    }

    /// The finished film (both halves merged for `adaptive`).
    pub fn into_film(mut self) -> Film {
        if let Some(half) = &self.half {
            self.film.merge_film(half).expect("two films of one render");
        }
        self.film
    }
}

/// The oracle's allocation: the predicted plan's rule (relative error, the default floor)
/// fed with a measured per-sample variance and mean (`variance.Y` and Y of an EXR that
/// `prism render` wrote), so its gain over `uniform` is the most a predictor can reach.
pub fn oracle_allocation(
    path: &std::path::Path,
    resolution: UVec2,
    seed: u64,
) -> Result<Allocated, String> {
    let image = prism_image::io::exr::read_exr(path)
        .map_err(|e| format!("--oracle-variance {}: {e}", path.display()))?;
    if (image.width() as u32, image.height() as u32) != (resolution.x, resolution.y) {
        return Err(format!(
            "--oracle-variance {}: {}×{} pixels, the render is {}×{}",
            path.display(),
            image.width(),
            image.height(),
            resolution.x,
            resolution.y
        ));
    }
    let layer = image
        .layer("variance")
        .filter(|l| l.channels.len() == 1 && l.channels[0] == "Y")
        .ok_or_else(|| {
            format!(
                "--oracle-variance {}: no `variance.Y` layer (write one with `prism render \
                 SCENE -o FILE.exr`)",
                path.display()
            )
        })?;
    // Y of linear Rec.709 RGB: the film's XYZ Y, the variance's units.
    let mean_y: Vec<f32> = image
        .pixels()
        .iter()
        .map(|p| 0.212_639 * p[0] + 0.715_169 * p[1] + 0.072_192 * p[2])
        .collect();
    let levels = vec![0; mean_y.len()];
    prism_bandwidth::allocate(
        resolution,
        prism_bandwidth::AllocationInputs {
            variance: &layer.samples,
            mean_y: &mean_y,
            shading_level: &levels,
        },
        prism_bandwidth::AllocationSettings {
            mean_spp: PREDICTED_PLAN_SPP,
            floor: prism_bandwidth::allocation::DEFAULT_FLOOR,
            allocation: prism_bandwidth::Allocation::RelativeError,
            seed,
        },
    )
    .map_err(|e| e.to_string())
}
