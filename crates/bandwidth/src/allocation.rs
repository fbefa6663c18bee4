//! From the bandwidth buffer to camera samples per pixel: N_p = budget · a_p / mean(a),
//! a_p = f + (1 − f) · s_p / mean(s), with a floor f for the light the predictor does not
//! see (indirect light), at least 4^−level samples where eq. 11 asks for sub-pixel
//! anti-aliasing (level < 0) and at least one everywhere, as far as the budget allows.
//!
//! s_p is the pixel's predicted relative standard deviation √V̂_p / √(L̂_p² + 0.01): the
//! allocation that minimises the image's relMSE gives each pixel samples ∝ σ_p / L_p (a
//! pixel's relMSE term is σ_p² / (N_p L_p²); with Σ N_p fixed, Lagrange gives N_p ∝ σ_p/L_p).
//! The paper keeps the variance itself constant (N_p ∝ V̂_p, Bagher et al. 2013 after eq. 9),
//! which is [`Allocation::Variance`]. The 0.01 keeps black pixels finite.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::sample_plan::SamplePlan;
use crate::stochastic_rounding::round_stochastic;

/// What s_p measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Allocation {
    /// s_p = √V̂_p / √(L̂_p² + 0.01): equal relative error (`--plan-allocation relative`).
    RelativeError,
    /// s_p = V̂_p: the paper's constant variance (`--plan-allocation variance`).
    Variance,
}

/// The allocation's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllocationSettings {
    /// The mean camera samples per pixel (`--spp`).
    pub mean_spp: f64,
    /// f in [0, 1]: the share of the budget spread uniformly (`--plan-floor`, default 0.25).
    pub floor: f64,
    pub allocation: Allocation,
    /// Seeds the stochastic rounding of the counts.
    pub seed: u64,
}

/// The default floor: a quarter of the budget is spent uniformly, because indirect light,
/// which the probe does not see, still needs samples everywhere.
pub const DEFAULT_FLOOR: f64 = 0.25;

/// The per-pixel inputs, row-major, as long as the image.
#[derive(Clone, Copy, Debug)]
pub struct AllocationInputs<'a> {
    /// V̂_p (eq. 9).
    pub variance: &'a [f32],
    /// L̂_p.
    pub mean_y: &'a [f32],
    /// Eq. 11's level per pixel (negative: sub-pixel anti-aliasing).
    pub shading_level: &'a [i32],
    /// Pixels whose prediction carries no information (a surface where the probe found no
    /// light at all): they get the uniform share a_p = 1 instead of the floor, since
    /// their light is there but unseen (it came by paths the probe does not follow).
    /// `None`: every pixel is informed.
    pub uninformed: Option<&'a [bool]>,
}

/// The plan and the relative sample density a_p / mean(a) (expected N_p / budget) that
/// splatting reconstruction divides each sample's weight by.
#[derive(Clone, Debug, PartialEq)]
pub struct Allocated {
    pub plan: SamplePlan,
    pub relative_density: Vec<f32>,
}

/// s_p of one pixel.
fn shape(allocation: Allocation, variance: f32, mean_y: f32) -> f64 {
    let v = f64::from(variance.max(0.0));
    match allocation {
        Allocation::RelativeError => v.sqrt() / (f64::from(mean_y).powi(2) + 0.01).sqrt(),
        Allocation::Variance => v,
    }
}

