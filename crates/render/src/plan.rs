//! The render plan: before rendering, look at the scene and switch on only what it uses
//! ("model no more than a scene needs", docs/architecture.md). Each choice records why it was made;
//! `prism render --explain` prints them without rendering.
//!
//! The integrator follows the same facts at run time (a delta light gets MIS weight 1, a
//! purely specular BSDF skips light sampling, dispersion keeps only the hero wavelength),
//! so the plan is a faithful description, not a second code path.
//!
//! Each fast path (packet tracing, small-scene intersection) gets a line: on, with why
//! `used`, or off, with why `not used: …` — the scene's features outside the path's
//! allow-list, or the limit the scene is past; and the last line, `simd: <isa> (<why>)`,
//! says which vector kernels they run and why (`simd: avx2 (PRISM_SIMD=avx2)`).

use std::fmt;

use glam::{Vec2, Vec3A};
use prism_geometry::{Curvature, Differentials, SurfaceInteraction};
use prism_spectrum::SampledWavelengths;

use crate::integrator::packet::PacketScene;
use crate::integrator::Integrator;
use crate::light::ShadingSelection;
use crate::scene_build::{small_scene_not_used, RenderScene, SceneFeatures};

/// One decision of the plan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanChoice {
    /// What is decided (e.g. "dispersion").
    pub feature: &'static str,
    /// On, off, or a value.
    pub setting: String,
    /// Why, in terms of the scene.
    pub reason: String,
}

/// What a render will do, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderPlan {
    pub choices: Vec<PlanChoice>,
    /// The ISA of the vector kernels (packet tracer, film splat, small-scene intersector)
    /// and why: the widest the CPU runs within `PRISM_SIMD` or `--simd`. Printed last, as
    /// the line `simd: <isa> (<why>)` (a process setting, not a choice about the scene).
    pub simd: prism_cpu::Choice,
}

/// Options that come from the command line rather than the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlanRequest {
    pub spp: u32,
    /// Spectral bins asked for with `--spectral-bins`.
    pub spectral_bins: Option<u32>,
    /// The output can hold AOV layers (EXR).
    pub aov_output: bool,
    /// The sampler's name.
    pub sampler: &'static str,
    /// How camera samples are spread over the pixels (`--plan`).
    pub sample_plan: SamplePlanKind,
}

/// `--plan`: how camera samples are spread over the pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplePlanKind {
    /// The same spp everywhere.
    #[default]
    Uniform,
    /// The bandwidth predictor's plan (`predictor`): n_b probe samples per pixel, the floor
    /// in thousandths of the budget, the allocation rule.
    Predicted {
        probe_samples: u32,
        floor_per_mille: u32,
        allocation: prism_bandwidth::Allocation,
        /// How V̂_p is predicted (`--plan-variance`).
        variance: prism_bandwidth::VarianceBandwidth,
        /// The colour noise of hero-wavelength sampling in V̂_p (`--plan-colour`; off: the
        /// luminance's variance alone).
        colour_noise: bool,
        /// The probe samples one pixel in S×S (`--plan-probe-stride`; `auto` = half the
        /// pooling radius, 1 = every pixel).
        probe_stride: prism_bandwidth::ProbeStride,
        /// The pooling radius (`--plan-pool-px`) of V̂ and L̂, within which a pixel the
        /// probe skips finds a probed one.
        pool_radius: prism_bandwidth::PoolRadius,
        /// `predicted-hier`: hierarchical shading with lattices up to this level.
        hierarchical_max_level: Option<u32>,
    },
    /// Variance-driven passes (`adaptive`).
    Adaptive,
}

/// A neutral hit for asking a material which lobes it has.
pub(crate) fn probe_hit() -> SurfaceInteraction {
    SurfaceInteraction {
        p: Vec3A::ZERO,
        t: 1.0,
        n_geometric: Vec3A::Z,
        n_shading: Vec3A::Z,
        uv: Vec2::splat(0.5),
        dpdu: Vec3A::X,
        dpdv: Vec3A::Y,
        dndu: Vec3A::ZERO,
        dndv: Vec3A::ZERO,
        curvature: Curvature::default(),
        differentials: Differentials::default(),
        primitive_id: 0,
        material_id: 0,
        object_id: 0,
        instance_id: 0,
    }
}

