//! The XYZ of one camera sample as a linear map of its radiance lanes, built once per
//! sample: the film converts the beauty and the illumination AOV of a sample at the same
//! wavelengths, and the bandwidth probe the same draws, with the same weights.

use glam::DVec3;

use crate::colorimetry::{cie1931_interleaved, cmf_lerp, y_bar_integral_1931_nm};
use crate::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

/// The linear map from one camera sample's radiance lanes to its XYZ estimate:
/// column i is (x̄, ȳ, z̄)(λᵢ) / (4 p(λᵢ) ∫ȳ dλ) (zero where p(λᵢ) = 0, a terminated
/// secondary), so `xyz(L)` = Σᵢ column i · L(λᵢ) is `sampled_radiance_to_xyz(L, wavelengths)`
/// up to the rounding of the reordered products (≤ a few ulp). The film converts both the beauty and
/// the illumination AOV of a sample at the same wavelengths: building this once per sample
/// halves the colour-matching lookups (callgrind: ≈ 170 instructions per conversion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XyzWeights {
    columns: [DVec3; N_SPECTRUM_SAMPLES],
}

impl XyzWeights {
    pub fn new(wavelengths: &SampledWavelengths) -> Self {
        let table = cie1931_interleaved();
        let pdf = wavelengths.pdf();
        let norm = 1.0 / (N_SPECTRUM_SAMPLES as f64 * y_bar_integral_1931_nm());
        let columns = std::array::from_fn(|lane| {
            let p = f64::from(pdf[lane]);
            // A lane of pdf 0 (a terminated secondary) weighs nothing, as in the conversion.
            if p > 0.0 {
                cmf_lerp(table, f64::from(wavelengths.wavelength_nm(lane))) * (norm / p)
            } else {
                DVec3::ZERO
            }
        });
        Self { columns }
    }

    /// XYZ of `radiance` (finite) at the wavelengths these weights were built for.
    #[inline]
    pub fn xyz(&self, radiance: SampledSpectrum) -> DVec3 {
        let c = &self.columns;
        let l = radiance.values.map(f64::from);
        (c[0] * l[0] + c[1] * l[1]) + (c[2] * l[2] + c[3] * l[3])
    }

    /// The Y of [`Self::xyz`] alone.
    #[inline]
    pub fn y(&self, radiance: SampledSpectrum) -> f64 {
        let c = &self.columns;
        let l = radiance.values.map(f64::from);
        (c[0].y * l[0] + c[1].y * l[1]) + (c[2].y * l[2] + c[3].y * l[3])
    }

    /// Lane `lane`'s term of [`Self::xyz`]: its column times L(λ_lane).
    #[inline]
    pub fn lane(&self, radiance: SampledSpectrum, lane: usize) -> DVec3 {
        self.columns[lane] * f64::from(radiance[lane])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::sampled_radiance_to_xyz;

    #[test]
    fn xyz_weights_match_the_per_sample_conversion() {
        // Every wavelength variate, with and without terminated secondaries, and radiance
        // with zero, tiny, large and mixed-sign lanes: the weights give the conversion's
        // XYZ up to the rounding of the reordered products.
        let spectra = [
            SampledSpectrum::new([1.0, 2.0, 0.5, 3.0]),
            SampledSpectrum::new([0.0, 1e-6, 4e3, 0.0]),
            SampledSpectrum::new([-1.0, 2.0, -0.25, 7.0]),
        ];
        for i in 0..2000 {
            let u = (i as f32 + 0.5) / 2000.0;
            for terminate in [false, true] {
                let mut w = SampledWavelengths::sample_visible(u);
                if terminate {
                    w.terminate_secondary();
                }
                let weights = XyzWeights::new(&w);
                for l in spectra {
                    let (want, got) = (sampled_radiance_to_xyz(l, &w), weights.xyz(l));
                    // Rounding is relative to the terms, not to a cancelled sum.
                    let scale = sampled_radiance_to_xyz(l.map(f32::abs), &w)
                        .max_element()
                        .max(1e-30);
                    assert!(
                        (want - got).abs().max_element() <= 1e-12 * scale,
                        "{u} {terminate}: {want} vs {got}"
                    );
                    assert!((weights.y(l) - want.y).abs() <= 1e-12 * scale);
                    let lanes: DVec3 = (0..N_SPECTRUM_SAMPLES).map(|i| weights.lane(l, i)).sum();
                    assert!((lanes - want).abs().max_element() <= 1e-12 * scale);
                }
            }
        }
    }
}
