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
    /// The largest penumbra bandwidth over the blocked samples, cycles/m (0: none blocked).
    pub penumbra_cycles_per_m: f32,
}

impl VisibilitySummary {
    /// The visible share of the traced samples (`None` if none was traced).
    pub fn visible_share(&self) -> Option<f32> {
        (self.traced > 0).then(|| self.visible as f32 / self.traced as f32)
    }

    /// Some traced samples see the light and some do not.
    pub fn disagrees(&self) -> bool {
        self.visible > 0 && self.visible < self.traced
    }
}

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
            penumbra_cycles_per_m: 5.0,
        };
        assert!(s.disagrees());
        assert_eq!(s.visible_share(), Some(0.375));
        assert_eq!(VisibilitySummary::default().visible_share(), None);
    }
}
