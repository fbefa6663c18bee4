//! Spectral samples → CIE 1931 XYZ in the output normalisation of docs/architecture.md ("Units and conventions"): XYZ =
//! ∫ L(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ ȳ dλ, so a flat spectral radiance of 1 gives Y = 1 (the
//! pbrt-v4 `SampledSpectrum::ToXYZ` / Mitsuba 3 convention), and Y · `cd_m2_per_unit()` is
//! the luminance in cd/m² (683.002 lm/W · ∫ L ȳ dλ).

use std::sync::OnceLock;

use glam::DVec3;
use prism_spectrum::data::{cmfs, Cmfs};
use prism_spectrum::photometry::{cd_m2_per_unit as photometry_cd_m2_per_unit, y_bar_integral_nm};
use prism_spectrum::Observer;

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
            SampledWavelengths::sample_rgb_output,
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
