//! BSDF micro-benchmark (issue 8, "Speed"): nanoseconds per `eval`, `pdf` and `sample` of
//! every lobe prism-render has — the core ones (Lambert, GGX and Beckmann conductors, GGX
//! and Beckmann rough dielectrics, smooth dielectric) and the material library (Oren–Nayar,
//! Phong, Blinn–Phong, Ward, Lafortune, coated, thin dielectric, mix, MERL) — through the
//! `Bsdf` the integrator calls, on one thread, over 2¹⁸ precomputed random (ωₒ, ωᵢ, u)
//! inputs (upper hemisphere, uniform in solid angle: incoherent, so every MERL lookup is a
//! cache miss). Every spectral lane of f is consumed (summed), as an integrator does;
//! reading one lane only would let the compiler drop the other three. Each figure is the
//! fastest of 7 passes in thread CPU time (the machine is shared). The MERL table is
//! written from the GGX α = 0.3 conductor, so `merl_sample_over_ggx_sample` compares equal
//! materials. `merl_in_cache` repeats the first 2¹² pairs instead (extra information: the
//! bins they touch stay cached, which separates the lookup's arithmetic from its cache
//! misses).
//!
//! Run: `cargo run --release -p bench-bsdf > tools/bench-results/bench-bsdf.json` (the latest
//! run is kept there; git keeps the earlier ones)

use std::hint::black_box;
use std::time::Instant;

use glam::{Vec2, Vec3A};
use prism_render::bsdf::merl_directions;
use prism_render::bsdf::{
    internal_diffuse_reflectance, BlinnPhong, Bsdf, BsdfLobe, Coated, Conductor, Dielectric,
    Lafortune, LafortuneLobe, Lambert, Measured, MerlBrdf, MerlTable, MicrofacetDistribution,
    MicrofacetModel, Mix, MixComponent, OrenNayar, OrenNayarForm, Phong, ThinDielectric,
    TransportMode, Ward, LAFORTUNE_MAX_LOBES,
};
use prism_spectrum::SampledSpectrum;
use serde_json::{json, Value};

const N: usize = 1 << 18;
const PASSES: usize = 7;

/// SplitMix64 (Steele, Lea & Flood 2014).
struct Rng(u64);
impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn upper(&mut self) -> Vec3A {
        let z = self.f32().max(1e-3);
        let phi = std::f32::consts::TAU * self.f32();
        let r = (1.0 - z * z).sqrt();
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// CPU time of this thread, s (CLOCK_THREAD_CPUTIME_ID: robust to other processes on a
/// shared machine, unlike wall time); wall time where the clock is missing.
fn thread_cpu_s(fallback: Instant) -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: clock_gettime writes the timespec we pass and nothing else.
        if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0 {
            return ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9;
        }
    }
    fallback.elapsed().as_secs_f64()
}

/// Fastest pass, ns of thread CPU time per call.
fn time(mut pass: impl FnMut() -> f32) -> f64 {
    let origin = Instant::now();
    let mut best = f64::INFINITY;
    for _ in 0..PASSES {
        let t0 = thread_cpu_s(origin);
        black_box(pass());
        best = best.min((thread_cpu_s(origin) - t0) * 1e9 / N as f64);
    }
    best
}

fn s(v: f32) -> SampledSpectrum {
    SampledSpectrum::splat(v)
}