fn on_off(b: bool) -> String {
    if b { "on" } else { "off" }.to_string()
}

/// "the scene's features (a, b) are within LIST", or that it has none.
fn within(features: SceneFeatures, list: &str) -> String {
    if features.is_empty() {
        "the scene uses none of the features a fast path may lack".into()
    } else {
        format!(
            "the scene's features ({}) are within {list}",
            features.names()
        )
    }
}

/// The sample plan's name and what it switches on, for the `sampler` line.
fn sample_plan_text(kind: SamplePlanKind, resolution: glam::UVec2) -> (&'static str, String) {
    match kind {
        SamplePlanKind::Uniform => (
            "uniform",
            "no predicted plan was asked for: every pixel gets the same samples".into(),
        ),
        SamplePlanKind::Predicted {
            probe_samples,
            floor_per_mille,
            allocation,
            variance,
            colour_noise,
            probe_stride,
            pool_radius,
            hierarchical_max_level,
        } => {
            let pool_radius_px = pool_radius.px(resolution);
            let probe_stride_px = probe_stride.px(pool_radius_px, hierarchical_max_level.is_some());
            (
            match hierarchical_max_level {
                Some(_) => "predicted-hier",
                None => "predicted",
            },
            format!(
                "--plan predicted: a G-buffer of pixel-centre hits, {} probe light \
                 samples per probed pixel ({}), bandwidth by Bagher et al. 2013 eqs. 4-6 (silhouettes, creases \
                 and material edges at the finest level, seen directly or through mirrors and \
                 smooth glass, where the two sides' L̂ differ by over 2 %), \
                 variance {}{}, {}, levels by eq. 11; {:.1} % of the budget uniform (light past the probe's one indirect \
                 bounce is not predicted), the rest {}",
                prism_bandwidth::samples_per_probed_pixel(probe_samples, probe_stride_px),
                match (probe_stride, probe_stride_px) {
                    (prism_bandwidth::ProbeStride::Auto, 1) => {
                        if hierarchical_max_level.is_some() {
                            "every pixel, as the paper: --plan-probe-stride auto is 1 for \
                             predicted-hier, whose lattice pixels shade for their neighbours"
                                .to_string()
                        } else {
                            format!(
                                "every pixel, as the paper: --plan-probe-stride auto is half \
                                 the pooling radius of {pool_radius_px} px, at least 1"
                            )
                        }
                    }
                    (prism_bandwidth::ProbeStride::Px(_), 1) => {
                        "every pixel, as the paper: --plan-probe-stride 1".to_string()
                    }
                    (stride, s) => format!(
                        "n_b = {probe_samples} times S²/4, at least n_b, and the indirect \
                         estimates likewise, at one pixel in {s}×{s} and each pixel of a \
                         surface with none within {pool_radius_px} px; the others take the \
                         nearest probed pixel's bandwidth and the pooled V̂: \
                         --plan-probe-stride {}",
                        match stride {
                            prism_bandwidth::ProbeStride::Auto => format!(
                                "auto, half the pooling radius within 1 to {}; 1 probes every \
                                 pixel, as the paper",
                                prism_bandwidth::AUTO_MAX_STRIDE_PX
                            ),
                            prism_bandwidth::ProbeStride::Px(_) => s.to_string(),
                        }
                    ),
                },
                match variance {
                    prism_bandwidth::VarianceBandwidth::Incident => {
                        "by eq. 9 with the incident angular bandwidth"
                    }
                    prism_bandwidth::VarianceBandwidth::OneBounce => {
                        "by eq. 9 with eq. 4's angular bandwidth at the eye"
                    }
                    prism_bandwidth::VarianceBandwidth::Measured => {
                        "measured by the probe (the render's estimate per camera sample)"
                    }
                },
                if colour_noise {
                    " plus the colour noise of the hero wavelengths' X, Y and Z"
                } else {
                    " of the luminance alone (--plan-colour off)"
                },
                match (pool_radius, pool_radius_px) {
                    (prism_bandwidth::PoolRadius::Auto, r) => format!(
                        "pooled over the pixels of the same material within {r} px \
                         (--plan-pool-px auto: min(W, H)/32, at least 1)"
                    ),
                    (prism_bandwidth::PoolRadius::Px(_), 0) => {
                        "per pixel, not pooled, as the paper (--plan-pool-px 0)".to_string()
                    }
                    (prism_bandwidth::PoolRadius::Px(_), r) => format!(
                        "pooled over the pixels of the same material within {r} px \
                         (--plan-pool-px)"
                    ),
                },
                f64::from(floor_per_mille) / 10.0,
                match allocation {
                    prism_bandwidth::Allocation::RelativeError => {
                        "in proportion to the predicted relative error"
                    }
                    prism_bandwidth::Allocation::Variance => {
                        "in proportion to the predicted variance (the paper's rule)"
                    }
                }
            ) + &match hierarchical_max_level {
                Some(level) => format!(
                    "; hierarchical shading (§3.2): pixels of level ≥ 1 are interpolated \
                     bilaterally from a lattice of shaded pixels, at most {} px apart, \
                     and their samples go to that lattice (biased where the prediction \
                     misses variation)",
                    1u32 << level
                ),
                None => String::new(),
            },
        )
        }
        SamplePlanKind::Adaptive => (
            "adaptive",
            "--plan adaptive: 4 spp everywhere, then passes spread by the error of a \
             half-sample image (Cycles' adaptive sampling)"
                .into(),
        ),
    }
}

