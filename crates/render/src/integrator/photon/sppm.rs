//! Stochastic progressive photon mapping's per-pixel statistics (Hachisuka & Jensen 2009),
//! the surface (caustic) gather of `photon_progressive`. Each pixel keeps a radius Rᵢ and
//! an accumulated photon count Nᵢ; its visible point of pass i (the first non-specular
//! vertex of that pass's camera path) gathers the caustic photons within Rᵢ, M of them
//! with flux Φ_M, and then (Hachisuka et al. 2008, §4.2 "radius reduction"):
//!
//!   Nᵢ₊₁ = Nᵢ + αM,   Rᵢ₊₁ = Rᵢ·√((Nᵢ + αM)/(Nᵢ + M)).
//!
//! The paper's flux τᵢ₊₁ = (τᵢ + Φ_M)·R²ᵢ₊₁/R²ᵢ ("flux correction") and radiance
//! τ/(π R² N_emitted) are not stored: τᵢ₊₁/R²ᵢ₊₁ = τᵢ/R²ᵢ + Φ_M/R²ᵢ, so after n passes of
//! N_e photons each τₙ/(π R²ₙ n N_e) = (1/n) Σᵢ Φ_M,ᵢ/(π R²ᵢ N_e) — the mean of the passes'
//! own estimates, each gathered with the pixel's radius of its pass. That mean is what the
//! film keeps, so the passes go through the film like every other sample (filter, AOVs,
//! sums), and only R and N persist here (`flux_form_equals_the_mean_of_pass_estimates`
//! checks the identity).
//!
//! The passes must come in order from the first: pass i's radii are the result of passes
//! 0 … i − 1. `found` is written during a pass (each pixel by the one work item that
//! renders it) and folded into R and N before the next, in pixel order, so the statistics
//! do not depend on the thread count.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::UVec2;

/// One pixel's statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelStatistics {
    /// R², m².
    pub radius2_m2: f64,
    /// N: photons accumulated (a real number: α M is added per pass).
    pub photons: f64,
}

impl PixelStatistics {
    pub fn new(radius_m: f64) -> Self {
        Self {
            radius2_m2: radius_m * radius_m,
            photons: 0.0,
        }
    }

    pub fn radius_m(&self) -> f64 {
        self.radius2_m2.sqrt()
    }

    /// After a pass whose visible point found `found` photons within the radius:
    /// N ← N + αM, R² ← R²·(N + αM)/(N + M) (Hachisuka et al. 2008, §4.2). A pass that
    /// found none leaves both as they are.
    pub fn update(&mut self, found: u32, alpha: f64) {
        if found == 0 {
            return;
        }
        let m = f64::from(found);
        let n = self.photons + alpha * m;
        self.radius2_m2 *= n / (self.photons + m);
        self.photons = n;
    }
}

/// Every pixel's statistics, and the photons each pixel found in the current pass.
#[derive(Debug)]
pub struct SppmStatistics {
    resolution: UVec2,
    alpha: f64,
    pixels: Vec<PixelStatistics>,
    found: Vec<AtomicU32>,
    /// The pass whose photons `found` counts.
    pass: u32,
}

impl SppmStatistics {
    /// Memory per pixel: its statistics and its count of the current pass's photons.
    pub const BYTES_PER_PIXEL: u64 =
        (std::mem::size_of::<PixelStatistics>() + std::mem::size_of::<AtomicU32>()) as u64;

    /// Pass 0's statistics: every pixel at `radius_m`, no photons.
    pub fn new(resolution: UVec2, radius_m: f32, alpha: f32) -> Self {
        let n = resolution.x as usize * resolution.y as usize;
        Self {
            resolution,
            alpha: f64::from(alpha),
            pixels: vec![PixelStatistics::new(f64::from(radius_m)); n],
            found: (0..n).map(|_| AtomicU32::new(0)).collect(),
            pass: 0,
        }
    }

