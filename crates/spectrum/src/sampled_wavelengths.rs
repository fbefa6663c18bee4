//! `SampledWavelengths`: the four wavelengths a path carries — a hero wavelength and three
//! rotated copies (Wilkie et al. 2014, "Hero wavelength spectral sampling"; pbrt-v4 §4.5.4).
//!
//! # Estimator
//!
//! With λ₀ drawn from the density p and λᵢ obtained by rotating the hero's uniform variate
//! u by i/4 (mod 1), every λᵢ is marginally distributed with density p, so
//!
//! ```text
//!     E = (1/4) Σᵢ f(λᵢ) / p(λᵢ)        (i = 0..3)
//! ```
//!
//! is an unbiased estimator of ∫ f(λ) dλ over 360–830 nm. In code:
//! `f.safe_div(wavelengths.pdf()).average()`.
//!
//! When a path meets a wavelength-dependent event (dispersion, fluorescence) only the hero
//! survives: `terminate_secondary` sets p₁ = p₂ = p₃ = 0 and p₀ ← p₀/4, so the same
//! expression with safe division (zero where the pdf is zero) becomes f(λ₀)/p(λ₀), still
//! unbiased (pbrt-v4 `SampledWavelengths::TerminateSecondary`).
//!
//! # Importance density
//!
//! pbrt-v4's "visible wavelengths" density (`SampleVisibleWavelengths`, util/sampling.h):
//! p(λ) = A / cosh²(k(λ − c)), k = 0.0072 nm⁻¹, c = 538 nm, on [360, 830] nm. Because
//! ∫ sech²(k(λ − c)) dλ = tanh(k(λ − c)) / k, the normalisation is
//! A = k / (tanh(k(830 − c)) − tanh(k(360 − c))), the CDF is
//! P(λ) = (tanh(k(λ − c)) − t₀) / (t₁ − t₀) and the inverse CDF is
//! λ = c + atanh(t₀ + u (t₁ − t₀)) / k, with t₀ = tanh(k(360 − c)), t₁ = tanh(k(830 − c)).

use crate::constants::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use crate::rgb_wavelength_density::RgbWavelengthDensity;
use crate::sampled_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

/// Falloff k of the visible-wavelength density, in nm⁻¹ (pbrt-v4).
pub const VISIBLE_DENSITY_FALLOFF_PER_NM: f64 = 0.0072;
/// Centre c of the visible-wavelength density, in nm (pbrt-v4).
pub const VISIBLE_DENSITY_CENTER_NM: f64 = 538.0;
/// t₀ = tanh(k (360 nm − c)).
const TANH_AT_MIN: f64 = -0.856_910_625_469_828;
/// t₁ = tanh(k (830 nm − c)).
const TANH_AT_MAX: f64 = 0.970_591_346_940_269_8;
/// A = k / (t₁ − t₀): normalises the density over exactly [360, 830] nm, in nm⁻¹
/// (pbrt-v4 rounds this to 0.0039398042).
const VISIBLE_DENSITY_NORMALISATION_PER_NM: f64 = 0.003_939_804_229_324_407;

/// Density of `sample_visible_wavelength` at `wavelength_nm`, in nm⁻¹; zero outside
/// 360–830 nm.
#[inline]
pub fn visible_wavelength_pdf(wavelength_nm: f32) -> f32 {
    if !(LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&wavelength_nm) {
        return 0.0;
    }
    let cosh = (VISIBLE_DENSITY_FALLOFF_PER_NM as f32
        * (wavelength_nm - VISIBLE_DENSITY_CENTER_NM as f32))
        .cosh();
    VISIBLE_DENSITY_NORMALISATION_PER_NM as f32 / (cosh * cosh)
}

/// `visible_wavelength_pdf` in f64, for reference integrals.
pub fn visible_wavelength_pdf_f64(wavelength_nm: f64) -> f64 {
    if !(LAMBDA_MIN_NM as f64..=LAMBDA_MAX_NM as f64).contains(&wavelength_nm) {
        return 0.0;
    }
    let cosh =
        (VISIBLE_DENSITY_FALLOFF_PER_NM * (wavelength_nm - VISIBLE_DENSITY_CENTER_NM)).cosh();
    VISIBLE_DENSITY_NORMALISATION_PER_NM / (cosh * cosh)
}

