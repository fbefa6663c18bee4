//! `--plan` and its options (`prism render`): how camera samples are spread over the pixels
//! (docs/bandwidth.md).

use clap::{Args, ValueEnum};
use prism_bandwidth::hierarchical_shading::DEFAULT_MAX_LEVEL;
use prism_bandwidth::{Allocation, AllocationSettings, PoolRadius, ProbeStride, VarianceBandwidth};
use prism_render::bsdf_table_cache::AngularTableCache;
use prism_render::predictor::PredictorSettings;
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
    /// `--plan predicted`: probe light samples per pixel (n_b; default 16).
    #[arg(long = "plan-nb", value_name = "N", value_parser = prism_args::numbers::parse_u32)]
    pub plan_nb: Option<u32>,
    /// `--plan predicted`: where the BSDF angular tables are kept across runs (created if
    /// missing; default $XDG_CACHE_HOME/prism, else ~/.cache/prism, and built each run when
    /// that is not writable).
    #[arg(long = "cache-dir", value_name = "DIR")]
    pub cache_dir: Option<std::path::PathBuf>,
    /// `--plan predicted`: share of the budget spread uniformly, in [0, 1] (default 0.25).
    #[arg(long = "plan-floor", value_name = "F")]
    pub plan_floor: Option<f64>,
    /// `--plan predicted`: what the samples follow (default relative).
    #[arg(long = "plan-allocation", value_enum)]
    pub plan_allocation: Option<AllocationArg>,
    /// `--plan predicted`: shadow edges from the probe's shadow rays (default on; `off`: the
    /// paper, which ignores visibility).
    #[arg(long = "plan-visibility", value_enum)]
    pub plan_visibility: Option<OnOff>,
    /// `--plan predicted`: how V̂_p is predicted (default measured).
    #[arg(long = "plan-variance", value_enum)]
    pub plan_variance: Option<VarianceArg>,
    /// `--plan predicted`: add the colour noise of hero-wavelength sampling (the X, Y and Z
    /// lanes' variance, measured by the probe) to V̂_p (default on; `off`: the luminance's
    /// variance alone).
    #[arg(long = "plan-colour", value_enum)]
    pub plan_colour: Option<OnOff>,
    /// `--plan predicted`: V̂_p is pooled over the (2R+1)² pixels of the same material around
    /// each pixel (default `auto`: R = min(W, H)/32, at least 1; 0: per pixel, as the paper).
    #[arg(long = "plan-pool-px", value_name = "R|auto", value_parser = parse_pool_radius)]
    pub plan_pool_px: Option<PoolRadius>,
    /// `--plan predicted`: one-bounce indirect estimates per pixel, which add the indirect
    /// light's mean and variance to the prediction (default 4; 0: direct light only, as the
    /// paper).
    #[arg(long = "plan-indirect", value_name = "N", value_parser = prism_args::numbers::parse_u32)]
    pub plan_indirect: Option<u32>,
    /// `--plan predicted`: the probe samples one pixel in S×S (and every pixel of a surface
    /// with no probed pixel within --plan-pool-px); the others take their probed
    /// neighbours' answers (default `auto`: half the pooling radius, 1 to 4, and 1 for
    /// predicted-hier; 1: every pixel, as the paper).
    #[arg(long = "plan-probe-stride", value_name = "S|auto", value_parser = parse_probe_stride)]
    pub plan_probe_stride: Option<ProbeStride>,
    /// `--plan predicted-hier`: the coarsest lattice, 2^L pixels between shaded pixels
    /// (1 to 8; default 3).
    #[arg(long = "plan-max-level", value_name = "L", value_parser = prism_args::numbers::parse_u32)]
    pub plan_max_level: Option<u32>,
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

/// The predictor's defaults, in one place (`PredictorSettings::defaults`; the mean and
/// seed are the render's, not options).
const DEFAULTS: PredictorSettings = PredictorSettings::defaults(1.0, 0);

impl From<bool> for OnOff {
    fn from(on: bool) -> Self {
        if on {
            OnOff::On
        } else {
            OnOff::Off
        }
    }
}

impl PlanArgs {
    // Each option's value, its default where it was not given: an option given without the
    // plan it sets up is refused (`check`), whatever its value.
    pub fn nb(&self) -> u32 {
        self.plan_nb.unwrap_or(DEFAULTS.probe_samples)
    }
    pub fn floor(&self) -> f64 {
        self.plan_floor.unwrap_or(DEFAULTS.allocation.floor)
    }
    pub fn allocation_arg(&self) -> AllocationArg {
        self.plan_allocation
            .unwrap_or(match DEFAULTS.allocation.allocation {
                Allocation::RelativeError => AllocationArg::Relative,
                Allocation::Variance => AllocationArg::Variance,
            })
    }
    pub fn visibility(&self) -> OnOff {
        self.plan_visibility
            .unwrap_or(OnOff::from(DEFAULTS.visibility))
    }
    pub fn variance(&self) -> VarianceArg {
        self.plan_variance
            .unwrap_or(match DEFAULTS.variance_bandwidth {
                VarianceBandwidth::Incident => VarianceArg::Eq9,
                VarianceBandwidth::OneBounce => VarianceArg::Eq9OneBounce,
                VarianceBandwidth::Measured => VarianceArg::Measured,
            })
    }
    pub fn colour(&self) -> OnOff {
        self.plan_colour
            .unwrap_or(OnOff::from(DEFAULTS.colour_noise))
    }
    pub fn pool_radius(&self) -> PoolRadius {
        self.plan_pool_px.unwrap_or(DEFAULTS.pool_radius)
    }
    pub fn indirect(&self) -> u32 {
        self.plan_indirect.unwrap_or(DEFAULTS.indirect_samples)
    }
    pub fn probe_stride(&self) -> ProbeStride {
        self.plan_probe_stride.unwrap_or(DEFAULTS.probe_stride)
    }
    pub fn max_level(&self) -> u32 {
        self.plan_max_level.unwrap_or(DEFAULT_MAX_LEVEL)
    }
    /// `predicted-hier`'s coarsest lattice level; `None` for the other plans.
    fn hierarchical_max_level(&self) -> Option<u32> {
        (self.plan == PlanArg::PredictedHier).then_some(self.max_level())
    }

