//! The wavelength density of estimates that end as RGB (the film): 0.4 × pbrt-v4's
//! visible-wavelength density + 0.6 × the Euclidean norm of the linear Rec. 709 colour-matching
//! functions (CIE 1931 2° x̄, ȳ, z̄ through the XYZ → linear sRGB matrix), normalised over
//! 360–830 nm on 1 nm bins, and drawn through a table of 4096 equal-probability cells.
//!
//! Why: the visible density p ∝ sech²(0.0072 (λ − 538)) follows luminance, so a sample's
//! red and above all blue components, which lean on the spectrum's ends, are estimated from
//! few wavelengths: in renders of the bench scenes the blue channel carried 35–90 % of the
//! per-pixel variance (the sky of a daylight scene almost all of it). For an estimate
//! f(λ)/p(λ) of several integrals ∫ S wᶜ dλ at once, the density that minimises the summed
//! variance for smooth S is p ∝ ‖w(λ)‖ (the multi-integrand form of the optimal importance
//! density, Owen 2013 "Monte Carlo theory, methods and examples" §9.1); the mixture with the
//! visible density keeps luminance, which the norm alone leaves noisier, close to what it
//! was. On D65 × the 24 ColorChecker reflectances and a white, with four rotated
//! wavelengths (hero wavelength sampling), the summed RGB variance of the spectral estimate
//! is 0.26× the visible density's for independent draws and 0.36× for 64 stratified ones,
//! and the channels' variances weighted as luminance weights them 1.20× (test below). The
//! norm's share 0.6 was the best of 0.25–0.75 in a model of the same estimate (0.5: 0.30×
//! and 0.38×); on the bench scenes at 64 spp it gave 0.88× the MSE of an equal mixture
//! with a daylight sky, 0.97–0.99× on three more and 1.03× on the two lit by warm white.

use std::sync::OnceLock;

use crate::colorimetry::{cie1931_interleaved, cmf_lerp};
use crate::constants::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use crate::rgb_space::RgbColorSpace;
use crate::sampled_wavelengths::visible_wavelength_pdf_f64;

/// 1 nm bins of the mixture over 360–830 nm.
const BINS: usize = (LAMBDA_MAX_NM - LAMBDA_MIN_NM) as usize;
/// Equal-probability cells of the sampling map: λ(u) is linear within each, so a draw is
/// two neighbouring table entries and a lerp, with no search (a search of the 1 nm CDF
/// cost the packet tracer 3–8 % of the Cornell box's time).
const CELLS: usize = 4096;
/// Share of the visible-wavelength density in the mixture.
const VISIBLE_SHARE: f64 = 0.4;

/// The sampling map: cell j of u ∈ [j/CELLS, (j+1)/CELLS) maps linearly onto
/// [λ_j, λ_{j+1}), so λ has density 1/(CELLS · (λ_{j+1} − λ_j)) there: piecewise constant,
/// and the mixture's within 1 % over each 1 nm bin (its CDF is inverted exactly at the cell
/// edges); pointwise, a cell that straddles a bin edge averages the two bins (1.6 % at most).
pub(crate) struct RgbWavelengthDensity {
    /// λ_j in nm, j = 0..=CELLS (λ_0 = 360, λ_CELLS = 830), increasing.
    edges_nm: Box<[f32; CELLS + 1]>,
    /// Density of cell j in nm⁻¹.
    pdf_per_nm: Box<[f32; CELLS]>,
}

impl RgbWavelengthDensity {
    /// The mixture's mass per 1 nm bin (summing to 1).
    fn bin_masses() -> Vec<f64> {
        let table = cie1931_interleaved();
        let xyz_to_rgb = RgbColorSpace::srgb().xyz_to_rgb;
        let centre = |i: usize| LAMBDA_MIN_NM as f64 + i as f64 + 0.5;
        let norm: Vec<f64> = (0..BINS)
            .map(|i| (xyz_to_rgb * cmf_lerp(table, centre(i))).length())
            .collect();
        let visible: Vec<f64> = (0..BINS)
            .map(|i| visible_wavelength_pdf_f64(centre(i)))
            .collect();
        let (norm_sum, visible_sum): (f64, f64) = (norm.iter().sum(), visible.iter().sum());
        (0..BINS)
            .map(|i| {
                VISIBLE_SHARE * visible[i] / visible_sum
                    + (1.0 - VISIBLE_SHARE) * norm[i] / norm_sum
            })
            .collect()
    }

