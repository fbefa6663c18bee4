//! Integrators: the diagnostic ones (depth, normal, albedo, ambient occlusion) and the
//! spectral path tracer's parameters.

use crate::reader::{Result, V};

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Distance to the first hit, in metres.
    Depth,
    /// Shading normal at the first hit, mapped to colour.
    Normal,
    /// Material reflectance at the first hit.
    Albedo,
    /// Fraction of the cosine-weighted hemisphere that is unoccluded within `max_distance_m`.
    AmbientOcclusion {
        /// `None`: rays go to infinity.
        max_distance_m: Option<f64>,
        /// Occlusion rays per camera sample.
        samples: u32,
    },
    Path {
        /// Longest path, in bounces (1 = direct lighting only).
        max_depth: u32,
        sampler: SamplerKind,
        mis: MisHeuristic,
        /// Russian roulette starts at this depth.
        rr_depth: u32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplerKind {
    /// Owen-scrambled Sobol (Burley 2020).
    Sobol,
    Independent,
}

/// Multiple importance sampling weights (Veach 1997, §9.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MisHeuristic {
    Balance,
    /// β = 2.
    Power,
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Path {
            max_depth: 8,
            sampler: SamplerKind::Sobol,
            mis: MisHeuristic::Power,
            rr_depth: 3,
        }
    }
}

pub const INTEGRATOR_TYPES: [&str; 5] = ["depth", "normal", "albedo", "ambient_occlusion", "path"];

pub(crate) fn parse_integrator(v: &V) -> Result<Integrator> {
    Ok(
        match v.tag("integrator", &INTEGRATOR_TYPES, Some("path"))? {
            "depth" => {
                v.tagged_object(&["type"])?;
                Integrator::Depth
            }
            "normal" => {
                v.tagged_object(&["type"])?;
                Integrator::Normal
            }
            "albedo" => {
                v.tagged_object(&["type"])?;
                Integrator::Albedo
            }
            "ambient_occlusion" => {
                let o = v.tagged_object(&["type", "max_distance_m", "samples"])?;
                Integrator::AmbientOcclusion {
                    max_distance_m: o.get("max_distance_m").map(|d| d.positive()).transpose()?,
                    samples: o.u32_or("samples", 1, 1)?,
                }
            }
            _ => {
                let o = v.tagged_object(&["type", "max_depth", "sampler", "mis", "rr_depth"])?;
                Integrator::Path {
                    max_depth: o.u32_or("max_depth", 1, 8)?,
                    sampler: match o.one_of_or(
                        "sampler",
                        "sampler",
                        &["sobol", "independent"],
                        "sobol",
                    )? {
                        "independent" => SamplerKind::Independent,
                        _ => SamplerKind::Sobol,
                    },
                    mis: match o.one_of_or(
                        "mis",
                        "MIS heuristic",
                        &["power", "balance"],
                        "power",
                    )? {
                        "balance" => MisHeuristic::Balance,
                        _ => MisHeuristic::Power,
                    },
                    rr_depth: o.u32_or("rr_depth", 1, 3)?,
                }
            }
        },
    )
}
