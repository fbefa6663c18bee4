//! A discrete distribution over a scene's lights: probabilities and their running sums, for
//! a light choice that does not depend on the shading point.

/// Selection probabilities (sum 1, or all 0 for no light) and their running sums, taken in
/// `order` (running-sum position → light index).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectionTable {
    /// By light index.
    pmf: Vec<f32>,
    /// Running sums in `order`.
    cdf: Vec<f32>,
    order: Vec<u32>,
    /// Lights at infinity chosen apart: the first this many of `order`, each with an equal
    /// share (`infinite_apart`); 0 for a table in proportion to power.
    infinite_apart: usize,
    /// Whether the other lights share one more slice after them (lights with power beside
    /// the lights at infinity).
    others_apart: bool,
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
        let order = (0..pmf.len() as u32).collect();
        Self::from_pmf(pmf, order, 0, false)
    }

    fn from_pmf(pmf: Vec<f32>, order: Vec<u32>, infinite_apart: usize, others_apart: bool) -> Self {
        let mut run = 0.0f32;
        let cdf = order
            .iter()
            .map(|&i| {
                run += pmf[i as usize];
                run
            })
            .collect();
        Self {
            pmf,
            cdf,
            order,
            infinite_apart,
            others_apart,
        }
    }

    /// Lights at infinity (`at_infinity[i]`) chosen apart, each with probability
    /// 1 / (their count + 1), the others sharing the remaining 1 / (count + 1) in proportion
    /// to `power_w` (pbrt-v4 `BVHLightSampler`'s rule for lights without bounds). A power
    /// at infinity grows with the scene's bounding sphere (π r² times the radiance), so
    /// comparing it with a luminaire's says little about which light lights a point; this
    /// keeps the luminaires' share from vanishing in a large scene under a sky.
    /// The lights at infinity come first in the running sums, so that the first
    /// `count / (count + 1)` of the unit interval picks each of them in one equal slice
    /// (`infinite_apart_count`). Two or more lights at infinity alone (the others without
    /// power) get 1 / count each, with no slice after them (`others_apart` false): each
    /// takes a light sample at every hit, so their powers are not compared.
    /// `proportional(power_w)` where no light is at infinity, or one is and the others have
    /// no power.
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
        let n = at_infinity.len() as u32;
        let order: Vec<u32> = (0..n)
            .filter(|&i| at_infinity[i as usize])
            .chain((0..n).filter(|&i| !at_infinity[i as usize]))
            .collect();
        if infinite >= 2 && bounded_total <= 0.0 {
            // Only lights at infinity (a sky and a sun): an equal slice each.
            let share = 1.0 / infinite as f32;
            let pmf = at_infinity
                .iter()
                .map(|&inf| if inf { share } else { 0.0 })
                .collect();
            return Self::from_pmf(pmf, order, infinite, false);
        }
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
        Self::from_pmf(pmf, order, infinite, true)
    }

    /// Whether the lights other than those at infinity share one slice after theirs.
    pub fn others_apart(&self) -> bool {
        self.others_apart
    }

    /// Lights at infinity chosen apart, each in its own equal slice at the start of the
    /// unit interval (1 / (this + 1) beside other lights, 1 / this alone); 0 for a table in
    /// proportion to power.
    pub fn infinite_apart_count(&self) -> usize {
        self.infinite_apart
    }

    /// The first light whose running sum exceeds `u`: (index, probability); `None` without
    /// lights or where that light has probability 0.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(u32, f32)> {
        if self.pmf.is_empty() {
            return None;
        }
        let position = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.pmf.len() - 1);
        let i = self.order[position];
        let p = self.pmf[i as usize];
        (p > 0.0).then_some((i, p))
    }

    /// Probability of light `index` (0 past the end).
    #[inline]
    pub fn pmf(&self, index: u32) -> f32 {
        self.pmf.get(index as usize).copied().unwrap_or(0.0)
    }

    pub fn pmf_slice(&self) -> &[f32] {
        &self.pmf
    }

    /// Running sums in `order_slice` order.
    pub fn cdf_slice(&self) -> &[f32] {
        &self.cdf
    }

    /// Running-sum position → light index.
    pub fn order_slice(&self) -> &[u32] {
        &self.order
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
        // The lights at infinity first, one slice of a third each: stratified samples over
        // three slices take the sky, the sun and one lamp.
        assert_eq!(t.infinite_apart_count(), 2);
        assert_eq!(t.order_slice(), &[0, 2, 1, 3]);
        for (u, light) in [
            (0.0, 0),
            (0.33, 0),
            (0.34, 2),
            (0.66, 2),
            (0.67, 1),
            (0.74, 1),
            (0.76, 3),
        ] {
            assert_eq!(t.sample(u).map(|(i, _)| i), Some(light), "u = {u}");
        }
        assert_eq!(
            SelectionTable::proportional(&[1.0, 3.0]).infinite_apart_count(),
            0
        );
        // Only lights at infinity (a sky and a sun, a lamp without power): an equal slice
        // each, nothing after them; none at infinity: by power.
        let only = SelectionTable::infinite_apart(&[1.0, 0.0, 3.0], &[true, false, true]);
        assert_eq!(only.pmf_slice(), &[0.5, 0.0, 0.5]);
        assert_eq!(only.order_slice(), &[0, 2, 1]);
        assert_eq!(
            (only.infinite_apart_count(), only.others_apart()),
            (2, false)
        );
        assert_eq!(only.sample(0.49).map(|(i, _)| i), Some(0));
        assert_eq!(only.sample(0.51).map(|(i, _)| i), Some(2));
        let none = SelectionTable::infinite_apart(&[1.0, 3.0], &[false, false]);
        assert_eq!(none, SelectionTable::proportional(&[1.0, 3.0]));
        // Lamps without power leave everything to the sky.
        let dark = SelectionTable::infinite_apart(&[2.0, 0.0], &[true, false]);
        assert_eq!(dark.pmf_slice(), &[1.0, 0.0]);
    }
}
