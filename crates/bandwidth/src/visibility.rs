//! Shadow edges (beyond Bagher et al. 2013, whose eq. 1 ignores visibility): the probe
//! traces its light samples' shadow rays; where a pixel's samples disagree, or its visible
//! share differs from a 4-neighbour's, the pixel is on a shadow boundary and the spatial
//! bandwidth there is that of the penumbra. After Mehta et al. 2012 ("Axis-aligned
//! filtering for interactive sampled soft shadows", the double wedge): a light of spatial
//! bandwidth ν_l (≈ 1/size) seen past a blocker at d2 from the light by a receiver at d1
//! casts a penumbra of width ∝ (d1 − d2)/d2, so ν_s = ν_l · d2/(d1 − d2); a delta light's
//! shadow edge is a step (∞); a distant light of angular bandwidth ν_a blurs over the
//! blocker distance d_b: ν_s = ν_a / d_b.

use crate::bandwidth::Bandwidth;

/// What a light sample's shadow ray met.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Visibility {
    /// Not traced (BSDF-sampled directions, probes without visibility).
    #[default]
    Unknown,
    /// Nothing between the hit and the light.
    Visible,
    /// A surface this far from the hit (m) blocks the light.
    Blocked { blocker_distance_m: f32 },
}

/// The penumbra bandwidth (cycles/m on the receiver) of one blocked light sample: the light
/// at `light_distance_m` (+∞: distant) with bandwidth `light`, `delta` for point-like and
/// ideal directional lights.
pub fn penumbra_bandwidth(
    light: Bandwidth,
    delta: bool,
    light_distance_m: f32,
    blocker_distance_m: f32,
) -> f32 {
    if delta {
        return f32::INFINITY;
    }
    if blocker_distance_m.is_nan() || blocker_distance_m <= 0.0 {
        return 0.0;
    }
    if light_distance_m.is_infinite() {
        return light.angular_cycles_per_rad / blocker_distance_m;
    }
    // d2 = d1 − d_b (light to blocker); ν_l d2 / (d1 − d2) = ν_l (d1 − d_b) / d_b.
    let d2 = (light_distance_m - blocker_distance_m).max(0.0);
    light.spatial_cycles_per_m * d2 / blocker_distance_m
}

/// A pixel's shadow-ray outcomes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VisibilitySummary {
    /// Light samples whose shadow ray was traced.
    pub traced: u32,
    /// Of those, the visible ones.
    pub visible: u32,
    /// Some samples of one area light (a position and an extent) see it and some do not:
    /// a compact emitter's samples disagree only where the pixel sees part of it, in its
    /// penumbra. (An environment's samples span the sky, so theirs disagree wherever part
    /// of the sky is hidden; a delta light's never do; samples of two lamps disagree in
    /// the shadow of one of them.)
    pub in_area_penumbra: bool,
    /// The blocked samples' penumbra bandwidths, each weighted by its share of the light
    /// the traced samples would bring unoccluded (eq. 5's weighting), cycles/m (0: none
    /// blocked).
    pub penumbra_cycles_per_m: f32,
}

impl VisibilitySummary {
    /// The visible share of the traced samples (`None` if none was traced).
    pub fn visible_share(&self) -> Option<f32> {
        (self.traced > 0).then(|| self.visible as f32 / self.traced as f32)
    }

    /// Whether a neighbour's visible share differs from this one's by more than the
    /// probes' sampling noise: by at least [`SHADOW_EDGE_SHARE_STEP`] and by more than
    /// [`SHADOW_EDGE_STANDARD_ERRORS`] standard errors of the difference of two binomial
    /// shares (pooled). `false` when either traced nothing.
    pub fn differs_from(&self, neighbour: &VisibilitySummary) -> bool {
        let (Some(a), Some(b)) = (self.visible_share(), neighbour.visible_share()) else {
            return false;
        };
        let (n_a, n_b) = (self.traced as f32, neighbour.traced as f32);
        let pooled = (self.visible + neighbour.visible) as f32 / (n_a + n_b);
        let standard_error = (pooled * (1.0 - pooled) * (1.0 / n_a + 1.0 / n_b)).sqrt();
        let step = (a - b).abs();
        step >= SHADOW_EDGE_SHARE_STEP && step > SHADOW_EDGE_STANDARD_ERRORS * standard_error
    }
}

/// Two visible shares this far apart put a shadow boundary between two pixels: the shadow
/// crosses in 4 pixels or fewer (a wider penumbra is smooth at the pixel scale).
pub const SHADOW_EDGE_SHARE_STEP: f32 = 0.25;

/// How many standard errors of sampling noise a share step must exceed. With 16 samples
/// in the sun's umbra under a visible sky (share ≈ 0.2) noise alone steps 0.25 between
/// ≈ 8 % of neighbour pairs and 2.5 standard errors (0.37 there) between ≈ 1 %; around a
/// pooled share of ½ (a hard edge, 0 against 1, or a penumbra crossed in two pixels,
/// ¼ against ¾) a step needs 0.44.
pub const SHADOW_EDGE_STANDARD_ERRORS: f32 = 2.5;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn penumbrae_narrow_as_the_blocker_nears_the_receiver() {
        let area = Bandwidth::area_light(4.0).unwrap(); // a 25 cm light
                                                        // Blocker halfway: d2 = d1 − d_b = d_b → ν_l.
        assert!((penumbra_bandwidth(area, false, 2.0, 1.0) - 4.0).abs() < 1e-6);
        // Blocker at 10 cm from the receiver of a light 2 m away: 19 ν_l.
        assert!((penumbra_bandwidth(area, false, 2.0, 0.1) - 76.0).abs() < 1e-4);
        assert!(penumbra_bandwidth(area, true, 2.0, 1.0).is_infinite());
        let sun = Bandwidth::distant_light(107.0).unwrap();
        assert!((penumbra_bandwidth(sun, false, f32::INFINITY, 0.5) - 214.0).abs() < 1e-3);
        let s = VisibilitySummary {
            traced: 8,
            visible: 3,
            in_area_penumbra: true,
            penumbra_cycles_per_m: 5.0,
        };
        assert_eq!(s.visible_share(), Some(0.375));
        assert_eq!(VisibilitySummary::default().visible_share(), None);
    }

    #[test]
    fn only_steps_beyond_sampling_noise_are_shadow_edges() {
        let share = |visible: u32| VisibilitySummary {
            traced: 16,
            visible,
            penumbra_cycles_per_m: 1.0,
            ..VisibilitySummary::default()
        };
        // A hard edge and a penumbra crossed in two pixels.
        assert!(share(0).differs_from(&share(16)));
        assert!(share(4).differs_from(&share(12)));
        // Noise around 0.2: 1/16 against 6/16 is 0.31 apart, under 2.5 standard errors (0.37).
        assert!(!share(1).differs_from(&share(6)));
        // Under the step: a penumbra wider than 4 pixels.
        assert!(!share(8).differs_from(&share(11)));
        assert!(!share(8).differs_from(&VisibilitySummary::default()));
    }
}
