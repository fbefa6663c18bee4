//! Physics tests of the material library (issue 8): chi-square tests of every sampler
//! against its pdf (`chi2_<model>`, Šidák-corrected per family over incident angles and
//! parameters), energy (albedo ≤ 1, Monte Carlo with 4.5 standard errors), reciprocity,
//! Oren–Nayar at σ = 0 against Lambert, the thin sheet's lobe frequencies, and the MERL
//! table: file format, errors, and its discretisation error against the analytic BSDF it
//! was written from.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::merl::{MERL_PHI_D, MERL_THETA_D, MERL_THETA_H};
use super::*;
use prism_testkit::chi2::{chi2_p_value, chi2_test, sidak, Chi2Config, SplitMix64};

const THETAS_DEG: [f32; 4] = [0.0, 30.0, 60.0, 85.0];
const PHI_DEG: f32 = 30.0;
const FAMILY_ALPHA: f64 = 0.01;

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3A {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn s(v: f32) -> SampledSpectrum {
    SampledSpectrum::splat(v)
}

/// Chi-square tests of every (label, BSDF) at every incident angle of `THETAS_DEG`.
fn chi2_family(name: &str, bsdfs: &[(String, Bsdf)]) {
    chi2_family_with(name, bsdfs, 16)
}

fn chi2_family_with(name: &str, bsdfs: &[(String, Bsdf)], integration_resolution: usize) {
    let count = bsdfs.len() * THETAS_DEG.len();
    let config = Chi2Config {
        sample_count: 200_000,
        significance: sidak(FAMILY_ALPHA, count),
        integration_resolution,
        ..Chi2Config::default()
    };
    let mut failures = Vec::new();
    let mut lowest_p = 1.0f64;
    for (label, bsdf) in bsdfs {
        for &theta in &THETAS_DEG {
            let wo = direction(theta, PHI_DEG);
            let mode = TransportMode::Radiance;
            let r = chi2_test(
                &config,
                |ul, u| {
                    bsdf.sample(wo, ul, u, mode)
                        .filter(|s| !s.specular)
                        .map(|s| s.wi)
                },
                |wi| f64::from(bsdf.pdf(wo, wi, mode)),
            );
            lowest_p = lowest_p.min(r.p_value);
            if !r.passed {
                failures.push(format!("{name} {label} θ = {theta}°: {}", r.message));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("{name}: {count} tests passed, lowest p = {lowest_p:.3e}");
}

fn oren_nayar(rho: f32, sigma_deg: f32, form: OrenNayarForm) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::OrenNayar(OrenNayar {
        reflectance: s(rho),
        sigma_rad: sigma_deg.to_radians(),
        form,
    }))
}

fn phong(kd: f32, ks: f32, n: f32) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::Phong(Phong {
        diffuse: s(kd),
        specular: s(ks),
        exponent: n,
    }))
}

fn blinn_phong(kd: f32, ks: f32, n: f32) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::BlinnPhong(BlinnPhong {
        diffuse: s(kd),
        specular: s(ks),
        exponent: n,
    }))
}

fn ward(kd: f32, ks: f32, ax: f32, ay: f32) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::Ward(Ward {
        diffuse: s(kd),
        specular: s(ks),
        alpha_x: ax,
        alpha_y: ay,
    }))
}

fn lafortune(kd: f32, lobes: &[[f32; 5]]) -> Bsdf<'static> {
    let mut l = Lafortune {
        diffuse: s(kd),
        lobes: [LafortuneLobe::NONE; LAFORTUNE_MAX_LOBES],
        count: lobes.len(),
    };
    for (slot, c) in l.lobes.iter_mut().zip(lobes) {
        *slot = LafortuneLobe {
            cx: c[0],
            cy: c[1],
            cz: c[2],
            exponent: c[3],
            albedo: s(c[4]),
        };
    }
    Bsdf::new(BsdfLobe::Lafortune(l))
}

fn coated(rho: f32, eta: f32, nonlinear: bool) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::Coated(Coated {
        diffuse: s(rho),
        eta,
        fdr_internal: internal_diffuse_reflectance(eta),
        nonlinear,
    }))
}

