//! Blackbody emission by Planck's law, in spectral radiance per nanometre:
//!
//! ```text
//!     B(λ, T) = 2hc² / λ⁵ · 1 / (exp(hc / (λ k_B T)) − 1)      [W·m⁻²·sr⁻¹·m⁻¹]
//! ```
//!
//! With λ in nm, λ⁵ gains a factor 10⁻⁴⁵ and the per-metre density is turned into a per-nm
//! one by a factor 10⁻⁹, so B = c₁ / λ_nm⁵ / expm1(c₂ / (λ_nm T)) with c₁ = 2hc²·10³⁶
//! (pbrt-v4 §4.4.1 `Blackbody`, which works in metres). c₂ is the ITS-90 value 1.4388·10⁻² m·K
//! that CIE 15:2018 §3.1 prescribes for Planckian radiators (exact hc/k_B = 1.438777·10⁻² m·K
//! would move colour temperatures by 1.6 K at 100 000 K), as colour-science uses too.
//! Normalised emission divides by the value at Wien's peak λ_max = b / T.

use crate::constants::{PLANCK_J_S, SPEED_OF_LIGHT_M_PER_S};
use crate::sampled_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

/// Wien's displacement constant b = c₂ / x₀ in m·K, x₀ = 4.965114231744276 the root of
/// 5(1 − e⁻ˣ) = x, with the ITS-90 c₂ used here (so the peak is exact for this Planck's law).
pub const WIEN_DISPLACEMENT_M_K: f64 = 1.4388e-2 / 4.965_114_231_744_276;

/// First radiation constant for spectral radiance per nm with λ in nm:
/// 2hc² · 10⁻⁹ (per nm) / 10⁻⁴⁵ (λ⁵ in nm⁵), in W·m⁻²·sr⁻¹·nm⁻¹·nm⁵.
pub const PLANCK_C1_RADIANCE_NM: f64 =
    2.0 * PLANCK_J_S * SPEED_OF_LIGHT_M_PER_S * SPEED_OF_LIGHT_M_PER_S * 1e36;
/// Second radiation constant c₂ in nm·K: ITS-90 / CIE 15:2018 §3.1 value 1.4388·10⁻² m·K.
pub const PLANCK_C2_NM_K: f64 = 1.4388e-2 * 1e9;

/// Spectral radiance of a blackbody at `temperature_k` and `wavelength_nm`, in
/// W·m⁻²·sr⁻¹·nm⁻¹. Zero for non-positive or non-finite temperatures and wavelengths.
pub fn blackbody_radiance(wavelength_nm: f64, temperature_k: f64) -> f64 {
    if !(wavelength_nm > 0.0 && temperature_k > 0.0 && temperature_k.is_finite()) {
        return 0.0;
    }
    let l2 = wavelength_nm * wavelength_nm;
    let l5 = l2 * l2 * wavelength_nm;
    // expm1 keeps precision in the Rayleigh–Jeans regime (small exponent);
    // a huge exponent gives ∞ and hence 0.
    PLANCK_C1_RADIANCE_NM / (l5 * (PLANCK_C2_NM_K / (wavelength_nm * temperature_k)).exp_m1())
}

/// `blackbody_radiance` in f32 (the renderer's precision).
#[inline]
pub fn blackbody_radiance_f32(wavelength_nm: f32, temperature_k: f32) -> f32 {
    if !(wavelength_nm > 0.0 && temperature_k > 0.0 && temperature_k.is_finite()) {
        return 0.0;
    }
    let l2 = wavelength_nm * wavelength_nm;
    let l5 = l2 * l2 * wavelength_nm;
    let exponent = PLANCK_C2_NM_K as f32 / (wavelength_nm * temperature_k);
    PLANCK_C1_RADIANCE_NM as f32 / (l5 * exponent.exp_m1())
}

/// `blackbody_radiance` at four wavelengths (one `SampledWavelengths`), times `scale`.
/// Written as whole-spectrum stages so the four lanes run as one SIMD vector (selects become
/// blends, not branches); agrees with the f64 version to ~1e-6.
#[inline]
pub fn blackbody_radiance_4(
    wavelengths_nm: [f32; N_SPECTRUM_SAMPLES],
    temperature_k: f32,
    scale: f32,
) -> SampledSpectrum {
    if !(temperature_k.is_finite() && temperature_k > 0.0) {
        return SampledSpectrum::zero();
    }
    let c1 = PLANCK_C1_RADIANCE_NM as f32 * scale;
    let c2_over_t = PLANCK_C2_NM_K as f32 / temperature_k;
    let wl = SampledSpectrum::new(wavelengths_nm);
    let l2 = wl * wl;
    let l5 = l2 * l2 * wl;
    let em1 = exp_m1_positive(c2_over_t / wl);
    let b = c1 / (l5 * em1);
    // Non-positive (or NaN) wavelengths give negative/NaN values: zero them.
    b.zip_map(wl, |b, wl| if wl > 0.0 { b } else { 0.0 })
}

