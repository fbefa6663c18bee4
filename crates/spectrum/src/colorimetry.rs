//! Spectrum → CIE XYZ by 1 nm summation over 360–830 nm, chromaticity coordinates
//! (xyY, CIE 1960 uv), CIELAB and the CIEDE2000 colour difference.
//!
//! All integrals are sums over the [`DenseSpectrum`] grid with Δλ = 1 nm (CIE 15:2018 §7.1,
//! eqs. 7.1–7.3 with summation replacing the integral), which is exactly colour-science's
//! `sd_to_XYZ(..., method="Integration")` for data already on 360–830 nm at 1 nm.

use glam::{DVec2, DVec3};

use crate::constants::{DENSE_SAMPLE_COUNT, K_M_PHOTOPIC_LM_PER_W, LAMBDA_MIN_NM};
use crate::data::{cmfs, Observer};
use crate::sampled_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};
use crate::sampled_wavelengths::SampledWavelengths;
use crate::table::DenseSpectrum;

/// The unnormalised tristimulus sums (Σ S x̄ Δλ, Σ S ȳ Δλ, Σ S z̄ Δλ) of a spectrum,
/// Δλ = 1 nm. Units are those of `spectrum` times nm.
pub fn tristimulus_sums(spectrum: &DenseSpectrum, observer: Observer) -> DVec3 {
    let c = cmfs(observer);
    DVec3::new(
        spectrum.inner_product(&c.x_bar),
        spectrum.inner_product(&c.y_bar),
        spectrum.inner_product(&c.z_bar),
    )
}

/// XYZ of a reflectance (or transmittance) under an illuminant, relative colorimetry
/// (CIE 15:2018 eqs. 7.1–7.3): XYZ = k Σ R I x̄ Δλ, k = 100 / Σ I ȳ Δλ, so a perfect
/// reflector has Y = 100. Returns zero when the illuminant has no luminance (Σ I ȳ = 0)
/// or the normalisation is not finite.
pub fn reflectance_to_xyz(
    reflectance: &DenseSpectrum,
    illuminant: &DenseSpectrum,
    observer: Observer,
) -> DVec3 {
    let c = cmfs(observer);
    let k = 100.0 / illuminant.inner_product(&c.y_bar);
    if !k.is_finite() {
        return DVec3::ZERO;
    }
    let stimulus = reflectance.product(illuminant);
    tristimulus_sums(&stimulus, observer) * k
}

/// XYZ of the perfect reflecting diffuser under `illuminant` (its white point, Y = 100).
/// Zero when the illuminant has no luminance.
pub fn illuminant_white_xyz(illuminant: &DenseSpectrum, observer: Observer) -> DVec3 {
    let c = cmfs(observer);
    let k = 100.0 / illuminant.inner_product(&c.y_bar);
    if !k.is_finite() {
        return DVec3::ZERO;
    }
    tristimulus_sums(illuminant, observer) * k
}

/// Absolute XYZ of an emitted spectral radiance L(λ) in W·m⁻²·sr⁻¹·nm⁻¹:
/// XYZ = K_m Σ L x̄ Δλ (and ȳ, z̄) with K_m = 683.002 lm/W, so Y is the luminance in cd/m²
/// (CIE 15:2018 eq. 7.8 with k = K_m). The same K_m is used with the 1964 observer, as
/// Prism's convention (CIE gives no K_m for the 10° observer).
pub fn emission_to_xyz_cd_per_m2(radiance: &DenseSpectrum, observer: Observer) -> DVec3 {
    tristimulus_sums(radiance, observer) * K_M_PHOTOPIC_LM_PER_W
}

/// The XYZ estimate of one hero-wavelength sample of spectral radiance in Prism's output
/// normalisation: (1/4) Σᵢ L(λᵢ) (x̄, ȳ, z̄)(λᵢ) / p(λᵢ) / ∫ ȳ dλ with the CIE 1931 CMFs linearly
/// interpolated on their 1 nm table (pbrt-v4 `SampledSpectrum::ToXYZ`), so a flat radiance of
/// 1 gives Y = 1 in expectation. Lanes with pdf 0 (terminated secondaries) contribute nothing.
pub fn sampled_radiance_to_xyz(
    radiance: SampledSpectrum,
    wavelengths: &SampledWavelengths,
) -> DVec3 {
    let table = cie1931_interleaved();
    let pdf = wavelengths.pdf();
    let mut xyz = DVec3::ZERO;
    for lane in 0..N_SPECTRUM_SAMPLES {
        let p = f64::from(pdf[lane]);
        let l = f64::from(radiance[lane]);
        if p <= 0.0 || l == 0.0 {
            continue;
        }
        let wl = f64::from(wavelengths.wavelength_nm(lane));
        xyz += cmf_lerp(table, wl) * (l / p);
    }
    xyz / (N_SPECTRUM_SAMPLES as f64 * y_bar_integral_1931_nm())
}

