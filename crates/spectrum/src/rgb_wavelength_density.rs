//! The wavelength density of estimates that end as RGB (the film): 0.4 × pbrt-v4's
//! visible-wavelength density + 0.6 × the Euclidean norm of the linear Rec. 709 colour-matching
//! functions (CIE 1931 2° x̄, ȳ, z̄ through the XYZ → linear sRGB matrix), normalised over
//! 360–830 nm and tabulated on 1 nm bins (piecewise constant).
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

/// 1 nm bins over 360–830 nm.
const BINS: usize = (LAMBDA_MAX_NM - LAMBDA_MIN_NM) as usize;
/// Cells of the guide table that starts the bin search.
const GUIDE_CELLS: usize = 4096;
/// Branchless steps from a cell's first bin: a cell holds at most this many bin edges when
/// every bin weighs at least 1/(GUIDE_STEPS · GUIDE_CELLS) (the lightest, at 830 nm,
/// ≈ 1.1·10⁻⁴; tested), so the search never branches on data (the loop after the steps is
/// box's time; without data-dependent branches the packet tracer's 64 draws at a time
/// vectorise (gathers).
const GUIDE_STEPS: usize = 3;
/// Share of the visible-wavelength density in the mixture.
const VISIBLE_SHARE: f64 = 0.4;

/// The tabulated density: bin i covers [360 + i, 361 + i) nm.
pub(crate) struct RgbWavelengthDensity {
    /// cdf[i] = probability below bin i (cdf[0] = 0, cdf[BINS] = 1), in f32 so that the
    /// sampling and the returned density agree exactly.
    cdf: Box<[f32; BINS + 1]>,
    /// Density of bin i in nm⁻¹: cdf[i + 1] − cdf[i] (the bins are 1 nm wide).
    pdf_per_nm: Box<[f32; BINS]>,
    /// guide[g]: the bin holding u = g / GUIDE_CELLS.
    guide: Box<[u16; GUIDE_CELLS]>,
}

impl RgbWavelengthDensity {
    fn build() -> Self {
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
        let mass: Vec<f64> = (0..BINS)
            .map(|i| {
                VISIBLE_SHARE * visible[i] / visible_sum
                    + (1.0 - VISIBLE_SHARE) * norm[i] / norm_sum
            })
            .collect();
        let total: f64 = mass.iter().sum();
        let mut cdf = Box::new([0.0f32; BINS + 1]);
        let mut running = 0.0f64;
        for (i, m) in mass.iter().enumerate() {
            running += m / total;
            cdf[i + 1] = running as f32;
        }
        cdf[BINS] = 1.0;
        let mut pdf_per_nm = Box::new([0.0f32; BINS]);
        for i in 0..BINS {
            pdf_per_nm[i] = cdf[i + 1] - cdf[i];
            debug_assert!(pdf_per_nm[i] > 0.0, "bin {i} has no mass");
        }
        let mut guide = Box::new([0u16; GUIDE_CELLS]);
        let mut bin = 0usize;
        for (g, cell) in guide.iter_mut().enumerate() {
            let u = g as f32 / GUIDE_CELLS as f32;
            while bin + 1 < BINS && cdf[bin + 1] <= u {
                bin += 1;
            }
            *cell = bin as u16;
        }
        Self {
            cdf,
            pdf_per_nm,
            guide,
        }
    }

    /// The density, built on first use.
    pub(crate) fn get() -> &'static Self {
        static DENSITY: OnceLock<RgbWavelengthDensity> = OnceLock::new();
        DENSITY.get_or_init(Self::build)
    }

    /// The wavelength (nm) of variate `u` ∈ [0, 1) by the inverse CDF, with its density
    /// (nm⁻¹).
    #[inline(always)]
    pub(crate) fn sample(&self, u: f32) -> (f32, f32) {
        let cell = ((u * GUIDE_CELLS as f32) as usize).min(GUIDE_CELLS - 1);
        let mut bin = self.guide[cell] as usize;
        for _ in 0..GUIDE_STEPS {
            // cdf[BINS] = 1 > u: the last bin never steps on.
            bin += usize::from(self.cdf[(bin + 1).min(BINS)] <= u);
        }
        debug_assert!(bin + 1 == BINS || u < self.cdf[bin + 1], "{u}: bin {bin}");
        let pdf = self.pdf_per_nm[bin];
        let offset = ((u - self.cdf[bin]) / pdf).clamp(0.0, 1.0);
        // Within the bin whose density is returned: below its upper edge, which the
        // rounding of `offset` could reach.
        let upper = LAMBDA_MIN_NM + (bin + 1) as f32;
        let wavelength_nm = (LAMBDA_MIN_NM + bin as f32 + offset).min(upper.next_down());
        (wavelength_nm, pdf)
    }

    /// Density at `wavelength_nm` in nm⁻¹ (zero outside 360–830 nm).
    pub(crate) fn pdf(&self, wavelength_nm: f32) -> f32 {
        if !(LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&wavelength_nm) {
            return 0.0;
        }
        let bin = ((wavelength_nm - LAMBDA_MIN_NM) as usize).min(BINS - 1);
        self.pdf_per_nm[bin]
    }
}

/// Density of [`crate::SampledWavelengths::sample_rgb_output`] at `wavelength_nm`, in nm⁻¹;
/// zero outside 360–830 nm.
pub fn rgb_output_wavelength_pdf(wavelength_nm: f32) -> f32 {
    RgbWavelengthDensity::get().pdf(wavelength_nm)
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
    fn the_table_is_a_density_and_sampling_inverts_its_cdf() {
        let d = RgbWavelengthDensity::get();
        let total: f64 = d.pdf_per_nm.iter().map(|&p| f64::from(p)).sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
        // GUIDE_STEPS steps from the guide find every bin.
        assert!(d
            .pdf_per_nm
            .iter()
            .all(|&p| p * GUIDE_STEPS as f32 > 1.0 / GUIDE_CELLS as f32));
        // Every bin gets exactly its share of a fine uniform grid of variates, and each
        // sample's density is its bin's.
        let n = 1 << 20;
        let mut counts = vec![0u32; BINS];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (wl, pdf) = d.sample(u);
            assert!((LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&wl), "{u} -> {wl}");
            let bin = ((wl - LAMBDA_MIN_NM) as usize).min(BINS - 1);
            assert_eq!(pdf, d.pdf_per_nm[bin], "u {u} wl {wl}");
            assert_eq!(pdf, rgb_output_wavelength_pdf(wl));
            counts[bin] += 1;
        }
        for (bin, &c) in counts.iter().enumerate() {
            let expected = f64::from(d.pdf_per_nm[bin]) * n as f64;
            assert!(
                (f64::from(c) - expected).abs() <= 2.0,
                "bin {bin}: {c} samples, expected {expected}"
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
