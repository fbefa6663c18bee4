//! Optional spectral output: N equal bins over 360–830 nm, each the mean spectral radiance
//! over its band in W·m⁻²·sr⁻¹·nm⁻¹ (pbrt-v4's `SpectralFilm` does the same with its own
//! bins).
//!
//! # Estimator
//!
//! A camera sample carries radiance L(λᵢ) at four hero-rotated wavelengths, each
//! marginally distributed with density pᵢ (Wilkie et al. 2014; `SampledWavelengths`). For
//! bin b of width Δλ,
//!
//! ```text
//!     L̂_b = (1/4) Σᵢ 1[λᵢ ∈ b] L(λᵢ) / (pᵢ Δλ)
//! ```
//!
//! is unbiased for (1/Δλ) ∫_b L(λ) dλ: E[1[λ ∈ b] L(λ)/p(λ)] = ∫_b L dλ for each lane.
//! Lanes with pᵢ = 0 are skipped; after `terminate_secondary` only the hero remains with
//! p₀/4, so its term L/(p₀/4)/4 = L/p₀ is again unbiased. The film weights each sample by
//! its filter weight w and divides by Σw, as it does for XYZ.

use crate::error::InvalidParameter;
use prism_spectrum::{
    SampledSpectrum, SampledWavelengths, WavelengthDensity, LAMBDA_MAX_NM, LAMBDA_MIN_NM,
};

/// The density a film's camera samples draw their wavelengths from: the visible density
/// where it records spectral bins (their far-red and violet bins need samples the
/// colour-matching functions give little weight to), the RGB-output density where its
/// output is colour alone. The one rule for tiles, photon passes and `--explain`.
pub fn film_wavelength_density(records_spectral_bins: bool) -> WavelengthDensity {
    if records_spectral_bins {
        WavelengthDensity::Visible
    } else {
        WavelengthDensity::RgbOutput
    }
}

/// Fewest bins.
pub const MIN_SPECTRAL_BINS: u32 = 1;
/// Most bins: one per nanometre of 360–830 nm (471 = the CIE 1 nm table's sample count; the
/// bins are then 470/471 ≈ 0.998 nm wide).
pub const MAX_SPECTRAL_BINS: u32 = 471;

/// A validated number of equal spectral bins over 360–830 nm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SpectralBins {
    count: u32,
}

impl SpectralBins {
    /// `count` bins, 1..=471.
    pub fn new(count: u32) -> Result<Self, InvalidParameter> {
        if (MIN_SPECTRAL_BINS..=MAX_SPECTRAL_BINS).contains(&count) {
            Ok(Self { count })
        } else {
            Err(InvalidParameter::new(
                "film spectral bins",
                "spectral_bins",
                count,
                format!(
                    "{MIN_SPECTRAL_BINS}..={MAX_SPECTRAL_BINS} equal bins over \
                     {LAMBDA_MIN_NM}–{LAMBDA_MAX_NM} nm"
                ),
            ))
        }
    }

    pub fn count(&self) -> u32 {
        self.count
    }

    /// Width of every bin in nm: 470 nm / N.
    pub fn width_nm(&self) -> f64 {
        f64::from(LAMBDA_MAX_NM - LAMBDA_MIN_NM) / f64::from(self.count)
    }

    /// Lower edge of bin `b` in nm.
    pub fn lower_edge_nm(&self, b: u32) -> f64 {
        f64::from(LAMBDA_MIN_NM) + f64::from(b) * self.width_nm()
    }

    /// Centre of bin `b` in nm.
    pub fn centre_nm(&self, b: u32) -> f64 {
        self.lower_edge_nm(b) + 0.5 * self.width_nm()
    }

    /// Centres of all bins in nm, increasing.
    pub fn centres_nm(&self) -> Vec<f64> {
        (0..self.count).map(|b| self.centre_nm(b)).collect()
    }

    /// The bin holding `wavelength_nm`: bins are half-open [lo, hi) except the last, which
    /// also holds 830 nm; `None` outside 360–830 nm or for NaN.
    #[inline]
    pub fn bin_of(&self, wavelength_nm: f32) -> Option<usize> {
        if !(LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&wavelength_nm) {
            return None;
        }
        let t = f64::from(wavelength_nm - LAMBDA_MIN_NM) / self.width_nm();
        Some((t as usize).min(self.count as usize - 1))
    }