fn ggx(alpha: f32) -> Conductor {
    // A grey conductor: the same η, k at every wavelength.
    Conductor {
        eta: s(0.2),
        k: s(3.0),
        distribution: MicrofacetDistribution::new(MicrofacetModel::Ggx, alpha, alpha),
    }
}

fn mix<'a>(parts: &[(LeafLobe<'a>, f32)]) -> Bsdf<'a> {
    Bsdf::new(BsdfLobe::Mix(Mix::new(parts).expect("valid mix")))
}

#[test]
fn chi2_oren_nayar() {
    let mut bsdfs = Vec::new();
    for form in [OrenNayarForm::Full, OrenNayarForm::Qualitative] {
        for sigma in [10.0, 40.0] {
            bsdfs.push((
                format!("{form:?} σ = {sigma}°"),
                oren_nayar(0.8, sigma, form),
            ));
        }
    }
    chi2_family("oren_nayar", &bsdfs);
}

#[test]
fn chi2_phong() {
    let bsdfs: Vec<_> = [(0.5, 0.5, 1.0), (0.2, 0.7, 20.0), (0.0, 1.0, 200.0)]
        .iter()
        .map(|&(kd, ks, n)| (format!("kd {kd} ks {ks} n {n}"), phong(kd, ks, n)))
        .collect();
    chi2_family("phong", &bsdfs);
}

#[test]
fn chi2_blinn_phong() {
    let bsdfs: Vec<_> = [(0.5, 0.5, 1.0), (0.2, 0.7, 30.0), (0.0, 1.0, 300.0)]
        .iter()
        .map(|&(kd, ks, n)| (format!("kd {kd} ks {ks} n {n}"), blinn_phong(kd, ks, n)))
        .collect();
    // n = 300 at θ = 85° squeezes the lobe against the horizon: 16 sub-cells per bin edge
    // misjudge its expected counts by 3 %, 48 do not.
    chi2_family_with("blinn_phong", &bsdfs, 48);
}

#[test]
fn chi2_ward() {
    let bsdfs: Vec<_> = [(0.3, 0.3), (0.1, 0.1), (0.08, 0.4)]
        .iter()
        .map(|&(ax, ay)| (format!("α ({ax}, {ay})"), ward(0.4, 0.5, ax, ay)))
        .collect();
    chi2_family("ward", &bsdfs);
}

#[test]
fn chi2_lafortune() {
    let bsdfs = vec![
        (
            "phong-like".to_string(),
            lafortune(0.3, &[[-1.0, -1.0, 1.0, 20.0, 0.5]]),
        ),
        (
            "off-specular + retro + anisotropic".to_string(),
            lafortune(
                0.1,
                &[
                    [-1.2, -1.2, 0.9, 10.0, 0.6],
                    [0.6, 0.6, 0.8, 4.0, 0.3],
                    [-0.9, -1.3, 1.0, 30.0, 0.4],
                ],
            ),
        ),
    ];
    chi2_family("lafortune", &bsdfs);
}

#[test]
fn chi2_coated() {
    let bsdfs: Vec<_> = [(0.5, 1.5, true), (0.9, 1.33, false), (0.1, 2.0, true)]
        .iter()
        .map(|&(rho, eta, nl)| {
            (
                format!("ρ {rho} η {eta} nonlinear {nl}"),
                coated(rho, eta, nl),
            )
        })
        .collect();
    chi2_family("coated", &bsdfs);
}

#[test]
fn chi2_mix() {
    let bsdfs = vec![
        (
            "lambert + rough GGX".to_string(),
            mix(&[
                (
                    LeafLobe::Lambert(Lambert {
                        reflectance: s(0.6),
                    }),
                    0.3,
                ),
                (LeafLobe::Conductor(ggx(0.2)), 0.7),
            ]),
        ),
        (
            "phong + ward + coated".to_string(),
            mix(&[
                (
                    LeafLobe::from_lobe(phong(0.3, 0.6, 30.0).lobe).unwrap(),
                    0.2,
                ),
                (
                    LeafLobe::from_lobe(ward(0.2, 0.6, 0.1, 0.3).lobe).unwrap(),
                    0.5,
                ),
                (
                    LeafLobe::from_lobe(coated(0.5, 1.5, true).lobe).unwrap(),
                    0.3,
                ),
            ]),
        ),
    ];
    chi2_family("mix", &bsdfs);
}