/// Cumulative distribution of the visible-wavelength density: 0 below 360 nm, 1 above 830 nm.
pub fn visible_wavelength_cdf(wavelength_nm: f64) -> f64 {
    let clamped = wavelength_nm.clamp(LAMBDA_MIN_NM as f64, LAMBDA_MAX_NM as f64);
    let t = (VISIBLE_DENSITY_FALLOFF_PER_NM * (clamped - VISIBLE_DENSITY_CENTER_NM)).tanh();
    ((t - TANH_AT_MIN) / (TANH_AT_MAX - TANH_AT_MIN)).clamp(0.0, 1.0)
}

/// Inverse CDF of the visible-wavelength density: maps u ∈ [0, 1) to a wavelength in nm.
#[inline]
pub fn sample_visible_wavelength(u: f32) -> f32 {
    let t = TANH_AT_MIN as f32 + u * (TANH_AT_MAX - TANH_AT_MIN) as f32;
    let wavelength_nm = VISIBLE_DENSITY_CENTER_NM as f32
        + t.atanh() * (1.0 / VISIBLE_DENSITY_FALLOFF_PER_NM) as f32;
    wavelength_nm.clamp(LAMBDA_MIN_NM, LAMBDA_MAX_NM)
}

/// ln x for positive normal x without library calls (Cephes `logf`: exponent from the bits,
/// mantissa folded into [√½, √2), degree-8 polynomial), about 1 ulp; lanes vectorise.
#[inline(always)]
fn ln_positive(x: f32) -> f32 {
    let bits = x.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 126;
    // Mantissa in [0.5, 1).
    let mantissa = f32::from_bits((bits & 0x807f_ffff) | 0x3f00_0000);
    let below = mantissa < std::f32::consts::FRAC_1_SQRT_2;
    let e = (exponent - below as i32) as f32;
    let m = if below {
        mantissa + mantissa - 1.0
    } else {
        mantissa - 1.0
    };
    let z = m * m;
    let mut y = ((((((((7.037_683_6e-2 * m - 1.151_461e-1) * m + 1.167_699_9e-1) * m
        - 1.242_014_1e-1)
        * m
        + 1.424_932_3e-1)
        * m
        - 1.666_805_8e-1)
        * m
        + 2.000_071_4e-1)
        * m
        - 2.499_999_4e-1)
        * m
        + 3.333_333e-1)
        * m
        * z;
    y += -2.121_944_4e-4 * e;
    y += -0.5 * z;
    m + y + 0.693_359_4 * e
}

/// One wavelength of `sample_visible` from its (rotated) variate: (λ in nm, pdf in nm⁻¹).
/// t = t₀ + u (t₁ − t₀) = tanh(k(λ − c)), so λ = c + ln((1 + t)/(1 − t)) / 2k and
/// p(λ) = A / cosh² = A (1 − t)(1 + t).
#[inline(always)]
fn visible_wavelength_and_pdf(variate: f32) -> (f32, f32) {
    let t = TANH_AT_MIN as f32 + variate * (TANH_AT_MAX - TANH_AT_MIN) as f32;
    let (one_plus, one_minus) = (1.0 + t, 1.0 - t);
    let wl = VISIBLE_DENSITY_CENTER_NM as f32
        + ln_positive(one_plus / one_minus) * (0.5 / VISIBLE_DENSITY_FALLOFF_PER_NM) as f32;
    (
        wl.clamp(LAMBDA_MIN_NM, LAMBDA_MAX_NM),
        VISIBLE_DENSITY_NORMALISATION_PER_NM as f32 * (one_plus * one_minus),
    )
}

/// Which density a camera sample's hero wavelength is drawn from (the three others are its
/// rotations): one contract, `sample`, for every estimator that writes a film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WavelengthDensity {
    /// pbrt-v4's visible density, which follows luminance and keeps mass out to 830 nm: for
    /// films that record spectral bins, whose far-red and violet bins need their samples.
    Visible,
    /// The RGB-output density ([`crate::rgb_wavelength_density`]): for films whose output is
    /// colour (XYZ / RGB) alone.
    RgbOutput,
}

