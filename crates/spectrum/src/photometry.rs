//! Photometry: photopic and scotopic luminance (or illuminance) from spectral radiance
//! (or irradiance) by 1 nm summation over 360–830 nm (CIE 15:2018 §7.3; CIE S 010/E:2004).

use crate::constants::{K_M_PHOTOPIC_LM_PER_W, K_M_SCOTOPIC_LM_PER_W};
use crate::data::{cmfs, photopic_efficiency, scotopic_efficiency, Observer};
use crate::table::DenseSpectrum;

/// Photopic luminance L_v = K_m Σ L_e,λ V(λ) Δλ in cd/m² from spectral radiance in
/// W·m⁻²·sr⁻¹·nm⁻¹ (K_m = 683.002 lm/W). Applied to spectral irradiance in W·m⁻²·nm⁻¹ it
/// gives illuminance in lux.
pub fn photopic_luminance_cd_per_m2(radiance: &DenseSpectrum) -> f64 {
    K_M_PHOTOPIC_LM_PER_W * radiance.inner_product(photopic_efficiency())
}

/// Scotopic luminance L′_v = K′_m Σ L_e,λ V′(λ) Δλ in scotopic cd/m² from spectral radiance
/// in W·m⁻²·sr⁻¹·nm⁻¹ (K′_m = 1700 lm/W, as colour-science rounds 1700.06).
pub fn scotopic_luminance_cd_per_m2(radiance: &DenseSpectrum) -> f64 {
    K_M_SCOTOPIC_LM_PER_W * radiance.inner_product(scotopic_efficiency())
}

/// Scotopic-to-photopic ratio S/P of a spectrum; `None` when its photopic luminance is 0.
pub fn scotopic_photopic_ratio(spectrum: &DenseSpectrum) -> Option<f64> {
    let p = photopic_luminance_cd_per_m2(spectrum);
    let s = scotopic_luminance_cd_per_m2(spectrum);
    let ratio = s / p;
    ratio.is_finite().then_some(ratio)
}

/// Luminous efficacy of radiation K = K_m Σ S V Δλ / Σ S Δλ in lm/W over 360–830 nm;
/// `None` when the spectrum carries no power.
pub fn luminous_efficacy_lm_per_w(spectrum: &DenseSpectrum) -> Option<f64> {
    let power: f64 = spectrum.values().iter().sum();
    let k = photopic_luminance_cd_per_m2(spectrum) / power;
    k.is_finite().then_some(k)
}

/// ∫ ȳ(λ) dλ of `observer` over 360–830 nm on its 1 nm table (Σ ȳ · 1 nm), in nm; ≈ 106.857
/// for CIE 1931. The normaliser of Prism's output XYZ = ∫ L (x̄, ȳ, z̄) dλ / ∫ ȳ dλ (docs/architecture.md).
pub fn y_bar_integral_nm(observer: Observer) -> f64 {
    cmfs(observer).y_bar.values().iter().sum()
}

/// Luminance in cd/m² of an output value Y = 1 in that normalisation: K_m · ∫ ȳ dλ
/// (the EXR header `prism:cd_m2_per_unit`, ≈ 72 983 for CIE 1931).
pub fn cd_m2_per_unit(observer: Observer) -> f64 {
    K_M_PHOTOPIC_LM_PER_W * y_bar_integral_nm(observer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monochromatic_555_nm_gives_km_and_507_nm_gives_scotopic_km() {
        let mut at_555 = DenseSpectrum::from_fn(|wl| if wl == 555.0 { 1.0 } else { 0.0 });
        assert!((photopic_luminance_cd_per_m2(&at_555) - 683.002).abs() < 1e-9);
        assert!((luminous_efficacy_lm_per_w(&at_555).unwrap() - 683.002).abs() < 1e-9);
        at_555 = DenseSpectrum::from_fn(|wl| if wl == 507.0 { 1.0 } else { 0.0 });
        assert!((scotopic_luminance_cd_per_m2(&at_555) - 1700.0).abs() < 1e-6);
    }

    #[test]
    fn dark_spectra_have_no_ratio_instead_of_nan() {
        let dark = DenseSpectrum::constant(0.0);
        assert!(scotopic_photopic_ratio(&dark).is_none());
        assert!(luminous_efficacy_lm_per_w(&dark).is_none());
        // Equal-energy light: S/P = 1700 ΣV′ / (683.002 ΣV) = 2.26108 (colour-science tables).
        let sp = scotopic_photopic_ratio(&DenseSpectrum::constant(1.0)).unwrap();
        assert!((sp - 2.261_076_340_49).abs() < 1e-9, "{sp}");
    }
}
