//! `--plan` and its options (`prism render`): how camera samples are spread over the pixels
//! (docs/bandwidth.md).

use clap::{Args, ValueEnum};
use prism_bandwidth::allocation::DEFAULT_FLOOR;
use prism_bandwidth::hierarchical_shading::DEFAULT_MAX_LEVEL;
use prism_bandwidth::{
    Allocation, AllocationSettings, PoolRadius, VarianceBandwidth, DEFAULT_POOL_RADIUS,
    DEFAULT_PROBE_STRIDE_PX,
};
use prism_render::bsdf_table_cache::AngularTableCache;
use prism_render::predictor::{PredictorSettings, DEFAULT_PROBE_SAMPLES};
use prism_render::SamplePlanKind;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PlanArg {
    /// The same spp in every pixel.
    Uniform,
    /// The bandwidth predictor's per-pixel plan (Bagher et al. 2013).
    Predicted,
    /// The predicted plan shaded hierarchically: pixels of eq. 11's level ≥ 1 are
    /// interpolated from a lattice of shaded pixels (Bagher et al. 2013 §3.2; biased).
    PredictedHier,
    /// Variance-driven passes after 4 spp (Cycles' adaptive sampling).
    Adaptive,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AllocationArg {
    /// Samples ∝ predicted relative error √V̂/L̂ (minimises relMSE).
    Relative,
    /// Samples ∝ predicted variance V̂ (the paper's rule).
    Variance,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VarianceArg {
    /// Eq. 9 with the angular bandwidth of the light arriving at the hit.
    Eq9,
    /// Eq. 9 with eq. 4's one-bounce angular bandwidth at the eye, as the paper writes it.
    Eq9OneBounce,
    /// The probe's sample variance of the render's estimate per camera sample (not the
    /// paper; the default, which test d of docs/bandwidth.md found to rank pixels better).
    Measured,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

#[derive(Clone, Debug, Args)]
pub struct PlanArgs {
    /// How camera samples are spread over the pixels; `--spp` is the mean.
    #[arg(long, value_enum, default_value = "uniform")]
    pub plan: PlanArg,
    /// `--plan predicted`: probe light samples per pixel (n_b).
    #[arg(long = "plan-nb", value_name = "N", default_value_t = DEFAULT_PROBE_SAMPLES, value_parser = prism_args::numbers::parse_u32)]
    pub plan_nb: u32,
    /// `--plan predicted`: where the BSDF angular tables are kept across runs (created if
    /// missing; default $XDG_CACHE_HOME/prism, else ~/.cache/prism, and built each run when
    /// that is not writable).
    #[arg(long = "cache-dir", value_name = "DIR")]
    pub cache_dir: Option<std::path::PathBuf>,
    /// `--plan predicted`: share of the budget spread uniformly, in [0, 1].
    #[arg(long = "plan-floor", value_name = "F", default_value_t = DEFAULT_FLOOR)]
    pub plan_floor: f64,
    /// `--plan predicted`: what the samples follow.
    #[arg(long = "plan-allocation", value_enum, default_value = "relative")]
    pub plan_allocation: AllocationArg,
    /// `--plan predicted`: shadow edges from the probe's shadow rays (`off`: the paper,
    /// which ignores visibility).
    #[arg(long = "plan-visibility", value_enum, default_value = "on")]
    pub plan_visibility: OnOff,
    /// `--plan predicted`: how V̂_p is predicted.
    #[arg(long = "plan-variance", value_enum, default_value = "measured")]
    pub plan_variance: VarianceArg,
    /// `--plan predicted`: add the colour noise of hero-wavelength sampling (the X, Y and Z
    /// lanes' variance, measured by the probe) to V̂_p (`off`: the luminance's variance alone).
    #[arg(long = "plan-colour", value_enum, default_value = "on")]
    pub plan_colour: OnOff,
    /// `--plan predicted`: V̂_p is pooled over the (2R+1)² pixels of the same material around
    /// each pixel (`auto`: R = min(W, H)/32, at least 1; 0: per pixel, as the paper).
    #[arg(long = "plan-pool-px", value_name = "R|auto", default_value_t = DEFAULT_POOL_RADIUS, value_parser = PoolRadius::parse)]
    pub plan_pool_px: PoolRadius,
    /// `--plan predicted`: one-bounce indirect estimates per pixel, which add the indirect
    /// light's mean and variance to the prediction (0: direct light only, as the paper).
    #[arg(long = "plan-indirect", value_name = "N", default_value_t = DEFAULT_PROBE_SAMPLES, value_parser = prism_args::numbers::parse_u32)]
    pub plan_indirect: u32,
    /// `--plan predicted`: the probe samples one pixel in S×S (and every pixel of a surface
    /// with no probed pixel within --plan-pool-px); the others take their probed
    /// neighbours' answers (1: every pixel, as the paper).
    #[arg(long = "plan-probe-stride", value_name = "S", default_value_t = DEFAULT_PROBE_STRIDE_PX, value_parser = prism_args::numbers::parse_u32)]
    pub plan_probe_stride: u32,
    /// `--plan predicted-hier`: the coarsest lattice, 2^L pixels between shaded pixels
    /// (1 to 8).
    #[arg(long = "plan-max-level", value_name = "L", default_value_t = DEFAULT_MAX_LEVEL, value_parser = prism_args::numbers::parse_u32)]
    pub plan_max_level: u32,
}

impl PlanArg {
    /// The name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PlanArg::Uniform => "uniform",
            PlanArg::Predicted => "predicted",
            PlanArg::PredictedHier => "predicted-hier",
            PlanArg::Adaptive => "adaptive",
        }
    }
}

impl PlanArgs {
    /// True for the plans the predictor makes.
    pub fn predicts(&self) -> bool {
        match self.plan {
            PlanArg::Predicted | PlanArg::PredictedHier => true,
            PlanArg::Uniform | PlanArg::Adaptive => false,
        }
    }

    fn allocation(&self) -> Allocation {
        match self.plan_allocation {
            AllocationArg::Relative => Allocation::RelativeError,
            AllocationArg::Variance => Allocation::Variance,
        }
    }

    /// The checked options; errors name the flag.
    pub fn check(&self) -> Result<(), String> {
        let predictor_flags_given = self.plan_nb != DEFAULT_PROBE_SAMPLES
            || self.plan_floor != DEFAULT_FLOOR
            || self.plan_allocation != AllocationArg::Relative
            || self.plan_variance != VarianceArg::Measured
            || self.plan_visibility != OnOff::On
            || self.plan_colour != OnOff::On
            || self.plan_pool_px != DEFAULT_POOL_RADIUS
            || self.plan_indirect != DEFAULT_PROBE_SAMPLES
            || self.plan_probe_stride != DEFAULT_PROBE_STRIDE_PX
            || self.cache_dir.is_some();
        if !self.predicts() && predictor_flags_given {
            return Err(
                "--plan-nb, --plan-floor, --plan-allocation, --plan-variance, \
                 --plan-colour, --plan-visibility, --plan-pool-px, --plan-indirect, \
                 --plan-probe-stride and --cache-dir set up the predictor: add --plan predicted \
                 or predicted-hier"
                    .into(),
            );
        }
        if self.plan_max_level != DEFAULT_MAX_LEVEL && self.plan != PlanArg::PredictedHier {
            return Err("--plan-max-level sets up hierarchical shading: add --plan \
                        predicted-hier"
                .into());
        }
        if !(1..=8).contains(&self.plan_max_level) {
            return Err(format!(
                "--plan-max-level {}: expected a level from 1 (2 pixels between shaded \
                 pixels) to 8 (256)",
                self.plan_max_level
            ));
        }
        if self.plan_nb == 0 {
            return Err("--plan-nb must be at least 1".into());
        }
        if self.plan_probe_stride == 0 {
            return Err("--plan-probe-stride 0: expected at least 1 (1 probes every pixel)".into());
        }
        if !(0.0..=1.0).contains(&self.plan_floor) {
            return Err(format!(
                "--plan-floor {}: expected a share of the budget in [0, 1]",
                self.plan_floor
            ));
        }
        Ok(())
    }

    /// What `--explain` reports.
    pub fn kind(&self) -> SamplePlanKind {
        match self.plan {
            PlanArg::Uniform => SamplePlanKind::Uniform,
            PlanArg::Predicted | PlanArg::PredictedHier => SamplePlanKind::Predicted {
                probe_samples: self.plan_nb,
                floor_per_mille: (self.plan_floor * 1000.0).round() as u32,
                allocation: self.allocation(),
                variance: self.variance_bandwidth(),
                colour_noise: self.plan_colour == OnOff::On,
                probe_stride_px: self.plan_probe_stride,
                pool_radius: self.plan_pool_px,
                hierarchical_max_level: (self.plan == PlanArg::PredictedHier)
                    .then_some(self.plan_max_level),
            },
            PlanArg::Adaptive => SamplePlanKind::Adaptive,
        }
    }

    /// The predictor's BSDF table cache (`--cache-dir`), for the predicted plans only.
    pub fn table_cache(&self) -> Result<Option<AngularTableCache>, String> {
        match self.plan {
            PlanArg::Predicted | PlanArg::PredictedHier => Ok(
                crate::cache_dir::optional_cache_dir(self.cache_dir.as_deref(), None)?
                    .map(AngularTableCache::new),
            ),
            PlanArg::Uniform | PlanArg::Adaptive => Ok(None),
        }
    }

    /// How V̂_p is predicted (`--plan-variance`).
    fn variance_bandwidth(&self) -> VarianceBandwidth {
        match self.plan_variance {
            VarianceArg::Eq9 => VarianceBandwidth::Incident,
            VarianceArg::Eq9OneBounce => VarianceBandwidth::OneBounce,
            VarianceArg::Measured => VarianceBandwidth::Measured,
        }
    }

    /// The predictor's settings for a render of `mean_spp` with `seed`.
    pub fn predictor(&self, mean_spp: u32, seed: u64) -> PredictorSettings {
        PredictorSettings {
            probe_samples: self.plan_nb,
            allocation: AllocationSettings {
                mean_spp: f64::from(mean_spp),
                floor: self.plan_floor,
                allocation: self.allocation(),
                seed,
            },
            variance_bandwidth: self.variance_bandwidth(),
            visibility: self.plan_visibility == OnOff::On,
            colour_noise: self.plan_colour == OnOff::On,
            pool_radius: self.plan_pool_px,
            indirect_samples: self.plan_indirect,
            probe_stride_px: self.plan_probe_stride,
        }
    }
}
