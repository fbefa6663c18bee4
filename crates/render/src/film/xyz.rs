//! Spectral samples → CIE 1931 XYZ in the output normalisation of docs/architecture.md ("Units and conventions"): XYZ =
//! ∫ L(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ ȳ dλ, so a flat spectral radiance of 1 gives Y = 1 (the
//! pbrt-v4 `SampledSpectrum::ToXYZ` / Mitsuba 3 convention), and Y · `cd_m2_per_unit()` is
//! the luminance in cd/m² (683.002 lm/W · ∫ L ȳ dλ).

use std::sync::OnceLock;

use glam::DVec3;
use prism_spectrum::data::{cmfs, Cmfs};
use prism_spectrum::photometry::{cd_m2_per_unit as photometry_cd_m2_per_unit, y_bar_integral_nm};
use prism_spectrum::{
    Observer, SampledSpectrum, SampledWavelengths, DENSE_SAMPLE_COUNT, LAMBDA_MIN_NM,
    N_SPECTRUM_SAMPLES,
};

fn cie1931() -> &'static Cmfs {
    cmfs(Observer::Cie1931)
}

/// ∫ ȳ dλ of CIE 1931 (prism-spectrum `photometry::y_bar_integral_nm`), cached.
pub fn cie_y_integral_nm() -> f64 {
    static Y: OnceLock<f64> = OnceLock::new();
    *Y.get_or_init(|| y_bar_integral_nm(Observer::Cie1931))
}

/// Luminance in cd/m² of an output value Y = 1 (prism-spectrum `photometry::cd_m2_per_unit`).
pub fn cd_m2_per_unit() -> f64 {
    photometry_cd_m2_per_unit(Observer::Cie1931)
}

/// XYZ of a flat spectral radiance of 1 in the output normalisation:
/// (∫x̄ / ∫ȳ, 1, ∫z̄ / ∫ȳ) over the 1 nm CIE 1931 table (equal-energy white E; X and Z
/// are ≈ 1 because the three CMFs have nearly equal integrals). Y is exactly 1, so a
/// diagnostic output written as a flat spectrum of value v has Y = v exactly.
pub fn flat_spectrum_xyz() -> DVec3 {
    static E: OnceLock<DVec3> = OnceLock::new();
    *E.get_or_init(|| {
        let c = cie1931();
        let y = cie_y_integral_nm();
        DVec3::new(
            c.x_bar.values().iter().sum::<f64>() / y,
            1.0,
            c.z_bar.values().iter().sum::<f64>() / y,
        )
    })
}

/// XYZ of a linear Rec.709 (sRGB primaries, D65) colour: `RgbColorSpace::srgb().rgb_to_xyz`,
/// the inverse of the matrix `Film::finish` applies, so the RGB comes back out of the film.
pub fn rec709_to_xyz(rgb: [f32; 3]) -> DVec3 {
    static M: OnceLock<glam::DMat3> = OnceLock::new();
    let m = M.get_or_init(|| prism_spectrum::rgb_space::RgbColorSpace::srgb().rgb_to_xyz);
    *m * DVec3::from(rgb.map(f64::from))
}

/// The XYZ estimate of one hero-wavelength sample (prism-spectrum
/// `colorimetry::sampled_radiance_to_xyz`).
pub use prism_spectrum::colorimetry::sampled_radiance_to_xyz as xyz_of_sample;

/// The CIE 1931 x̄, ȳ, z̄ interleaved per 1 nm sample (360–830 nm), for `XyzWeights`.
fn cie1931_rows() -> &'static [DVec3; DENSE_SAMPLE_COUNT] {
    static TABLE: OnceLock<Box<[DVec3; DENSE_SAMPLE_COUNT]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let c = cie1931();
        let (x, y, z) = (c.x_bar.values(), c.y_bar.values(), c.z_bar.values());
        let mut t = Box::new([DVec3::ZERO; DENSE_SAMPLE_COUNT]);
        for (i, row) in t.iter_mut().enumerate() {
            *row = DVec3::new(x[i], y[i], z[i]);
        }
        t
    })
}