/// The CIE 1931 x̄, ȳ, z̄ interleaved per 1 nm sample (one row per wavelength), for
/// `sampled_radiance_to_xyz`: the film converts every camera sample, and one index
/// computation for the three functions instead of three `DenseSpectrum::eval` calls halves
/// its cost. Same values and arithmetic, so the same bits (tested).
pub(crate) fn cie1931_interleaved() -> &'static [DVec3; DENSE_SAMPLE_COUNT] {
    static TABLE: std::sync::OnceLock<Box<[DVec3; DENSE_SAMPLE_COUNT]>> =
        std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let c = cmfs(Observer::Cie1931);
        let (x, y, z) = (c.x_bar.values(), c.y_bar.values(), c.z_bar.values());
        let mut t = Box::new([DVec3::ZERO; DENSE_SAMPLE_COUNT]);
        for (i, row) in t.iter_mut().enumerate() {
            *row = DVec3::new(x[i], y[i], z[i]);
        }
        t
    })
}

/// `DenseSpectrum::eval` of the three rows at once (linear between the 1 nm samples, zero
/// outside 360–830 nm), with the same arithmetic per component.
#[inline(always)]
pub(crate) fn cmf_lerp(table: &[DVec3; DENSE_SAMPLE_COUNT], wavelength_nm: f64) -> DVec3 {
    let x = wavelength_nm - LAMBDA_MIN_NM as f64;
    if !(x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f64) {
        return DVec3::ZERO;
    }
    let i = (x as usize).min(DENSE_SAMPLE_COUNT - 2);
    let t = x - i as f64;
    let (a, b) = (table[i], table[i + 1]);
    DVec3::new(
        a.x + t * (b.x - a.x),
        a.y + t * (b.y - a.y),
        a.z + t * (b.z - a.z),
    )
}

/// ∫ ȳ dλ of CIE 1931, cached (the hot-path normaliser of [`sampled_radiance_to_xyz`]).
pub(crate) fn y_bar_integral_1931_nm() -> f64 {
    static Y: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *Y.get_or_init(|| crate::photometry::y_bar_integral_nm(Observer::Cie1931))
}

/// Chromaticity (x, y) of XYZ; `None` for black (X + Y + Z = 0) or non-finite input.
pub fn xyz_to_xy(xyz: DVec3) -> Option<DVec2> {
    let sum = xyz.x + xyz.y + xyz.z;
    if sum == 0.0 || !sum.is_finite() {
        return None;
    }
    Some(DVec2::new(xyz.x / sum, xyz.y / sum))
}

/// XYZ → xyY (CIE 15:2018 eq. 7.4). Black (X + Y + Z = 0) gives (0, 0, 0), as colour-science
/// 0.4.7's `XYZ_to_xyY` does; use [`xyz_to_xyy_or`] to give black a white's chromaticity.
pub fn xyz_to_xyy(xyz: DVec3) -> DVec3 {
    xyz_to_xyy_or(xyz, DVec2::ZERO)
}

/// XYZ → xyY, with black (or non-finite X + Y + Z) given the chromaticity `black_xy`
/// (typically the adopted white's) and Y as given.
pub fn xyz_to_xyy_or(xyz: DVec3, black_xy: DVec2) -> DVec3 {
    let xy = xyz_to_xy(xyz).unwrap_or(black_xy);
    DVec3::new(xy.x, xy.y, xyz.y)
}

/// xyY → XYZ; y = 0 gives black (0, 0, 0).
pub fn xyy_to_xyz(xyy: DVec3) -> DVec3 {
    let (x, y, big_y) = (xyy.x, xyy.y, xyy.z);
    if y == 0.0 {
        return DVec3::ZERO;
    }
    DVec3::new(x * big_y / y, big_y, (1.0 - x - y) * big_y / y)
}

/// XYZ → CIE 1960 UCS (u, v): u = 4X / (X + 15Y + 3Z), v = 6Y / (X + 15Y + 3Z)
/// (CIE 15:2018 §9.3, used for CCT). `None` when the denominator is zero or not finite.
pub fn xyz_to_uv_1960(xyz: DVec3) -> Option<DVec2> {
    let d = xyz.x + 15.0 * xyz.y + 3.0 * xyz.z;
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    Some(DVec2::new(4.0 * xyz.x / d, 6.0 * xyz.y / d))
}

