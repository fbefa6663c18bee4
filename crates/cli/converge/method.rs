//! The method grammar of `prism converge --method`: `INTEGRATOR[+PLAN][:SAMPLER][,lanes=L]`.
//!
//! - INTEGRATOR: the rendering method — `path` (the spectral path tracer), `light` (light
//!   tracing) or `bdpt` (bidirectional path tracing), each with the scene's `max_depth`,
//!   `rr_depth` and (`path`, `bdpt`) `mis` when the scene's integrator is one of these three
//!   (so one scene compares the methods at equal depth), else the defaults; or one of the
//!   diagnostic integrators (`ambient_occlusion`, `depth`, `normal`, `albedo`); or `photon`
//!   / `photon_progressive` (photon mapping), with the scene's photon settings when the
//!   scene's integrator is that one, else every photon default, and the scene's depth and
//!   roulette.
//! - PLAN: how samples are distributed over the pixels — `uniform` (the default: the same
//!   spp everywhere), `predicted` (the bandwidth predictor's per-pixel plan, computed once
//!   before the first pass with `prism render --plan predicted`'s defaults),
//!   `predicted-hier` (that plan shaded hierarchically, `prism render --plan
//!   predicted-hier`'s defaults: interpolated pixels get no samples) or `adaptive`
//!   (variance-driven passes after 4 spp) or `oracle` (the predicted plan's allocation fed
//!   with a measured `variance.Y`, `--oracle-variance`: the best a predictor could do).
//!   All but `uniform` are for `path` only.
//! - SAMPLER: `independent` (the default, so that `path` is plain Monte Carlo with the
//!   −0.5 RMSE rate) or `sobol` (Owen-scrambled Sobol, Burley 2020).
//!
//! - `,lanes=all|hero` (`path` only): the re-radiation lane mode (`fluorescence_lanes`) instead
//!   of the scene's, so one run charts both modes of a fluorescent scene.
//!
//! Unknown or unavailable names are errors that list what is known.

use prism_render::integrator::AmbientOcclusion;
use prism_render::{Integrator, SamplerKind};

/// Integrator names: (name, available in this build, what it is).
pub const INTEGRATORS: [(&str, bool, &str); 10] = [
    ("path", true, "spectral path tracer (NEE + MIS)"),
    (
        "light",
        true,
        "light tracing (light paths connected to the camera)",
    ),
    (
        "bdpt",
        true,
        "bidirectional path tracing (MIS over all strategies)",
    ),
    ("ambient_occlusion", true, "diagnostic"),
    ("depth", true, "diagnostic"),
    ("normal", true, "diagnostic"),
    ("albedo", true, "diagnostic"),
    (
        "photon",
        true,
        "photon mapping, fixed radius (caustic map and volume beams; biased)",
    ),
    (
        "photon_progressive",
        true,
        "progressive photon mapping (stochastic on surfaces, Hachisuka & Jensen 2009; consistent)",
    ),
    (
        "radiosity",
        true,
        "hierarchical radiosity with clustering and a final gather (diffuse scenes, area lights; \
         biased by the solution's error bound)",
    ),
];

/// Sample plans: (name, available, what it is).
pub const PLANS: [(&str, bool, &str); 5] = [
    ("uniform", true, "same spp in every pixel"),
    ("predicted", true, "bandwidth predictor's per-pixel plan"),
    (
        "predicted-hier",
        true,
        "the predicted plan shaded hierarchically: low-bandwidth pixels interpolated from a \
         lattice of shaded pixels (biased)",
    ),
    (
        "adaptive",
        true,
        "variance-driven passes after 4 spp (Cycles' adaptive sampling)",
    ),
    (
        "oracle",
        true,
        "the allocation from a measured variance.Y (--oracle-variance FILE.exr): the ceiling",
    ),
];

/// Samplers: (name, what it is).
pub const SAMPLERS: [(&str, &str); 2] = [
    ("independent", "independent uniform samples"),
    ("sobol", "Owen-scrambled Sobol"),
];