/// The linear map from one camera sample's radiance lanes to its XYZ estimate:
/// column i is (x̄, ȳ, z̄)(λᵢ) / (4 p(λᵢ) ∫ȳ dλ) (zero where p(λᵢ) = 0, a terminated
/// secondary), so `xyz(L)` = Σᵢ column i · L(λᵢ) is `xyz_of_sample(L, wavelengths)` up to the
/// rounding of the reordered products (≤ a few ulp). The film converts both the beauty and
/// the illumination AOV of a sample at the same wavelengths: building this once per sample
/// halves the colour-matching lookups (callgrind: ≈ 170 instructions per conversion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XyzWeights {
    columns: [DVec3; N_SPECTRUM_SAMPLES],
}

impl XyzWeights {
    pub fn new(wavelengths: &SampledWavelengths) -> Self {
        let table = cie1931_rows();
        let pdf = wavelengths.pdf();
        let norm = 1.0 / (N_SPECTRUM_SAMPLES as f64 * cie_y_integral_nm());
        let columns = std::array::from_fn(|lane| {
            let p = f64::from(pdf[lane]);
            let x = f64::from(wavelengths.wavelength_nm(lane) - LAMBDA_MIN_NM);
            // The CMFs are 0 outside the table (`DenseSpectrum::eval`), like a lane of pdf 0.
            if !(p > 0.0 && x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f64) {
                return DVec3::ZERO;
            }
            // SAFETY: x ∈ [0, 470] (checked above, so not NaN), inside u32: the truncation
            // is defined, and is the floor; `min` keeps i + 1 in the table.
            let i = (unsafe { x.to_int_unchecked::<u32>() } as usize).min(DENSE_SAMPLE_COUNT - 2);
            let t = x - i as f64;
            let (a, b) = (table[i], table[i + 1]);
            (a + t * (b - a)) * (norm / p)
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
    use prism_spectrum::{SampledSpectrum, SampledWavelengths};

    #[test]
    fn y_integral_matches_the_cie_table() {
        let y = cie_y_integral_nm();
        assert!((y - 106.857).abs() < 0.01, "{y}");
        assert!((cd_m2_per_unit() - 683.002 * y).abs() < 1e-9);
    }

    #[test]
    fn flat_radiance_integrates_to_y_one_with_stratified_wavelengths() {
        for sample in [
            SampledWavelengths::sample_visible as fn(f32) -> SampledWavelengths,
            SampledWavelengths::sample_uniform,
        ] {
            let n = 20_000;
            let mut sum = DVec3::ZERO;
            for i in 0..n {
                let u = (i as f32 + 0.5) / n as f32;
                sum += xyz_of_sample(SampledSpectrum::one(), &sample(u));
            }
            let xyz = sum / n as f64;
            assert!((xyz.y - 1.0).abs() < 2e-3, "{xyz}");
            // Equal-energy white: X ≈ Y ≈ Z (the CMFs have equal integrals).
            assert!(
                (xyz.x - 1.0).abs() < 5e-3 && (xyz.z - 1.0).abs() < 5e-3,
                "{xyz}"
            );
        }
    }

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
                    let (want, got) = (xyz_of_sample(l, &w), weights.xyz(l));
                    // Rounding is relative to the terms, not to a cancelled sum.
                    let scale = xyz_of_sample(l.map(f32::abs), &w).max_element().max(1e-30);
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

    #[test]
    fn terminated_secondaries_keep_the_estimate_unbiased() {
        let n = 20_000;
        let mut sum = 0.0;
        for i in 0..n {
            let mut w = SampledWavelengths::sample_visible((i as f32 + 0.5) / n as f32);
            w.terminate_secondary();
            sum += xyz_of_sample(SampledSpectrum::one(), &w).y;
        }
        assert!((sum / n as f64 - 1.0).abs() < 2e-3);
    }
}
