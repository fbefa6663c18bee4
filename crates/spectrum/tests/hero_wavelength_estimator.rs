//! The hero-wavelength estimator E = (1/4) Σᵢ f(λᵢ)/p(λᵢ) of ∫ ȳ(λ) L(λ) dλ is unbiased
//! (Wilkie et al. 2014; pbrt-v4 §4.5.4): the mean of 10⁶ estimates lies within 4 standard
//! errors (from the sample variance) of a deterministic reference integral of the very same
//! continuous integrand (ȳ and L evaluated by `Spectrum::eval_nm`, linear between table
//! samples), for flat, blackbody and spiky (CIE F11) spectra, with all four wavelengths and
//! with secondary wavelengths terminated.

use prism_spectrum::data::{cmfs, Observer};
use prism_spectrum::{SampledWavelengths, Spectrum};

/// SplitMix64 (Steele et al. 2014): a tiny deterministic generator.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

const SAMPLES: usize = 1_000_000;

#[derive(Clone, Copy, Debug)]
enum Sampling {
    Visible,
    VisibleHeroOnly,
    Uniform,
}

fn y_bar() -> Spectrum {
    Spectrum::from_dense(&cmfs(Observer::Cie1931).y_bar).unwrap()
}

/// ∫ ȳ(λ) L(λ) dλ over [360, 830] nm by composite Simpson on 0.01 nm steps within each
/// 1 nm segment (exact for products of the linear pieces of 1 nm tables).
fn reference_integral(y: &Spectrum, radiance: &Spectrum) -> f64 {
    const SUB: usize = 100;
    let h = 1.0 / SUB as f64;
    let f = |wl: f64| y.eval_nm(wl) * radiance.eval_nm(wl);
    let mut total = 0.0;
    for segment in 0..470 {
        let a = 360.0 + segment as f64;
        let mut sum = f(a) + f(a + 1.0);
        for i in 1..SUB {
            sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
        }
        total += sum * h / 3.0;
    }
    total
}

/// Mean and standard error of `SAMPLES` hero-wavelength estimates.
fn estimate(y: &Spectrum, radiance: &Spectrum, sampling: Sampling, seed: u64) -> (f64, f64) {
    let mut rng = SplitMix64(seed);
    let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let u = rng.next_f32();
        let wavelengths = match sampling {
            Sampling::Visible => SampledWavelengths::sample_visible(u),
            Sampling::VisibleHeroOnly => {
                let mut w = SampledWavelengths::sample_visible(u);
                w.terminate_secondary();
                w
            }
            Sampling::Uniform => SampledWavelengths::sample_uniform(u),
        };
        let f = y.eval(&wavelengths) * radiance.eval(&wavelengths);
        let e = f.safe_div(wavelengths.pdf()).average() as f64;
        sum += e;
        sum_sq += e * e;
    }
    let n = SAMPLES as f64;
    let mean = sum / n;
    let variance = (sum_sq - n * mean * mean) / (n - 1.0);
    (mean, (variance / n).sqrt())
}

fn assert_unbiased(name: &str, radiance: Spectrum, seed: u64) {
    let y = y_bar();
    let reference = reference_integral(&y, &radiance);
    for (k, sampling) in [
        Sampling::Visible,
        Sampling::VisibleHeroOnly,
        Sampling::Uniform,
    ]
    .into_iter()
    .enumerate()
    {
        let (mean, standard_error) = estimate(&y, &radiance, sampling, seed + k as u64);
        assert!(standard_error > 0.0);
        let z = (mean - reference) / standard_error;
        println!("{name} {sampling:?}: mean {mean}, reference {reference}, se {standard_error}, z {z:.2}");
        assert!(
            z.abs() < 4.0,
            "{name} {sampling:?}: mean {mean} vs reference {reference} is {z:.2} standard errors off"
        );
    }
}

#[test]
fn flat_spectrum_estimate_is_unbiased() {
    let flat = Spectrum::constant(1.0);
    // Sanity of the reference: ∫ȳ dλ of the CIE 1931 observer is about 106.857 nm.
    let reference = reference_integral(&y_bar(), &flat);
    assert!((reference - 106.857).abs() < 0.01, "∫ȳ = {reference}");
    assert_unbiased("flat", flat, 0x0001_0000);
}

#[test]
fn blackbody_3000_k_estimate_is_unbiased() {
    assert_unbiased(
        "blackbody 3000 K",
        Spectrum::blackbody(3000.0).unwrap(),
        0x0002_0000,
    );
}

#[test]
fn blackbody_6500_k_estimate_is_unbiased() {
    assert_unbiased(
        "blackbody 6500 K (normalised)",
        Spectrum::blackbody_normalized(6500.0).unwrap(),
        0x0003_0000,
    );
}

#[test]
fn spiky_f11_estimate_is_unbiased() {
    assert_unbiased("F11", Spectrum::cie_illuminant("F11").unwrap(), 0x0004_0000);
}

#[test]
fn terminating_secondaries_keeps_the_estimator_unbiased_but_noisier() {
    let y = y_bar();
    let radiance = Spectrum::cie_illuminant("D65").unwrap();
    let reference = reference_integral(&y, &radiance);
    let (mean_all, se_all) = estimate(&y, &radiance, Sampling::Visible, 0x0005_0000);
    let (mean_hero, se_hero) = estimate(&y, &radiance, Sampling::VisibleHeroOnly, 0x0005_0001);
    assert!(((mean_all - reference) / se_all).abs() < 4.0);
    assert!(((mean_hero - reference) / se_hero).abs() < 4.0);
    // Four stratified wavelengths beat one: the hero-only estimator has a larger error.
    assert!(
        se_hero > 1.5 * se_all,
        "se hero-only {se_hero}, all {se_all}"
    );
}
