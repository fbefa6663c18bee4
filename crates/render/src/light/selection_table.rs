//! A discrete distribution over a scene's lights: probabilities and their running sums, for
//! a light choice that does not depend on the shading point.

/// Selection probabilities (sum 1, or all 0 for no light) and their running sums.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectionTable {
    pmf: Vec<f32>,
    cdf: Vec<f32>,
}

impl SelectionTable {
    /// Probabilities in proportion to `weights` (negative and non-finite weights count as
    /// 0); uniform where every weight is 0.
    pub fn proportional(weights: &[f64]) -> Self {
        let clean = |w: f64| if w.is_finite() { w.max(0.0) } else { 0.0 };
        let total: f64 = weights.iter().map(|&w| clean(w)).sum();
        let pmf = if total > 0.0 {
            weights.iter().map(|&w| (clean(w) / total) as f32).collect()
        } else {
            vec![1.0 / weights.len().max(1) as f32; weights.len()]
        };
        Self::from_pmf(pmf)
    }

    fn from_pmf(pmf: Vec<f32>) -> Self {
        let mut run = 0.0f32;
        let cdf = pmf
            .iter()
            .map(|p| {
                run += p;
                run
            })
            .collect();
        Self { pmf, cdf }
    }

    /// Lights at infinity (`at_infinity[i]`) chosen apart, each with probability
    /// 1 / (their count + 1), the others sharing the remaining 1 / (count + 1) in proportion
    /// to `power_w` (pbrt-v4 `BVHLightSampler`'s rule for lights without bounds). A power
    /// at infinity grows with the scene's bounding sphere (π r² times the radiance), so
    /// comparing it with a luminaire's says little about which light lights a point; this
    /// keeps the luminaires' share from vanishing in a large scene under a sky.
    /// `proportional(power_w)` where either group is empty or the others have no power.
    pub fn infinite_apart(power_w: &[f64], at_infinity: &[bool]) -> Self {
        debug_assert_eq!(power_w.len(), at_infinity.len());
        let infinite = at_infinity.iter().filter(|&&b| b).count();
        let bounded: Vec<f64> = power_w
            .iter()
            .zip(at_infinity)
            .map(|(&p, &inf)| {
                if inf || !p.is_finite() {
                    0.0
                } else {
                    p.max(0.0)
                }
            })
            .collect();
        let bounded_total: f64 = bounded.iter().sum();
        if infinite == 0 || bounded_total <= 0.0 {
            return Self::proportional(power_w);
        }
        let share = 1.0 / (infinite as f64 + 1.0);
        let pmf = bounded
            .iter()
            .zip(at_infinity)
            .map(|(&p, &inf)| {
                (if inf {
                    share
                } else {
                    share * p / bounded_total
                }) as f32
            })
            .collect();
        Self::from_pmf(pmf)
    }

    /// The first light whose running sum exceeds `u`: (index, probability); `None` without
    /// lights or where that light has probability 0.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(u32, f32)> {
        if self.pmf.is_empty() {
            return None;
        }
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.pmf.len() - 1);
        let p = self.pmf[i];
        (p > 0.0).then_some((i as u32, p))
    }

    /// Probability of light `index` (0 past the end).
    #[inline]
    pub fn pmf(&self, index: u32) -> f32 {
        self.pmf.get(index as usize).copied().unwrap_or(0.0)
    }

    pub fn pmf_slice(&self) -> &[f32] {
        &self.pmf
    }

    pub fn cdf_slice(&self) -> &[f32] {
        &self.cdf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proportional_follows_the_weights_and_falls_back_to_uniform() {
        let t = SelectionTable::proportional(&[1.0, 3.0]);
        assert_eq!(t.pmf_slice(), &[0.25, 0.75]);
        assert_eq!(t.sample(0.2), Some((0, 0.25)));
        assert_eq!(t.sample(0.3), Some((1, 0.75)));
        let zero = SelectionTable::proportional(&[0.0, f64::NAN, -1.0, 0.0]);
        assert_eq!(zero.pmf_slice(), &[0.25; 4]);
        assert_eq!(SelectionTable::proportional(&[]).sample(0.5), None);
    }

    #[test]
    fn lights_at_infinity_take_one_share_each_and_the_rest_go_by_power() {
        // A sky and a sun at infinity, two lamps of 1 and 3 W.
        let t = SelectionTable::infinite_apart(&[1e6, 1.0, 5e3, 3.0], &[true, false, true, false]);
        let third = 1.0 / 3.0;
        for (i, want) in [third, third / 4.0, third, 3.0 * third / 4.0]
            .into_iter()
            .enumerate()
        {
            assert!(
                (t.pmf(i as u32) - want).abs() < 1e-6,
                "{i}: {}",
                t.pmf(i as u32)
            );
        }
        assert!((t.cdf_slice()[3] - 1.0).abs() < 1e-6);
        // Only lights at infinity, or none: by power.
        let only = SelectionTable::infinite_apart(&[1.0, 3.0], &[true, true]);
        assert_eq!(only, SelectionTable::proportional(&[1.0, 3.0]));
        let none = SelectionTable::infinite_apart(&[1.0, 3.0], &[false, false]);
        assert_eq!(none, SelectionTable::proportional(&[1.0, 3.0]));
        // Lamps without power leave everything to the sky.
        let dark = SelectionTable::infinite_apart(&[2.0, 0.0], &[true, false]);
        assert_eq!(dark.pmf_slice(), &[1.0, 0.0]);
    }
}
