//! The sample plan: how many camera samples each pixel gets and how many light samples
//! each hit of that pixel takes — what the predictor hands to the integrator (Bagher et al.
//! 2013: N_p of §2.4 per pixel; docs/architecture.md: "Uniform plan = same spp everywhere; Predicted
//! plan = per-pixel spp").
//!
//! Light samples are stored **per pixel**: every camera sample of pixel p takes
//! `light_samples(p)` light samples at each hit (the integrator decides which hits: at
//! least the first; Bagher's N_p is for the first hit). Per pixel, because the predictor's
//! variance bound (eq. 9) is a per-pixel quantity; a global count is the special case
//! `with_uniform_light_samples`.
//!
//! A pixel may get 0 camera samples: a predicted plan leaves pixels whose value the
//! reconstruction step up-samples from their neighbours (Bagher §3.2); the film then
//! records `spp.Y` = 0 for them.
//!
//! A pass of a progressive render with a non-uniform plan continues each pixel's own
//! sequence: `first_samples` (default 0 everywhere) says where pixel p's samples of this
//! plan start, so passes [0, n₁(p)), [n₁(p), n₂(p)), … equal one render of n₂(p) samples.

use std::sync::Arc;

use glam::UVec2;

use crate::error::{pixel_count, pixel_index, BandwidthError};

/// Light samples per hit of a uniform plan.
pub const DEFAULT_LIGHT_SAMPLES: u32 = 1;

/// Per-pixel camera and light sample counts, row-major like the film.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplePlan {
    resolution: UVec2,
    camera_samples: Vec<u32>,
    light_samples: Vec<u32>,
    /// Per pixel, the index of its first sample; `None`: 0 everywhere.
    first_samples: Option<Vec<u32>>,
    /// Per pixel, 1 / its relative sample density (`with_relative_density`); `None`: 1.
    splat_weights: Option<Arc<[f32]>>,
}

impl SamplePlan {
    /// `spp` camera samples (0 allowed) and one light sample per hit everywhere: the
    /// default plan. Errors for a zero resolution.
    pub fn uniform(resolution: UVec2, spp: u32) -> Result<Self, BandwidthError> {
        let n = pixel_count("sample plan", resolution)?;
        Ok(Self {
            resolution,
            camera_samples: vec![spp; n],
            light_samples: vec![DEFAULT_LIGHT_SAMPLES; n],
            first_samples: None,
            splat_weights: None,
        })
    }

    /// A plan from per-pixel counts (row-major, one entry per pixel each).
    pub fn from_counts(
        resolution: UVec2,
        camera_samples: Vec<u32>,
        light_samples: Vec<u32>,
    ) -> Result<Self, BandwidthError> {
        let n = pixel_count("sample plan", resolution)?;
        for (what, list) in [
            ("sample plan camera samples", &camera_samples),
            ("sample plan light samples", &light_samples),
        ] {
            if list.len() != n {
                return Err(BandwidthError::LengthMismatch {
                    what,
                    resolution,
                    found: list.len(),
                });
            }
        }
        Ok(Self {
            resolution,
            camera_samples,
            light_samples,
            first_samples: None,
            splat_weights: None,
        })
    }

    /// The same plan with pixel p's samples starting at `first_samples[p]` (row-major).
    pub fn with_first_samples(mut self, first_samples: Vec<u32>) -> Result<Self, BandwidthError> {
        if first_samples.len() != self.camera_samples.len() {
            return Err(BandwidthError::LengthMismatch {
                what: "sample plan first samples",
                resolution: self.resolution,
                found: first_samples.len(),
            });
        }
        self.first_samples = Some(first_samples);
        Ok(self)
    }

    /// The index of pixel p's first sample in this plan (0 unless `with_first_samples`).
    #[inline]
    pub fn first_sample(&self, pixel: UVec2) -> u32 {
        match &self.first_samples {
            None => 0,
            Some(first) => {
                pixel_index("sample plan", pixel, self.resolution).map_or(0, |i| first[i])
            }
        }
    }

    /// The same plan with the relative sample density of each pixel (a_p / mean(a), the
    /// expected N_p over the mean: `Allocated::relative_density`): a splatting film spreads
    /// a sample over its neighbours, where the density differs, so it weights each sample
    /// by 1 / its own pixel's density (`splat_weights`). A pixel of density 0 (it takes no
    /// samples) keeps weight 1; all densities 1 leave the plan as it is.
    pub fn with_relative_density(mut self, density: &[f32]) -> Result<Self, BandwidthError> {
        if density.len() != self.camera_samples.len() {
            return Err(BandwidthError::LengthMismatch {
                what: "sample plan relative density",
                resolution: self.resolution,
                found: density.len(),
            });
        }
        if let Some(bad) = density.iter().find(|d| !(d.is_finite() && **d >= 0.0)) {
            return Err(BandwidthError::invalid(
                "sample plan",
                "relative density",
                bad,
                "finite, ≥ 0",
            ));
        }
        let weights: Arc<[f32]> = density
            .iter()
            .map(|&d| if d > 0.0 { 1.0 / d } else { 1.0 })
            .collect();
        // A uniform density is the plan without densities.
        self.splat_weights = weights.iter().any(|&w| w != 1.0).then_some(weights);
        Ok(self)
    }