/// The thin sheet is all Dirac: its test is on the lobe choice. Pearson's statistic of the
/// reflect/transmit counts against R' and 1 − R' (1 degree of freedom) at every angle.
#[test]
fn chi2_thin_dielectric() {
    let eta = [1.5f32, 1.33, 2.4];
    let count = eta.len() * THETAS_DEG.len();
    let alpha = sidak(FAMILY_ALPHA, count);
    let mut rng = SplitMix64(17);
    for &e in &eta {
        let b = Bsdf::new(BsdfLobe::ThinDielectric(ThinDielectric { eta: s(e) }));
        assert!(b.is_specular() && !b.lobe.is_reflection_only());
        for &theta in &THETAS_DEG {
            for side in [1.0f32, -1.0] {
                let wo = direction(theta, PHI_DEG) * Vec3A::new(1.0, 1.0, side);
                let n = 100_000;
                let mut reflected = 0usize;
                for _ in 0..n {
                    let smp = b
                        .sample(wo, rng.next_f32(), Vec2::ZERO, TransportMode::Radiance)
                        .expect("always samples");
                    assert!(smp.specular);
                    // Throughput is R'/P = 1 for a grey sheet, either way.
                    assert!((smp.weight()[0] - 1.0).abs() < 1e-5, "{:?}", smp);
                    if smp.transmission {
                        assert!((smp.wi + wo).length() < 1e-6);
                    } else {
                        reflected += 1;
                        assert!((smp.wi - Vec3A::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                    }
                }
                let r = f64::from(ThinDielectric { eta: s(e) }.reflectance(wo.z.abs())[0]);
                let (er, et) = (r * n as f64, (1.0 - r) * n as f64);
                let (or, ot) = (reflected as f64, (n - reflected) as f64);
                let stat = (or - er).powi(2) / er + (ot - et).powi(2) / et;
                let p = chi2_p_value(stat, 1);
                assert!(
                    p > alpha,
                    "η {e} θ {theta} side {side}: R' {r}, {reflected}/{n}, p {p}"
                );
            }
        }
    }
}

#[test]
fn thin_dielectric_sums_the_interreflections() {
    // R' = R + T²R Σ R²ᵏ, summed explicitly, against the closed form 2R/(1 + R).
    let sheet = ThinDielectric { eta: s(1.5) };
    for cos in [1.0f32, 0.7, 0.3, 0.05] {
        let r = super::fresnel::fresnel_dielectric(cos, 1.5);
        let (mut total, mut term) = (r, (1.0 - r) * (1.0 - r) * r);
        for _ in 0..200 {
            total += term;
            term *= r * r;
        }
        let closed = sheet.reflectance(cos)[0];
        assert!(
            (total - closed).abs() < 1e-6,
            "cos {cos}: {total} vs {closed}"
        );
        assert!((closed - 2.0 * r / (1.0 + r)).abs() < 1e-6);
    }
}

/// Monte Carlo albedo ∫ f cos θᵢ dωᵢ (lane 0) by the BSDF's own sampling, ± standard error.
fn albedo(bsdf: &Bsdf, wo: Vec3A, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = SplitMix64(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let ul = rng.next_f32();
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(smp) = bsdf.sample(wo, ul, u, TransportMode::Radiance) {
            let w = f64::from(smp.weight()[0]);
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn albedo_of_the_energy_conserving_models_is_at_most_one() {
    // White parameters, the worst case each paper's bound covers.
    let cases: Vec<(String, Bsdf)> = vec![
        (
            "oren_nayar full σ 20°".into(),
            oren_nayar(1.0, 20.0, OrenNayarForm::Full),
        ),
        (
            "oren_nayar full σ 60°".into(),
            oren_nayar(1.0, 60.0, OrenNayarForm::Full),
        ),
        (
            "oren_nayar qualitative σ 60°".into(),
            oren_nayar(1.0, 60.0, OrenNayarForm::Qualitative),
        ),
        ("phong n 1".into(), phong(0.0, 1.0, 1.0)),
        ("phong n 50".into(), phong(0.0, 1.0, 50.0)),
        ("phong mixed".into(), phong(0.4, 0.6, 10.0)),
        ("blinn_phong n 1".into(), blinn_phong(0.0, 1.0, 1.0)),
        ("blinn_phong n 50".into(), blinn_phong(0.0, 1.0, 50.0)),
        ("blinn_phong n 500".into(), blinn_phong(0.0, 1.0, 500.0)),
        ("ward α 0.05".into(), ward(0.0, 1.0, 0.05, 0.05)),
        ("ward α 0.3".into(), ward(0.0, 1.0, 0.3, 0.3)),
        ("ward α (0.1, 0.5)".into(), ward(0.0, 1.0, 0.1, 0.5)),
        ("coated nonlinear".into(), coated(1.0, 1.5, true)),
        ("coated linear".into(), coated(1.0, 1.5, false)),
        (
            "mix".into(),
            mix(&[
                (
                    LeafLobe::from_lobe(ward(0.0, 1.0, 0.2, 0.2).lobe).unwrap(),
                    0.5,
                ),
                (
                    LeafLobe::from_lobe(coated(1.0, 1.5, true).lobe).unwrap(),
                    0.5,
                ),
            ]),
        ),
    ];
    let mut report = Vec::new();
    for (name, bsdf) in &cases {
        for theta in [0.0f32, 45.0, 75.0, 89.0] {
            // The full Oren–Nayar model is not energy-conserving at grazing exit: with
            // ρ = 1, σ = 20° its albedo is 1.024 at 85° and 1.042 at 89° (a midpoint
            // quadrature of eqs. 8–9 agrees; the C₁–C₃ and L₂ fits were made for
            // θ ≲ 80°), so the paper promises nothing there.
            if name.starts_with("oren_nayar full") && theta > 75.0 {
                continue;
            }
            let wo = direction(theta, PHI_DEG);
            let (mean, se) = albedo(bsdf, wo, 60_000, 5);
            assert!(
                mean <= 1.0 + 4.5 * se + 1e-4,
                "{name} θ = {theta}: albedo {mean} ± {se}"
            );
            report.push(format!("{name} θ {theta}: {mean:.4}"));
        }
    }
    eprintln!("albedo: {}", report.join("; "));
    // Normalisations: a white lobe at normal incidence reflects everything (Phong and
    // Blinn–Phong exactly; the coated ρ = 1 surface returns all light, mirror included —
    // `albedo` counts the Dirac samples too).
    for (name, bsdf) in [
        ("phong", phong(0.0, 1.0, 30.0)),
        ("blinn_phong", blinn_phong(0.0, 1.0, 30.0)),
        ("coated", coated(1.0, 1.5, true)),
    ] {
        let (mean, se) = albedo(&bsdf, Vec3A::Z, 200_000, 9);
        assert!(
            (mean - 1.0).abs() < 4.5 * se + 2e-3,
            "{name} at normal incidence: {mean} ± {se}"
        );
    }
}

#[test]
fn reciprocity_of_the_library() {
    let bsdfs: Vec<(&str, Bsdf)> = vec![
        (
            "oren_nayar full",
            oren_nayar(0.7, 30.0, OrenNayarForm::Full),
        ),
        (
            "oren_nayar qualitative",
            oren_nayar(0.7, 30.0, OrenNayarForm::Qualitative),
        ),
        ("phong", phong(0.3, 0.6, 20.0)),
        ("blinn_phong", blinn_phong(0.3, 0.6, 20.0)),
        ("ward", ward(0.3, 0.6, 0.1, 0.4)),
        (
            "lafortune",
            lafortune(
                0.2,
                &[[-1.1, -0.8, 0.9, 8.0, 0.5], [0.5, 0.5, 0.7, 3.0, 0.2]],
            ),
        ),
        ("coated", coated(0.6, 1.5, true)),
        (
            "mix",
            mix(&[
                (
                    LeafLobe::from_lobe(phong(0.3, 0.6, 20.0).lobe).unwrap(),
                    0.4,
                ),
                (LeafLobe::Conductor(ggx(0.3)), 0.6),
            ]),
        ),
    ];
    let mut rng = SplitMix64(21);
    let mut pick = || {
        let z = rng.next_f32().max(1e-3);
        let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
        let r = (1.0 - z * z).sqrt();
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    };
    for (name, b) in &bsdfs {
        for _ in 0..300 {
            let (wo, wi) = (pick(), pick());
            let (a, c) = (
                b.eval(wo, wi, TransportMode::Radiance)[0],
                b.eval(wi, wo, TransportMode::Radiance)[0],
            );
            assert!(
                (a - c).abs() <= 2e-4 * a.abs().max(c.abs()) + 1e-6,
                "{name}: f({wo}, {wi}) = {a} vs {c}"
            );
        }
    }
}

#[test]
fn oren_nayar_at_zero_sigma_is_lambert() {
    let lambert = Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: SampledSpectrum::new([0.2, 0.4, 0.6, 0.8]),
    }));
    let mut rng = SplitMix64(3);
    for form in [OrenNayarForm::Full, OrenNayarForm::Qualitative] {
        let on = Bsdf::new(BsdfLobe::OrenNayar(OrenNayar {
            reflectance: SampledSpectrum::new([0.2, 0.4, 0.6, 0.8]),
            sigma_rad: 0.0,
            form,
        }));
        for _ in 0..200 {
            let wo = direction(90.0 * rng.next_f32(), 360.0 * rng.next_f32());
            let wi = direction(90.0 * rng.next_f32(), 360.0 * rng.next_f32());
            assert_eq!(
                on.eval(wo, wi, TransportMode::Radiance),
                lambert.eval(wo, wi, TransportMode::Radiance)
            );
            assert_eq!(
                on.pdf(wo, wi, TransportMode::Radiance),
                lambert.pdf(wo, wi, TransportMode::Radiance)
            );
        }
        // A tiny σ is continuous with it (no jump at 0).
        let on = oren_nayar(0.5, 1e-3, form);
        let l = 0.5 / std::f32::consts::PI;
        let v = on.eval(
            direction(40.0, 0.0),
            direction(70.0, 180.0),
            TransportMode::Radiance,
        )[0];
        assert!((v - l).abs() < 1e-5 * l + 1e-6, "{form:?}: {v}");
    }
}

#[test]
fn oren_nayar_full_model_matches_the_paper_at_known_points() {
    // Retro-reflection (θᵢ = θᵣ = 60°, same azimuth) with σ = 30°, ρ = 0.9: every term of
    // eqs. 8–9 by hand: C₁ = 1 − 0.5·0.274/0.604, C₂ = 0.45·0.274/0.364·sin 60°,
    // tan β = tan 60°, the C₃ term vanishes (|cos Δφ| = 1), L₂ = 0.17ρ²/π · 0.274/0.404 ·
    // (1 − (2/3)²).
    let sigma = 30f32.to_radians();
    let s2 = sigma * sigma;
    let b = oren_nayar(0.9, 30.0, OrenNayarForm::Full);
    let (wo, wi) = (direction(60.0, 0.0), direction(60.0, 0.0));
    let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let c2 = 0.45 * s2 / (s2 + 0.09) * 60f32.to_radians().sin();
    let tan_b = 60f32.to_radians().tan();
    let inv_pi = std::f32::consts::FRAC_1_PI;
    let expected = 0.9 * inv_pi * (c1 + c2 * tan_b)
        + 0.17 * 0.81 * inv_pi * s2 / (s2 + 0.13) * (1.0 - (2.0f32 / 3.0).powi(2));
    let got = b.eval(wo, wi, TransportMode::Radiance)[0];
    assert!((got - expected).abs() < 1e-5, "{got} vs {expected}");
    // Backward scattering is brighter than forward scattering (the paper's fig. 2).
    let forward = b.eval(wo, direction(60.0, 180.0), TransportMode::Radiance)[0];
    assert!(got > forward);
}

pub(super) fn merl_from(bsdf: Bsdf) -> MerlTable {
    MerlTable::from_fn(|th, td, pd| {
        let (wi, wo) = merl_directions(th, td, pd);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return [0.0; 3];
        }
        let f = f64::from(bsdf.eval(wo, wi, TransportMode::Radiance)[0]);
        [f; 3]
    })
}

#[test]
fn merl_files_round_trip_and_bad_files_are_refused() {
    let lambert = Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: s(0.5),
    }));
    let table = merl_from(lambert);
    let bytes = table.to_bytes();
    assert_eq!(bytes.len(), MERL_FILE_BYTES);
    assert_eq!(&bytes[..12], &[90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0]);
    // Stored divided by the channel scales.
    let red0 = f64::from_le_bytes(bytes[12..20].try_into().unwrap());
    // (The source is evaluated in f32.)
    assert!((red0 * MERL_SCALE[0] - 0.5 / std::f64::consts::PI).abs() < 1e-7);
    let back = MerlTable::from_bytes(&bytes, false).unwrap();
    for k in (0..3 * MERL_ENTRIES).step_by(997) {
        assert!((back.values[k] - table.values[k]).abs() <= 1e-15 * table.values[k].abs());
    }
    // Through a real file, written atomically.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lambert.binary");
    table.write(&path).unwrap();
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary left"
    );
    assert_eq!(MerlTable::read(&path, false).unwrap(), back);

    let err = |b: &[u8]| MerlTable::from_bytes(b, false).unwrap_err().message;
    let truncated = err(&bytes[..bytes.len() - 8]);
    assert!(
        truncated.contains("truncated") && truncated.contains(&MERL_FILE_BYTES.to_string()),
        "{truncated}"
    );
    assert!(err(&bytes[..7]).contains("header"));
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 8]);
    assert!(err(&long).contains("too long"));
    let mut header = bytes.clone();
    header[8] = 90;
    assert!(err(&header).contains("[90, 90, 90]"), "{}", err(&header));
    let mut negative = bytes.clone();
    let at = 12 + 8 * (MERL_ENTRIES + 5); // green table, bin (0, 0, 5)
    negative[at..at + 8].copy_from_slice(&(-1.0f64).to_le_bytes());
    let message = err(&negative);
    assert!(
        message.contains("1 negative")
            && message.contains("green")
            && message.contains("clamp_negative"),
        "{message}"
    );
    let clamped = MerlTable::from_bytes(&negative, true).unwrap();
    assert_eq!(clamped.values[MERL_ENTRIES + 5], 0.0);
    let mut nan = bytes.clone();
    nan[20..28].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(err(&nan).contains("not finite"));
    let missing = MerlTable::read(&dir.path().join("nope.binary"), false).unwrap_err();
    assert!(missing.to_string().contains("nope.binary"), "{missing}");
}