fn main() {
    let mut rng = Rng(42);
    let wo: Vec<Vec3A> = (0..N).map(|_| rng.upper()).collect();
    let wi: Vec<Vec3A> = (0..N).map(|_| rng.upper()).collect();
    let u: Vec<(f32, Vec2)> = (0..N)
        .map(|_| (rng.f32(), Vec2::new(rng.f32(), rng.f32())))
        .collect();
    let mode = TransportMode::Radiance;
    let gold = (
        SampledSpectrum::new([1.38, 0.43, 0.17, 0.14]),
        SampledSpectrum::new([1.85, 2.45, 3.6, 4.6]),
    );
    let conductor = |model, a: f32| Conductor {
        eta: gold.0,
        k: gold.1,
        distribution: MicrofacetDistribution::new(model, a, a),
    };
    let ggx = conductor(MicrofacetModel::Ggx, 0.3);
    let merl_t0 = Instant::now();
    let table = MerlTable::from_fn(|th, td, pd| {
        let (wi, wo) = merl_directions(th, td, pd);
        let f = Bsdf::new(BsdfLobe::Conductor(ggx)).eval(wo, wi, TransportMode::Radiance);
        [f[0], f[1], f[2]].map(f64::from)
    });
    let merl = MerlBrdf::new(&table);
    let merl_build_s = merl_t0.elapsed().as_secs_f64();
    let mut lafortune = Lafortune {
        diffuse: s(0.2),
        lobes: [LafortuneLobe::NONE; LAFORTUNE_MAX_LOBES],
        count: 2,
    };
    lafortune.lobes[0] = LafortuneLobe {
        cx: -1.1,
        cy: -1.1,
        cz: 0.9,
        exponent: 12.0,
        albedo: s(0.5),
    };
    lafortune.lobes[1] = LafortuneLobe {
        cx: 0.5,
        cy: 0.5,
        cz: 0.7,
        exponent: 3.0,
        albedo: s(0.2),
    };
    let coated = Coated {
        diffuse: s(0.5),
        eta: 1.5,
        fdr_internal: internal_diffuse_reflectance(1.5),
        nonlinear: true,
    };
    let ward = Ward {
        diffuse: s(0.3),
        specular: s(0.5),
        alpha_x: 0.1,
        alpha_y: 0.3,
    };
    let lobes: Vec<(&str, bool, BsdfLobe)> = vec![
        (
            "lambert",
            false,
            BsdfLobe::Lambert(Lambert {
                reflectance: s(0.5),
            }),
        ),
        ("conductor_ggx", false, BsdfLobe::Conductor(ggx)),
        (
            "conductor_beckmann",
            false,
            BsdfLobe::Conductor(conductor(MicrofacetModel::Beckmann, 0.3)),
        ),
        (
            "conductor_smooth",
            false,
            BsdfLobe::Conductor(conductor(MicrofacetModel::Ggx, 0.0)),
        ),
        (
            "dielectric_rough",
            false,
            BsdfLobe::Dielectric(Dielectric {
                eta: s(1.5),
                distribution: MicrofacetDistribution::new(MicrofacetModel::Ggx, 0.3, 0.3),
            }),
        ),
        (
            "dielectric_beckmann",
            false,
            BsdfLobe::Dielectric(Dielectric {
                eta: s(1.5),
                distribution: MicrofacetDistribution::new(MicrofacetModel::Beckmann, 0.3, 0.3),
            }),
        ),
        (
            "dielectric_smooth",
            false,
            BsdfLobe::Dielectric(Dielectric {
                eta: s(1.5),
                distribution: MicrofacetDistribution::new(MicrofacetModel::Ggx, 0.0, 0.0),
            }),
        ),
        (
            "oren_nayar",
            true,
            BsdfLobe::OrenNayar(OrenNayar {
                reflectance: s(0.5),
                sigma_rad: 0.4,
                form: OrenNayarForm::Full,
            }),
        ),
        (
            "oren_nayar_qualitative",
            true,
            BsdfLobe::OrenNayar(OrenNayar {
                reflectance: s(0.5),
                sigma_rad: 0.4,
                form: OrenNayarForm::Qualitative,
            }),
        ),
        (
            "phong",
            true,
            BsdfLobe::Phong(Phong {
                diffuse: s(0.3),
                specular: s(0.6),
                exponent: 30.0,
            }),
        ),
        (
            "blinn_phong",
            true,
            BsdfLobe::BlinnPhong(BlinnPhong {
                diffuse: s(0.3),
                specular: s(0.6),
                exponent: 30.0,
            }),
        ),
        ("ward", true, BsdfLobe::Ward(ward)),
        ("lafortune", true, BsdfLobe::Lafortune(lafortune)),
        ("coated", true, BsdfLobe::Coated(coated)),
        (
            "thin_dielectric",
            true,
            BsdfLobe::ThinDielectric(ThinDielectric { eta: s(1.5) }),
        ),
        (
            "mix_ward_coated",
            true,
            BsdfLobe::Mix(
                Mix::new(&[
                    (MixComponent::Ward(ward), 0.5),
                    (MixComponent::Coated(coated), 0.5),
                ])
                .unwrap(),
            ),
        ),
        (
            "merl",
            true,
            BsdfLobe::Measured(Measured {
                brdf: &merl,
                lambda_nm: [450.0, 550.0, 650.0, 750.0],
            }),
        ),
    ];
    let mut rows = Vec::new();
    let mut by_name = std::collections::BTreeMap::new();
    for (name, new, lobe) in &lobes {
        let b = Bsdf::new(*lobe);
        let eval_ns = time(|| {
            let mut acc = 0.0;
            for k in 0..N {
                acc += b.eval(black_box(wo[k]), black_box(wi[k]), mode).sum();
            }
            acc
        });
        let pdf_ns = time(|| {
            let mut acc = 0.0;
            for k in 0..N {
                acc += b.pdf(black_box(wo[k]), black_box(wi[k]), mode);
            }
            acc
        });
        let sample_ns = time(|| {
            let mut acc = 0.0;
            for k in 0..N {
                if let Some(smp) = b.sample(black_box(wo[k]), u[k].0, u[k].1, mode) {
                    acc += smp.pdf + smp.f.sum();
                }
            }
            acc
        });
        by_name.insert(*name, sample_ns);
        rows.push(json!({
            "bsdf": name,
            "library": new,
            "eval_ns": (eval_ns * 10.0).round() / 10.0,
            "pdf_ns": (pdf_ns * 10.0).round() / 10.0,
            "sample_ns": (sample_ns * 10.0).round() / 10.0,
        }));
    }
    // Extra information, not the headline: MERL with a working set of 2¹² pairs repeated
    // (the bins they touch stay in cache), so the arithmetic is seen apart from the misses.
    let merl_bsdf = Bsdf::new(lobes.last().unwrap().2);
    let small = 1usize << 12;
    let merl_in_cache = (
        time(|| {
            let mut acc = 0.0;
            for k in 0..N {
                let k = k & (small - 1);
                acc += merl_bsdf
                    .eval(black_box(wo[k]), black_box(wi[k]), mode)
                    .sum();
            }
            acc
        }),
        time(|| {
            let mut acc = 0.0;
            for k in 0..N {
                let k = k & (small - 1);
                if let Some(smp) = merl_bsdf.sample(black_box(wo[k]), u[k].0, u[k].1, mode) {
                    acc += smp.pdf + smp.f.sum();
                }
            }
            acc
        }),
    );
    let max_eval = rows
        .iter()
        .map(|r| r["eval_ns"].as_f64().unwrap())
        .fold(0.0, f64::max);
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string));
    let out: Value = json!({
        "benchmark": "bench-bsdf",
        "calls_per_pass": N,
        "passes": PASSES,
        "statistic": "minimum over passes of thread CPU time, ns per call, one thread",
        "sample_includes": "f and pdf of the sampled direction (what the integrator gets)",
        "merl_source": "GGX conductor α = 0.3 (gold-like η, k), written with MerlTable::from_fn",
        "merl_table_build_s": (merl_build_s * 1000.0).round() / 1000.0,
        "bsdfs": rows,
        "merl_sample_over_ggx_sample": ((by_name["merl"] / by_name["conductor_ggx"]) * 100.0).round() / 100.0,
        "max_eval_ns": max_eval,
        "merl_in_cache": {
            "working_set_pairs": small,
            "eval_ns": (merl_in_cache.0 * 10.0).round() / 10.0,
            "sample_ns": (merl_in_cache.1 * 10.0).round() / 10.0,
        },
        "load_average_1min_at_end": load,
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap());
}