/// eˣ − 1 for x > 0 per lane without library calls, so the lanes vectorise: a Taylor
/// series below 1/4 (truncation < 5e-8 relative), else Cephes `expf` (range reduction by
/// ln 2 in two parts, degree-6 polynomial, 2ⁿ built from the exponent bits), ∞ above 88.
#[inline(always)]
fn exp_m1_positive(x: SampledSpectrum) -> SampledSpectrum {
    // Taylor: x + x²/2 + … + x⁶/720 (Horner).
    let series = x.map(|x| {
        x * (1.0
            + x * (0.5
                + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x * (1.0 / 720.0))))))
    });
    // Cephes expf on the clamped argument. n = round(x·log₂e) by the 1.5·2²³ trick: the
    // integer sits in the low mantissa bits of `shifted` (no float → int conversion).
    const ROUNDER: f32 = 12_582_912.0;
    let xc = x.map(|x| x.min(88.0));
    let shifted = xc.map(|x| x * std::f32::consts::LOG2_E + ROUNDER);
    let n = shifted - ROUNDER;
    let r = xc.zip_map(n, |x, n| x - n * 0.693_359_4 - n * -2.121_944_4e-4);
    let exp_r = r.map(|r| {
        let poly =
            ((((1.987_569_1e-4 * r + 1.398_199_9e-3) * r + 8.333_452e-3) * r + 4.166_579_6e-2) * r
                + 1.666_666_5e-1)
                * r
                + 0.5;
        poly * r * r + r + 1.0
    });
    // 2ⁿ from the exponent bits (n ≤ 127 since x ≤ 88).
    let two_n = shifted.map(|s| {
        let n_bits = (s.to_bits() as i32).wrapping_sub(ROUNDER.to_bits() as i32);
        f32::from_bits((n_bits.wrapping_add(127) as u32) << 23)
    });
    let big = exp_r * two_n - 1.0;
    let mut out = SampledSpectrum::zero();
    for lane in 0..N_SPECTRUM_SAMPLES {
        let small = if x[lane] < 0.25 {
            series[lane]
        } else {
            big[lane]
        };
        out[lane] = if x[lane] > 88.0 { f32::INFINITY } else { small };
    }
    out
}

/// Wavelength of maximal spectral radiance per nm, λ_max = b / T (Wien), in nm.
pub fn wien_peak_wavelength_nm(temperature_k: f64) -> f64 {
    WIEN_DISPLACEMENT_M_K / temperature_k * 1e9
}

/// B(λ_max, T): the largest spectral radiance per nm of a blackbody at `temperature_k`.
pub fn blackbody_peak_radiance(temperature_k: f64) -> f64 {
    blackbody_radiance(wien_peak_wavelength_nm(temperature_k), temperature_k)
}