/// Sample plans that exist.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlanKind {
    Uniform,
    Predicted,
    PredictedHier,
    Adaptive,
    Oracle,
}

impl PlanKind {
    pub fn name(&self) -> &'static str {
        match self {
            PlanKind::Uniform => "uniform",
            PlanKind::Predicted => "predicted",
            PlanKind::PredictedHier => "predicted-hier",
            PlanKind::Adaptive => "adaptive",
            PlanKind::Oracle => "oracle",
        }
    }
}

/// One parsed `--method`.
#[derive(Clone, Debug, PartialEq)]
pub struct Method {
    /// As the user wrote it (the chart's legend).
    pub label: String,
    /// The integrator's name (one of `INTEGRATORS`).
    pub integrator: &'static str,
    pub plan: PlanKind,
    pub sampler: SamplerKind,
    /// `,lanes=…`: the lane mode of re-radiation; `None`: the scene's.
    pub lanes: Option<prism_scene::FluorescenceLanes>,
}

fn list(names: impl Iterator<Item = String>) -> String {
    names.collect::<Vec<_>>().join(", ")
}

/// The grammar and every known name, for error messages.
pub fn known_methods() -> String {
    format!(
        "INTEGRATOR[+PLAN][:SAMPLER][,lanes=all|hero] with INTEGRATOR one of {}; PLAN one of {}; \
         SAMPLER one of {} (e.g. `path`, `path+uniform:sobol`, `path,lanes=hero`)",
        list(INTEGRATORS.iter().map(|(n, ok, _)| if *ok {
            (*n).to_string()
        } else {
            format!("{n} (not built yet)")
        })),
        list(
            PLANS
                .iter()
                .enumerate()
                .map(|(i, (n, ok, _))| match (i, ok) {
                    (_, false) => format!("{n} (not built yet)"),
                    (0, true) => format!("{n} (default)"),
                    (_, true) => (*n).to_string(),
                })
        ),
        list(SAMPLERS.iter().enumerate().map(|(i, (n, _))| if i == 0 {
            format!("{n} (default)")
        } else {
            (*n).to_string()
        })),
    )
}