impl RenderPlan {
    /// The plan for `scene` with the command line's `request`.
    pub fn new(scene: &RenderScene, request: &PlanRequest) -> Self {
        let mut choices = Vec::new();
        let mut choose = |feature: &'static str, setting: String, reason: String| {
            choices.push(PlanChoice {
                feature,
                setting,
                reason,
            })
        };
        // Materials that some instance uses (the default one only if a shape has none).
        let mut used = vec![false; scene.materials.len()];
        for inst in scene.geometry.instances() {
            let id = inst.material.unwrap_or(u32::MAX) as usize;
            used[id.min(scene.materials.len() - 1)] = true;
        }
        let wavelengths = SampledWavelengths::sample_visible(0.5);
        let hit = probe_hit();
        let mut dispersive = Vec::new();
        let mut any_non_specular = false;
        for (i, m) in scene.materials.iter().enumerate() {
            if !used[i] {
                continue;
            }
            if m.is_dispersive() {
                dispersive.push(i);
            }
            let bsdf = m.bsdf(&hit, &wavelengths);
            any_non_specular |= !bsdf.is_specular();
        }
        let lights = scene.lights.lights();
        let delta_lights = lights.iter().filter(|l| l.is_delta()).count();
        let hittable_lights = lights.len() - delta_lights;
        let env_lights = scene.lights.infinite_lights().len();