    /// True for the plans the predictor makes.
    pub fn predicts(&self) -> bool {
        match self.plan {
            PlanArg::Predicted | PlanArg::PredictedHier => true,
            PlanArg::Uniform | PlanArg::Adaptive => false,
        }
    }

    fn allocation(&self) -> Allocation {
        match self.allocation_arg() {
            AllocationArg::Relative => Allocation::RelativeError,
            AllocationArg::Variance => Allocation::Variance,
        }
    }

    /// The checked options; errors name the flag.
    pub fn check(&self) -> Result<(), String> {
        let predictor_flags_given = self.plan_nb.is_some()
            || self.plan_floor.is_some()
            || self.plan_allocation.is_some()
            || self.plan_variance.is_some()
            || self.plan_visibility.is_some()
            || self.plan_colour.is_some()
            || self.plan_pool_px.is_some()
            || self.plan_indirect.is_some()
            || self.plan_probe_stride.is_some()
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
        if self.plan_max_level.is_some() && self.plan != PlanArg::PredictedHier {
            return Err("--plan-max-level sets up hierarchical shading: add --plan \
                        predicted-hier"
                .into());
        }
        if !(1..=8).contains(&self.max_level()) {
            return Err(format!(
                "--plan-max-level {}: expected a level from 1 (2 pixels between shaded \
                 pixels) to 8 (256)",
                self.max_level()
            ));
        }
        if self.nb() == 0 {
            return Err("--plan-nb must be at least 1".into());
        }
        if !(0.0..=1.0).contains(&self.floor()) {
            return Err(format!(
                "--plan-floor {}: expected a share of the budget in [0, 1]",
                self.floor()
            ));
        }
        Ok(())
    }

    /// What `--explain` reports.
    pub fn kind(&self) -> SamplePlanKind {
        match self.plan {
            PlanArg::Uniform => SamplePlanKind::Uniform,
            PlanArg::Predicted | PlanArg::PredictedHier => SamplePlanKind::Predicted {
                probe_samples: self.nb(),
                floor_per_mille: (self.floor() * 1000.0).round() as u32,
                allocation: self.allocation(),
                variance: self.variance_bandwidth(),
                colour_noise: self.colour() == OnOff::On,
                probe_stride: self.probe_stride(),
                pool_radius: self.pool_radius(),
                hierarchical_max_level: self.hierarchical_max_level(),
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
        match self.variance() {
            VarianceArg::Eq9 => VarianceBandwidth::Incident,
            VarianceArg::Eq9OneBounce => VarianceBandwidth::OneBounce,
            VarianceArg::Measured => VarianceBandwidth::Measured,
        }
    }

    /// The predictor's settings for a render of `mean_spp` with `seed`.
    pub fn predictor(&self, mean_spp: u32, seed: u64) -> PredictorSettings {
        PredictorSettings {
            probe_samples: self.nb(),
            allocation: AllocationSettings {
                mean_spp: f64::from(mean_spp),
                floor: self.floor(),
                allocation: self.allocation(),
                seed,
            },
            variance_bandwidth: self.variance_bandwidth(),
            visibility: self.visibility() == OnOff::On,
            colour_noise: self.colour() == OnOff::On,
            pool_radius: self.pool_radius(),
            indirect_samples: self.indirect(),
            probe_stride: self.probe_stride(),
            hierarchical_max_level: self.hierarchical_max_level(),
        }
    }
}

/// `--plan-pool-px`: `auto` or a radius in whole pixels (the project's whole-number rules).
fn parse_pool_radius(text: &str) -> Result<PoolRadius, String> {
    match text.trim() {
        "auto" => Ok(PoolRadius::Auto),
        _ => prism_args::numbers::parse_u32(text)
            .map(PoolRadius::Px)
            .map_err(|_| {
                format!("'{text}': expected `auto` or a radius in whole pixels (0, 1, 2, ...)")
            }),
    }
}

/// `--plan-probe-stride`: `auto` or a stride of at least one whole pixel.
fn parse_probe_stride(text: &str) -> Result<ProbeStride, String> {
    let expected = "expected `auto` or a stride in whole pixels, at least 1 (1 probes every pixel)";
    match text.trim() {
        "auto" => Ok(ProbeStride::Auto),
        _ => match prism_args::numbers::parse_u32(text) {
            Ok(0) | Err(_) => Err(format!("'{text}': {expected}")),
            Ok(s) => Ok(ProbeStride::Px(s)),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_probe_stride_is_auto_or_at_least_one_pixel() {
        assert_eq!(parse_probe_stride("auto"), Ok(ProbeStride::Auto));
        assert_eq!(parse_probe_stride("2"), Ok(ProbeStride::Px(2)));
        for bad in ["0", "-1", "two"] {
            let e = parse_probe_stride(bad).unwrap_err();
            assert!(e.contains("auto") && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn the_pool_radius_is_auto_or_whole_pixels() {
        assert_eq!(parse_pool_radius("auto"), Ok(PoolRadius::Auto));
        assert_eq!(parse_pool_radius("3"), Ok(PoolRadius::Px(3)));
        let e = parse_pool_radius("-1").unwrap_err();
        assert!(e.contains("auto") && e.contains("-1"), "{e}");
    }
}