    /// The pass the statistics are ready for.
    pub fn pass(&self) -> u32 {
        self.pass
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    fn index(&self, pixel: UVec2) -> usize {
        pixel.y as usize * self.resolution.x as usize + pixel.x as usize
    }

    /// `pixel`'s statistics.
    pub fn pixel(&self, pixel: UVec2) -> PixelStatistics {
        self.pixels[self.index(pixel)]
    }

    /// Records that `pixel`'s visible point found `found` photons this pass (the one
    /// work item rendering `pixel` calls this, once per sample).
    pub fn record(&self, pixel: UVec2, found: u32) {
        // One writer per pixel and pass; the driver's join orders it before `advance`.
        self.found[self.index(pixel)].fetch_add(found, Ordering::Relaxed);
    }

    /// Folds the pass's counts into every pixel's R and N and readies the next pass.
    pub fn advance(&mut self) {
        let alpha = self.alpha;
        for (stats, found) in self.pixels.iter_mut().zip(&mut self.found) {
            stats.update(std::mem::take(found.get_mut()), alpha);
        }
        self.pass += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The update rule, step by step, against the paper's formulas.
    #[test]
    fn the_radius_shrinks_as_hachisuka_et_al_say() {
        let alpha = 0.7;
        let mut s = PixelStatistics::new(0.1);
        // First pass: N = αM, R² = R₀²·α.
        s.update(10, alpha);
        assert!((s.photons - 7.0).abs() < 1e-12);
        assert!((s.radius2_m2 - 0.01 * 0.7).abs() < 1e-15);
        // Second: N = 7 + 0.7·4, R² = R₁²·(7 + 2.8)/(7 + 4).
        let r2 = s.radius2_m2;
        s.update(4, alpha);
        assert!((s.photons - 9.8).abs() < 1e-12);
        assert!((s.radius2_m2 - r2 * 9.8 / 11.0).abs() < 1e-15);
        // No photons: nothing changes.
        let before = s;
        s.update(0, alpha);
        assert_eq!(s, before);
        // α = 1 keeps every photon and the radius.
        let mut keep = PixelStatistics::new(0.1);
        let r2 = keep.radius2_m2;
        keep.update(5, 1.0);
        assert_eq!(keep.radius2_m2, r2);
    }

    /// In a uniform photon density ρ (photons per m² and pass), a pixel that finds the
    /// expected M = ρ π R² each pass shrinks its radius without bound while N grows
    /// without bound (the two conditions of consistency, Hachisuka et al. 2008 §4.2), R
    /// falling and N rising in every pass that finds a photon, at the rate R² ∝ i^(α − 1)
    /// of Knaus & Zwicker 2011's global radius schedule: the log–log slope of
    /// R² between passes 1000 and 4000 is α − 1 within 0.01.
    #[test]
    fn in_a_uniform_density_the_radius_goes_to_zero_at_the_expected_rate() {
        let (alpha, rho) = (2.0 / 3.0, 4.0e4);
        let mut s = PixelStatistics::new(0.05);
        let mut last = s;
        let mut at_1000 = 0.0;
        for pass in 1..=4000 {
            let m = (rho * std::f64::consts::PI * s.radius2_m2).round() as u32;
            s.update(m, alpha);
            if m > 0 {
                assert!(s.radius2_m2 < last.radius2_m2, "pass {pass}");
                assert!(s.photons > last.photons, "pass {pass}");
            }
            if pass == 1000 {
                at_1000 = s.radius2_m2;
            }
            last = s;
        }
        let slope = (s.radius2_m2 / at_1000).ln() / 4f64.ln();
        assert!((slope - (alpha - 1.0)).abs() < 0.01, "{slope}");
        assert!(s.photons > 1000.0, "{}", s.photons);
    }

    /// τ/(π R² N_emitted) with the paper's flux correction equals the mean over passes
    /// of Φ_M/(π R²ᵢ N_e) with each pass's own radius — what the film averages.
    #[test]
    fn flux_form_equals_the_mean_of_pass_estimates() {
        let (alpha, photons_per_pass) = (0.7, 1000.0);
        let mut s = PixelStatistics::new(0.2);
        let mut tau = 0.0f64;
        let mut sum_of_pass_estimates = 0.0;
        let passes = 50;
        for i in 0..passes {
            // Some photons found, some flux: any sequence will do.
            let m = 3 + (i * 7919) % 13;
            let flux = 0.01 * f64::from(m) * (1.0 + 0.1 * f64::from(i % 5));
            sum_of_pass_estimates +=
                flux / (std::f64::consts::PI * s.radius2_m2 * photons_per_pass);
            let r2_before = s.radius2_m2;
            s.update(m, alpha);
            tau = (tau + flux) * s.radius2_m2 / r2_before;
        }
        let paper =
            tau / (std::f64::consts::PI * s.radius2_m2 * f64::from(passes) * photons_per_pass);
        let film = sum_of_pass_estimates / f64::from(passes);
        assert!((paper - film).abs() <= 1e-12 * film, "{paper} vs {film}");
    }

    /// Counts recorded in a pass reach their own pixel only, when the pass advances.
    #[test]
    fn counts_go_to_their_pixel() {
        let mut stats = SppmStatistics::new(UVec2::new(3, 2), 0.1, 0.5);
        stats.record(UVec2::new(2, 1), 4);
        assert_eq!(stats.pixel(UVec2::new(2, 1)).photons, 0.0);
        stats.advance();
        assert_eq!(stats.pass(), 1);
        assert_eq!(stats.pixel(UVec2::new(2, 1)).photons, 2.0);
        let r2 = f64::from(0.1f32).powi(2);
        assert!((stats.pixel(UVec2::new(2, 1)).radius2_m2 - r2 * 0.5).abs() < 1e-15);
        assert_eq!(
            stats.pixel(UVec2::new(1, 1)),
            PixelStatistics::new(0.1f32 as f64)
        );
        // The counts were taken: the next pass starts from zero.
        stats.advance();
        assert_eq!(stats.pixel(UVec2::new(2, 1)).photons, 2.0);
    }
}
