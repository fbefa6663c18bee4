//! A chi-square goodness-of-fit harness for direction sampling routines (BSDFs, emitters):
//! does `sample` produce directions distributed as `pdf` says? After Mitsuba 3's
//! `mitsuba.chi2.ChiSquareTest` and pbrt-v3's `bsdfs.cpp` tests: the sphere is cut into
//! θ × φ bins, `sample_count` directions are histogrammed, the expected count of each bin is
//! `sample_count · ∫_bin pdf dω` (integrated numerically), bins with an expected count
//! below `min_expected` are pooled (Cochran's rule), and Pearson's statistic is compared
//! with the χ² distribution of (bins − 1) degrees of freedom.
//!
//! Samples that fail (`None`) or are Dirac (the caller returns `None` for those) count in
//! `sample_count` but land in no bin: `pdf` must then integrate to the probability of a
//! successful continuous sample, which is exactly what a correct `pdf` does.
//!
//! Lives in the dev-only prism-testkit so every crate's tests reuse it while statrs stays
//! out of the renderer's dependencies.

use glam::{Vec2, Vec3A};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Parameters of a test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Config {
    /// Bins over θ ∈ [0, π]; φ ∈ [0, 2π) gets twice as many.
    pub theta_bins: usize,
    pub sample_count: usize,
    /// Bins expecting fewer samples than this are pooled into one.
    pub min_expected: f64,
    /// Reject when the p-value is below this (callers running k tests use
    /// `sidak(α, k)` to keep the family-wise error rate at α).
    pub significance: f64,
    /// Seed of the uniform variates.
    pub seed: u64,
    /// Sub-cells per bin edge for integrating `pdf` (midpoint rule on each sub-cell).
    pub integration_resolution: usize,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Self {
            theta_bins: 10,
            sample_count: 1_000_000,
            min_expected: 5.0,
            significance: 0.01,
            seed: 1,
            integration_resolution: 12,
        }
    }
}

/// Per-test significance that keeps the family-wise error rate at `alpha` over
/// `test_count` independent tests (Šidák 1967).
pub fn sidak(alpha: f64, test_count: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / test_count.max(1) as f64)
}

/// P(X ≥ `statistic`) for X ~ χ² with `degrees_of_freedom` (the p-value of Pearson's
/// statistic); 0 for a non-finite statistic or zero degrees of freedom.
pub fn chi2_p_value(statistic: f64, degrees_of_freedom: usize) -> f64 {
    match ChiSquared::new(degrees_of_freedom as f64) {
        Ok(d) if statistic.is_finite() => 1.0 - d.cdf(statistic),
        _ => 0.0,
    }
}

/// What a test found.
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Result {
    pub statistic: f64,
    pub degrees_of_freedom: usize,
    pub p_value: f64,
    /// ∫ pdf dω over the sphere (≤ 1; < 1 when some samples fail or are Dirac).
    pub pdf_integral: f64,
    /// Fraction of `sample_count` that produced a direction.
    pub success_fraction: f64,
    pub passed: bool,
    /// Why it failed, or a summary.
    pub message: String,
}

/// SplitMix64 (Steele, Lea & Flood 2014): deterministic variates for the harness.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

fn direction(theta: f64, phi: f64) -> Vec3A {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3A::new((st * cp) as f32, (st * sp) as f32, ct as f32)
}

/// Runs the test. `sample(u_1d, u_2d)` returns a unit direction or `None`; `pdf(ω)` is the
/// solid-angle density of the non-Dirac part.
pub fn chi2_test(
    config: &Chi2Config,
    sample: impl FnMut(f32, Vec2) -> Option<Vec3A>,
    pdf: impl Fn(Vec3A) -> f64,
) -> Chi2Result {
    run(config, false, sample, pdf)
}