        match &scene.integrator {
            Integrator::Path(p) => {
                choose(
                    "integrator",
                    format!(
                        "path tracing, max_depth {} (1 = direct light only), MIS {:?}",
                        p.max_depth, p.mis
                    ),
                    "the scene's `integrator` section (default `path`)".into(),
                );
                let (plan_name, plan_reason) =
                    sample_plan_text(request.sample_plan, scene.resolution);
                choose(
                    "sampler",
                    format!(
                        "{}, {} spp (mean), {plan_name} sample plan",
                        request.sampler, request.spp
                    ),
                    plan_reason,
                );
                let (density, density_why) = match crate::film::film_wavelength_density(
                    request.spectral_bins.is_some(),
                ) {
                    prism_spectrum::WavelengthDensity::Visible => (
                        "visible density (pbrt-v4)",
                        "the film records spectral bins, whose far-red and violet bins need the samples the colour-matching functions give little weight to",
                    ),
                    prism_spectrum::WavelengthDensity::RgbOutput => (
                        "RGB-output density (0.4 visible + 0.6 Rec. 709 CMF norm)",
                        "the output is colour: the density follows the film's red, green and blue, not luminance alone, so the spectrum's ends are sampled enough for the colour channels (prism_spectrum::rgb_wavelength_density)",
                    ),
                };
                choose(
                    "wavelengths",
                    format!("hero + 3 rotated wavelengths per path, {density}"),
                    format!(
                        "spectral transport (Wilkie et al. 2014); 4 wavelengths share every ray; {density_why}"
                    ),
                );
                let (selection, why) = light_selection_text(scene);
                choose("light selection", selection, why);
                if let (SamplePlanKind::Predicted { .. }, crate::camera::Camera::ThinLens(_)) =
                    (request.sample_plan, &scene.camera)
                {
                    choose(
                        "predictor: defocus",
                        "on: b_p capped at 1.22 / (circle of confusion in px) at each pixel's \
                         hit; V̂ and L̂ mixed over each circle of confusion"
                            .into(),
                        "the camera is a thin lens: the aperture low-passes what lies out of \
                         focus (Soler et al. 2009), so detail there needs fewer samples, and \
                         a lens sample sees what a pinhole pixel up to half a circle away \
                         sees, so the variance is the mixture's (law of total variance)"
                            .into(),
                    );
                }
                let names: Vec<String> = dispersive
                    .iter()
                    .map(|&i| format!("`{}`", scene.material_names[i]))
                    .collect();
                choose(
                    "dispersion",
                    on_off(!dispersive.is_empty()),
                    if dispersive.is_empty() {
                        "no material's index of refraction varies with wavelength: all 4 \
                         wavelengths follow every path"
                            .into()
                    } else {
                        format!(
                            "{} refract(s) with a wavelength-dependent IOR: paths that meet it \
                             keep only the hero wavelength",
                            names.join(", ")
                        )
                    },
                );
                choose(
                    "re-radiation (fluorescence)",
                    if scene.has_reradiation {
                        format!("on, lanes: {}", lanes_name(p.fluorescence_lanes))
                    } else {
                        "off".into()
                    },
                    reradiation_reason(scene, p.fluorescence_lanes),
                );
                let nee = !lights.is_empty() && any_non_specular;
                choose(
                    "light sampling (next-event estimation)",
                    on_off(nee),
                    if lights.is_empty() {
                        "the scene has no lights".into()
                    } else if !any_non_specular {
                        "every material is purely specular: no light sample can be weighted \
                         by a Dirac BSDF"
                            .into()
                    } else {
                        format!(
                            "{} light(s), chosen as `light selection` says; {} delta (point/\
                             spot/parallel), {} with area or extent",
                            lights.len(),
                            delta_lights,
                            hittable_lights
                        )
                    },
                );
                if nee {
                    let per_hit = scene.light_samples_per_hit(1);
                    choose(
                        "light samples per hit",
                        if per_hit > 1 && scene.lights.lights().iter().all(|l| l.is_infinite()) {
                            format!(
                                "{per_hit} per light sample the plan asks for: each light at \
                                 infinity"
                            )
                        } else if per_hit > 1 {
                            format!(
                                "{per_hit} per light sample the plan asks for: each light at \
                                 infinity and one of the others"
                            )
                        } else {
                            "1 per light sample the plan asks for".into()
                        },
                        if per_hit > 1 {
                            "lights at infinity are chosen apart, each in an equal slice of \
                             the choice: samples stratified over the slices take every one of \
                             them, so the choice between a sky and a lamp (or a sun) adds no \
                             noise"
                                .into()
                        } else if !scene.lights.sample_each_infinite() {
                            "switched off (--light-samples-per-hit one): one choice among all \
                             lights per light sample"
                                .into()
                        } else {
                            "no light at infinity is chosen apart beside other lights: one \
                             choice per light sample"
                                .into()
                        },
                    );
                }
                let mis = nee && hittable_lights > 0;
                choose(
                    "multiple importance sampling",
                    on_off(mis),
                    if !nee {
                        "only BSDF sampling is used, nothing to combine".into()
                    } else if hittable_lights == 0 {
                        "all lights are delta lights: BSDF-sampled rays never hit them, so \
                         light samples get weight 1"
                            .into()
                    } else {
                        "lights with area or extent can be reached by both light and BSDF \
                         sampling: weights by the chosen heuristic (Veach 1997, §9.2)"
                            .into()
                    },
                );
                choose(
                    "environment importance table",
                    on_off(env_lights > 0),
                    if env_lights > 0 {
                        format!("{env_lights} infinite light(s) (environment, sky, sun disk)")
                    } else {
                        "no environment or sky".into()
                    },
                );
                choose(
                    "opacity masks in shadow rays",
                    on_off(scene.has_masks),
                    if scene.has_masks {
                        "a `mask` material is present: shadow rays multiply 1 − α through \
                         masked surfaces"
                            .into()
                    } else {
                        "no `mask` material: shadow rays stop at the first hit".into()
                    },
                );
                choose(
                    "thin glazing in shadow rays",
                    on_off(scene.has_glazing),
                    if scene.has_glazing {
                        "a `thin_dielectric` pane is present: shadow rays cross it with its \
                         transmittance (1 − R)/(1 + R), paths pass it straight as a null event"
                            .into()
                    } else {
                        "no `thin_dielectric` material".into()
                    },
                );
                choose(
                    "Russian roulette",
                    if p.rr_depth < p.max_depth {
                        format!("after {} bounces", p.rr_depth)
                    } else {
                        "off".into()
                    },
                    if p.rr_depth < p.max_depth {
                        "long paths end with probability 1 − throughput (Arvo & Kirk 1990)".into()
                    } else {
                        format!(
                            "rr_depth {} ≥ max_depth {}: paths never get that long",
                            p.rr_depth, p.max_depth
                        )
                    },
                );
            }
            Integrator::Light(l) => {
                choose(
                    "integrator",
                    format!(
                        "light tracing, max_depth {}, roulette from {}: {} light paths \
                         ({} spp × {} pixels), each vertex connected to the camera",
                        l.max_depth,
                        l.rr_depth,
                        u64::from(request.spp)
                            * u64::from(scene.resolution.x)
                            * u64::from(scene.resolution.y),
                        request.spp,
                        u64::from(scene.resolution.x) * u64::from(scene.resolution.y)
                    ),
                    "the scene's `integrator` section; pixels that see a specular surface \
                     first stay black (a light path cannot connect through a Dirac lobe)"
                        .into(),
                );
            }
            Integrator::Photon(m) => {
                let (text, reason) = photon_explain(m, scene);
                choose("integrator", text, reason);
            }
            Integrator::Radiosity(r) => {
                choose(
                    "integrator",
                    format!(
                        "hierarchical radiosity with clustering, error_bound_rel {}, {} \
                         iteration(s), 16 bands of 25 nm over 380–780 nm; final gather: direct \
                         light as `path` (max_depth 1), then the solution's reflected radiance",
                        r.error_bound_rel, r.iterations
                    ),
                    "the scene's `integrator` section; the interpolated gather (4D tree and \
                     gathering list) is not built yet, so every gather ray is traced"
                        .into(),
                );
            }
            Integrator::Bdpt(b) => {
                choose(
                    "integrator",
                    format!(
                        "bidirectional path tracing, max_depth {}, MIS {:?} over all \
                         strategies, roulette from {}{}",
                        b.max_depth,
                        b.mis,
                        b.rr_depth,
                        match b.strategy {
                            Some(s) => format!(
                                "; only strategy ({}, {}){}",
                                s.s,
                                s.t,
                                if s.unweighted { " unweighted" } else { "" }
                            ),
                            None => String::new(),
                        }
                    ),
                    "the scene's `integrator` section (and --bdpt-strategy)".into(),
                );
            }
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => choose(
                "integrator",
                scene.integrator.name().to_string(),
                "a diagnostic integrator: no light transport, lights and BSDFs are unused".into(),
            ),
        }
        if let Some(media) = &scene.media {
            if let Integrator::Path(p) = &scene.integrator {
                choose(
                    "medium transport",
                    format!(
                        "null-scattering delta tracking, spectral MIS {}, light and BSDF \
                         samples weighted by the balance heuristic",
                        on_off(p.spectral_mis)
                    ),
                    "the scene has participating media: `path` follows pbrt-v4's \
                     VolPathIntegrator (rescaled path probabilities; docs/media.md)"
                        .into(),
                );
            }
            for (name, medium) in media.names.iter().zip(&media.media) {
                let (setting, reason) = describe_medium(name, medium);
                choose("medium", setting, reason);
            }
            for (position, what) in lights_in_closed_dielectrics(scene) {
                choose(
                    "volumetric caustic",
                    format!("warning: the {what} at {position:?} m is inside a closed dielectric"),
                    "path cannot sample light that reaches a medium only through specular \
                     surfaces (its light sample is blocked, its BSDF sample never hits a \
                     point): the glow around it will be missing. volumetric caustic: use \
                     photon_progressive"
                        .into(),
                );
            }
        }
        match &scene.packet {
            Some(packet) => choose(
                "packet tracing",
                format!(
                    "on, {} paths per ray query, {} patches and {} boxes",
                    packet.lane_count(),
                    packet.patch_count(),
                    packet.box_count()
                ),
                format!(
                    "used: {}; flat patches with constant Lambertian materials: many paths \
                     share every ray query, cuboid meshes are tested as boxes (same estimator \
                     as the scalar tracer)",
                    within(scene.features, "PacketScene::SUPPORTS")
                ),
            ),
            // Off: ask the scene why (only then is its packet form built again).
            None => choose(
                "packet tracing",
                "off".into(),
                match PacketScene::new(scene) {
                    Ok(_) => "not used: switched off for this render".into(),
                    Err(why) => format!("not used: {why}"),
                },
            ),
        }
        match small_scene_not_used(&scene.geometry, scene.features) {
            None => choose(
                "small-scene intersection",
                format!(
                    "on, {} leaves tested eight at a time without a BVH",
                    scene.geometry.flattened_triangle_count()
                        + scene.geometry.instance_leaf_count()
                ),
                format!(
                    "used: {}, and at most {} leaves",
                    within(scene.features, "SMALL_SCENE_SUPPORTS"),
                    prism_geometry::SMALL_SCENE_MAX_LEAVES
                ),
            ),
            Some(why) => choose(
                "small-scene intersection",
                "off".into(),
                format!("not used: {why}"),
            ),
        }
        choose(
            "spectral output bins",
            match request.spectral_bins {
                Some(n) => format!("{n} bins over 360–830 nm"),
                None => "off".into(),
            },
            if request.spectral_bins.is_some() {
                "asked for with --spectral-bins".into()
            } else {
                "not asked for (--spectral-bins N)".into()
            },
        );
        choose(
            "AOV layers",
            on_off(request.aov_output),
            if request.aov_output {
                "EXR output: depth, normal, albedo, illumination, spp and luminance layers".into()
            } else {
                "the output format holds no layers".into()
            },
        );
        Self {
            choices,
            simd: prism_cpu::choice(),
        }
    }
}