    fn build() -> Self {
        let mass = Self::bin_masses();
        let total: f64 = mass.iter().sum();
        // The mixture's CDF at the bin edges, then inverted at u = j / CELLS (linear
        // within a bin, where the mixture is constant).
        let mut cdf = vec![0.0f64; BINS + 1];
        for (i, m) in mass.iter().enumerate() {
            cdf[i + 1] = cdf[i] + m / total;
        }
        let mut edges_nm = Box::new([0.0f32; CELLS + 1]);
        let mut bin = 0usize;
        for (j, edge) in edges_nm.iter_mut().enumerate() {
            let u = j as f64 / CELLS as f64;
            while bin + 1 < BINS && cdf[bin + 1] <= u {
                bin += 1;
            }
            let t = ((u - cdf[bin]) / (cdf[bin + 1] - cdf[bin])).clamp(0.0, 1.0);
            *edge = (LAMBDA_MIN_NM as f64 + bin as f64 + t) as f32;
        }
        edges_nm[0] = LAMBDA_MIN_NM;
        edges_nm[CELLS] = LAMBDA_MAX_NM;
        let mut pdf_per_nm = Box::new([0.0f32; CELLS]);
        for j in 0..CELLS {
            let width = edges_nm[j + 1] - edges_nm[j];
            debug_assert!(width > 0.0, "cell {j} is empty");
            pdf_per_nm[j] = 1.0 / (CELLS as f32 * width);
        }
        Self {
            edges_nm,
            pdf_per_nm,
        }
    }

    /// The density, built on first use.
    pub(crate) fn get() -> &'static Self {
        static DENSITY: OnceLock<RgbWavelengthDensity> = OnceLock::new();
        DENSITY.get_or_init(Self::build)
    }

    /// The wavelength (nm) of variate `u` ∈ [0, 1), with its density (nm⁻¹).
    #[inline(always)]
    pub(crate) fn sample(&self, u: f32) -> (f32, f32) {
        let x = u * CELLS as f32;
        let cell = (x as usize).min(CELLS - 1);
        let t = x - cell as f32;
        let (lo, hi) = (self.edges_nm[cell], self.edges_nm[cell + 1]);
        (lo + t * (hi - lo), self.pdf_per_nm[cell])
    }
}