/// CIE 1931 (x, y) → CIE 1960 (u, v): u = 4x / (−2x + 12y + 3), v = 6y / (−2x + 12y + 3).
/// `None` when the denominator is zero.
pub fn xy_to_uv_1960(xy: DVec2) -> Option<DVec2> {
    let d = -2.0 * xy.x + 12.0 * xy.y + 3.0;
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    Some(DVec2::new(4.0 * xy.x / d, 6.0 * xy.y / d))
}

/// CIE 1960 (u, v) → CIE 1931 (x, y): x = 3u / (2u − 8v + 4), y = 2v / (2u − 8v + 4).
/// `None` when the denominator is zero.
pub fn uv_1960_to_xy(uv: DVec2) -> Option<DVec2> {
    let d = 2.0 * uv.x - 8.0 * uv.y + 4.0;
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    Some(DVec2::new(3.0 * uv.x / d, 2.0 * uv.y / d))
}

/// CIE 15:2018 eq. 8.3 constant ε = 216/24389 = (6/29)³.
pub const LAB_EPSILON: f64 = 216.0 / 24389.0;
/// CIE 15:2018 eq. 8.3 constant κ = 24389/27 = (29/3)³.
pub const LAB_KAPPA: f64 = 24389.0 / 27.0;

/// f(t) of CIE 15:2018 eqs. 8.3–8.5: ∛t for t > ε, else (κ t + 16) / 116.
fn lab_f(t: f64) -> f64 {
    if t > LAB_EPSILON {
        t.cbrt()
    } else {
        (LAB_KAPPA * t + 16.0) / 116.0
    }
}

/// Inverse of [`lab_f`]: f³ when f³ > ε, else (116 f − 16) / κ.
fn lab_f_inv(f: f64) -> f64 {
    let f3 = f * f * f;
    if f3 > LAB_EPSILON {
        f3
    } else {
        (116.0 * f - 16.0) / LAB_KAPPA
    }
}

/// XYZ → CIELAB relative to `white_xyz` (CIE 15:2018 eqs. 8.1–8.5). `xyz` and `white_xyz`
/// must share a scale (both with white Y = 100, or both Y = 1). A white component of zero
/// yields non-finite output rather than a panic.
pub fn xyz_to_lab(xyz: DVec3, white_xyz: DVec3) -> DVec3 {
    let fx = lab_f(xyz.x / white_xyz.x);
    let fy = lab_f(xyz.y / white_xyz.y);
    let fz = lab_f(xyz.z / white_xyz.z);
    DVec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
}

/// CIELAB → XYZ relative to `white_xyz` (inverse of [`xyz_to_lab`], CIE 15:2018 §8.2.1
/// note; the output has the scale of `white_xyz`).
pub fn lab_to_xyz(lab: DVec3, white_xyz: DVec3) -> DVec3 {
    let fy = (lab.x + 16.0) / 116.0;
    let fx = fy + lab.y / 500.0;
    let fz = fy - lab.z / 200.0;
    // Y uses L* directly below the knee (L* ≤ κε = 8) so that L* → Y is exact there.
    let y_rel = if lab.x > LAB_KAPPA * LAB_EPSILON {
        fy * fy * fy
    } else {
        lab.x / LAB_KAPPA
    };
    DVec3::new(
        lab_f_inv(fx) * white_xyz.x,
        y_rel * white_xyz.y,
        lab_f_inv(fz) * white_xyz.z,
    )
}

/// CIEDE2000 colour difference ΔE₀₀ with kL = kC = kH = 1 (CIE 142-2001).
pub fn delta_e_2000(lab1: DVec3, lab2: DVec3) -> f64 {
    delta_e_2000_weighted(lab1, lab2, 1.0, 1.0, 1.0)
}