#[test]
fn merl_lookup_follows_the_reference_reader() {
    // BRDFRead.cpp's indices for hand-computed configurations: normal incidence and exit
    // (θ_h = 0 → bin 0, θ_d = 0 → bin 0); θᵢ = θₒ = 30.5° on opposite azimuths 90°, 270° (θ_h = 0, θ_d = 30.5° →
    // bin 30, φ_d = ±90° → bin 90 after folding).
    let mut table = MerlTable {
        values: vec![0.0; 3 * MERL_ENTRIES],
    };
    for (k, v) in table.values.iter_mut().enumerate() {
        *v = (k % MERL_ENTRIES) as f64;
    }
    let index = |wo: Vec3A, wi: Vec3A| table.lookup(wo, wi)[0] as usize;
    assert_eq!(index(Vec3A::Z, Vec3A::Z), 0);
    let (wo, wi) = (direction(30.5, 90.0), direction(30.5, 270.0));
    let (i_h, i_d, i_phi) = merl_bin(index(wo, wi));
    assert_eq!((i_h, i_d), (0, 30));
    assert!((89..=90).contains(&i_phi), "φ_d bin {i_phi}");
    // Half vector at θ_h = 45°: √(45/90)·90 = 63.6 → bin 63.
    let wo = Vec3A::Z;
    let wi = direction(90.0 - 1e-3, 0.0);
    assert_eq!(merl_bin(index(wo, wi)).0, 63);
    // Swapping the directions gives the same bin (reciprocity through the φ_d fold).
    let (a, b) = (direction(50.0, 10.0), direction(20.0, 250.0));
    assert_eq!(index(a, b), index(b, a));
    let _ = (MERL_THETA_H, MERL_THETA_D, MERL_PHI_D);
}