/// The linear Rec. 709 colour-matching functions at `wavelength_nm` (for the tests).
#[cfg(test)]
fn rec709_cmfs(wavelength_nm: f64) -> glam::DVec3 {
    RgbColorSpace::srgb().xyz_to_rgb * cmf_lerp(cie1931_interleaved(), wavelength_nm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SampledWavelengths, N_SPECTRUM_SAMPLES};
    use glam::DVec3;

    #[test]
    fn the_map_is_a_density_close_to_the_mixture() {
        let d = RgbWavelengthDensity::get();
        // Each cell holds 1/CELLS of the probability.
        for j in 0..CELLS {
            let p = f64::from(d.pdf_per_nm[j]) * f64::from(d.edges_nm[j + 1] - d.edges_nm[j]);
            assert!((p * CELLS as f64 - 1.0).abs() < 1e-3, "cell {j}: {p}");
        }
        // Draws land in their cell, with its density, and the density is the mixture's
        // within 1 % averaged over each 1 nm bin, and at each bin's centre within the
        // neighbouring bins' step (1.6 % at most; 3 % allowed).
        let n = 1 << 20;
        let mut counts = vec![0u32; BINS];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (wl, pdf) = d.sample(u);
            let cell = ((u * CELLS as f32) as usize).min(CELLS - 1);
            assert!(
                (d.edges_nm[cell]..=d.edges_nm[cell + 1]).contains(&wl),
                "{u} -> {wl}"
            );
            assert_eq!(pdf, d.pdf_per_nm[cell]);
            counts[((wl - LAMBDA_MIN_NM) as usize).min(BINS - 1)] += 1;
        }
        let mass = RgbWavelengthDensity::bin_masses();
        let total: f64 = mass.iter().sum();
        for (bin, &c) in counts.iter().enumerate() {
            let want = mass[bin] / total * n as f64;
            assert!(
                (f64::from(c) - want).abs() <= 0.01 * want + 2.0,
                "bin {bin}: {c} draws, the mixture {want}"
            );
            let wl = LAMBDA_MIN_NM + bin as f32 + 0.5;
            let cell = d.edges_nm[1..CELLS].partition_point(|&e| e <= wl);
            let pdf = f64::from(d.pdf_per_nm[cell]);
            assert!(
                (pdf / (mass[bin] / total) - 1.0).abs() < 0.03,
                "{wl}: {pdf}"
            );
        }
    }

    /// The RGB estimate (1/4) Σ S(λᵢ) w(λᵢ)/p(λᵢ) of four rotated wavelengths: its mean
    /// is the integral, and its summed variance over R, G, B (D65 × the 24 ColorChecker
    /// patches and a white) is well below the visible density's, for independent and for
    /// stratified hero variates.
    #[test]
    fn rgb_estimates_are_unbiased_and_less_noisy_than_the_visible_densitys() {
        let d65 = crate::data::illuminant("D65").expect("D65");
        let mut spectra: Vec<Box<dyn Fn(f64) -> f64>> = vec![Box::new(|_| 1.0)];
        for index in 0..24 {
            let patch = crate::data::colorchecker_patch(index);
            spectra.push(Box::new(move |wl| patch.eval(wl)));
        }
        let n = 4096;
        let strata = 64;
        let stats = |sample: &dyn Fn(f32) -> SampledWavelengths| {
            let (mut indep, mut strat, mut luminance) = (0.0, 0.0, 0.0);
            for s in &spectra {
                let f = |wl: f64| rec709_cmfs(wl) * (s(wl) * d65.eval(wl));
                let exact: DVec3 = (0..47_000)
                    .map(|k| f(360.0 + (k as f64 + 0.5) * 0.01) * 0.01)
                    .sum();
                let estimates: Vec<DVec3> = (0..n)
                    .map(|k| {
                        let w = sample((k as f32 + 0.5) / n as f32);
                        (0..N_SPECTRUM_SAMPLES)
                            .map(|i| f(f64::from(w.wavelength_nm(i))) / f64::from(w.pdf()[i]))
                            .sum::<DVec3>()
                            / N_SPECTRUM_SAMPLES as f64
                    })
                    .collect();
                let mean = estimates.iter().sum::<DVec3>() / n as f64;
                let scale = exact.abs().max_element();
                assert!(
                    (mean - exact).abs().max_element() < 2e-3 * scale,
                    "mean {mean} against {exact}"
                );
                let var = |xs: &[DVec3]| {
                    let m = xs.iter().sum::<DVec3>() / xs.len() as f64;
                    xs.iter().map(|x| (*x - m) * (*x - m)).sum::<DVec3>() / xs.len() as f64
                };
                indep += var(&estimates).element_sum();
                luminance += var(&estimates).dot(DVec3::new(0.2126, 0.7152, 0.0722).powf(2.0));
                strat += estimates
                    .chunks(n / strata)
                    .map(|c| var(c).element_sum())
                    .sum::<f64>()
                    / strata as f64;
            }
            (indep, strat, luminance)
        };
        let visible = stats(&SampledWavelengths::sample_visible);
        let rgb = stats(&SampledWavelengths::sample_rgb_output);
        let (indep, strat) = (rgb.0 / visible.0, rgb.1 / visible.1);
        let luminance = rgb.2 / visible.2;
        eprintln!(
            "over the visible density's: summed RGB variance {indep:.3} (independent), \
             {strat:.3} (stratified); the RGB channels' own variances in luminance's \
             weights {luminance:.3}"
        );
        assert!(
            indep < 0.4 && strat < 0.5,
            "variance ratios {indep} {strat}"
        );
    }
}