impl WavelengthDensity {
    /// Hero wavelength from `u` ∈ [0, 1) and its three rotations, with their pdfs.
    #[inline]
    pub fn sample(self, u: f32) -> SampledWavelengths {
        match self {
            WavelengthDensity::Visible => SampledWavelengths::sample_visible(u),
            WavelengthDensity::RgbOutput => SampledWavelengths::sample_rgb_output(u),
        }
    }

    /// `sample` for `N` variates at once, the same bits per sample.
    #[inline(always)]
    pub fn sample_many<const N: usize>(self, u: &[f32; N]) -> [SampledWavelengths; N] {
        match self {
            WavelengthDensity::Visible => SampledWavelengths::sample_visible_many(u),
            WavelengthDensity::RgbOutput => SampledWavelengths::sample_rgb_output_many(u),
        }
    }
}

/// Four wavelengths (nm) with the density (nm⁻¹) each was sampled with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda_nm: [f32; N_SPECTRUM_SAMPLES],
    pdf: SampledSpectrum,
}

/// The hero's variate rotated by i/4 (mod 1) for lane i: stratified over [0, 1).
#[inline]
fn rotated_variates(u: f32) -> [f32; N_SPECTRUM_SAMPLES] {
    std::array::from_fn(|lane| rotated_variate(u, lane))
}

/// Lane `lane` of [`rotated_variates`].
#[inline(always)]
fn rotated_variate(u: f32, lane: usize) -> f32 {
    let v = u + lane as f32 / N_SPECTRUM_SAMPLES as f32;
    if v >= 1.0 {
        v - 1.0
    } else {
        v
    }
}

impl SampledWavelengths {
    /// Wavelengths and pdfs given directly (tests, or wavelengths fixed by an integrator).
    pub const fn new(lambda_nm: [f32; N_SPECTRUM_SAMPLES], pdf: SampledSpectrum) -> Self {
        Self { lambda_nm, pdf }
    }

    /// Hero wavelength from `u` ∈ [0, 1) by the visible-wavelength importance density, plus
    /// three rotated copies (u + i/4 mod 1), each with its pdf.
    ///
    /// Per lane t = t₀ + u (t₁ − t₀) = tanh(k(λ − c)), so λ = c + ln((1 + t)/(1 − t)) / 2k
    /// and p(λ) = A / cosh² = A (1 − t)(1 + t): no hyperbolic functions, and the loop over
    /// the lanes vectorises (the logarithm is `ln_positive` below).
    #[inline]
    pub fn sample_visible(u: f32) -> Self {
        Self::drawn_by(u, visible_wavelength_and_pdf)
    }

    /// `sample_visible` for `N` variates at once, the same bits per sample: one loop over
    /// all `4N` wavelengths, which becomes `N`-wide vector code where the caller is compiled
    /// for it (the packet path tracer starts 16 camera samples at a time).
    #[inline(always)]
    pub fn sample_visible_many<const N: usize>(u: &[f32; N]) -> [Self; N] {
        Self::many_drawn_by(u, visible_wavelength_and_pdf)
    }

    /// Hero wavelength from `u` ∈ [0, 1) by the RGB-output density
    /// ([`crate::rgb_wavelength_density`]: 0.4 × the visible density + 0.6 × the norm of the
    /// Rec. 709 colour-matching functions), plus three rotated copies, each with its pdf.
    /// For estimates that end as colour: the film's camera samples.
    #[inline]
    pub fn sample_rgb_output(u: f32) -> Self {
        let density = RgbWavelengthDensity::get();
        Self::drawn_by(u, |v| density.sample(v))
    }

    /// `sample_rgb_output` for `N` variates at once, the same bits per sample.
    #[inline(always)]
    pub fn sample_rgb_output_many<const N: usize>(u: &[f32; N]) -> [Self; N] {
        let density = RgbWavelengthDensity::get();
        Self::many_drawn_by(u, |v| density.sample(v))
    }

    /// The hero from `u` and its three rotations, each drawn by `draw` (variate →
    /// (λ in nm, pdf in nm⁻¹)).
    #[inline(always)]
    fn drawn_by(u: f32, draw: impl Fn(f32) -> (f32, f32)) -> Self {
        let variates = rotated_variates(u);
        let mut lambda_nm = [0.0f32; N_SPECTRUM_SAMPLES];
        let mut pdf = [0.0f32; N_SPECTRUM_SAMPLES];
        for lane in 0..N_SPECTRUM_SAMPLES {
            (lambda_nm[lane], pdf[lane]) = draw(variates[lane]);
        }
        Self {
            lambda_nm,
            pdf: SampledSpectrum::new(pdf),
        }
    }