fn lanes_name(lanes: prism_scene::FluorescenceLanes) -> &'static str {
    match lanes {
        prism_scene::FluorescenceLanes::All => "all",
        prism_scene::FluorescenceLanes::Hero => "hero",
    }
}

/// Why re-radiation is on or off: the fluorescent materials with their entries (and, for BFC
/// files, the negatives policy and what it did: clamping moves XYZ), the lane mode and how
/// far down the lights excite.
fn reradiation_reason(scene: &RenderScene, lanes: prism_scene::FluorescenceLanes) -> String {
    let materials: Vec<String> = scene
        .materials
        .iter()
        .zip(&scene.material_names)
        .filter_map(|(m, name)| {
            let f = m.fluorescent()?;
            Some(match &f.negatives {
                Some((policy, report)) => format!(
                    "`{name}` (BFC `{}`, negatives {}: {report})",
                    f.reradiation,
                    policy.name()
                ),
                None => format!("`{name}` (dye `{}`)", f.reradiation),
            })
        })
        .collect();
    if materials.is_empty() {
        return "no `fluorescent` material".into();
    }
    let lanes = match lanes {
        prism_scene::FluorescenceLanes::All => {
            "each lane reflects or re-radiates on its own and keeps going"
        }
        prism_scene::FluorescenceLanes::Hero => {
            "secondary lanes end where a lane re-radiates (fluorescence_lanes hero)"
        }
    };
    format!(
        "{} shift lanes to excitation wavelengths down to 300 nm; {lanes}. Lights excite \
         below 360 nm where their spectrum reaches: CIE illuminant tables, blackbodies, \
         spectrum files and daylight skies and suns do; RGB-given emitters and environment \
         maps give 0 there",
        materials.join(", ")
    )
}

