//! Tests of the `Bxdf` contract over every lobe in `leaves`: χ² of `sample` against `pdf`,
//! reciprocity of reflection, `albedo` against an independent Monte Carlo estimate of
//! ∫ f |cos θᵢ| dωᵢ (and ≤ 1 where the model claims energy conservation), the angular
//! bandwidths against the formulas probe.rs used before they moved into the lobes, and the
//! size of a `Bsdf`. A new lobe is covered once it has a representative in `leaves` and the
//! arms the compiler asks for.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::library_tests::merl_from;
use super::*;
use prism_testkit::chi2::{chi2_test, sidak, Chi2Config, SplitMix64};

fn s(v: f32) -> SampledSpectrum {
    SampledSpectrum::splat(v)
}

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3A {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn conductor(model: MicrofacetModel, ax: f32, ay: f32) -> Conductor {
    // Gold-like at every lane: η = 0.2, k = 3.
    Conductor {
        eta: s(0.2),
        k: s(3.0),
        distribution: MicrofacetDistribution::new(model, ax, ay),
    }
}

fn dielectric(alpha: f32, eta: f32) -> Dielectric {
    Dielectric {
        eta: s(eta),
        distribution: MicrofacetDistribution::new(MicrofacetModel::Ggx, alpha, alpha),
    }
}

fn lafortune() -> Lafortune {
    let lobe = |cx, cy, cz, exponent, albedo| LafortuneLobe {
        cx,
        cy,
        cz,
        exponent,
        albedo: s(albedo),
    };
    Lafortune {
        diffuse: s(0.3),
        // A Phong-like lobe about the mirror direction and an off-specular one.
        lobes: [
            lobe(-1.0, -1.0, 1.0, 20.0, 0.5),
            lobe(-1.1, -1.1, 0.9, 8.0, 0.2),
            LafortuneLobe::NONE,
        ],
        count: 2,
    }
}

fn coated() -> Coated {
    Coated {
        diffuse: s(0.6),
        eta: 1.5,
        fdr_internal: internal_diffuse_reflectance(1.5),
        nonlinear: true,
    }
}

/// Every leaf lobe with a name, smooth and rough variants where the albedo or bandwidth
/// takes a different branch; `Measured` (borrowing `brdf`) only with a table.
fn leaves(brdf: Option<&MerlBrdf>) -> Vec<(&'static str, LeafLobe<'_>)> {
    let mut out = vec![
        (
            "lambert",
            LeafLobe::Lambert(Lambert {
                reflectance: s(0.7),
            }),
        ),
        (
            "conductor smooth",
            LeafLobe::Conductor(conductor(MicrofacetModel::Ggx, 0.0, 0.0)),
        ),
        (
            "conductor GGX α 0.3",
            LeafLobe::Conductor(conductor(MicrofacetModel::Ggx, 0.3, 0.3)),
        ),
        (
            "conductor Beckmann α (0.1, 0.4)",
            LeafLobe::Conductor(conductor(MicrofacetModel::Beckmann, 0.1, 0.4)),
        ),
        (
            "dielectric smooth",
            LeafLobe::Dielectric(dielectric(0.0, 1.5)),
        ),
        (
            "dielectric GGX α 0.3",
            LeafLobe::Dielectric(dielectric(0.3, 1.5)),
        ),
        (
            "oren_nayar σ 0",
            LeafLobe::OrenNayar(OrenNayar {
                reflectance: s(0.8),
                sigma_rad: 0.0,
                form: OrenNayarForm::Full,
            }),
        ),
        (
            "oren_nayar full σ 20°",
            LeafLobe::OrenNayar(OrenNayar {
                reflectance: s(0.8),
                sigma_rad: 20f32.to_radians(),
                form: OrenNayarForm::Full,
            }),
        ),
        (
            "oren_nayar qualitative σ 60°",
            LeafLobe::OrenNayar(OrenNayar {
                reflectance: s(0.8),
                sigma_rad: 60f32.to_radians(),
                form: OrenNayarForm::Qualitative,
            }),
        ),
        (
            "phong",
            LeafLobe::Phong(Phong {
                diffuse: s(0.3),
                specular: s(0.6),
                exponent: 30.0,
            }),
        ),
        (
            "phong without specular",
            LeafLobe::Phong(Phong {
                diffuse: s(0.5),
                specular: s(0.0),
                exponent: 30.0,
            }),
        ),
        (
            "blinn_phong",
            LeafLobe::BlinnPhong(BlinnPhong {
                diffuse: s(0.2),
                specular: s(0.7),
                exponent: 50.0,
            }),
        ),
        (
            "blinn_phong without specular",
            LeafLobe::BlinnPhong(BlinnPhong {
                diffuse: s(0.5),
                specular: s(0.0),
                exponent: 50.0,
            }),
        ),
        (
            "ward α (0.1, 0.3)",
            LeafLobe::Ward(Ward {
                diffuse: s(0.2),
                specular: s(0.6),
                alpha_x: 0.1,
                alpha_y: 0.3,
            }),
        ),
        ("lafortune", LeafLobe::Lafortune(lafortune())),
        ("coated", LeafLobe::Coated(coated())),
        (
            "thin_dielectric",
            LeafLobe::ThinDielectric(ThinDielectric { eta: s(1.5) }),
        ),
        // White at the roughest and the smoothest roughness the scene format accepts.
        (
            "sheen r 0.1",
            LeafLobe::Sheen(Sheen {
                reflectance: s(1.0),
                roughness: 0.1,
            }),
        ),
        (
            "sheen r 1",
            LeafLobe::Sheen(Sheen {
                reflectance: s(1.0),
                roughness: 1.0,
            }),
        ),
    ];
    if let Some(brdf) = brdf {
        out.push((
            "measured (GGX α 0.3 table)",
            LeafLobe::Measured(Measured {
                brdf,
                lambda_nm: [450.0, 550.0, 650.0, 750.0],
            }),
        ));
    }
    out
}

/// A mix of a diffuse, a Dirac and a glossy leaf (closed-form and estimated albedos).
fn mix_lobe<'a>() -> BsdfLobe<'a> {
    let parts = [
        (
            LeafLobe::Lambert(Lambert {
                reflectance: s(0.5),
            }),
            0.3,
        ),
        (
            LeafLobe::Conductor(conductor(MicrofacetModel::Ggx, 0.0, 0.0)),
            0.3,
        ),
        (
            LeafLobe::Ward(Ward {
                diffuse: s(0.1),
                specular: s(0.8),
                alpha_x: 0.2,
                alpha_y: 0.2,
            }),
            0.4,
        ),
    ];
    BsdfLobe::Mix(Mix::new(&parts).expect("valid mix"))
}

/// χ² of every leaf's sampler against its pdf (its non-Dirac samples; a lobe that is only
/// Dirac has no density to test), at three incident angles, Šidák-corrected to 1 % over
/// all. The per-family tests (`tests.rs`, `library_tests.rs`) sweep more parameters.
#[test]
fn sampling_of_every_leaf_matches_its_pdf() {
    let thetas_deg = [20.0f32, 60.0, 85.0];
    let lobes: Vec<_> = leaves(None)
        .into_iter()
        .filter(|(_, leaf)| !leaf.is_specular())
        .collect();
    let count = lobes.len() * thetas_deg.len();
    let config = Chi2Config {
        sample_count: 200_000,
        significance: sidak(0.01, count),
        integration_resolution: 32,
        ..Chi2Config::default()
    };
    let (mut failures, mut lowest_p) = (Vec::new(), 1.0f64);
    for (name, leaf) in &lobes {
        for theta in thetas_deg {
            let (wo, mode) = (direction(theta, 30.0), TransportMode::Radiance);
            let r = chi2_test(
                &config,
                |ul, u| {
                    leaf.sample(wo, ul, u, mode)
                        .filter(|smp| !smp.specular)
                        .map(|smp| smp.wi)
                },
                |wi| f64::from(leaf.pdf(wo, wi, mode)),
            );
            lowest_p = lowest_p.min(r.p_value);
            if !r.passed {
                failures.push(format!("{name} θ {theta}°: {}", r.message));
            }
        }
    }
    eprintln!("{count} χ² tests, lowest p = {lowest_p:.3e}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// f(ωₒ, ωᵢ) = f(ωᵢ, ωₒ) for reflection (both directions above the surface) for every
/// leaf (Helmholtz; refraction's generalised form is tested in `tests.rs`), to f32
/// rounding.
#[test]
fn reflection_of_every_leaf_is_reciprocal() {
    let mut rng = SplitMix64(21);
    let mut pick = || {
        let z = rng.next_f32().max(1e-3);
        let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
        let r = (1.0 - z * z).sqrt();
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    };
    let mut failures = Vec::new();
    for (name, leaf) in leaves(None) {
        for _ in 0..300 {
            let (wo, wi) = (pick(), pick());
            let (a, b) = (
                leaf.eval(wo, wi, TransportMode::Radiance)[0],
                leaf.eval(wi, wo, TransportMode::Radiance)[0],
            );
            if (a - b).abs() > 2e-4 * a.abs().max(b.abs()) + 1e-6 {
                failures.push(format!("{name}: f({wo}, {wi}) = {a}, swapped {b}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// True where the lobe's `albedo` is a closed form (as each lobe's doc says), so it carries
/// no estimation error of its own.
fn closed_form(lobe: &LeafLobe) -> bool {
    match lobe {
        Lobe::Lambert(_) | Lobe::ThinDielectric(_) => true,
        Lobe::Conductor(l) => l.is_specular(),
        Lobe::Dielectric(l) => l.is_specular(),
        Lobe::OrenNayar(l) => l.sigma_rad == 0.0,
        Lobe::Phong(_)
        | Lobe::BlinnPhong(_)
        | Lobe::Ward(_)
        | Lobe::Lafortune(_)
        | Lobe::Coated(_)
        | Lobe::Measured(_)
        | Lobe::Sheen(_) => false,
        Lobe::Mix(never) => match *never {},
    }
}

/// Mean and standard deviation of `n` values drawn by `draw`.
fn mean_sd(n: usize, mut draw: impl FnMut() -> f64) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let w = draw();
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    (mean, (sum2 / n as f64 - mean * mean).max(0.0).sqrt())
}

/// Lane 0 of the sample weight f |cos θᵢ| / p of one draw of the lobe's own sampler.
fn own_weight(lobe: &impl Bxdf, wo: Vec3A, mode: TransportMode, rng: &mut SplitMix64) -> f64 {
    let (ul, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
    lobe.sample(wo, ul, u, mode)
        .map_or(0.0, |smp| f64::from(smp.weight()[0]))
}

/// Standard error of `albedo` (lane 0): 0 for a closed form, σ/√N for `estimate_albedo`
/// (σ the spread of the lobe's sample weights; a quasi-Monte Carlo rule does no worse than
/// N independent samples on these integrands), and a mix's weighted sum of its leaves'.
fn albedo_se(lobe: &BsdfLobe, wo: Vec3A, mode: TransportMode) -> f64 {
    let leaf_se = |leaf: &LeafLobe| {
        if closed_form(leaf) {
            return 0.0;
        }
        let mut rng = SplitMix64(17);
        let (_, sd) = mean_sd(20_000, || own_weight(leaf, wo, mode, &mut rng));
        sd / (ALBEDO_SAMPLES as f64).sqrt()
    };
    match lobe.map_mix(Err::<NoMix, Mix>) {
        Ok(leaf) => leaf_se(&leaf),
        Err(m) => (0..m.count)
            .map(|j| (f64::from(m.weights[j]) * leaf_se(&m.components[j])).powi(2))
            .sum::<f64>()
            .sqrt(),
    }
}

/// An estimate of ∫ f |cos θᵢ| dωᵢ (lane 0) that does not go through `albedo`, ± its
/// standard error: the Dirac part from the lobe's Dirac samples (their weights), plus the
/// rest from `eval` under the defensive mixture q = ½ (uniform sphere) + ½ pdf (Hesterberg
/// 1995), so it stays unbiased even where pdf misses part of f.
fn reference_albedo(lobe: &BsdfLobe, wo: Vec3A, mode: TransportMode, n: usize) -> (f64, f64) {
    let mut rng = SplitMix64(0x5EED);
    let (dirac, dirac_sd) = mean_sd(n, || {
        let (ul, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
        match lobe.sample(wo, ul, u, mode) {
            Some(smp) if smp.specular => f64::from(smp.weight()[0]),
            Some(_) | None => 0.0,
        }
    });
    let uniform_pdf = 0.25 * std::f64::consts::FRAC_1_PI;
    let (smooth, smooth_sd) = mean_sd(n, || {
        let (pick, ul, u) = (
            rng.next_f32(),
            rng.next_f32(),
            Vec2::new(rng.next_f32(), rng.next_f32()),
        );
        let wi = if pick < 0.5 {
            crate::light::warp::sample_uniform_sphere(u)
        } else {
            match lobe.sample(wo, ul, u, mode) {
                Some(smp) if !smp.specular => smp.wi,
                // A Dirac or failed draw of the pdf half of the mixture scores 0.
                Some(_) | None => return 0.0,
            }
        };
        let q = 0.5 * uniform_pdf + 0.5 * f64::from(lobe.pdf(wo, wi, mode));
        f64::from(lobe.eval(wo, wi, mode)[0]) * f64::from(wi.z.abs()) / q
    });
    let se = ((dirac_sd * dirac_sd + smooth_sd * smooth_sd) / n as f64).sqrt();
    (dirac + smooth, se)
}

/// Checks `albedo` at each direction; returns the failures and a report line per direction.
fn check_albedo(
    name: &str,
    lobe: &BsdfLobe,
    mode: TransportMode,
    energy_conserving: bool,
    directions: &[Vec3A],
) -> (Vec<String>, Vec<String>) {
    let (mut failures, mut report) = (Vec::new(), Vec::new());
    for &wo in directions {
        let got = lobe.albedo(wo, mode);
        assert_eq!(
            got,
            lobe.albedo(wo, mode),
            "{name}: albedo is deterministic"
        );
        let got = f64::from(got[0]);
        let (want, se_ref) = reference_albedo(lobe, wo, mode, 100_000);
        let se_albedo = albedo_se(lobe, wo, mode);
        // 4 standard errors of the difference, plus f32 rounding of the closed forms.
        let tol = 4.0 * (se_ref * se_ref + se_albedo * se_albedo).sqrt() + 1e-5;
        let line = format!(
            "{name} {mode:?} cos θₒ {:.3}: albedo {got:.5}, reference {want:.5} ± {se_ref:.5} \
             (albedo s.e. {se_albedo:.5})",
            wo.z
        );
        if (got - want).abs() > tol {
            failures.push(format!("{line}: off by {:.5} > {tol:.5}", got - want));
        }
        if energy_conserving && got > 1.0 + 4.0 * se_albedo + 1e-5 {
            failures.push(format!("{line}: exceeds 1"));
        }
        report.push(line);
    }
    (failures, report)
}

fn upper_directions() -> Vec<Vec3A> {
    [0.0f32, 45.0, 80.0]
        .iter()
        .map(|&t| direction(t, 30.0))
        .chain([direction(135.0, 30.0)])
        .collect()
}

fn both_sides() -> Vec<Vec3A> {
    [0.0f32, 45.0, 80.0, 120.0, 170.0]
        .iter()
        .map(|&t| direction(t, 30.0))
        .collect()
}

fn assert_albedo_cases(cases: &[(&str, BsdfLobe, TransportMode, bool, Vec<Vec3A>)]) {
    let (mut failures, mut report) = (Vec::new(), Vec::new());
    for (name, lobe, mode, conserving, dirs) in cases {
        let (f, r) = check_albedo(name, lobe, *mode, *conserving, dirs);
        failures.extend(f);
        report.extend(r);
    }
    eprintln!("{}", report.join("\n"));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn albedo_of_the_core_lobes_matches_monte_carlo() {
    let mut cases = Vec::new();
    for (name, leaf) in leaves(None) {
        let lobe = leaf.as_lobe();
        match leaf {
            Lobe::Lambert(_) | Lobe::Conductor(_) => cases.push((
                name,
                lobe,
                TransportMode::Radiance,
                true,
                upper_directions(),
            )),
            Lobe::Dielectric(_) => {
                // Flux is conserved in importance form; radiance form scales by 1/η'².
                cases.push((name, lobe, TransportMode::Importance, true, both_sides()));
                cases.push((name, lobe, TransportMode::Radiance, false, both_sides()));
            }
            Lobe::ThinDielectric(_) => {
                cases.push((name, lobe, TransportMode::Radiance, true, both_sides()))
            }
            Lobe::OrenNayar(_)
            | Lobe::Phong(_)
            | Lobe::BlinnPhong(_)
            | Lobe::Ward(_)
            | Lobe::Lafortune(_)
            | Lobe::Coated(_)
            | Lobe::Measured(_)
            | Lobe::Sheen(_) => {}
            Lobe::Mix(never) => match never {},
        }
    }
    assert_albedo_cases(&cases);
}

#[test]
fn albedo_of_the_library_lobes_matches_monte_carlo() {
    let mut cases = Vec::new();
    for (name, leaf) in leaves(None) {
        // Energy conservation is each paper's claim: not Lafortune's (a fit, unnormalised)
        // nor the full Oren–Nayar model's (above 1 near grazing exit, see library_tests).
        let conserving = match leaf {
            Lobe::Phong(_)
            | Lobe::BlinnPhong(_)
            | Lobe::Ward(_)
            | Lobe::Coated(_)
            | Lobe::Sheen(_) => true,
            Lobe::OrenNayar(o) => o.form == OrenNayarForm::Qualitative || o.sigma_rad == 0.0,
            Lobe::Lafortune(_) => false,
            Lobe::Lambert(_)
            | Lobe::Conductor(_)
            | Lobe::Dielectric(_)
            | Lobe::ThinDielectric(_)
            | Lobe::Measured(_) => continue,
            Lobe::Mix(never) => match never {},
        };
        let lobe = leaf.as_lobe();
        cases.push((
            name,
            lobe,
            TransportMode::Radiance,
            conserving,
            upper_directions(),
        ));
    }
    cases.push((
        "mix (lambert, mirror, ward)",
        mix_lobe(),
        TransportMode::Radiance,
        true,
        upper_directions(),
    ));
    assert_albedo_cases(&cases);
}

#[test]
fn albedo_of_a_measured_table_matches_monte_carlo() {
    let ggx = Bsdf::new(BsdfLobe::Conductor(conductor(
        MicrofacetModel::Ggx,
        0.3,
        0.3,
    )));
    let brdf = MerlBrdf::new(&merl_from(ggx));
    let lobe = BsdfLobe::Measured(Measured {
        brdf: &brdf,
        lambda_nm: [450.0, 550.0, 650.0, 750.0],
    });
    // The table of a single-scattering conductor conserves energy up to its RGB and bin
    // discretisation; not claimed.
    assert_albedo_cases(&[(
        "measured (GGX α 0.3 table)",
        lobe,
        TransportMode::Radiance,
        false,
        upper_directions(),
    )]);
}

/// probe.rs's material bandwidth before it moved into the lobes (commit bdf920f), verbatim
/// but for names and the `MaterialBandwidth` wrapper, plus the arms of lobes added since
/// (the formula each one's doc states): the oracle of `angular_bandwidth_cycles_per_rad`.
#[allow(clippy::wildcard_enum_match_arm)]
fn former_material_bandwidth(bsdf: &Bsdf) -> f32 {
    match &bsdf.lobe {
        BsdfLobe::Lambert(_) => 0.0,
        BsdfLobe::Conductor(c) => {
            former_lobe_bandwidth(c.distribution.alpha_x, c.distribution.alpha_y, bsdf)
        }
        BsdfLobe::Dielectric(d) => {
            former_lobe_bandwidth(d.distribution.alpha_x, d.distribution.alpha_y, bsdf)
        }
        _ => former_library_lobe_bandwidth(&bsdf.lobe),
    }
}

fn former_library_lobe_bandwidth(lobe: &BsdfLobe) -> f32 {
    let from_exponent = |n: f32| 1.0 / (2.0 * std::f32::consts::PI * (2.0 / (n + 2.0)).sqrt());
    let from_alpha = |a: f32| 1.0 / (2.0 * std::f32::consts::PI * a.max(1e-4));
    match lobe {
        BsdfLobe::Lambert(_) | BsdfLobe::OrenNayar(_) => 0.0,
        BsdfLobe::Phong(p) if p.specular.max_component() > 0.0 => from_exponent(p.exponent),
        BsdfLobe::BlinnPhong(p) if p.specular.max_component() > 0.0 => from_exponent(p.exponent),
        BsdfLobe::Phong(_) | BsdfLobe::BlinnPhong(_) => 0.0,
        BsdfLobe::Ward(w) => from_alpha(w.alpha_x.min(w.alpha_y)),
        BsdfLobe::Lafortune(l) => l.lobes[..l.count]
            .iter()
            .filter(|j| j.albedo.max_component() > 0.0)
            .map(|j| from_exponent(j.exponent))
            .fold(0.0, f32::max),
        BsdfLobe::Coated(_) | BsdfLobe::ThinDielectric(_) => f32::INFINITY,
        BsdfLobe::Measured(m) => from_alpha(m.brdf.equivalent_alpha),
        BsdfLobe::Sheen(l) => from_exponent(1.0 / l.roughness),
        BsdfLobe::Mix(m) => m.components[..m.count]
            .iter()
            .map(|c| former_material_bandwidth(&Bsdf::new(c.as_lobe())))
            .fold(0.0, f32::max),
        BsdfLobe::Conductor(_) | BsdfLobe::Dielectric(_) => {
            former_material_bandwidth(&Bsdf::new(*lobe))
        }
    }
}

fn former_lobe_bandwidth(alpha_x: f32, alpha_y: f32, bsdf: &Bsdf) -> f32 {
    if bsdf.is_specular() {
        f32::INFINITY
    } else {
        // The narrower direction of an anisotropic lobe sets the bandwidth.
        1.0 / (2.0 * std::f32::consts::PI * alpha_x.min(alpha_y).max(1e-4))
    }
}

#[test]
fn angular_bandwidth_of_every_lobe_is_what_probe_returned_before() {
    let ggx = Bsdf::new(BsdfLobe::Conductor(conductor(
        MicrofacetModel::Ggx,
        0.3,
        0.3,
    )));
    let brdf = MerlBrdf::new(&merl_from(ggx));
    let mut lobes: Vec<(&str, BsdfLobe)> = leaves(Some(&brdf))
        .into_iter()
        .map(|(name, leaf)| (name, leaf.as_lobe()))
        .collect();
    lobes.push(("mix (lambert, mirror, ward)", mix_lobe()));
    lobes.push((
        "mix (lambert, phong)",
        BsdfLobe::Mix(
            Mix::new(&[
                (
                    LeafLobe::Lambert(Lambert {
                        reflectance: s(0.5),
                    }),
                    0.5,
                ),
                (
                    LeafLobe::Phong(Phong {
                        diffuse: s(0.1),
                        specular: s(0.5),
                        exponent: 200.0,
                    }),
                    0.5,
                ),
            ])
            .expect("valid mix"),
        ),
    ));
    let mut report = Vec::new();
    for (name, lobe) in &lobes {
        let got = lobe.angular_bandwidth_cycles_per_rad();
        let bsdf = Bsdf::new(*lobe);
        let before = former_material_bandwidth(&bsdf);
        let probe = crate::probe::material_bandwidth(&bsdf).angular_cycles_per_rad;
        assert_eq!(got.to_bits(), before.to_bits(), "{name}: {got} ≠ {before}");
        assert_eq!(
            probe.to_bits(),
            before.to_bits(),
            "{name} via probe: {probe}"
        );
        report.push(format!("{name}: {got}"));
    }
    eprintln!("angular bandwidth, cycles/rad: {}", report.join("; "));
    // The table covers every variant (a new lobe must join `leaves`).
    let mut seen = [false; 13];
    for (_, lobe) in &lobes {
        let index = match lobe {
            Lobe::Lambert(_) => 0,
            Lobe::Conductor(_) => 1,
            Lobe::Dielectric(_) => 2,
            Lobe::OrenNayar(_) => 3,
            Lobe::Phong(_) => 4,
            Lobe::BlinnPhong(_) => 5,
            Lobe::Ward(_) => 6,
            Lobe::Lafortune(_) => 7,
            Lobe::Coated(_) => 8,
            Lobe::ThinDielectric(_) => 9,
            Lobe::Measured(_) => 10,
            Lobe::Sheen(_) => 11,
            Lobe::Mix(_) => 12,
        };
        seen[index] = true;
    }
    assert!(seen.iter().all(|&s| s), "{seen:?}");
}

#[test]
fn the_lobe_enum_costs_no_space_beyond_a_mix() {
    // `Lobe`'s tag lives in a niche of the mix (as `BsdfLobe`'s did before the leaves were
    // shared): a BsdfLobe is exactly a Mix, and a Mix its leaves, weights and count.
    let (bsdf, lobe, leaf, mix) = (
        std::mem::size_of::<Bsdf>(),
        std::mem::size_of::<BsdfLobe>(),
        std::mem::size_of::<LeafLobe>(),
        std::mem::size_of::<Mix>(),
    );
    eprintln!("size_of: Bsdf {bsdf}, BsdfLobe {lobe}, LeafLobe {leaf}, Mix {mix}");
    assert_eq!(lobe, mix);
    assert_eq!(
        mix,
        MIX_MAX_COMPONENTS * (leaf + std::mem::size_of::<f32>()) + std::mem::size_of::<usize>()
    );
}