/// Camera samples per pixel for the whole image.
pub fn allocate(
    resolution: UVec2,
    inputs: AllocationInputs<'_>,
    settings: AllocationSettings,
) -> Result<Allocated, BandwidthError> {
    let n = pixel_count("sample allocation", resolution)?;
    check_lengths(
        resolution,
        n,
        &[
            ("sample allocation variance", inputs.variance.len()),
            ("sample allocation mean", inputs.mean_y.len()),
            (
                "sample allocation shading level",
                inputs.shading_level.len(),
            ),
            (
                "sample allocation uninformed mask",
                inputs.uninformed.map_or(n, <[bool]>::len),
            ),
        ],
    )?;
    let informed = |i: usize| inputs.uninformed.is_none_or(|u| !u[i]);
    if !(settings.mean_spp > 0.0 && settings.mean_spp.is_finite()) {
        return Err(BandwidthError::invalid(
            "sample allocation",
            "mean_spp",
            settings.mean_spp,
            "finite, > 0",
        ));
    }
    if !(0.0..=1.0).contains(&settings.floor) {
        return Err(BandwidthError::invalid(
            "sample allocation",
            "floor",
            settings.floor,
            "in [0, 1]",
        ));
    }
    let s: Vec<f64> = (0..n)
        .map(|i| shape(settings.allocation, inputs.variance[i], inputs.mean_y[i]))
        .map(|s| if s.is_finite() { s } else { 0.0 })
        .collect();
    let informed_count = (0..n).filter(|&i| informed(i)).count();
    let mean_s =
        (0..n).filter(|&i| informed(i)).map(|i| s[i]).sum::<f64>() / informed_count.max(1) as f64;
    // a_p; with nothing predicted anywhere (mean(s) = 0) the plan is uniform.
    let a: Vec<f64> = (0..n)
        .map(|i| {
            if mean_s > 0.0 && informed(i) {
                settings.floor + (1.0 - settings.floor) * s[i] / mean_s
            } else {
                1.0
            }
        })
        .collect();
    // Every pixel gets a camera sample where the budget has one per pixel: a pixel with
    // none has no estimate at all (a hole in a box-filtered film), which no saving
    // elsewhere pays for; at 4 spp the anti-aliasing minimums alone left 72 % of the
    // Cornell box's pixels at 0 (64², before this floor).
    let one_each = settings.mean_spp.min(1.0);
    let budget = settings.mean_spp * n as f64;
    let anti_aliasing_excess: Vec<f64> = inputs
        .shading_level
        .iter()
        .map(|&level| {
            if level < 0 {
                (4f64.powi(-level) - one_each).max(0.0)
            } else {
                0.0
            }
        })
        .collect();
    let minimum = minimums(one_each, &anti_aliasing_excess, budget);
    let expected = fill_with_minimums(&a, &minimum, budget);
    let camera_samples: Vec<u32> = expected
        .iter()
        .enumerate()
        .map(|(i, &x)| round_stochastic(x, settings.seed, i as u64))
        .collect();
    let plan = SamplePlan::from_counts(
        resolution,
        camera_samples,
        vec![crate::sample_plan::DEFAULT_LIGHT_SAMPLES; n],
    )?;
    let relative_density: Vec<f32> = expected
        .iter()
        .map(|&x| (x / settings.mean_spp) as f32)
        .collect();
    let plan = plan.with_relative_density(&relative_density)?;
    Ok(Allocated {
        plan,
        relative_density,
    })
}

impl Allocated {
    /// Camera samples per pixel for a render of `mean_spp` on average with this plan's
    /// densities: ⌊x⌋ or ⌈x⌉ of x = density·mean_spp, rounded stochastically per
    /// (seed, pixel) with the same variate at every `mean_spp`, so the counts never
    /// decrease as `mean_spp` grows (progressive passes add the difference).
    pub fn cumulative_counts(&self, mean_spp: f64, seed: u64) -> Vec<u32> {
        counts_for_density(&self.relative_density, mean_spp, seed)
    }
}

/// Camera samples per pixel for relative densities `density` at `mean_spp`, rounded
/// stochastically per (seed, pixel) ([`Allocated::cumulative_counts`]).
pub(crate) fn counts_for_density(density: &[f32], mean_spp: f64, seed: u64) -> Vec<u32> {
    density
        .iter()
        .enumerate()
        .map(|(i, &d)| round_stochastic(f64::from(d) * mean_spp, seed, i as u64))
        .collect()
}

/// Per-pixel minimums: `each` for every pixel (at most the mean budget per pixel, so their
/// total fits) plus `extra` above it, scaled down to what the budget leaves beside them
/// where the extras do not fit: the budget is the user's (`--spp` is the mean), the extras
/// a preference.
fn minimums(each: f64, extra: &[f64], budget: f64) -> Vec<f64> {
    let total_extra: f64 = extra.iter().sum();
    let room = (budget - each * extra.len() as f64).max(0.0);
    let scale = if total_extra > room {
        room / total_extra
    } else {
        1.0
    };
    extra.iter().map(|e| each + e * scale).collect()
}