/// The `medium` line of one medium: its type, σt range over 360–830 nm and grid size; why
/// spectral MIS matters (a chromatic σt) or not.
fn describe_medium(name: &str, medium: &crate::medium::Medium) -> (String, String) {
    let optics = medium.optics();
    let mut terms = vec![&optics.sigma_a, &optics.sigma_s];
    if let Some(f) = &optics.fluorescence {
        terms.push(&f.sigma_f);
    }
    let (lo, hi) = crate::scene_build::media::coefficient_range(&terms);
    let grid = match medium {
        crate::medium::Medium::Homogeneous(_) => String::new(),
        crate::medium::Medium::Grid(g) => {
            let [x, y, z] = g.density.resolution();
            format!(
                ", {x}×{y}×{z} voxels (max density {}), 16³ majorant cells",
                g.density.max_density()
            )
        }
    };
    let chromatic = hi > lo * (1.0 + 1e-4);
    let setting = format!(
        "`{name}`: {}, σt {lo:.4}–{hi:.4} m⁻¹ over 360–830 nm{grid}{}{}",
        medium.kind_name(),
        if optics.emission.is_some() {
            ", emissive"
        } else {
            ""
        },
        if optics.fluorescence.is_some() {
            ", fluorescent (re-emits what its dye absorbs: lanes shift to excitation \
             wavelengths down to 300 nm)"
        } else {
            ""
        }
    );
    let reason = if chromatic {
        "chromatic σt: free flights are sampled at the hero wavelength and spectral MIS \
         weights the four wavelengths (pbrt-v4 rescaled probabilities)"
            .to_string()
    } else {
        "grey σt: every wavelength samples the same free flights".to_string()
    };
    (setting, reason)
}

