//! Photometric strengths (lm, cd, cd/m², lx) → the factor that makes a relative emission
//! spectrum absolute. The photometric value of a spectral quantity S(λ) is
//! K_m Σ S(λ) ȳ(λ) Δλ with K_m = 683.002 lm/W, ȳ the CIE 1931 colour-matching function
//! (= V(λ), the photopic luminous efficiency) and the sum over 360–830 nm at Δλ = 1 nm —
//! exactly the luminance the film reports (`film::xyz`: Y · K_m ∫ȳ dλ with
//! Y = ∫ L ȳ dλ / ∫ ȳ dλ). The per-light formulas are in docs/lights.md.

use std::f64::consts::PI;

use prism_spectrum::constants::K_M_PHOTOPIC_LM_PER_W;
use prism_spectrum::data::cmfs;
use prism_spectrum::{Observer, Spectrum};

/// K_m Σ S(λ) ȳ(λ) Δλ: the photometric value of `spectrum` taken as an absolute
/// radiometric quantity (cd/m² per W·m⁻²·sr⁻¹·nm⁻¹ of radiance, cd per W·sr⁻¹·nm⁻¹ of
/// intensity, lx per W·m⁻²·nm⁻¹ of irradiance).
pub fn photometric_value(spectrum: &Spectrum) -> f64 {
    K_M_PHOTOPIC_LM_PER_W
        * spectrum
            .to_dense()
            .inner_product(&cmfs(Observer::Cie1931).y_bar)
}

/// The factor k such that `photometric_value(k · spectrum)` = `target` (≥ 0); an error
/// message when the spectrum has no luminous content, so no scale can reach the target.
pub fn photometric_scale(spectrum: &Spectrum, target: f64) -> Result<f64, String> {
    if !(target.is_finite() && target >= 0.0) {
        return Err(format!("expected a finite value ≥ 0, found {target}"));
    }
    if target == 0.0 {
        return Ok(0.0);
    }
    let per_unit = photometric_value(spectrum);
    if !(per_unit.is_finite() && per_unit > 0.0) {
        return Err(format!(
            "the emission spectrum has no luminous content (683.002 lm/W × Σ S(λ) ȳ(λ) Δλ = \
             {per_unit}), so a photometric strength cannot set its scale; use `scale` instead"
        ));
    }
    let k = target / per_unit;
    if !(k.is_finite() && (k as f32).is_finite()) {
        return Err(format!(
            "{target} needs the spectrum scaled by {k:e}, beyond single precision"
        ));
    }
    Ok(k)
}

/// Luminous intensity I = Φ / 4π (cd) of an isotropic point source of flux Φ (lm).
pub fn point_intensity_from_flux(flux_lm: f64) -> f64 {
    flux_lm / (4.0 * PI)
}

/// Luminance L = Φ / (π A · sides) (cd/m²) of a Lambertian emitter of area A (m²) that
/// emits Φ (lm) from one side (or both: `sides` = 2); Φ = ∫_A ∫_hemisphere L cos θ dω dA.
pub fn lambertian_luminance_from_flux(flux_lm: f64, area_m2: f64, sides: f64) -> f64 {
    flux_lm / (PI * area_m2 * sides)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn photometric_value_matches_the_film_normalisation() {
        // A flat spectrum of 1 has luminance K_m ∫ȳ dλ = cd_m2_per_unit.
        let v = photometric_value(&Spectrum::constant(1.0));
        assert!(
            (v - crate::film::xyz::cd_m2_per_unit()).abs() < 1e-9 * v,
            "{v}"
        );
        let k = photometric_scale(&Spectrum::constant(2.0), 1000.0).unwrap();
        assert!((k * photometric_value(&Spectrum::constant(2.0)) - 1000.0).abs() < 1e-9);
        assert_eq!(photometric_scale(&Spectrum::constant(0.0), 0.0), Ok(0.0));
    }

    #[test]
    fn a_spectrum_without_luminous_content_cannot_take_a_photometric_strength() {
        // Zero over the visible range: only above 830 nm.
        let ir = Spectrum::piecewise_linear(&[900.0, 1000.0], &[1.0, 1.0]).unwrap();
        let e = photometric_scale(&ir, 100.0).unwrap_err();
        assert!(e.contains("no luminous content"), "{e}");
        assert!(photometric_scale(&Spectrum::constant(1.0), f64::NAN).is_err());
        assert!(photometric_scale(&Spectrum::constant(1.0), -1.0).is_err());
    }
}