    /// Every pixel's splat weight (row-major): 1 / its relative density, 1 where that is 0;
    /// `None` for a plan without densities (every weight 1).
    pub fn splat_weights(&self) -> Option<&Arc<[f32]>> {
        self.splat_weights.as_ref()
    }

    /// True when some pixel's samples start at its own index (`with_first_samples`).
    pub fn has_per_pixel_first_samples(&self) -> bool {
        self.first_samples.is_some()
    }

    /// The same plan with `light_samples` per hit in every pixel.
    pub fn with_uniform_light_samples(mut self, light_samples: u32) -> Self {
        self.light_samples.fill(light_samples);
        self
    }

    /// Sets the counts of one pixel (an error when it lies outside the plan).
    pub fn set(
        &mut self,
        pixel: UVec2,
        camera_samples: u32,
        light_samples: u32,
    ) -> Result<(), BandwidthError> {
        let i = pixel_index("sample plan", pixel, self.resolution)?;
        self.camera_samples[i] = camera_samples;
        self.light_samples[i] = light_samples;
        Ok(())
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// Camera samples of `pixel` (0 outside the plan).
    #[inline]
    pub fn camera_samples(&self, pixel: UVec2) -> u32 {
        pixel_index("sample plan", pixel, self.resolution).map_or(0, |i| self.camera_samples[i])
    }

    /// Light samples per hit of `pixel` (0 outside the plan).
    #[inline]
    pub fn light_samples(&self, pixel: UVec2) -> u32 {
        pixel_index("sample plan", pixel, self.resolution).map_or(0, |i| self.light_samples[i])
    }

    /// Σ camera samples over all pixels (for progress bars and statistics).
    pub fn total_camera_samples(&self) -> u64 {
        self.camera_samples.iter().map(|&n| u64::from(n)).sum()
    }

    /// The largest per-pixel camera sample count.
    pub fn max_camera_samples(&self) -> u32 {
        self.camera_samples.iter().copied().max().unwrap_or(0)
    }

    /// Ok when the plan was made for a film of `resolution`; else an error giving both.
    pub fn check_resolution(&self, resolution: UVec2) -> Result<(), BandwidthError> {
        if resolution == self.resolution {
            Ok(())
        } else {
            Err(BandwidthError::ResolutionMismatch {
                what: "sample plan",
                expected: resolution,
                found: self.resolution,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_plan_has_spp_and_one_light_sample_everywhere() {
        let plan = SamplePlan::uniform(UVec2::new(5, 3), 16).unwrap();
        assert_eq!(plan.camera_samples(UVec2::new(4, 2)), 16);
        assert_eq!(plan.light_samples(UVec2::new(0, 0)), DEFAULT_LIGHT_SAMPLES);
        assert_eq!(plan.total_camera_samples(), 5 * 3 * 16);
        assert_eq!(plan.max_camera_samples(), 16);
        assert_eq!(plan.camera_samples(UVec2::new(5, 0)), 0, "outside");
        let zero = SamplePlan::uniform(UVec2::new(2, 2), 0).unwrap();
        assert_eq!(zero.total_camera_samples(), 0);
    }

    #[test]
    fn per_pixel_counts_are_row_major_and_editable() {
        let mut plan =
            SamplePlan::from_counts(UVec2::new(2, 2), vec![0, 1, 2, 3], vec![4, 5, 6, 7]).unwrap();
        assert_eq!(plan.camera_samples(UVec2::new(1, 1)), 3);
        assert_eq!(plan.light_samples(UVec2::new(0, 1)), 6);
        plan.set(UVec2::new(0, 0), 9, 2).unwrap();
        assert_eq!(plan.total_camera_samples(), 15);
        assert!(plan.set(UVec2::new(0, 2), 1, 1).is_err());
        let plan = plan.with_uniform_light_samples(3);
        assert_eq!(plan.light_samples(UVec2::new(1, 0)), 3);
        assert_eq!(plan.first_sample(UVec2::new(1, 1)), 0);
        assert!(!plan.has_per_pixel_first_samples());
        let plan = plan.with_first_samples(vec![0, 5, 6, 7]).unwrap();
        assert_eq!(plan.first_sample(UVec2::new(1, 0)), 5);
        assert!(plan.clone().with_first_samples(vec![1]).is_err());
    }

    #[test]
    fn mismatches_are_errors_naming_both_sides() {
        let e = SamplePlan::from_counts(UVec2::new(2, 2), vec![1; 4], vec![1; 5]).unwrap_err();
        assert!(e.to_string().contains("light samples"), "{e}");
        assert!(SamplePlan::uniform(UVec2::new(3, 0), 1).is_err());
        let plan = SamplePlan::uniform(UVec2::new(4, 3), 1).unwrap();
        assert!(plan.check_resolution(UVec2::new(4, 3)).is_ok());
        let e = plan.check_resolution(UVec2::new(3, 4)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "sample plan: resolution 4×3 does not match the expected 3×4"
        );
    }
}