/// Point, spot and goniometric lights enclosed by a dielectric: rays from the light
/// along the six axes all first meet a dielectric surface from its inside.
fn lights_in_closed_dielectrics(scene: &RenderScene) -> Vec<([f32; 3], &'static str)> {
    use crate::light::Light;
    use crate::material::{Material, SurfaceMaterial};
    let mut out = Vec::new();
    for light in scene.lights.lights() {
        let (position, what) = match light {
            Light::Point(l) => (l.position_m, "point light"),
            Light::Spot(l) => (l.position_m, "spot light"),
            Light::Goniometric(l) => (l.position_m, "luminaire"),
            Light::Directional(_)
            | Light::Area(_)
            | Light::Environment(_)
            | Light::Sky(_)
            | Light::Daylight(_) => continue,
        };
        let enclosed = [
            Vec3A::X,
            Vec3A::NEG_X,
            Vec3A::Y,
            Vec3A::NEG_Y,
            Vec3A::Z,
            Vec3A::NEG_Z,
        ]
        .iter()
        .all(|&d| {
            let ray = prism_geometry::Ray::infinite(position, d);
            scene.geometry.intersect(&ray).is_some_and(|hit| {
                let si = scene.geometry.shading_interaction(&ray, &hit);
                let dielectric = matches!(
                    scene.material(si.material_id),
                    Material::Surface(SurfaceMaterial::Dielectric { .. })
                );
                dielectric && d.dot(si.n_geometric) > 0.0
            })
        });
        if enclosed {
            out.push((position.to_array(), what));
        }
    }
    out
}

impl fmt::Display for RenderPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self
            .choices
            .iter()
            .map(|c| c.feature.chars().count())
            .max()
            .unwrap_or(0);
        for c in &self.choices {
            let pad = width - c.feature.chars().count();
            writeln!(
                f,
                "{}{} : {}\n{}   why: {}",
                c.feature,
                " ".repeat(pad),
                c.setting,
                " ".repeat(width),
                c.reason
            )?;
        }
        writeln!(f, "simd: {}", self.simd)
    }
}

