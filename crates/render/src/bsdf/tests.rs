//! Physics tests shared by every BSDF: chi-square tests of each sampling routine against
//! its pdf (Šidák-corrected per family), reciprocity, energy bounds (Monte Carlo, with the
//! estimator's standard error) and the smooth dielectric's Fresnel split.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::*;
use prism_testkit::chi2::{chi2_test, sidak, Chi2Config, SplitMix64};

/// Incident polar angles of every chi-square family (degrees), at azimuth `PHI_DEG`.
const THETAS_DEG: [f32; 4] = [0.0, 30.0, 60.0, 85.0];
/// Off-axis azimuth so anisotropic lobes are not seen along a symmetry axis.
const PHI_DEG: f32 = 30.0;
/// Family-wise error rate of each chi-square test function.
const FAMILY_ALPHA: f64 = 0.01;

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3A {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn gold_like() -> (SampledSpectrum, SampledSpectrum) {
    // Johnson & Christy 1972 Au at ~450, 550, 650, 750 nm, rounded.
    (
        SampledSpectrum::new([1.38, 0.43, 0.17, 0.14]),
        SampledSpectrum::new([1.85, 2.45, 3.6, 4.6]),
    )
}

fn conductor(model: MicrofacetModel, ax: f32, ay: f32) -> Bsdf<'static> {
    let (eta, k) = gold_like();
    Bsdf::new(BsdfLobe::Conductor(Conductor {
        eta,
        k,
        distribution: MicrofacetDistribution::new(model, ax, ay),
    }))
}

fn dielectric(model: MicrofacetModel, ax: f32, ay: f32, eta: f32) -> Bsdf<'static> {
    Bsdf::new(BsdfLobe::Dielectric(Dielectric {
        eta: SampledSpectrum::splat(eta),
        distribution: MicrofacetDistribution::new(model, ax, ay),
    }))
}

/// Roughnesses of every rough family: isotropic low and high, and anisotropic.
const ROUGHNESS: [(f32, f32); 3] = [(0.2, 0.2), (0.5, 0.5), (0.1, 0.4)];

/// Runs the chi-square family for `make(α_x, α_y)` over `ROUGHNESS` × `THETAS_DEG` ×
/// `sides` (+1: ωₒ above, −1: below), Šidák-corrected; panics listing every failure.
///
/// Refraction near the critical angle makes the transmission pdf peak sharply, so the
/// expected counts of transmissive families are integrated on finer sub-cells (at 16 per
/// bin edge the midpoint rule's error alone fails η = 1.33 at θ = 85°, α = 0.5).
fn chi2_family(name: &str, sides: &[f32], make: impl Fn(f32, f32) -> Bsdf<'static>) {
    chi2_family_over(name, &ROUGHNESS, sides, make);
}