/// x_p = k·a_p with the total `budget`, except that no pixel gets less than its minimum
/// (whose total is within the budget: [`minimums`]): pixels held at their minimum leave the
/// rest a smaller budget, so k is solved again over the free pixels until no free pixel
/// falls below its minimum (at most n rounds; a few in practice).
fn fill_with_minimums(a: &[f64], minimum: &[f64], budget: f64) -> Vec<f64> {
    let mut held = vec![false; a.len()];
    loop {
        let held_total: f64 = (0..a.len()).filter(|&i| held[i]).map(|i| minimum[i]).sum();
        let free_a: f64 = (0..a.len()).filter(|&i| !held[i]).map(|i| a[i]).sum();
        let k = if free_a > 0.0 {
            ((budget - held_total) / free_a).max(0.0)
        } else {
            0.0
        };
        let mut changed = false;
        for i in 0..a.len() {
            if !held[i] && k * a[i] < minimum[i] {
                held[i] = true;
                changed = true;
            }
        }
        if !changed {
            return (0..a.len())
                .map(|i| if held[i] { minimum[i] } else { k * a[i] })
                .collect();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(allocation: Allocation) -> AllocationSettings {
        AllocationSettings {
            mean_spp: 16.0,
            floor: DEFAULT_FLOOR,
            allocation,
            seed: 5,
        }
    }

    #[test]
    fn samples_follow_the_predicted_relative_error_above_the_floor() {
        // Pixel 0: σ/L = 1; pixel 1: σ/L = 3; pixels 2, 3: nothing predicted.
        let variance = [1.0, 9.0, 0.0, 0.0];
        let mean = [((1.0f64 - 0.01).sqrt()) as f32; 4];
        let levels = [0; 4];
        let inputs = AllocationInputs {
            variance: &variance,
            mean_y: &mean,
            shading_level: &levels,
            uninformed: None,
        };
        let out = allocate(
            UVec2::new(2, 2),
            inputs,
            settings(Allocation::RelativeError),
        )
        .unwrap();
        // s = [1, 3, 0, 0], mean 1; a = 0.25 + 0.75 s = [1, 2.5, 0.25, 0.25], mean 1.
        let expected = [1.0, 2.5, 0.25, 0.25];
        for (d, e) in out.relative_density.iter().zip(expected) {
            assert!((d - e).abs() < 1e-5, "{:?}", out.relative_density);
        }
        assert_eq!(out.plan.camera_samples(UVec2::new(0, 0)), 16);
        assert_eq!(out.plan.camera_samples(UVec2::new(1, 0)), 40);
        assert_eq!(out.plan.camera_samples(UVec2::new(0, 1)), 4);
        assert_eq!(out.plan.total_camera_samples(), 64);
    }

    #[test]
    fn uninformed_pixels_get_the_uniform_share() {
        // Pixels 0, 1 as above; pixel 2 saw no light (uninformed), pixel 3 is predicted
        // dark. s over the informed pixels = [1, 3, 0], mean 4/3: a = 0.25 + 0.75 s/mean =
        // [0.8125, 1.9375, 0.25] and 1 for pixel 2 — mean 1, the budget kept.
        let variance = [1.0, 9.0, 0.0, 0.0];
        let mean = [((1.0f64 - 0.01).sqrt()) as f32; 4];
        let levels = [0; 4];
        let uninformed = [false, false, true, false];
        let inputs = AllocationInputs {
            variance: &variance,
            mean_y: &mean,
            shading_level: &levels,
            uninformed: Some(&uninformed),
        };
        let out = allocate(
            UVec2::new(2, 2),
            inputs,
            settings(Allocation::RelativeError),
        )
        .unwrap();
        let expected = [0.8125, 1.9375, 1.0, 0.25];
        for (d, e) in out.relative_density.iter().zip(expected) {
            assert!((d - e).abs() < 1e-5, "{:?}", out.relative_density);
        }
        let short = AllocationInputs {
            uninformed: Some(&uninformed[..3]),
            ..inputs
        };
        let e = allocate(UVec2::new(2, 2), short, settings(Allocation::RelativeError))
            .unwrap_err()
            .to_string();
        assert!(e.contains("uninformed"), "{e}");
    }

    #[test]
    fn the_papers_allocation_is_proportional_to_the_variance() {
        let variance = [1.0, 9.0];
        let inputs = AllocationInputs {
            variance: &variance,
            mean_y: &[0.0, 100.0],
            shading_level: &[0, 0],
            uninformed: None,
        };
        let mut s = settings(Allocation::Variance);
        s.floor = 0.0;
        let out = allocate(UVec2::new(2, 1), inputs, s).unwrap();
        assert!((out.relative_density[1] / out.relative_density[0] - 9.0).abs() < 1e-5);
    }

    #[test]
    fn every_pixel_gets_a_sample_before_anti_aliasing_takes_more() {
        // 2 spp over 8 pixels: two want 16 (level −2), 32 in all, the whole budget of 16;
        // the other six predicted nearly black. Each pixel gets one sample first, the two
        // anti-aliased ones share what is left.
        let mut variance = [1e-6f32; 8];
        variance[0] = 4.0;
        variance[1] = 4.0;
        let mut levels = [0; 8];
        levels[0] = -2;
        levels[1] = -2;
        let inputs = AllocationInputs {
            variance: &variance,
            mean_y: &[1.0; 8],
            shading_level: &levels,
            uninformed: None,
        };
        let mut s = settings(Allocation::RelativeError);
        s.mean_spp = 2.0;
        for seed in 0..20 {
            s.seed = seed;
            let out = allocate(UVec2::new(8, 1), inputs, s).unwrap();
            let counts: Vec<u32> = (0..8)
                .map(|x| out.plan.camera_samples(UVec2::new(x, 0)))
                .collect();
            assert!(counts.iter().all(|c| *c >= 1), "{counts:?}");
            assert_eq!(counts[0] + counts[1], 10, "{counts:?}");
            assert_eq!(out.plan.total_camera_samples(), 16);
        }
    }

    #[test]
    fn anti_aliased_levels_get_their_minimum_and_the_rest_keeps_the_budget() {
        // Level −2 wants 16 samples although nothing is predicted there.
        let inputs = AllocationInputs {
            variance: &[0.0, 4.0, 4.0, 4.0],
            mean_y: &[1.0; 4],
            shading_level: &[-2, 0, 0, 0],
            uninformed: None,
        };
        let mut s = settings(Allocation::RelativeError);
        s.mean_spp = 8.0;
        let out = allocate(UVec2::new(4, 1), inputs, s).unwrap();
        assert_eq!(out.plan.camera_samples(UVec2::new(0, 0)), 16);
        let rest: f32 = out.relative_density[1..].iter().sum::<f32>() * 8.0;
        assert!((rest - 16.0).abs() < 1e-4, "{rest}");
        // Minimums above the budget are scaled to fit it: 4 + 16 wanted, 10 spent, one each
        // first and the excess (3 + 15) scaled by 8/18: 1 + 3·4/9 = 7/3 and 23/3.
        let tight = AllocationInputs {
            variance: &[0.0; 2],
            mean_y: &[1.0; 2],
            shading_level: &[-1, -2],
            uninformed: None,
        };
        s.mean_spp = 5.0;
        let out = allocate(UVec2::new(2, 1), tight, s).unwrap();
        assert_eq!(out.plan.total_camera_samples(), 10);
        assert!((out.relative_density[0] * 5.0 - 7.0 / 3.0).abs() < 1e-5);
        assert!((out.relative_density[1] * 5.0 - 23.0 / 3.0).abs() < 1e-5);
    }

    #[test]
    fn cumulative_counts_never_decrease() {
        let inputs = AllocationInputs {
            variance: &[0.3, 4.0, 0.0, 1.0, 2.5, 0.1],
            mean_y: &[1.0; 6],
            shading_level: &[0; 6],
            uninformed: None,
        };
        let out = allocate(
            UVec2::new(3, 2),
            inputs,
            settings(Allocation::RelativeError),
        )
        .unwrap();
        let mut previous = vec![0u32; 6];
        for spp in 1..200 {
            let counts = out.cumulative_counts(f64::from(spp) * 0.37, 3);
            assert!(counts.iter().zip(&previous).all(|(c, p)| c >= p), "{spp}");
            previous = counts;
        }
        let total: u32 = previous.iter().sum();
        assert!(
            (f64::from(total) - 199.0 * 0.37 * 6.0).abs() < 6.0,
            "{total}"
        );
    }

    #[test]
    fn nothing_predicted_is_uniform_and_bad_settings_are_errors() {
        let inputs = AllocationInputs {
            variance: &[0.0; 6],
            mean_y: &[0.5; 6],
            shading_level: &[3; 6],
            uninformed: None,
        };
        let out = allocate(
            UVec2::new(3, 2),
            inputs,
            settings(Allocation::RelativeError),
        )
        .unwrap();
        assert_eq!(out.plan, SamplePlan::uniform(UVec2::new(3, 2), 16).unwrap());
        let mut bad = settings(Allocation::RelativeError);
        bad.floor = 1.5;
        let e = allocate(UVec2::new(3, 2), inputs, bad).unwrap_err();
        assert!(e.to_string().contains("floor"), "{e}");
        bad.floor = 0.25;
        bad.mean_spp = 0.0;
        assert!(allocate(UVec2::new(3, 2), inputs, bad).is_err());
        assert!(allocate(UVec2::new(2, 2), inputs, settings(Allocation::Variance)).is_err());
    }
}