/// `--explain`'s light-selection line for light samples at shading points.
fn light_selection_text(scene: &RenderScene) -> (String, String) {
    let min = crate::light::LIGHT_BVH_MIN_BOUNDED;
    match scene.lights.light_bvh() {
        Some(bvh) => (
            format!(
                "light BVH over {} lights with bounds{}",
                bvh.bounded_count(),
                if bvh.infinite_count() > 0 {
                    format!(
                        ", {} at infinity chosen apart (each 1/{})",
                        bvh.infinite_count(),
                        bvh.infinite_count() + 1
                    )
                } else {
                    String::new()
                }
            ),
            format!(
                "{}: each light sample descends the tree by the importance of its children \
                 at the shading point (Conty Estevez & Kulla 2018; pbrt-v4 \
                 BVHLightSampler), so near, facing lights get the samples",
                if bvh.bounded_count() >= min {
                    format!("{min} or more lights with bounds")
                } else {
                    "asked for (--light-selection bvh)".to_string()
                }
            ),
        ),
        None => {
            let lights = scene.lights.lights();
            let at_infinity = lights.iter().filter(|l| l.is_infinite()).count();
            let selection = scene.lights.shading_selection();
            // `auto` never chooses power alone, and below the BVH's threshold it chooses
            // lights at infinity apart; from the threshold on only the flag can have.
            let reason = match selection {
                ShadingSelection::Power => "asked for (--light-selection power)".to_string(),
                ShadingSelection::InfiniteApart | ShadingSelection::Bvh
                    if scene.lights.bounded_light_count() >= min =>
                {
                    "asked for (--light-selection infinite-apart)".to_string()
                }
                ShadingSelection::InfiniteApart | ShadingSelection::Bvh => {
                    format!("fewer than {min} lights with bounds: the light BVH gains little")
                }
            };
            match selection {
                ShadingSelection::InfiniteApart
                    if scene.lights.infinite_apart_differs_from_power()
                        && at_infinity == lights.len() =>
                {
                    let what = format!(
                        "{at_infinity} lights at infinity, each 1/{at_infinity}, no other light"
                    );
                    let why = format!(
                        "{reason}; only lights at infinity: each takes one light sample at \
                         every hit (`light samples per hit`), so their powers need not be \
                         compared"
                    );
                    (what, why)
                }
                ShadingSelection::InfiniteApart
                    if scene.lights.infinite_apart_differs_from_power()
                        && at_infinity < lights.len() =>
                {
                    let what = format!(
                        "{at_infinity} light(s) at infinity apart (each 1/{}), the other {} in \
                         proportion to power",
                        at_infinity + 1,
                        lights.len() - at_infinity
                    );
                    let why = format!(
                        "{reason}; the power of a light at infinity grows with the scene's size \
                         and says little about which light lights a point, so it is chosen \
                         apart as in pbrt-v4's BVHLightSampler"
                    );
                    (what, why)
                }
                ShadingSelection::InfiniteApart | ShadingSelection::Bvh => (
                    format!("in proportion to power over {} light(s)", lights.len()),
                    format!(
                        "{reason}; no light at infinity stands beside other lights with \
                         power, where choosing those at infinity apart is choosing by power \
                         (pbrt-v4 PowerLightSampler)"
                    ),
                ),
                ShadingSelection::Power => (
                    format!("in proportion to power over {} light(s)", lights.len()),
                    format!("{reason} (pbrt-v4 PowerLightSampler)"),
                ),
            }
        }
    }
}

/// `--explain`'s line for a photon integrator: its settings as this scene resolves them
/// (photons per pass, radius, α, the memory estimate against the limit).
fn photon_explain(m: &crate::integrator::PhotonMapper, scene: &RenderScene) -> (String, String) {
    let plan = match m.plan(scene) {
        Ok(plan) => plan,
        Err(e) => return (m.name().to_string(), e.to_string()),
    };
    let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
    let radius = match (plan.alpha, plan.nearest) {
        (Some(alpha), _) => format!(
            "initial radius {:.4} m, α {alpha:.3}: per pixel on surfaces (stochastic \
             progressive photon mapping, Hachisuka & Jensen 2009), r²ᵢ₊₁ = r²ᵢ(i + α)/(i + 1) \
             in media (Knaus & Zwicker 2011)",
            plan.radius_m
        ),
        (None, Some(k)) => format!("radius: distance to the {k}-th nearest photon"),
        (None, None) => format!("fixed radius {:.4} m (biased)", plan.radius_m),
    };
    let limit = match plan.limit_bytes {
        Some(l) => format!("limit {:.0} MiB", mib(l)),
        None => "no memory limit known".into(),
    };
    (
        format!(
            "{}, max_depth {}: {} photons per pass (one pass per sample index), {radius}; \
             caustic map on surfaces, beam estimate in media; photon storage ≤ {:.1} MiB \
             per pass{} ({limit})",
            m.name(),
            m.max_depth,
            plan.photons_per_pass,
            mib(plan.estimate_bytes - plan.statistics_bytes),
            if plan.statistics_bytes > 0 {
                format!(
                    " and {:.1} MiB of per-pixel statistics",
                    mib(plan.statistics_bytes)
                )
            } else {
                String::new()
            }
        ) + &crate::integrator::photon::source_shares(scene),
        "the scene's `integrator` section (defaults: one photon per pixel, radius from the \
         scene bounds and the pixel footprint, α 2/3)"
            .into(),
    )
}