impl Method {
    /// Parses `INTEGRATOR[+PLAN][:SAMPLER][,lanes=L]` (see the module documentation).
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = |what: String| format!("--method `{text}`: {what}; known: {}", known_methods());
        let (method, option) = match text.split_once(',') {
            Some((m, o)) => (m, Some(o)),
            None => (text, None),
        };
        let lanes = match option {
            None => None,
            Some("lanes=all") => Some(prism_scene::FluorescenceLanes::All),
            Some("lanes=hero") => Some(prism_scene::FluorescenceLanes::Hero),
            Some(o) => return Err(bad(format!("unknown option `{o}`"))),
        };
        let (head, sampler) = match method.split_once(':') {
            Some((h, s)) => (h, Some(s)),
            None => (method, None),
        };
        let (integrator, plan) = match head.split_once('+') {
            Some((i, p)) => (i, Some(p)),
            None => (head, None),
        };
        let integrator = match INTEGRATORS.iter().find(|(n, _, _)| *n == integrator) {
            Some((n, true, _)) => *n,
            Some((n, false, what)) => {
                return Err(bad(format!(
                    "the integrator `{n}` ({what}) is not available"
                )))
            }
            None => return Err(bad(format!("unknown integrator `{integrator}`"))),
        };
        let plan = match plan {
            None | Some("uniform") => PlanKind::Uniform,
            Some("predicted") => PlanKind::Predicted,
            Some("predicted-hier") => PlanKind::PredictedHier,
            Some("adaptive") => PlanKind::Adaptive,
            Some("oracle") => PlanKind::Oracle,
            Some(p) => match PLANS.iter().find(|(n, _, _)| *n == p) {
                Some((n, _, what)) => {
                    return Err(bad(format!(
                        "the sample plan `{n}` ({what}) is not available"
                    )))
                }
                None => return Err(bad(format!("unknown sample plan `{p}`"))),
            },
        };
        let sampler = match sampler {
            None | Some("independent") => SamplerKind::Independent,
            Some("sobol") => SamplerKind::Sobol,
            Some(s) => return Err(bad(format!("unknown sampler `{s}`"))),
        };
        if lanes.is_some() && integrator != "path" {
            return Err(bad(format!(
                "`lanes` is the re-radiation mode of `path`, not of `{integrator}`"
            )));
        }
        if plan != PlanKind::Uniform && integrator != "path" {
            return Err(bad(format!(
                "the sample plan `{}` is for `path`, not `{integrator}`",
                plan.name()
            )));
        }
        Ok(Self {
            label: text.to_string(),
            integrator,
            plan,
            sampler,
            lanes,
        })
    }

    /// The fully spelled name, e.g. `path+uniform:independent`.
    pub fn canonical(&self) -> String {
        let sampler = match self.sampler {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        };
        let lanes = match self.lanes {
            None => "",
            Some(prism_scene::FluorescenceLanes::All) => ",lanes=all",
            Some(prism_scene::FluorescenceLanes::Hero) => ",lanes=hero",
        };
        format!("{}+{}:{sampler}{lanes}", self.integrator, self.plan.name())
    }

    /// Whether the method estimates radiance (the path family) rather than a diagnostic
    /// quantity; a run compares one quantity only.
    pub fn quantity(&self) -> &'static str {
        match self.integrator {
            "path" | "light" | "bdpt" | "photon" | "photon_progressive" | "radiosity" => "radiance",
            other => other,
        }
    }

    /// The runtime integrator, with the scene's parameters where the scene's own integrator
    /// is of the same kind, else that kind's defaults.
    pub fn integrator(&self, scene: &prism_scene::Integrator) -> Result<Integrator, String> {
        // The depth, roulette and MIS settings of the scene's spectral method, if it has one.
        let spectral = match *scene {
            prism_scene::Integrator::Path {
                max_depth,
                mis,
                rr_depth,
                ..
            }
            | prism_scene::Integrator::Bdpt {
                max_depth,
                mis,
                rr_depth,
                ..
            } => Some((max_depth, Some(mis), rr_depth)),
            prism_scene::Integrator::Light {
                max_depth,
                rr_depth,
                ..
            }
            | prism_scene::Integrator::Photon {
                max_depth,
                rr_depth,
                ..
            }
            | prism_scene::Integrator::PhotonProgressive {
                max_depth,
                rr_depth,
                ..
            } => Some((max_depth, None, rr_depth)),
            prism_scene::Integrator::Depth
            | prism_scene::Integrator::Normal
            | prism_scene::Integrator::Albedo
            | prism_scene::Integrator::AmbientOcclusion { .. }
            | prism_scene::Integrator::Radiosity { .. } => None,
        };
        let defaults = match prism_scene::Integrator::default() {
            prism_scene::Integrator::Path {
                max_depth,
                mis,
                rr_depth,
                ..
            } => (max_depth, mis, rr_depth),
            prism_scene::Integrator::Light { .. }
            | prism_scene::Integrator::Bdpt { .. }
            | prism_scene::Integrator::Photon { .. }
            | prism_scene::Integrator::PhotonProgressive { .. }
            | prism_scene::Integrator::Radiosity { .. }
            | prism_scene::Integrator::Depth
            | prism_scene::Integrator::Normal
            | prism_scene::Integrator::Albedo
            | prism_scene::Integrator::AmbientOcclusion { .. } => {
                (8, prism_scene::MisHeuristic::Power, 3)
            }
        };
        let (max_depth, mis, rr_depth) = match spectral {
            Some((d, m, r)) => (d, m.unwrap_or(defaults.1), r),
            None => defaults,
        };
        // The sampler is the method's (`:SAMPLER`); the description's is not read.
        let sampler = self.sampler;
        // The lane mode of re-radiation: the method's, else the scene's when it renders
        // with `path`.
        let fluorescence_lanes = match *scene {
            prism_scene::Integrator::Path {
                fluorescence_lanes, ..
            } => fluorescence_lanes,
            prism_scene::Integrator::Light { .. }
            | prism_scene::Integrator::Bdpt { .. }
            | prism_scene::Integrator::Photon { .. }
            | prism_scene::Integrator::PhotonProgressive { .. }
            | prism_scene::Integrator::Radiosity { .. }
            | prism_scene::Integrator::Depth
            | prism_scene::Integrator::Normal
            | prism_scene::Integrator::Albedo
            | prism_scene::Integrator::AmbientOcclusion { .. } => {
                prism_scene::FluorescenceLanes::default()
            }
        };
        let fluorescence_lanes = self.lanes.unwrap_or(fluorescence_lanes);
        let description = match (self.integrator, scene) {
            ("path", _) => prism_scene::Integrator::Path {
                max_depth,
                sampler,
                mis,
                rr_depth,
                fluorescence_lanes,
                spectral_mis: match *scene {
                    prism_scene::Integrator::Path { spectral_mis, .. } => spectral_mis,
                    prism_scene::Integrator::Light { .. }
                    | prism_scene::Integrator::Bdpt { .. }
                    | prism_scene::Integrator::Photon { .. }
                    | prism_scene::Integrator::PhotonProgressive { .. }
                    | prism_scene::Integrator::Radiosity { .. }
                    | prism_scene::Integrator::Depth
                    | prism_scene::Integrator::Normal
                    | prism_scene::Integrator::Albedo
                    | prism_scene::Integrator::AmbientOcclusion { .. } => true,
                },
            },
            ("light", _) => prism_scene::Integrator::Light {
                max_depth,
                sampler,
                rr_depth,
            },
            ("bdpt", _) => prism_scene::Integrator::Bdpt {
                max_depth,
                sampler,
                mis,
                rr_depth,
            },
            ("ambient_occlusion", d @ prism_scene::Integrator::AmbientOcclusion { .. }) => *d,
            ("ambient_occlusion", _) => {
                return Ok(Integrator::AmbientOcclusion(AmbientOcclusion::new(
                    f32::INFINITY,
                    1,
                )?))
            }
            ("photon", d @ prism_scene::Integrator::Photon { .. }) => *d,
            ("photon", _) => prism_scene::Integrator::Photon {
                max_depth,
                sampler,
                rr_depth,
                photons_per_pass: None,
                radius: prism_scene::PhotonRadius::Fixed(None),
            },
            ("photon_progressive", d @ prism_scene::Integrator::PhotonProgressive { .. }) => *d,
            ("photon_progressive", _) => prism_scene::Integrator::PhotonProgressive {
                max_depth,
                sampler,
                rr_depth,
                photons_per_pass: None,
                initial_radius_m: None,
                alpha: prism_scene::DEFAULT_PHOTON_ALPHA,
            },
            ("radiosity", d @ prism_scene::Integrator::Radiosity { .. }) => *d,
            ("radiosity", _) => prism_scene::Integrator::Radiosity {
                error_bound_rel: 0.004,
                iterations: 3,
                gather_epsilon: 0.1,
                sampler,
            },
            ("depth", _) => prism_scene::Integrator::Depth,
            ("normal", _) => prism_scene::Integrator::Normal,
            ("albedo", _) => prism_scene::Integrator::Albedo,
            (other, _) => return Err(format!("integrator `{other}` is not available")),
        };
        Integrator::from_description(&description)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_is_uniform_independent_and_spellings_agree() {
        let m = Method::parse("path").unwrap();
        assert_eq!(m.canonical(), "path+uniform:independent");
        assert_eq!(
            Method::parse("path+uniform").unwrap().canonical(),
            m.canonical()
        );
        let s = Method::parse("path:sobol").unwrap();
        assert_eq!(s.sampler, SamplerKind::Sobol);
        assert_eq!(s.canonical(), "path+uniform:sobol");
        assert_eq!(
            Method::parse("ambient_occlusion+uniform:independent")
                .unwrap()
                .quantity(),
            "ambient_occlusion"
        );
    }

    #[test]
    fn unknown_and_unbuilt_names_are_errors_listing_the_known_ones() {
        for (text, says) in [
            ("vcm", "unknown integrator `vcm`"),
            (
                "bdpt+predicted",
                "the sample plan `predicted` is for `path`, not `bdpt`",
            ),
            ("path+hier", "unknown sample plan `hier`"),
            ("path,lanes=some", "unknown option `lanes=some`"),
            (
                "bdpt,lanes=hero",
                "`lanes` is the re-radiation mode of `path`",
            ),
            ("path:halton", "unknown sampler `halton`"),
        ] {
            let e = Method::parse(text).unwrap_err();
            assert!(e.contains(says), "{e}");
            assert!(
                e.contains("path") && e.contains("sobol") && e.contains("uniform"),
                "{e}"
            );
        }
    }

    #[test]
    fn light_and_bdpt_take_the_scenes_spectral_parameters() {
        let scene = prism_scene::Integrator::Path {
            max_depth: 4,
            sampler: SamplerKind::Sobol,
            mis: prism_scene::MisHeuristic::Balance,
            rr_depth: 2,
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        };
        let m = Method::parse("bdpt:sobol").unwrap();
        assert_eq!(m.quantity(), "radiance");
        match m.integrator(&scene).unwrap() {
            Integrator::Bdpt(b) => assert_eq!(
                (b.max_depth, b.rr_depth, b.mis),
                (4, 2, prism_scene::MisHeuristic::Balance)
            ),
            other => panic!("{other:?}"),
        }
        match Method::parse("light").unwrap().integrator(&scene).unwrap() {
            Integrator::Light(l) => assert_eq!((l.max_depth, l.rr_depth), (4, 2)),
            other => panic!("{other:?}"),
        }
        // A diagnostic scene integrator: the defaults.
        match Method::parse("bdpt")
            .unwrap()
            .integrator(&prism_scene::Integrator::Depth)
            .unwrap()
        {
            Integrator::Bdpt(b) => assert_eq!((b.max_depth, b.rr_depth), (8, 3)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn path_takes_the_scene_parameters_or_the_defaults() {
        let scene = prism_scene::Integrator::Path {
            max_depth: 3,
            sampler: SamplerKind::Sobol,
            mis: prism_scene::MisHeuristic::Balance,
            rr_depth: 2,
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        };
        let m = Method::parse("path").unwrap();
        match m.integrator(&scene).unwrap() {
            Integrator::Path(p) => assert_eq!((p.max_depth, p.rr_depth), (3, 2)),
            other => panic!("{other:?}"),
        }
        match m.integrator(&prism_scene::Integrator::Depth).unwrap() {
            Integrator::Path(p) => assert_eq!(p.max_depth, 8),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn photon_methods_take_the_scene_depth_and_the_photon_defaults() {
        let scene = prism_scene::Integrator::Path {
            max_depth: 5,
            sampler: SamplerKind::Sobol,
            mis: prism_scene::MisHeuristic::Power,
            rr_depth: 2,
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        };
        for (name, progressive) in [("photon", false), ("photon_progressive", true)] {
            let m = Method::parse(name).unwrap();
            assert_eq!(m.quantity(), "radiance");
            match m.integrator(&scene).unwrap() {
                Integrator::Photon(p) => {
                    assert_eq!((p.max_depth, p.rr_depth), (5, 2));
                    assert_eq!(p.photons_per_pass, None);
                    assert_eq!(p.is_progressive(), progressive);
                }
                other => panic!("{other:?}"),
            }
        }
    }
}