/// ∫ |f_table − f| cos θᵢ dωᵢ and ∫ (f_table − f) cos θᵢ dωᵢ by a midpoint rule (θ 360 ×
/// φ 720), spectral lane 0.
fn discretisation_error(table: &Measured, analytic: &Bsdf, wo: Vec3A) -> (f64, f64) {
    let (nt, np) = (360, 720);
    let (mut abs, mut signed) = (0.0f64, 0.0f64);
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..np {
            let p = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let wi = Vec3A::new(
                (t.sin() * p.cos()) as f32,
                (t.sin() * p.sin()) as f32,
                t.cos() as f32,
            );
            let d = f64::from(table.eval(wo, wi, TransportMode::Radiance)[0])
                - f64::from(analytic.eval(wo, wi, TransportMode::Radiance)[0]);
            let w = t.cos() * t.sin();
            abs += d.abs() * w;
            signed += d * w;
        }
    }
    let cell = std::f64::consts::FRAC_PI_2 / nt as f64 * std::f64::consts::TAU / np as f64;
    (abs * cell, signed * cell)
}

#[test]
fn merl_tables_reproduce_their_analytic_source() {
    let lambda = [450.0, 550.0, 650.0, 750.0];
    // Lambert 0.5: every bin holds 0.5/π, so the table is exact.
    let lambert = Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: s(0.5),
    }));
    let brdf = MerlBrdf::new(&merl_from(lambert));
    let m = Measured {
        brdf: &brdf,
        lambda_nm: lambda,
    };
    let mut rng = SplitMix64(8);
    for _ in 0..500 {
        let wo = direction(89.0 * rng.next_f32(), 360.0 * rng.next_f32());
        let wi = direction(89.0 * rng.next_f32(), 360.0 * rng.next_f32());
        let f = m.eval(wo, wi, TransportMode::Radiance);
        for lane in 0..4 {
            assert!((f[lane] - 0.5 / std::f32::consts::PI).abs() < 1e-6, "{f:?}");
        }
    }
    // Grey GGX α = 0.3: the piecewise-constant table's error in directional albedo.
    let analytic = Bsdf::new(BsdfLobe::Conductor(ggx(0.3)));
    let brdf = MerlBrdf::new(&merl_from(analytic));
    let m = Measured {
        brdf: &brdf,
        lambda_nm: lambda,
    };
    let mut worst = (0.0f64, 0.0f64);
    for theta in [0.0f32, 30.0, 60.0, 80.0] {
        let wo = direction(theta, 15.0);
        let (abs, signed) = discretisation_error(&m, &analytic, wo);
        eprintln!("MERL(GGX α 0.3) θₒ {theta}°: ∫|Δf|cos = {abs:.4}, Δalbedo = {signed:+.4}");
        worst = (worst.0.max(abs), worst.1.max(signed.abs()));
    }
    // The numbers docs/materials.md states (measured here): the bound is what the render
    // comparisons add to their Monte Carlo tolerance.
    assert!(worst.1 < 0.01, "albedo error {worst:?}");
    assert!(worst.0 < 0.05, "L1 error {worst:?}");
}