/// As [`chi2_test`] for densities with discontinuities inside the bins (the outline of an
/// area light, texel edges of an environment map): each sub-cell whose five samples
/// (corners and centre) include both zero and non-zero values, or differ by more than 25 %,
/// is split in four, recursively up to `ADAPTIVE_DEPTH` levels, so the expected counts
/// stay accurate where the plain midpoint rule would misjudge a bin the outline crosses;
/// a bin that received samples but whose density integrated to 0 (an outline's corner
/// between the sample points) is integrated again on a grid 8× finer before the test
/// rejects it. Smooth densities cost little more than with [`chi2_test`].
pub fn chi2_test_adaptive(
    config: &Chi2Config,
    sample: impl FnMut(f32, Vec2) -> Option<Vec3A>,
    pdf: impl Fn(Vec3A) -> f64,
) -> Chi2Result {
    run(config, true, sample, pdf)
}

/// Levels of four-way splitting of a sub-cell in [`chi2_test_adaptive`] (a sub-cell edge
/// shrinks up to 2⁶ = 64 times).
pub const ADAPTIVE_DEPTH: u32 = 6;

/// ∫ pdf sin θ dθ dφ over bin (i, j): midpoint rule on `resolution²` sub-cells, each
/// refined when `adaptive`; an error message for a negative or non-finite density.
fn bin_integral(
    resolution: usize,
    adaptive: bool,
    pdf: &impl Fn(Vec3A) -> f64,
    i: usize,
    j: usize,
    dt: f64,
    dp: f64,
) -> Result<f64, String> {
    let eval = |theta: f64, phi: f64| -> Result<f64, String> {
        let p = pdf(direction(theta, phi));
        if !p.is_finite() || p < 0.0 {
            return Err(format!(
                "pdf is {p} at θ = {theta:.4}, φ = {phi:.4} (expected finite ≥ 0)"
            ));
        }
        Ok(p)
    };
    let r = resolution.max(1);
    let (ct, cp) = (dt / r as f64, dp / r as f64);
    let mut integral = 0.0;
    for a in 0..r {
        let theta0 = (i as f64 + a as f64 / r as f64) * dt;
        for b in 0..r {
            let phi0 = (j as f64 + b as f64 / r as f64) * dp;
            integral += if adaptive {
                cell_adaptive(&eval, theta0, phi0, ct, cp, ADAPTIVE_DEPTH)?
            } else {
                let theta = theta0 + 0.5 * ct;
                eval(theta, phi0 + 0.5 * cp)? * theta.sin() * ct * cp
            };
        }
    }
    Ok(integral)
}