    /// Calls `share(bin, L̂)` for each lane of one sample that lands in a bin: the lane's
    /// share of the bin's mean radiance before weighting (what `accumulate` adds times w).
    #[inline]
    pub(crate) fn for_each_lane_share(
        &self,
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        mut share: impl FnMut(usize, f64),
    ) {
        let pdf = wavelengths.pdf();
        let scale = 1.0 / (self.width_nm() * prism_spectrum::N_SPECTRUM_SAMPLES as f64);
        for lane in 0..prism_spectrum::N_SPECTRUM_SAMPLES {
            let p = f64::from(pdf[lane]);
            let l = f64::from(radiance[lane]);
            if p <= 0.0 || l == 0.0 {
                continue;
            }
            if let Some(b) = self.bin_of(wavelengths.wavelength_nm(lane)) {
                share(b, scale * l / p);
            }
        }
    }

    /// Adds w · L̂_b of one sample (see the module documentation) to `sums`, one entry per
    /// bin. Lanes with pdf ≤ 0 or a wavelength outside the range add nothing.
    #[inline]
    pub(crate) fn accumulate(
        &self,
        sums: &mut [super::fixed_sum::FixedSum],
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        weight: f64,
    ) {
        let pdf = wavelengths.pdf();
        let scale = weight / (self.width_nm() * prism_spectrum::N_SPECTRUM_SAMPLES as f64);
        for lane in 0..prism_spectrum::N_SPECTRUM_SAMPLES {
            let p = f64::from(pdf[lane]);
            let l = f64::from(radiance[lane]);
            if p <= 0.0 || l == 0.0 {
                continue;
            }
            if let Some(b) = self.bin_of(wavelengths.wavelength_nm(lane)) {
                sums[b] += super::fixed_sum::FixedSum::from_f64(scale * l / p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_outside_1_to_471_are_rejected_naming_the_parameter() {
        for bad in [0, 472, u32::MAX] {
            let e = SpectralBins::new(bad).unwrap_err();
            assert_eq!(e.parameter, "spectral_bins");
            assert!(e.to_string().contains("1..=471"), "{e}");
        }
        // The limits: one bin over 360–830 nm, and 471 bins of 470/471 nm.
        let one = SpectralBins::new(1).unwrap();
        assert_eq!(
            (one.count(), one.width_nm(), one.centre_nm(0)),
            (1, 470.0, 595.0)
        );
        let finest = SpectralBins::new(471).unwrap();
        assert_eq!(finest.count(), 471);
        assert!((finest.width_nm() - 470.0 / 471.0).abs() < 1e-12);
    }

    #[test]
    fn bins_tile_the_range_and_the_edges_land_in_the_end_bins() {
        let bins = SpectralBins::new(10).unwrap();
        assert_eq!(bins.width_nm(), 47.0);
        assert_eq!(bins.centre_nm(0), 383.5);
        assert_eq!(bins.centre_nm(9), 806.5);
        assert_eq!(bins.bin_of(360.0), Some(0));
        assert_eq!(bins.bin_of(406.999), Some(0));
        assert_eq!(bins.bin_of(407.0), Some(1));
        assert_eq!(bins.bin_of(830.0), Some(9));
        assert_eq!(bins.bin_of(359.9), None);
        assert_eq!(bins.bin_of(830.5), None);
        assert_eq!(bins.bin_of(f32::NAN), None);
        let one = SpectralBins::new(1).unwrap();
        assert_eq!(one.centres_nm(), vec![595.0]);
    }

    #[test]
    fn terminated_secondaries_put_the_whole_estimate_on_the_hero() {
        let bins = SpectralBins::new(4).unwrap();
        let mut w = SampledWavelengths::sample_visible(0.3);
        let p0 = w.pdf()[0];
        w.terminate_secondary();
        let mut fixed = vec![crate::film::FixedSum::ZERO; 4];
        bins.accumulate(&mut fixed, SampledSpectrum::one(), &w, 1.0);
        let sums: Vec<f64> = fixed.iter().map(|s| s.to_f64()).collect();
        let b = bins.bin_of(w.wavelength_nm(0)).unwrap();
        let want = 1.0 / (f64::from(p0) * bins.width_nm());
        assert!(
            (sums[b] - want).abs() < 1e-9 * want,
            "{} vs {want}",
            sums[b]
        );
        assert_eq!(sums.iter().filter(|&&s| s != 0.0).count(), 1);
    }
}
