//! The samples of each progressive pass per method's sample plan (`prism converge`): uniform
//! passes add the same count everywhere; `predicted` runs the bandwidth predictor once and
//! each pass tops every pixel up to its share of the new mean (`Allocated::cumulative_counts`);
//! `predicted-hier` does the same with the hierarchical plan, whose interpolated pixels get
//! no samples and are filled at each checkpoint (`Upsampling`);
//! `adaptive` keeps two films (each pass's samples of a pixel split between them) and, after
//! 4 spp, spreads a uniform pass's total by the error between the full image and the half
//! (`prism_render::adaptive` is the same method for `prism render`).

use std::sync::Arc;

use glam::UVec2;
use prism_bandwidth::hierarchical_shading::DEFAULT_MAX_LEVEL;
use prism_bandwidth::{adaptive_pass_counts, Allocated, Upsampling};
use prism_render::adaptive::{PerPixelPasses, ADAPTIVE_FIRST_PASS_SPP};
use prism_render::bsdf_table_cache::AngularTableCache;
use prism_render::predictor::PredictorSettings;
use prism_render::{Film, RenderScene, RenderSettings, RenderStats};

use crate::predictor_time::{predict_timed, PredictorCpu};

use super::method::PlanKind;

/// The mean spp the predicted plan's densities are computed for (its anti-aliasing
/// minimums depend on the budget; the densities are then scaled to each checkpoint).
const PREDICTED_PLAN_SPP: f64 = 64.0;

/// What a plan needs besides the scene: the oracle's allocation (`path+oracle`) and where
/// the predictor keeps its BSDF tables (`--cache-dir`; `None`: built each run).
#[derive(Clone, Copy, Debug, Default)]
pub struct PlanInputs<'a> {
    pub oracle: Option<&'a Allocated>,
    pub table_cache: Option<&'a AngularTableCache>,
}

/// A method's films and the state its plan carries between passes.
pub struct PassPlanner {
    kind: PlanKind,
    passes: PerPixelPasses,
    allocated: Option<Allocated>,
    /// `predicted-hier`: how the pixels without samples are filled.
    pub upsampling: Option<Arc<Upsampling>>,
    /// `None` unless the plan is `predicted` and the platform has a process clock.
    pub predictor_cpu: Option<PredictorCpu>,
    seed: u64,
    pass_count: u32,
}

impl PassPlanner {
    /// The planner of `kind`; `predicted` runs the predictor here (on the current rayon
    /// pool), so its time counts as the method's.
    pub fn new(
        kind: PlanKind,
        scene: &RenderScene,
        settings: &RenderSettings,
        inputs: PlanInputs<'_>,
    ) -> Result<Self, String> {
        let mut predictor_cpu = None;
        let mut upsampling = None;
        let allocated = match kind {
            PlanKind::Predicted | PlanKind::PredictedHier => {
                let predictor = PredictorSettings {
                    hierarchical_max_level: (kind == PlanKind::PredictedHier)
                        .then_some(DEFAULT_MAX_LEVEL),
                    ..PredictorSettings::defaults(PREDICTED_PLAN_SPP, settings.seed)
                };
                let (prediction, hierarchy, time) =
                    predict_timed(scene, &predictor, settings.seed, inputs.table_cache)?;
                upsampling = hierarchy.map(Arc::new);
                predictor_cpu = time.cpu();
                Some(prediction.allocated)
            }
            PlanKind::Oracle => Some(
                inputs
                    .oracle
                    .ok_or("path+oracle needs --oracle-variance FILE.exr")?
                    .clone(),
            ),
            PlanKind::Uniform | PlanKind::Adaptive => None,
        };
        let mut passes = PerPixelPasses::new(scene, settings, kind == PlanKind::Adaptive);
        if let Some(allocated) = &allocated {
            passes = passes.with_relative_density(allocated.relative_density.clone());
        }
        Ok(Self {
            kind,
            passes,
            allocated,
            upsampling,
            predictor_cpu,
            seed: settings.seed,
            pass_count: 0,
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
        let n = self.passes.done().len();
        let pass = target - spp_done;
        let counts: Vec<u32> = match (self.kind, &self.allocated) {
            (PlanKind::Uniform, _) => vec![pass; n],
            (PlanKind::Predicted | PlanKind::PredictedHier | PlanKind::Oracle, Some(allocated)) => {
                allocated
                    .cumulative_counts(f64::from(target), self.seed)
                    .iter()
                    .zip(self.passes.done())
                    .map(|(c, d)| c.saturating_sub(*d))
                    .collect()
            }
            (PlanKind::Predicted | PlanKind::PredictedHier | PlanKind::Oracle, None) => {
                unreachable!("the predicted and oracle plans are made in `new`")
            }
            (PlanKind::Adaptive, _) if spp_done < ADAPTIVE_FIRST_PASS_SPP => vec![pass; n],
            (PlanKind::Adaptive, _) => {
                let errors = self
                    .passes
                    .adaptive_error(scene.resolution)
                    .expect("adaptive passes are split")
                    .map_err(|e| e.to_string())?;
                adaptive_pass_counts(
                    &errors,
                    u64::from(pass) * n as u64,
                    self.seed,
                    self.pass_count,
                )
            }
        };
        self.pass_count += 1;
        self.passes
            .render(scene, settings, &counts, &|_| {})
            .map_err(|e| e.to_string())
    }

    /// The colour sums of every sample so far.
    pub fn snapshot(&self) -> Film {
        self.passes.snapshot()
    }

    /// The finished film.
    pub fn into_film(self) -> Film {
        self.passes.into_film()
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
    // Y of the image's RGB: the film's XYZ Y, the variance's units.
    let rgb_to_xyz = image.color_space.rgb_to_xyz;
    let mean_y: Vec<f32> = image
        .pixels()
        .iter()
        .map(|&p| (rgb_to_xyz * glam::Vec3::from(p).as_dvec3()).y as f32)
        .collect();
    let levels = vec![0; mean_y.len()];
    prism_bandwidth::allocate(
        resolution,
        prism_bandwidth::AllocationInputs {
            variance: &layer.samples,
            mean_y: &mean_y,
            shading_level: &levels,
            uninformed: None,
        },
        PredictorSettings::defaults(PREDICTED_PLAN_SPP, seed).allocation,
    )
    .map_err(|e| e.to_string())
}