/// B(λ, T) / B(λ_max, T): 1 at Wien's peak; zero for invalid temperatures.
pub fn blackbody_normalized(wavelength_nm: f64, temperature_k: f64) -> f64 {
    let peak = blackbody_peak_radiance(temperature_k);
    if peak > 0.0 && peak.is_finite() {
        blackbody_radiance(wavelength_nm, temperature_k) / peak
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Planck's law written out in SI units, independently of the nm-scaled constants.
    fn planck_si_per_nm(wavelength_nm: f64, temperature_k: f64) -> f64 {
        // Planck's law in SI units, c₂ = 1.4388e-2 m·K (ITS-90, CIE 15:2018 §3.1).
        let (h, c, c2) = (6.626_070_15e-34, 299_792_458.0, 1.4388e-2);
        let lambda_m = wavelength_nm * 1e-9;
        let per_m =
            2.0 * h * c * c / lambda_m.powi(5) / ((c2 / (lambda_m * temperature_k)).exp() - 1.0);
        per_m * 1e-9
    }

    #[test]
    fn radiance_matches_colour_science_planck_law() {
        // colour-science 0.4.7 docstring: planck_law(500e-9, 5500) = 20472701909806.5
        // W·m⁻²·sr⁻¹·m⁻¹ with c₁ = 3.741771e-16 W·m² (2πhc² rounded, 2.3e-7 below the exact
        // value we use) and c₂ = 1.4388e-2 m·K.
        let l = blackbody_radiance(500.0, 5500.0);
        assert!((l / 1e-9 / 20_472_701_909_806.5 - 1.0).abs() < 3e-7, "{l}");
    }

    #[test]
    fn radiance_at_500_nm_and_5000_k_matches_the_closed_form() {
        let expected = planck_si_per_nm(500.0, 5000.0);
        // ≈ 1.2108e4 W·m⁻²·sr⁻¹·nm⁻¹ (hand check: c₁/λ⁵ = 3.811e6, exp(5.7551) − 1 = 314.8).
        assert!((expected - 1.2107e4).abs() < 5.0, "{expected}");
        let got = blackbody_radiance(500.0, 5000.0);
        assert!((got / expected - 1.0).abs() < 1e-12, "{got} vs {expected}");
        let got32 = blackbody_radiance_f32(500.0, 5000.0) as f64;
        assert!((got32 / expected - 1.0).abs() < 1e-5);
    }

    #[test]
    fn peak_is_at_wiens_wavelength() {
        for temperature_k in [1000.0, 3000.0, 5000.0, 6500.0, 10_000.0] {
            let peak_nm = wien_peak_wavelength_nm(temperature_k);
            let b = |wl: f64| blackbody_radiance(wl, temperature_k);
            // The peak is a maximum: the neighbours ±0.01 % are lower, and the numerical
            // derivative vanishes there to the precision of Wien's constant.
            let h = peak_nm * 1e-4;
            assert!(b(peak_nm) > b(peak_nm - h) && b(peak_nm) > b(peak_nm + h));
            let slope = (b(peak_nm + h) - b(peak_nm - h)) / (2.0 * h);
            let curvature_scale = b(peak_nm) / peak_nm;
            assert!(
                slope.abs() < 1e-6 * curvature_scale,
                "{temperature_k} K: {slope}"
            );
            assert!((blackbody_normalized(peak_nm, temperature_k) - 1.0).abs() < 1e-15);
            assert!(blackbody_normalized(peak_nm * 1.3, temperature_k) < 1.0);
        }
        assert!((wien_peak_wavelength_nm(5000.0) - 579.563_705).abs() < 1e-5);
    }

    #[test]
    fn four_lane_version_agrees_with_f64() {
        let wavelengths_nm = [360.0f32, 555.5, 700.25, 830.0];
        for temperature_k in [800.0f32, 2856.0, 6504.0, 25_000.0] {
            let got = blackbody_radiance_4(wavelengths_nm, temperature_k, 2.0);
            for (lane, &wl) in wavelengths_nm.iter().enumerate() {
                let expected = 2.0 * blackbody_radiance(wl as f64, temperature_k as f64);
                assert!(
                    (got[lane] as f64 / expected - 1.0).abs() < 2e-5,
                    "{wl} nm, {temperature_k} K: {} vs {expected}",
                    got[lane]
                );
            }
        }
    }

    #[test]
    fn fast_exp_m1_is_accurate_over_the_range() {
        let mut x = 1e-6f32;
        while x < 88.0 {
            let expected = (x as f64).exp_m1();
            let got = exp_m1_positive(SampledSpectrum::splat(x))[0] as f64;
            assert!(
                (got / expected - 1.0).abs() < 1e-6,
                "expm1({x}) = {got}, expected {expected}"
            );
            x *= 1.01;
        }
        let big = exp_m1_positive(SampledSpectrum::new([89.0, 1e30, f32::INFINITY, 0.5]));
        assert_eq!(&big.values[..3], &[f32::INFINITY; 3]);
        assert!((big[3] as f64 / 0.5f64.exp_m1() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn invalid_inputs_give_zero() {
        assert_eq!(blackbody_radiance(500.0, 0.0), 0.0);
        assert_eq!(blackbody_radiance(500.0, -10.0), 0.0);
        assert_eq!(blackbody_radiance(500.0, f64::NAN), 0.0);
        assert_eq!(blackbody_radiance(500.0, f64::INFINITY), 0.0);
        assert_eq!(blackbody_radiance(-1.0, 5000.0), 0.0);
        assert_eq!(blackbody_radiance(360.0, 10.0), 0.0); // exp overflows → 0, not NaN
        assert_eq!(blackbody_radiance_f32(500.0, -1.0), 0.0);
        assert!(blackbody_radiance_4([360.0; 4], 0.0, 1.0).is_black());
        assert!(blackbody_radiance_4([-5.0, 0.0, 500.0, 600.0], 10.0, 1.0).is_black());
        assert_eq!(blackbody_normalized(500.0, 0.0), 0.0);
    }
}