/// CIEDE2000 with parametric factors kL, kC, kH, following the implementation notes and
/// equation numbers of Sharma, Wu & Dalal (2005), Color Res. Appl. 30(1):21–30, including
/// their hue edge cases: h′ = 0 when a′ = b′ = 0, Δh′ = 0 and h̄′ = h′₁ + h′₂ when
/// C′₁C′₂ = 0, and the ±360° rules at |h′₁ − h′₂| = 180°.
pub fn delta_e_2000_weighted(lab1: DVec3, lab2: DVec3, k_l: f64, k_c: f64, k_h: f64) -> f64 {
    const POW25_7: f64 = 6_103_515_625.0; // 25⁷
    let (l1, a1, b1) = (lab1.x, lab1.y, lab1.z);
    let (l2, a2, b2) = (lab2.x, lab2.y, lab2.z);

    // Eqs. 2–6: a′ rescaling, C′ and h′.
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let c_bar = 0.5 * (c1 + c2);
    let c_bar7 = c_bar.powi(7);
    let g = 0.5 * (1.0 - (c_bar7 / (c_bar7 + POW25_7)).sqrt());
    let a1p = (1.0 + g) * a1;
    let a2p = (1.0 + g) * a2;
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let hue_deg = |b: f64, ap: f64| -> f64 {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            let h = b.atan2(ap).to_degrees();
            if h < 0.0 {
                h + 360.0
            } else {
                h
            }
        }
    };
    let h1p = hue_deg(b1, a1p);
    let h2p = hue_deg(b2, a2p);

    // Eqs. 8–10: differences.
    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let chroma_product = c1p * c2p;
    let dh = h2p - h1p;
    let dhp = if chroma_product == 0.0 {
        0.0
    } else if dh.abs() <= 180.0 {
        dh
    } else if dh > 180.0 {
        dh - 360.0
    } else {
        dh + 360.0
    };
    let d_big_hp = 2.0 * chroma_product.sqrt() * (0.5 * dhp).to_radians().sin();

    // Eqs. 12–14: means.
    let lp_bar = 0.5 * (l1 + l2);
    let cp_bar = 0.5 * (c1p + c2p);
    let hp_sum = h1p + h2p;
    let hp_bar = if chroma_product == 0.0 {
        hp_sum
    } else if (h1p - h2p).abs() <= 180.0 {
        0.5 * hp_sum
    } else if hp_sum < 360.0 {
        0.5 * (hp_sum + 360.0)
    } else {
        0.5 * (hp_sum - 360.0)
    };

    // Eqs. 15–22: weighting functions and rotation term.
    let t = 1.0 - 0.17 * (hp_bar - 30.0).to_radians().cos()
        + 0.24 * (2.0 * hp_bar).to_radians().cos()
        + 0.32 * (3.0 * hp_bar + 6.0).to_radians().cos()
        - 0.20 * (4.0 * hp_bar - 63.0).to_radians().cos();
    let d_theta_deg = 30.0 * (-((hp_bar - 275.0) / 25.0).powi(2)).exp();
    let cp_bar7 = cp_bar.powi(7);
    let r_c = 2.0 * (cp_bar7 / (cp_bar7 + POW25_7)).sqrt();
    let l50 = (lp_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * cp_bar;
    let s_h = 1.0 + 0.015 * cp_bar * t;
    let r_t = -(2.0 * d_theta_deg).to_radians().sin() * r_c;

    // Eq. 23.
    let tl = dlp / (k_l * s_l);
    let tc = dcp / (k_c * s_c);
    let th = d_big_hp / (k_h * s_h);
    (tl * tl + tc * tc + th * th + r_t * tc * th)
        .max(0.0)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::illuminant;

    #[test]
    fn interleaved_cmfs_give_the_bits_of_the_dense_tables() {
        // Every 1/7 nm from below 360 to above 830 nm, nodes and the ends included.
        let c = cmfs(Observer::Cie1931);
        let table = cie1931_interleaved();
        for k in 0..=3400 {
            let wl = 355.0 + f64::from(k) / 7.0;
            let expected = DVec3::new(c.x_bar.eval(wl), c.y_bar.eval(wl), c.z_bar.eval(wl));
            let got = cmf_lerp(table, wl);
            assert_eq!(
                got.to_array().map(f64::to_bits),
                expected.to_array().map(f64::to_bits)
            );
        }
        for wl in [360.0, 830.0, 555.0] {
            let expected = DVec3::new(c.x_bar.eval(wl), c.y_bar.eval(wl), c.z_bar.eval(wl));
            assert_eq!(cmf_lerp(table, wl), expected);
        }
    }

    #[test]
    fn xyy_round_trips_and_black_is_defined() {
        let xyz = DVec3::new(41.24, 21.26, 1.93);
        let back = xyy_to_xyz(xyz_to_xyy(xyz));
        assert!((back - xyz).abs().max_element() < 1e-12);
        assert_eq!(xyz_to_xyy(DVec3::ZERO), DVec3::ZERO);
        let white = DVec2::new(0.3127, 0.329);
        assert_eq!(
            xyz_to_xyy_or(DVec3::ZERO, white),
            DVec3::new(0.3127, 0.329, 0.0)
        );
        assert_eq!(xyy_to_xyz(DVec3::new(0.3, 0.0, 1.0)), DVec3::ZERO);
        assert!(xyz_to_xy(DVec3::ZERO).is_none());
    }

    #[test]
    fn uv_1960_from_xyz_and_xy_agree_and_invert() {
        let xyz = DVec3::new(95.047, 100.0, 108.883);
        let uv = xyz_to_uv_1960(xyz).unwrap();
        let uv2 = xy_to_uv_1960(xyz_to_xy(xyz).unwrap()).unwrap();
        assert!((uv - uv2).abs().max_element() < 1e-15);
        let xy = uv_1960_to_xy(uv).unwrap();
        assert!((xy - xyz_to_xy(xyz).unwrap()).abs().max_element() < 1e-15);
    }

    #[test]
    fn lab_round_trips_on_both_sides_of_the_knee() {
        let white = DVec3::new(95.047, 100.0, 108.883);
        for xyz in [
            DVec3::new(41.24, 21.26, 1.93),
            DVec3::new(0.1, 0.2, 0.05), // below ε: linear segment
            DVec3::new(95.047, 100.0, 108.883),
            DVec3::ZERO,
        ] {
            let back = lab_to_xyz(xyz_to_lab(xyz, white), white);
            assert!((back - xyz).abs().max_element() < 1e-11, "{xyz}");
        }
        let lab_white = xyz_to_lab(white, white);
        assert!(
            (lab_white - DVec3::new(100.0, 0.0, 0.0))
                .abs()
                .max_element()
                < 1e-12
        );
    }

    #[test]
    fn delta_e_2000_is_symmetric_and_zero_on_equal_colours() {
        let samples = [
            DVec3::new(50.0, 2.6772, -79.7751),
            DVec3::new(50.0, 0.0, 0.0),
            DVec3::new(50.0, -0.001, 2.49),
            DVec3::new(50.0, 0.0011, -2.49),
            DVec3::new(90.8027, -2.0831, 1.441),
            DVec3::new(2.0776, 0.0795, -1.135),
        ];
        for a in samples {
            assert_eq!(delta_e_2000(a, a), 0.0);
            for b in samples {
                let d1 = delta_e_2000(a, b);
                let d2 = delta_e_2000(b, a);
                assert!((d1 - d2).abs() < 1e-12, "{a} {b}: {d1} vs {d2}");
            }
        }
        // Sharma et al. 2005, Table 1, pair 1.
        let d = delta_e_2000(
            DVec3::new(50.0, 2.6772, -79.7751),
            DVec3::new(50.0, 0.0, -82.7485),
        );
        assert!((d - 2.0425).abs() < 5e-5);
    }

    #[test]
    fn perfect_reflector_has_y_100_and_white_matches() {
        let d65 = illuminant("D65").unwrap().to_dense();
        let ones = DenseSpectrum::constant(1.0);
        for observer in [Observer::Cie1931, Observer::Cie1964] {
            let xyz = reflectance_to_xyz(&ones, &d65, observer);
            assert!((xyz.y - 100.0).abs() < 1e-12);
            let white = illuminant_white_xyz(&d65, observer);
            assert!((xyz - white).abs().max_element() < 1e-12);
        }
        let xy = xyz_to_xy(illuminant_white_xyz(&d65, Observer::Cie1931)).unwrap();
        assert!((xy - DVec2::new(0.3127, 0.3290)).abs().max_element() < 2e-4);
        // No luminance: defined zero instead of NaN.
        let dark = DenseSpectrum::constant(0.0);
        assert_eq!(
            reflectance_to_xyz(&ones, &dark, Observer::Cie1931),
            DVec3::ZERO
        );
    }

    #[test]
    fn flat_radiance_luminance_is_km_times_integral_of_y_bar() {
        let xyz = emission_to_xyz_cd_per_m2(&DenseSpectrum::constant(1.0), Observer::Cie1931);
        let sum_y: f64 = cmfs(Observer::Cie1931).y_bar.values().iter().sum();
        assert!((xyz.y - 683.002 * sum_y).abs() < 1e-9);
        // ∫ȳ dλ ≈ 106.86 nm for CIE 1931.
        assert!((sum_y - 106.857).abs() < 0.01, "{sum_y}");
    }
}