#[test]
fn chi2_merl() {
    let lambda = [450.0, 550.0, 650.0, 750.0];
    let sources = [
        ("GGX α 0.3", Bsdf::new(BsdfLobe::Conductor(ggx(0.3)))),
        ("GGX α 0.1", Bsdf::new(BsdfLobe::Conductor(ggx(0.1)))),
        (
            "oren_nayar σ 30° + blinn_phong",
            mix(&[
                (
                    LeafLobe::from_lobe(oren_nayar(0.5, 30.0, OrenNayarForm::Full).lobe).unwrap(),
                    0.5,
                ),
                (
                    LeafLobe::from_lobe(blinn_phong(0.0, 1.0, 60.0).lobe).unwrap(),
                    0.5,
                ),
            ]),
        ),
    ];
    let brdfs: Vec<(String, MerlBrdf)> = sources
        .iter()
        .map(|(name, b)| (name.to_string(), MerlBrdf::new(&merl_from(*b))))
        .collect();
    let bsdfs: Vec<(String, Bsdf)> = brdfs
        .iter()
        .map(|(name, brdf)| {
            (
                name.clone(),
                Bsdf::new(BsdfLobe::Measured(Measured {
                    brdf,
                    lambda_nm: lambda,
                })),
            )
        })
        .collect();
    // The tabulated density is piecewise constant on a grid finer than the test's bins:
    // integrate the expected counts on 32 sub-cells per bin edge.
    chi2_family_with("merl", &bsdfs, 32);
}