/// ∫ pdf dω over the cell [θ0, θ0 + ct] × [φ0, φ0 + cp], split while the density jumps.
fn cell_adaptive(
    eval: &impl Fn(f64, f64) -> Result<f64, String>,
    theta0: f64,
    phi0: f64,
    ct: f64,
    cp: f64,
    depth: u32,
) -> Result<f64, String> {
    let centre = eval(theta0 + 0.5 * ct, phi0 + 0.5 * cp)?;
    // Exact ∫ sin θ dθ over the cell times the centre value.
    let cell = || centre * (theta0.cos() - (theta0 + ct).cos()) * cp;
    if depth == 0 {
        return Ok(cell());
    }
    let corners = [
        eval(theta0, phi0)?,
        eval(theta0 + ct, phi0)?,
        eval(theta0, phi0 + cp)?,
        eval(theta0 + ct, phi0 + cp)?,
    ];
    let (lo, hi) = corners
        .iter()
        .fold((centre, centre), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let jumps = (lo == 0.0 && hi > 0.0) || hi > 1.25 * lo;
    if !jumps {
        return Ok(cell());
    }
    let (ht, hp) = (0.5 * ct, 0.5 * cp);
    let mut sum = 0.0;
    for (a, b) in [(0.0, 0.0), (ht, 0.0), (0.0, hp), (ht, hp)] {
        sum += cell_adaptive(eval, theta0 + a, phi0 + b, ht, hp, depth - 1)?;
    }
    Ok(sum)
}

fn run(
    config: &Chi2Config,
    adaptive: bool,
    mut sample: impl FnMut(f32, Vec2) -> Option<Vec3A>,
    pdf: impl Fn(Vec3A) -> f64,
) -> Chi2Result {
    let nt = config.theta_bins.max(1);
    let np = 2 * nt;
    let (dt, dp) = (
        std::f64::consts::PI / nt as f64,
        2.0 * std::f64::consts::PI / np as f64,
    );
    let mut observed = vec![0.0f64; nt * np];
    let mut rng = SplitMix64(config.seed);
    let mut successes = 0usize;
    for _ in 0..config.sample_count {
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        let Some(w) = sample(u1, u2) else { continue };
        let w = w.as_dvec3();
        let len = w.length();
        if !len.is_finite() || (len - 1.0).abs() > 1e-3 {
            return Chi2Result {
                statistic: f64::INFINITY,
                degrees_of_freedom: 0,
                p_value: 0.0,
                pdf_integral: f64::NAN,
                success_fraction: 0.0,
                passed: false,
                message: format!("sample returned a non-unit direction {w:?} (length {len})"),
            };
        }
        let w = w / len;
        let theta = w.z.clamp(-1.0, 1.0).acos();
        let mut phi = w.y.atan2(w.x);
        if phi < 0.0 {
            phi += 2.0 * std::f64::consts::PI;
        }
        let i = ((theta / dt) as usize).min(nt - 1);
        let j = ((phi / dp) as usize).min(np - 1);
        observed[i * np + j] += 1.0;
        successes += 1;
    }
    // Expected counts: ∫_bin pdf dω on sub-cells (midpoint rule, or adaptive).
    let mut expected = vec![0.0f64; nt * np];
    let mut pdf_integral = 0.0;
    for i in 0..nt {
        for j in 0..np {
            let mut integral =
                bin_integral(config.integration_resolution, adaptive, &pdf, i, j, dt, dp);
            // A bin with samples whose sub-cells all missed the density (a corner of an
            // outline between the sample points): look again, 8× finer.
            if adaptive && matches!(integral, Ok(v) if v == 0.0) && observed[i * np + j] > 0.0 {
                integral = bin_integral(
                    8 * config.integration_resolution,
                    adaptive,
                    &pdf,
                    i,
                    j,
                    dt,
                    dp,
                );
            }
            let integral = match integral {
                Ok(v) => v,
                Err(message) => {
                    return Chi2Result {
                        statistic: f64::INFINITY,
                        degrees_of_freedom: 0,
                        p_value: 0.0,
                        pdf_integral: f64::NAN,
                        success_fraction: successes as f64 / config.sample_count as f64,
                        passed: false,
                        message,
                    }
                }
            };
            pdf_integral += integral;
            expected[i * np + j] = integral * config.sample_count as f64;
        }
    }
    let success_fraction = successes as f64 / config.sample_count.max(1) as f64;
    // Pool the small bins (Cochran's rule), then Pearson's statistic.
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pooled_obs, mut pooled_exp, mut pooled_count) = (0.0, 0.0, 0usize);
    let mut statistic = 0.0;
    let mut bins = 0usize;
    for &k in &order {
        if expected[k] == 0.0 && observed[k] > 0.0 {
            return Chi2Result {
                statistic: f64::INFINITY,
                degrees_of_freedom: 0,
                p_value: 0.0,
                pdf_integral,
                success_fraction,
                passed: false,
                message: format!(
                    "{} samples in bin (θ {}, φ {}) where pdf integrates to 0",
                    observed[k],
                    k / np,
                    k % np
                ),
            };
        }
        if expected[k] < config.min_expected {
            pooled_obs += observed[k];
            pooled_exp += expected[k];
            pooled_count += 1;
        } else {
            let d = observed[k] - expected[k];
            statistic += d * d / expected[k];
            bins += 1;
        }
    }
    if pooled_count > 0 && pooled_exp > 0.0 {
        let d = pooled_obs - pooled_exp;
        statistic += d * d / pooled_exp;
        bins += 1;
    } else if pooled_obs > 0.0 {
        statistic = f64::INFINITY;
    }
    let dof = bins.saturating_sub(1).max(1);
    let p_value = chi2_p_value(statistic, dof);
    let passed = p_value >= config.significance;
    let message = format!(
        "χ² = {statistic:.2} with {dof} dof, p = {p_value:.3e} (reject below {:.3e}); \
         ∫pdf = {pdf_integral:.5}, success fraction = {success_fraction:.5}, {pooled_count} bins pooled",
        config.significance
    );
    Chi2Result {
        statistic,
        degrees_of_freedom: dof,
        p_value,
        pdf_integral,
        success_fraction,
        passed,
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cosine-weighted hemisphere (Malley's method on the uniform disk, pbrt-v4 §A.5.3):
    /// z = √(1 − u₀), so p(ω) = cos θ / π. Local because this crate depends on no renderer.
    fn sample_cosine_hemisphere(u: Vec2) -> Vec3A {
        let r = u.x.sqrt();
        let phi = 2.0 * std::f32::consts::PI * u.y;
        Vec3A::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
    }

    fn config() -> Chi2Config {
        Chi2Config {
            sample_count: 200_000,
            ..Chi2Config::default()
        }
    }

    #[test]
    fn cosine_hemisphere_sampling_passes_against_its_pdf() {
        let r = chi2_test(
            &config(),
            |_, u| Some(sample_cosine_hemisphere(u)),
            |w| (w.z.max(0.0) as f64) / std::f64::consts::PI,
        );
        assert!(r.passed, "{}", r.message);
        assert!((r.pdf_integral - 1.0).abs() < 1e-3, "{}", r.message);
    }

    #[test]
    fn a_wrong_pdf_is_rejected() {
        // Uniform-hemisphere pdf against cosine-weighted samples.
        let r = chi2_test(
            &config(),
            |_, u| Some(sample_cosine_hemisphere(u)),
            |w| {
                if w.z > 0.0 {
                    0.5 / std::f64::consts::PI
                } else {
                    0.0
                }
            },
        );
        assert!(!r.passed, "{}", r.message);
    }

    #[test]
    fn samples_where_the_pdf_is_zero_fail_at_once() {
        let r = chi2_test(
            &config(),
            |_, u| Some(-sample_cosine_hemisphere(u)),
            |w| (w.z.max(0.0) as f64) / std::f64::consts::PI,
        );
        assert!(!r.passed);
        assert!(r.p_value == 0.0, "{}", r.message);
    }

    #[test]
    fn adaptive_integration_resolves_an_outline_inside_the_bins() {
        // A uniform cone of half-angle 50° (its edge crosses the 18° θ bins): the adaptive
        // integral of its density is 1 to 1e-3 (the finest cells, 1.5°/64, straddle the
        // edge at the same offset, so their midpoint errors add up) and the test passes.
        let omc = 1.0 - 50f64.to_radians().cos();
        let pdf = |w: Vec3A| {
            if f64::from(w.z) >= 1.0 - omc {
                1.0 / (2.0 * std::f64::consts::PI * omc)
            } else {
                0.0
            }
        };
        let sample = |_: f32, u: Vec2| {
            let z = 1.0 - f64::from(u.x) * omc;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * std::f64::consts::PI * f64::from(u.y);
            Some(Vec3A::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ))
        };
        let r = chi2_test_adaptive(&config(), sample, pdf);
        assert!(r.passed, "{}", r.message);
        assert!((r.pdf_integral - 1.0).abs() < 1e-3, "{}", r.message);
    }

    #[test]
    fn p_values_match_the_chi_square_table() {
        // Upper 5 % points of χ² (Abramowitz & Stegun Table 26.8): 3.841 (1 dof), 18.307 (10).
        assert!((chi2_p_value(3.841_459, 1) - 0.05).abs() < 1e-6);
        assert!((chi2_p_value(18.307_04, 10) - 0.05).abs() < 1e-6);
        assert_eq!(chi2_p_value(f64::INFINITY, 3), 0.0);
        assert_eq!(chi2_p_value(1.0, 0), 0.0);
    }

    #[test]
    fn sidak_keeps_the_family_rate() {
        let a = sidak(0.01, 10);
        assert!((1.0 - (1.0 - a).powi(10) - 0.01).abs() < 1e-12);
    }
}
