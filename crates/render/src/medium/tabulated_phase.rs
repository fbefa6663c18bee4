//! A phase function given as a table over the scattering angle's cosine μ (1 = forward):
//! a Mie table, or Cornette–Shanks sampled by the user. Linear between the rows,
//! normalised so that ∫ p dω = 2π ∫ p dμ = 1, and sampled exactly by inverting its cdf
//! (a quadratic on each piece: the density is linear there), so its pdf is p.

use std::f32::consts::PI;

/// A normalised piecewise-linear p(μ), sr⁻¹.
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedPhase {
    /// Ascending, from −1 to 1.
    mu: Vec<f32>,
    /// p at each `mu`, sr⁻¹.
    p: Vec<f32>,
    /// The probability of μ' < `mu[i]` (0 at the first row, 1 at the last).
    cdf: Vec<f32>,
    mean_cosine: f32,
}

impl TabulatedPhase {
    /// The table of `values` (≥ 0, not all 0) at `cos_theta` (ascending from −1 to 1);
    /// the scene reader checks both, so an error here is a message for a build error.
    pub fn new(cos_theta: &[f64], values: &[f64]) -> Result<Self, String> {
        let n = cos_theta.len();
        let ascending = cos_theta.windows(2).all(|w| w[0] < w[1]);
        if n < 2
            || values.len() != n
            || !ascending
            || cos_theta[0] != -1.0
            || cos_theta[n - 1] != 1.0
        {
            return Err("a phase table needs ascending cos θ from -1 to 1, one value each".into());
        }
        if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err("a phase table's values must be finite and ≥ 0".into());
        }
        // ∫ f dμ and ∫ μ f dμ, exact for the linear pieces (in f64).
        let (mut integral, mut first_moment) = (0.0f64, 0.0f64);
        for i in 0..n - 1 {
            let (a, b) = (cos_theta[i], cos_theta[i + 1]);
            let (fa, fb) = (values[i], values[i + 1]);
            integral += 0.5 * (fa + fb) * (b - a);
            // ∫ μ (fa + (fb − fa)(μ − a)/(b − a)) dμ over [a, b].
            first_moment += (b - a) * (fa * (2.0 * a + b) + fb * (a + 2.0 * b)) / 6.0;
        }
        if integral <= 0.0 {
            return Err("a phase table's values are all 0".into());
        }
        let norm = 1.0 / (2.0 * std::f64::consts::PI * integral);
        let mut cdf = Vec::with_capacity(n);
        let mut acc = 0.0f64;
        cdf.push(0.0f32);
        for i in 0..n - 1 {
            acc += 0.5 * (values[i] + values[i + 1]) * (cos_theta[i + 1] - cos_theta[i]) / integral;
            cdf.push(acc as f32);
        }
        cdf[n - 1] = 1.0;
        Ok(Self {
            mu: cos_theta.iter().map(|&c| c as f32).collect(),
            p: values.iter().map(|&v| (v * norm) as f32).collect(),
            cdf,
            mean_cosine: (first_moment / integral) as f32,
        })
    }

    /// The piece [mu[i], mu[i + 1]] that holds `mu` (clamped to the table).
    #[inline]
    fn piece(&self, mu: f32) -> usize {
        let i = self.mu.partition_point(|&m| m <= mu);
        i.clamp(1, self.mu.len() - 1) - 1
    }

    /// p at scattering cosine `mu`, sr⁻¹.
    #[inline]
    pub fn eval(&self, mu: f32) -> f32 {
        let i = self.piece(mu);
        let t = ((mu - self.mu[i]) / (self.mu[i + 1] - self.mu[i])).clamp(0.0, 1.0);
        self.p[i] + (self.p[i + 1] - self.p[i]) * t
    }

    /// The scattering cosine whose cdf is `u` ∈ [0, 1).
    pub fn sample_cos_theta(&self, u: f32) -> f32 {
        // The piece: cdf[i] ≤ u < cdf[i + 1], skipping pieces of zero probability.
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .clamp(1, self.mu.len() - 1)
            - 1;
        let (m0, m1) = (self.mu[i], self.mu[i + 1]);
        let (a, b) = (self.p[i], self.p[i + 1]);
        let width = m1 - m0;
        // Solve 2π·width·(a·t + (b − a)·t²/2) = u − cdf[i] for t ∈ [0, 1], in the form
        // that stays accurate when b ≈ a: t = 2r / (a + √(a² + 2(b − a)r)).
        let r = ((u - self.cdf[i]) / (2.0 * PI * width)).max(0.0);
        let disc = (a * a + 2.0 * (b - a) * r).max(0.0);
        let denom = a + disc.sqrt();
        let t = if denom > 0.0 { 2.0 * r / denom } else { 0.0 };
        (m0 + t.clamp(0.0, 1.0) * width).clamp(-1.0, 1.0)
    }

    /// ⟨μ⟩, the table's asymmetry.
    pub fn mean_cosine(&self) -> f32 {
        self.mean_cosine
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampling_inverts_the_cdf() {
        let t = TabulatedPhase::new(&[-1.0, 0.0, 0.5, 1.0], &[1.0, 0.0, 2.0, 8.0]).unwrap();
        // cdf(μ) by fine midpoint quadrature of 2π p.
        let cdf = |mu: f32| {
            let n = 20_000;
            let h = (mu + 1.0) / n as f32;
            (0..n)
                .map(|k| 2.0 * PI * t.eval(-1.0 + (k as f32 + 0.5) * h) * h)
                .sum::<f32>()
        };
        assert!((cdf(1.0) - 1.0).abs() < 1e-4, "∫p = {}", cdf(1.0));
        for k in 0..50 {
            let u = (k as f32 + 0.5) / 50.0;
            let mu = t.sample_cos_theta(u);
            assert!((cdf(mu) - u).abs() < 2e-4, "u {u}: μ {mu}, cdf {}", cdf(mu));
        }
    }

    #[test]
    fn bad_tables_are_refused() {
        assert!(TabulatedPhase::new(&[-1.0, 0.5], &[1.0, 1.0]).is_err());
        assert!(TabulatedPhase::new(&[-1.0, 1.0], &[0.0, 0.0]).is_err());
        assert!(TabulatedPhase::new(&[-1.0, 1.0], &[1.0, -1.0]).is_err());
    }
}