    /// `drawn_by` for `N` variates, lane-major so that the `4N` draws form one loop.
    #[inline(always)]
    fn many_drawn_by<const N: usize>(u: &[f32; N], draw: impl Fn(f32) -> (f32, f32)) -> [Self; N] {
        let mut variates = [[0.0f32; N]; N_SPECTRUM_SAMPLES];
        for (i, row) in variates.iter_mut().enumerate() {
            for (v, &u) in row.iter_mut().zip(u) {
                *v = rotated_variate(u, i);
            }
        }
        let mut lambda_nm = [[0.0f32; N]; N_SPECTRUM_SAMPLES];
        let mut pdf = [[0.0f32; N]; N_SPECTRUM_SAMPLES];
        for i in 0..N_SPECTRUM_SAMPLES {
            for k in 0..N {
                (lambda_nm[i][k], pdf[i][k]) = draw(variates[i][k]);
            }
        }
        std::array::from_fn(|k| Self {
            lambda_nm: std::array::from_fn(|i| lambda_nm[i][k]),
            pdf: SampledSpectrum::new(std::array::from_fn(|i| pdf[i][k])),
        })
    }

    /// Hero wavelength uniform over 360–830 nm plus three rotated copies; pdf 1/470 nm⁻¹.
    #[inline]
    pub fn sample_uniform(u: f32) -> Self {
        let range_nm = LAMBDA_MAX_NM - LAMBDA_MIN_NM;
        let lambda_nm =
            rotated_variates(u).map(|up| (LAMBDA_MIN_NM + up * range_nm).min(LAMBDA_MAX_NM));
        Self {
            lambda_nm,
            pdf: SampledSpectrum::splat(1.0 / range_nm),
        }
    }

    /// The four wavelengths in nm (lane 0 is the hero).
    #[inline]
    pub fn lambda(&self) -> [f32; N_SPECTRUM_SAMPLES] {
        self.lambda_nm
    }

    /// Same as `lambda`, named with its unit.
    #[inline]
    pub fn wavelengths_nm(&self) -> [f32; N_SPECTRUM_SAMPLES] {
        self.lambda_nm
    }

    /// Wavelength of `lane` in nm.
    #[inline]
    pub fn wavelength_nm(&self, lane: usize) -> f32 {
        self.lambda_nm[lane]
    }

    /// Sampling density of each lane in nm⁻¹ (zero for terminated secondary lanes).
    #[inline]
    pub fn pdf(&self) -> SampledSpectrum {
        self.pdf
    }