#[test]
fn merl_samples_carry_the_eval_and_pdf_of_their_direction() {
    // `Measured::sample` computes f and pdf from the cell it sampled (no second lookup);
    // they must equal `eval` and `pdf` at the returned direction (up to a sample landing
    // on a bin edge, where rounding may pick the neighbour: at most 0.5 %).
    let brdf = MerlBrdf::new(&merl_from(Bsdf::new(BsdfLobe::Conductor(ggx(0.2)))));
    let m = Measured {
        brdf: &brdf,
        lambda_nm: [450.0, 550.0, 650.0, 750.0],
    };
    let mut rng = SplitMix64(77);
    let (mut total, mut off) = (0usize, 0usize);
    for _ in 0..20_000 {
        let wo = direction(85.0 * rng.next_f32(), 360.0 * rng.next_f32());
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let Some(smp) = m.sample(wo, rng.next_f32(), u, TransportMode::Radiance) else {
            continue;
        };
        total += 1;
        let f = m.eval(wo, smp.wi, TransportMode::Radiance);
        let p = m.pdf(wo, smp.wi, TransportMode::Radiance);
        if (f[0] - smp.f[0]).abs() > 1e-4 * f[0].abs() + 1e-7
            || (p - smp.pdf).abs() > 1e-3 * p.abs()
        {
            off += 1;
        }
    }
    assert!(total > 15_000, "{total} samples");
    assert!(
        off * 200 <= total,
        "{off} of {total} samples disagree with eval/pdf"
    );
}

#[test]
fn merl_sampling_is_unbiased() {
    // A Lambert ρ = 0.5 table is exact, so E[f cos θᵢ / p] through the tabulated sampler
    // (its cells fitted to the table, not to the cosine) must be 0.5 at every angle (5
    // standard errors, 400 000 samples each).
    let lambert = Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: s(0.5),
    }));
    let brdf = MerlBrdf::new(&merl_from(lambert));
    let m = Bsdf::new(BsdfLobe::Measured(Measured {
        brdf: &brdf,
        lambda_nm: [450.0, 550.0, 650.0, 750.0],
    }));
    for theta in [0.0f32, 20.0, 45.0, 70.0, 85.0] {
        let wo = direction(theta, 40.0);
        let (mean, se) = albedo(&m, wo, 400_000, 31);
        assert!(
            (mean - 0.5).abs() < 5.0 * se + 1e-6,
            "θ {theta}: albedo {mean} ± {se}"
        );
    }
}