fn chi2_family_over(
    name: &str,
    roughness: &[(f32, f32)],
    sides: &[f32],
    make: impl Fn(f32, f32) -> Bsdf<'static>,
) {
    let count = roughness.len() * THETAS_DEG.len() * sides.len();
    let transmissive = sides.contains(&-1.0) && !make(0.3, 0.3).lobe.is_reflection_only();
    let config = Chi2Config {
        sample_count: if transmissive { 100_000 } else { 200_000 },
        significance: sidak(FAMILY_ALPHA, count),
        integration_resolution: if transmissive { 32 } else { 16 },
        ..Chi2Config::default()
    };
    let mut failures = Vec::new();
    let mut lowest_p = 1.0f64;
    for &(ax, ay) in roughness {
        let bsdf = make(ax, ay);
        for &theta in &THETAS_DEG {
            for &side in sides {
                let wo = direction(theta, PHI_DEG) * Vec3A::new(1.0, 1.0, side);
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
                    failures.push(format!(
                        "{name} α = ({ax}, {ay}) θ = {theta}° side {side}: {}",
                        r.message
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("{name}: {count} tests passed, lowest p = {lowest_p:.3e}");
}

#[test]
fn chi2_rough_conductor_ggx() {
    chi2_family("rough conductor GGX", &[1.0], |ax, ay| {
        conductor(MicrofacetModel::Ggx, ax, ay)
    });
}

#[test]
fn chi2_rough_conductor_beckmann() {
    chi2_family("rough conductor Beckmann", &[1.0], |ax, ay| {
        conductor(MicrofacetModel::Beckmann, ax, ay)
    });
}

#[test]
fn chi2_rough_dielectric() {
    chi2_family("rough dielectric GGX η = 1.5", &[1.0, -1.0], |ax, ay| {
        dielectric(MicrofacetModel::Ggx, ax, ay, 1.5)
    });
}

#[test]
fn chi2_rough_dielectric_beckmann() {
    chi2_family(
        "rough dielectric Beckmann η = 1.5",
        &[1.0, -1.0],
        |ax, ay| dielectric(MicrofacetModel::Beckmann, ax, ay, 1.5),
    );
}

#[test]
fn chi2_rough_dielectric_dispersive() {
    // Lanes differ; sampling and pdf follow the hero lane (η = 1.33 here, water-like, and
    // an index below 1 as for an air bubble in glass).
    for eta0 in [1.33f32, 0.67] {
        let name = format!("dispersive rough dielectric, hero η = {eta0}");
        chi2_family_over(&name, &[(0.5, 0.5)], &[1.0, -1.0], |ax, ay| {
            Bsdf::new(BsdfLobe::Dielectric(Dielectric {
                eta: SampledSpectrum::new([eta0, eta0 * 1.02, eta0 * 1.04, eta0 * 0.98]),
                distribution: MicrofacetDistribution::new(MicrofacetModel::Ggx, ax, ay),
            }))
        });
    }
}

#[test]
fn chi2_two_sided() {
    // Seen from below, a two-sided conductor samples the mirrored lobe.
    chi2_family("two-sided rough conductor", &[-1.0], |ax, ay| {
        let mut b = conductor(MicrofacetModel::Ggx, ax, ay);
        b.two_sided = true;
        b
    });
}

/// Random unit directions on the upper hemisphere (uniform in solid angle).
fn upper_directions(n: usize, seed: u64) -> Vec<Vec3A> {
    let mut rng = SplitMix64(seed);
    (0..n)
        .map(|_| {
            let z = rng.next_f32().max(1e-3);
            let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
            let r = (1.0 - z * z).sqrt();
            Vec3A::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// |a − b| ≤ rel·max(|a|, |b|) + 10⁻⁶ per lane. The absolute floor covers refraction
/// near the critical angle, where cos θₜ = √(1 − sin²θₜ) amplifies the f32 rounding of
/// the inputs (a 1.6 % difference at f ≈ 6·10⁻⁷ was seen; f64 agrees to 10⁻¹⁰ there).
fn assert_close_spectra(a: SampledSpectrum, b: SampledSpectrum, rel: f32, what: &str) {
    for l in 0..4 {
        let scale = a[l].abs().max(b[l].abs());
        assert!(
            (a[l] - b[l]).abs() <= rel * scale + 1e-6,
            "{what}: lane {l}: {} vs {}",
            a[l],
            b[l]
        );
    }
}

#[test]
fn reciprocity_of_reflection_only_bsdfs() {
    let mut bsdfs = vec![Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: SampledSpectrum::new([0.2, 0.4, 0.6, 0.8]),
    }))];
    for model in [MicrofacetModel::Ggx, MicrofacetModel::Beckmann] {
        for &(ax, ay) in &ROUGHNESS {
            bsdfs.push(conductor(model, ax, ay));
        }
    }
    let dirs = upper_directions(400, 11);
    for bsdf in &bsdfs {
        for pair in dirs.chunks(2) {
            let (wo, wi) = (pair[0], pair[1]);
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                let a = bsdf.eval(wo, wi, mode);
                let b = bsdf.eval(wi, wo, mode);
                assert_close_spectra(a, b, 2e-4, &format!("{bsdf:?} {wo} {wi}"));
            }
            // Two-sided: the same from below.
            let mut two = *bsdf;
            two.two_sided = true;
            let flip = Vec3A::new(1.0, 1.0, -1.0);
            let (a, b) = (
                two.eval(wo * flip, wi * flip, TransportMode::Radiance),
                bsdf.eval(wo, wi, TransportMode::Radiance),
            );
            assert_close_spectra(a, b, 1e-6, "two-sided from below");
            assert!(bsdf
                .eval(wo * flip, wi * flip, TransportMode::Radiance)
                .is_black());
        }
    }
}

#[test]
fn generalised_reciprocity_of_the_rough_dielectric() {
    // Veach 1997 eq. 5.14: f(ωᵢ→ωₒ)/η_o² = f(ωₒ→ωᵢ)/η_i², η of the medium each direction
    // lies in; `eval(ωₒ, ωᵢ)` is f(ωᵢ→ωₒ). And the adjoint: f*(ωₒ, ωᵢ) = f(ωᵢ, ωₒ).
    let eta = 1.5f32;
    let side_eta = |w: Vec3A| if w.z > 0.0 { 1.0 } else { eta };
    let mut rng = SplitMix64(5);
    for model in [MicrofacetModel::Ggx, MicrofacetModel::Beckmann] {
        for &(ax, ay) in &ROUGHNESS {
            let b = dielectric(model, ax, ay, eta);
            let mut nonzero = 0;
            for _ in 0..400 {
                let mut pick = || {
                    let z = 2.0 * rng.next_f32() - 1.0;
                    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    Vec3A::new(r * phi.cos(), r * phi.sin(), z)
                };
                let (wo, wi) = (pick(), pick());
                let fwd = b.eval(wo, wi, TransportMode::Radiance);
                let rev = b.eval(wi, wo, TransportMode::Radiance);
                let (eo, ei) = (side_eta(wo), side_eta(wi));
                assert_close_spectra(
                    fwd / (eo * eo),
                    rev / (ei * ei),
                    5e-4,
                    &format!("{model:?} α ({ax}, {ay}) {wo} {wi}"),
                );
                let adj = b.eval(wo, wi, TransportMode::Importance);
                assert_close_spectra(adj, rev, 5e-4, "adjoint");
                if !fwd.is_black() {
                    nonzero += 1;
                }
            }
            assert!(nonzero > 100, "{nonzero}");
        }
    }
}

/// Monte Carlo estimate of ∫ f |cos θᵢ| dωᵢ (lane 0) from `n` BSDF samples, and its
/// standard error.
fn albedo(bsdf: &Bsdf, wo: Vec3A, mode: TransportMode, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = SplitMix64(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let ul = rng.next_f32();
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(s) = bsdf.sample(wo, ul, u, mode) {
            let w = f64::from(s.weight()[0]);
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn albedo_of_reflection_only_bsdfs_is_at_most_one() {
    // A near-perfect conductor (η = 0.05, k = 10: F ≥ 0.998) so that a loss of energy can
    // only come from masking, and a white Lambertian.
    let strong = |model, ax, ay| {
        Bsdf::new(BsdfLobe::Conductor(Conductor {
            eta: SampledSpectrum::splat(0.05),
            k: SampledSpectrum::splat(10.0),
            distribution: MicrofacetDistribution::new(model, ax, ay),
        }))
    };
    let mut cases = vec![(
        "lambert 1".to_string(),
        Bsdf::new(BsdfLobe::Lambert(Lambert {
            reflectance: SampledSpectrum::splat(1.0),
        })),
    )];
    for model in [MicrofacetModel::Ggx, MicrofacetModel::Beckmann] {
        for (ax, ay) in [(0.05, 0.05), (0.2, 0.2), (0.5, 0.5), (1.0, 1.0), (0.1, 0.4)] {
            cases.push((format!("{model:?} α ({ax}, {ay})"), strong(model, ax, ay)));
        }
    }
    cases.push((
        "smooth conductor".into(),
        strong(MicrofacetModel::Ggx, 0.0, 0.0),
    ));
    let mut report = Vec::new();
    for (name, bsdf) in &cases {
        for theta in [0.0f32, 30.0, 60.0, 85.0, 89.0] {
            let wo = direction(theta, PHI_DEG);
            let (mean, se) = albedo(bsdf, wo, TransportMode::Radiance, 40_000, 3);
            assert!(
                mean <= 1.0 + 4.0 * se + 1e-6,
                "{name} θ = {theta}: albedo {mean} ± {se}"
            );
            assert!(mean > 0.0, "{name} θ = {theta}: albedo {mean}");
            report.push(format!("{name} θ={theta}: {mean:.4}±{se:.4}"));
        }
    }
    eprintln!("albedo: {}", report.join("; "));
    // Smooth-ish lobes lose almost nothing at normal incidence (masking ≈ 1).
    let (mean, se) = albedo(
        &strong(MicrofacetModel::Ggx, 0.05, 0.05),
        Vec3A::Z,
        TransportMode::Radiance,
        100_000,
        4,
    );
    assert!(mean > 0.99 && mean <= 1.0 + 4.0 * se, "{mean} ± {se}");
}

#[test]
fn dielectric_energy_in_importance_form_is_at_most_one() {
    // In importance (adjoint) form the BSDF carries flux: reflected + transmitted ≤ 1.
    let mut report = Vec::new();
    for model in [MicrofacetModel::Ggx, MicrofacetModel::Beckmann] {
        for (ax, ay) in [(0.0, 0.0), (0.05, 0.05), (0.3, 0.3), (0.8, 0.8), (0.1, 0.4)] {
            for eta in [1.5f32, 1.0 / 1.5] {
                let b = dielectric(model, ax, ay, eta);
                for theta in [0.0f32, 30.0, 60.0, 85.0] {
                    for side in [1.0f32, -1.0] {
                        let wo = direction(theta, PHI_DEG) * Vec3A::new(1.0, 1.0, side);
                        let (mean, se) = albedo(&b, wo, TransportMode::Importance, 20_000, 9);
                        assert!(
                            mean <= 1.0 + 4.0 * se + 1e-5,
                            "{model:?} α ({ax}, {ay}) η {eta} θ {theta} side {side}: {mean} ± {se}"
                        );
                        if ax == 0.0 {
                            // Smooth: every sample carries exactly 1.
                            assert!((mean - 1.0).abs() < 1e-4, "{mean}");
                        }
                        report.push(format!("{ax}/{eta:.2}/{theta}/{side}: {mean:.4}"));
                    }
                }
            }
        }
    }
    eprintln!("dielectric importance energy: {}", report.join("; "));
}

#[test]
fn smooth_dielectric_splits_by_fresnel() {
    let eta = 1.5f32;
    let b = dielectric(MicrofacetModel::Ggx, 0.0, 0.0, eta);
    assert!(b.is_specular() && b.has_specular());
    for theta in [0.0f32, 30.0, 60.0, 85.0] {
        for side in [1.0f32, -1.0] {
            let wo = direction(theta, PHI_DEG) * Vec3A::new(1.0, 1.0, side);
            let fr = fresnel::fresnel_dielectric(wo.z, eta);
            // Probabilities: the lobe pdfs sum to 1 and equal F and 1 − F.
            let refl = b
                .sample(wo, 0.0, Vec2::ZERO, TransportMode::Radiance)
                .unwrap();
            assert!(!refl.transmission && refl.specular);
            assert!((refl.pdf - fr).abs() < 1e-6);
            assert!((refl.wi - Vec3A::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            assert!((refl.weight()[0] - 1.0).abs() < 1e-5);
            match b.sample(wo, 0.999_999, Vec2::ZERO, TransportMode::Radiance) {
                Some(t) if t.transmission => {
                    assert!((refl.pdf + t.pdf - 1.0).abs() < 1e-6);
                    let etap = if wo.z > 0.0 { eta } else { 1.0 / eta };
                    assert!((t.eta - etap).abs() < 1e-6);
                    // Snell: sin θₜ = sin θᵢ / η'; radiance scaled by 1/η'².
                    let sin_o = (1.0 - wo.z * wo.z).sqrt();
                    let sin_t = (1.0 - t.wi.z * t.wi.z).sqrt();
                    assert!((sin_t - sin_o / etap).abs() < 1e-5);
                    assert!((t.weight()[0] - 1.0 / (etap * etap)).abs() < 1e-5);
                    let ti = b
                        .sample(wo, 0.999_999, Vec2::ZERO, TransportMode::Importance)
                        .unwrap();
                    assert!((ti.weight()[0] - 1.0).abs() < 1e-5);
                }
                // Total internal reflection: F = 1, only reflection is ever chosen.
                other => assert!(
                    fr == 1.0 && other.is_some_and(|s| !s.transmission),
                    "θ {theta} side {side}: F = {fr}"
                ),
            }
            // Monte Carlo: the reflected fraction matches F within 4 standard errors.
            let n = 20_000;
            let mut rng = SplitMix64(21);
            let reflected = (0..n)
                .filter(|_| {
                    b.sample(wo, rng.next_f32(), Vec2::ZERO, TransportMode::Radiance)
                        .is_some_and(|s| !s.transmission)
                })
                .count() as f64
                / n as f64;
            let se = (f64::from(fr) * (1.0 - f64::from(fr)) / n as f64).sqrt();
            assert!((reflected - f64::from(fr)).abs() <= 4.0 * se + 1e-9);
            // Dirac lobes: eval and pdf are zero.
            assert!(b.eval(wo, refl.wi, TransportMode::Radiance).is_black());
            assert_eq!(b.pdf(wo, refl.wi, TransportMode::Radiance), 0.0);
        }
    }
}

#[test]
fn smooth_conductor_is_a_fresnel_mirror() {
    let b = conductor(MicrofacetModel::Ggx, 0.0, 0.0);
    assert!(b.is_specular());
    let (eta, k) = gold_like();
    for theta in [0.0f32, 45.0, 80.0] {
        let wo = direction(theta, PHI_DEG);
        let s = b
            .sample(wo, 0.3, Vec2::new(0.2, 0.9), TransportMode::Radiance)
            .unwrap();
        assert!(s.specular && !s.transmission && s.pdf == 1.0 && s.eta == 1.0);
        assert!((s.wi - Vec3A::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        let expected = fresnel::fresnel_complex_spectrum(wo.z, eta, k);
        assert_close_spectra(s.weight(), expected, 1e-5, "mirror weight");
        assert!(b.eval(wo, s.wi, TransportMode::Radiance).is_black());
    }
    // Seen from below: nothing (one-sided), unless two-sided.
    let below = Vec3A::new(0.0, 0.6, -0.8);
    assert!(b
        .sample(below, 0.5, Vec2::splat(0.5), TransportMode::Radiance)
        .is_none());
    let mut two = b;
    two.two_sided = true;
    let s = two
        .sample(below, 0.5, Vec2::splat(0.5), TransportMode::Radiance)
        .unwrap();
    assert!((s.wi - Vec3A::new(0.0, -0.6, -0.8)).length() < 1e-6);
}

#[test]
fn rough_dielectric_evaluates_each_lane_with_its_own_eta() {
    let etas = [1.5f32, 1.52, 1.48, 1.55];
    let dist = MicrofacetDistribution::new(MicrofacetModel::Ggx, 0.3, 0.3);
    let b = Dielectric {
        eta: SampledSpectrum::new(etas),
        distribution: dist,
    };
    let wo = direction(40.0, 10.0);
    let wi = direction(150.0, 200.0);
    let f = b.eval(wo, wi, TransportMode::Radiance);
    for (l, &eta) in etas.iter().enumerate() {
        let single = Dielectric {
            eta: SampledSpectrum::splat(eta),
            distribution: dist,
        };
        let expected = single.eval(wo, wi, TransportMode::Radiance)[0];
        assert!(
            (f[l] - expected).abs() <= 1e-6 * expected.max(1e-3),
            "lane {l}"
        );
    }
    // The pdf is the hero lane's.
    let hero = Dielectric {
        eta: SampledSpectrum::splat(etas[0]),
        distribution: dist,
    };
    assert_eq!(
        b.pdf(wo, wi, TransportMode::Radiance),
        hero.pdf(wo, wi, TransportMode::Radiance)
    );
    assert!(f[0] != f[1]);
}

#[test]
fn two_sided_is_ignored_for_dielectrics() {
    let mut b = dielectric(MicrofacetModel::Ggx, 0.3, 0.3, 1.5);
    let wo = direction(30.0, 0.0) * Vec3A::new(1.0, 1.0, -1.0);
    let wi = direction(20.0, 180.0);
    let plain = b.eval(wo, wi, TransportMode::Radiance);
    b.two_sided = true;
    assert_eq!(b.eval(wo, wi, TransportMode::Radiance), plain);
    assert!(!plain.is_black());
}

#[test]
fn index_matched_dielectric_passes_straight_through() {
    // η = 1 is a Dirac pass-through even when rough (no refraction, no reflection).
    let b = dielectric(MicrofacetModel::Ggx, 0.4, 0.4, 1.0);
    assert!(b.is_specular());
    let wo = direction(40.0, 70.0);
    let s = b
        .sample(wo, 0.5, Vec2::splat(0.3), TransportMode::Radiance)
        .unwrap();
    assert!(s.transmission && s.specular && (s.wi + wo).length() < 1e-6);
    assert!((s.weight()[0] - 1.0).abs() < 1e-6 && s.eta == 1.0);
}

#[test]
fn every_lobe_stays_finite_on_edge_directions() {
    let mut lobes = vec![Bsdf::new(BsdfLobe::Lambert(Lambert {
        reflectance: SampledSpectrum::splat(0.5),
    }))];
    for model in [MicrofacetModel::Ggx, MicrofacetModel::Beckmann] {
        for (ax, ay) in [(0.0, 0.0), (1e-4, 1e-4), (0.0, 0.3), (0.3, 0.3), (1.0, 1.0)] {
            lobes.push(conductor(model, ax, ay));
            lobes.push(dielectric(model, ax, ay, 1.5));
            lobes.push(dielectric(model, ax, ay, 0.7));
        }
    }
    let mut dirs = vec![
        Vec3A::Z,
        -Vec3A::Z,
        Vec3A::X,
        Vec3A::new(0.0, -1.0, 0.0),
        Vec3A::new(1.0, 0.0, 1e-7).normalize(),
        Vec3A::new(0.6, 0.0, -0.8),
    ];
    dirs.extend(
        upper_directions(20, 4)
            .into_iter()
            .map(|w| w * Vec3A::new(1.0, 1.0, -1.0)),
    );
    dirs.extend(upper_directions(20, 5));
    let mut rng = SplitMix64(13);
    for b in &lobes {
        for &wo in &dirs {
            for &wi in &dirs {
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let f = b.eval(wo, wi, mode);
                    let p = b.pdf(wo, wi, mode);
                    assert!(
                        !f.has_non_finite() && f.min_component() >= 0.0,
                        "{b:?} {wo} {wi}: {f:?}"
                    );
                    assert!(p.is_finite() && p >= 0.0, "{b:?} {wo} {wi}: {p}");
                }
            }
            for _ in 0..50 {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                if let Some(s) = b.sample(wo, rng.next_f32(), u, TransportMode::Radiance) {
                    assert!((s.wi.length() - 1.0).abs() < 1e-4, "{b:?} {wo}: {s:?}");
                    assert!(
                        s.pdf > 0.0 && !s.weight().has_non_finite(),
                        "{b:?} {wo}: {s:?}"
                    );
                }
            }
        }
    }
}