    /// Keeps only the hero wavelength (dispersion, fluorescence): lanes 1–3 get pdf 0 and
    /// lane 0's pdf is divided by 4, so `(f.safe_div(pdf)).average()` stays unbiased
    /// (pbrt-v4 `TerminateSecondary`). Idempotent.
    #[inline]
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for lane in 1..N_SPECTRUM_SAMPLES {
            self.pdf[lane] = 0.0;
        }
        self.pdf[0] /= N_SPECTRUM_SAMPLES as f32;
    }

    /// True when lanes 1–3 carry no light (their pdfs are zero).
    #[inline]
    pub fn secondary_terminated(&self) -> bool {
        self.pdf.values[1..].iter().all(|&p| p == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64 (Steele et al. 2014): a tiny deterministic generator for tests.
    struct SplitMix64(u64);
    impl SplitMix64 {
        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        /// Uniform in [0, 1) with 24 bits, as a renderer's f32 sampler gives.
        fn next_f32(&mut self) -> f32 {
            (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
        }
    }

    /// Upper `1 - alpha` quantile of χ²(dof) by Wilson–Hilferty; `z` is the standard normal
    /// quantile of 1 − alpha.
    fn chi_square_quantile(dof: f64, z: f64) -> f64 {
        let a = 2.0 / (9.0 * dof);
        dof * (1.0 - a + z * a.sqrt()).powi(3)
    }
    /// Standard normal quantile at 1 − 10⁻³.
    const Z_0_999: f64 = 3.090_232_306;

    /// The batch forms give the one-sample forms' bits for every sample, with both
    /// densities.
    #[test]
    fn the_batch_forms_are_the_one_sample_forms_per_sample() {
        let mut u = [0.0f32; 16];
        for (k, v) in u.iter_mut().enumerate() {
            *v = (k as f32 * 0.618_034).fract();
        }
        u[3] = 0.0;
        u[7] = 1.0 - f32::EPSILON;
        for density in [WavelengthDensity::Visible, WavelengthDensity::RgbOutput] {
            let many = density.sample_many(&u);
            for (k, w) in many.iter().enumerate() {
                let one = density.sample(u[k]);
                assert_eq!(w.lambda().map(f32::to_bits), one.lambda().map(f32::to_bits));
                assert_eq!(
                    w.pdf().to_array().map(f32::to_bits),
                    one.pdf().to_array().map(f32::to_bits)
                );
            }
        }
    }

    #[test]
    fn normalisation_constants_match_their_closed_forms() {
        let k = VISIBLE_DENSITY_FALLOFF_PER_NM;
        let c = VISIBLE_DENSITY_CENTER_NM;
        let t0 = (k * (360.0 - c)).tanh();
        let t1 = (k * (830.0 - c)).tanh();
        assert!((t0 - TANH_AT_MIN).abs() < 1e-15);
        assert!((t1 - TANH_AT_MAX).abs() < 1e-15);
        assert!((k / (t1 - t0) - VISIBLE_DENSITY_NORMALISATION_PER_NM).abs() < 1e-17);
        // pbrt-v4's constant, rounded to 8 significant digits, agrees.
        assert!((VISIBLE_DENSITY_NORMALISATION_PER_NM - 0.003_939_804_2).abs() < 5e-11);
    }

    #[test]
    fn visible_pdf_integrates_to_one() {
        // Composite Simpson over [360, 830] with 0.01 nm steps.
        let n = 47_000;
        let h = 470.0 / n as f64;
        let mut sum = visible_wavelength_pdf_f64(360.0) + visible_wavelength_pdf_f64(830.0);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            sum += w * visible_wavelength_pdf_f64(360.0 + i as f64 * h);
        }
        let integral = sum * h / 3.0;
        assert!((integral - 1.0).abs() < 1e-12, "∫p = {integral}");
        // The f32 pdf agrees with the f64 one.
        for wl in [360.0f32, 400.0, 538.0, 700.0, 830.0] {
            let rel =
                (visible_wavelength_pdf(wl) as f64 / visible_wavelength_pdf_f64(wl as f64)) - 1.0;
            assert!(rel.abs() < 1e-6);
        }
        assert_eq!(visible_wavelength_pdf(359.9), 0.0);
        assert_eq!(visible_wavelength_pdf(830.1), 0.0);
        assert_eq!(visible_wavelength_pdf(f32::NAN), 0.0);
    }

    #[test]
    fn inverse_cdf_inverts_the_cdf() {
        assert_eq!(visible_wavelength_cdf(360.0), 0.0);
        assert!((visible_wavelength_cdf(830.0) - 1.0).abs() < 1e-15);
        for i in 0..=1000 {
            let u = i as f32 / 1000.0;
            let wl = sample_visible_wavelength(u);
            assert!((360.0..=830.0).contains(&wl));
            let back = visible_wavelength_cdf(wl as f64);
            assert!((back - u as f64).abs() < 2e-6, "u {u} → {wl} nm → {back}");
        }
        // And the other way round: λ → CDF → inverse CDF.
        for i in 0..=470 {
            let wl = 360.0 + i as f64;
            let u = visible_wavelength_cdf(wl) as f32;
            let back = sample_visible_wavelength(u) as f64;
            assert!((back - wl).abs() < 0.02, "{wl} nm → {u} → {back} nm");
        }
        // The derivative of the CDF is the pdf.
        for wl in [365.0, 450.0, 538.0, 620.0, 825.0] {
            let h = 1e-3;
            let slope =
                (visible_wavelength_cdf(wl + h) - visible_wavelength_cdf(wl - h)) / (2.0 * h);
            assert!((slope / visible_wavelength_pdf_f64(wl) - 1.0).abs() < 1e-6);
        }
    }

    /// χ² of `count` samples of lane `lane` against the visible density, 100 bins.
    fn chi_square_of_lane(lane: usize, seed: u64, count: usize) -> (f64, f64) {
        const BINS: usize = 100;
        let bin_width_nm = 470.0 / BINS as f64;
        let mut rng = SplitMix64(seed);
        let mut histogram = [0u64; BINS];
        for _ in 0..count {
            let wl = SampledWavelengths::sample_visible(rng.next_f32()).lambda()[lane] as f64;
            let bin = (((wl - 360.0) / bin_width_nm) as usize).min(BINS - 1);
            histogram[bin] += 1;
        }
        let mut chi2 = 0.0;
        for (b, &observed) in histogram.iter().enumerate() {
            let lo = 360.0 + b as f64 * bin_width_nm;
            let p = visible_wavelength_cdf(lo + bin_width_nm) - visible_wavelength_cdf(lo);
            let expected = p * count as f64;
            assert!(expected > 5.0, "bin {b} too sparse for χ²");
            chi2 += (observed as f64 - expected).powi(2) / expected;
        }
        (chi2, chi_square_quantile((BINS - 1) as f64, Z_0_999))
    }

    #[test]
    fn hero_wavelength_matches_its_pdf_chi_square() {
        let (chi2, limit) = chi_square_of_lane(0, 0x5eed_0001, 1_000_000);
        assert!(chi2 < limit, "χ² = {chi2} ≥ {limit}");
    }

    #[test]
    fn every_rotated_lane_has_the_same_marginal_chi_square() {
        for lane in 1..N_SPECTRUM_SAMPLES {
            let (chi2, limit) = chi_square_of_lane(lane, 0x5eed_0100 + lane as u64, 1_000_000);
            assert!(chi2 < limit, "lane {lane}: χ² = {chi2} ≥ {limit}");
        }
    }

    #[test]
    fn lanes_are_stratified_rotations_of_the_hero() {
        let mut rng = SplitMix64(7);
        for _ in 0..1000 {
            let u = rng.next_f32();
            let s = SampledWavelengths::sample_visible(u);
            for lane in 0..N_SPECTRUM_SAMPLES {
                let expected = (u + lane as f32 * 0.25).fract();
                let cdf = visible_wavelength_cdf(s.lambda()[lane] as f64) as f32;
                // Near the wrap point u + i/4 ≈ 1 the CDF can read 0 or 1.
                let diff = (cdf - expected).abs();
                assert!(diff.min(1.0 - diff) < 1e-5);
                let pdf = visible_wavelength_pdf(s.lambda()[lane]);
                assert!((s.pdf()[lane] / pdf - 1.0).abs() < 1e-5);
                let scalar = sample_visible_wavelength(expected);
                assert!(
                    (s.lambda()[lane] - scalar).abs() < 1e-3,
                    "{} vs {scalar}",
                    s.lambda()[lane]
                );
            }
        }
    }

    #[test]
    fn fast_ln_matches_std() {
        let mut x = 1e-3f32;
        while x < 1e3 {
            let expected = (x as f64).ln();
            assert!(
                (ln_positive(x) as f64 - expected).abs() < 2e-7 * expected.abs().max(1.0),
                "ln {x}"
            );
            x *= 1.001;
        }
    }

    #[test]
    fn uniform_sampling_covers_the_range_with_constant_pdf() {
        let s = SampledWavelengths::sample_uniform(0.0);
        assert_eq!(s.lambda(), [360.0, 477.5, 595.0, 712.5]);
        assert_eq!(s.pdf(), SampledSpectrum::splat(1.0 / 470.0));
        let s = SampledWavelengths::sample_uniform(0.999_999_9);
        assert!(s.lambda().iter().all(|wl| (360.0..=830.0).contains(wl)));
    }

    #[test]
    fn terminate_secondary_zeroes_secondary_pdfs_and_quarters_the_hero() {
        let mut s = SampledWavelengths::sample_visible(0.3);
        let hero_pdf = s.pdf()[0];
        assert!(!s.secondary_terminated());
        s.terminate_secondary();
        assert!(s.secondary_terminated());
        assert_eq!(s.pdf().values, [hero_pdf / 4.0, 0.0, 0.0, 0.0]);
        s.terminate_secondary();
        assert_eq!(s.pdf().values, [hero_pdf / 4.0, 0.0, 0.0, 0.0]);
    }
}
