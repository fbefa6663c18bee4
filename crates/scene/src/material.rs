//! Material descriptions (BSDFs are built from them by render): lambert, conductor,
//! dielectric, two-sided wrapper and opacity mask. Materials are named in the `materials`
//! section and referenced by name.

use crate::reader::{quoted_list, suggest, Obj, Result, V};
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};

#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MaterialKind {
    /// Ideal diffuse reflector.
    Lambert { reflectance: SpectrumRef },
    Conductor {
        optics: ConductorOptics,
        roughness: Roughness,
        distribution: Microfacet,
    },
    Dielectric {
        ior: Ior,
        roughness: Roughness,
        distribution: Microfacet,
    },
    /// The referenced material on both sides of the surface (index into `materials`).
    TwoSided { material: usize },
    /// The referenced material with this opacity; the rest passes straight through.
    Mask { material: usize, opacity: f64 },
}

/// Complex index of refraction of a conductor.
#[derive(Debug, Clone, PartialEq)]
pub enum ConductorOptics {
    /// A metal whose η, k tables render ships (see `METAL_NAMES`).
    Named(&'static str),
    Spectra {
        eta: SpectrumRef,
        k: SpectrumRef,
    },
}

/// Metals known by name (chemical symbols).
pub const METAL_NAMES: [&str; 9] = ["Ag", "Al", "Au", "Cr", "Cu", "Fe", "Ni", "Pt", "Ti"];

/// Microfacet roughness α along the tangent (u) and bitangent (v); equal when isotropic;
/// 0 is a perfectly smooth surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roughness {
    pub alpha_u: f64,
    pub alpha_v: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Microfacet {
    /// Trowbridge–Reitz (Walter et al. 2007).
    Ggx,
    Beckmann,
}

/// Index of refraction of a dielectric, relative to vacuum.
#[derive(Debug, Clone, PartialEq)]
pub enum Ior {
    Constant(f64),
    /// n² = 1 + Σ Bᵢλ²/(λ² − Cᵢ), λ in µm.
    Sellmeier {
        b: [f64; 3],
        c_um2: [f64; 3],
    },
    /// n = A + B/λ², λ in µm.
    Cauchy {
        a: f64,
        b_um2: f64,
    },
}

const TYPES: [&str; 5] = ["lambert", "conductor", "dielectric", "two_sided", "mask"];

/// Parses the `materials` section: names in file order, references between materials
/// resolved, cycles refused.
pub(crate) fn parse_materials(v: &V, spectra: &NamedSpectra) -> Result<Vec<Material>> {
    let entries = v.map()?;
    let names: Vec<&str> = entries.iter().map(|(n, _)| *n).collect();
    let mut materials = Vec::with_capacity(entries.len());
    for (name, entry) in &entries {
        materials.push(Material {
            name: name.to_string(),
            kind: parse_material(entry, spectra, &names)?,
        });
    }
    // A wrapper chain must end in a real material.
    for (start, (_, entry)) in entries.iter().enumerate() {
        let mut current = start;
        for _ in 0..=materials.len() {
            match materials[current].kind {
                MaterialKind::TwoSided { material } | MaterialKind::Mask { material, .. } => {
                    current = material;
                    if current == start {
                        return Err(entry.err(format!(
                            "material `{}` refers back to itself through `material`",
                            names[start]
                        )));
                    }
                }
                _ => break,
            }
        }
    }
    Ok(materials)
}

/// A material name → index into the `materials` section, with a suggestion on typos.
pub(crate) fn material_index(v: &V, names: &[&str]) -> Result<usize> {
    let wanted = v.str()?;
    names.iter().position(|n| *n == wanted).ok_or_else(|| {
        let known = if names.is_empty() {
            "the `materials` section is empty".to_string()
        } else {
            format!("defined: {}", quoted_list(names))
        };
        v.err(format!(
            "unknown material `{wanted}` ({known}){}",
            suggest(wanted, names.iter().copied())
        ))
    })
}

fn roughness_and_distribution(o: &Obj) -> Result<(Roughness, Microfacet)> {
    let roughness = match o.get("roughness") {
        None => Roughness {
            alpha_u: 0.0,
            alpha_v: 0.0,
        },
        Some(r) => match r.f64() {
            Ok(_) => {
                let a = r.in_range(0.0, 1.0)?;
                Roughness {
                    alpha_u: a,
                    alpha_v: a,
                }
            }
            Err(_) => {
                let items = r.array().map_err(|_| {
                    r.type_err("a roughness α in [0, 1] or [α_u, α_v] for an anisotropic surface")
                })?;
                if items.len() != 2 {
                    return Err(r.err(format!(
                        "expected [α_u, α_v], found {} numbers",
                        items.len()
                    )));
                }
                Roughness {
                    alpha_u: items[0].in_range(0.0, 1.0)?,
                    alpha_v: items[1].in_range(0.0, 1.0)?,
                }
            }
        },
    };
    let distribution = match o.one_of_or(
        "distribution",
        "microfacet distribution",
        &["ggx", "beckmann"],
        "ggx",
    )? {
        "beckmann" => Microfacet::Beckmann,
        _ => Microfacet::Ggx,
    };
    Ok((roughness, distribution))
}

fn parse_material(v: &V, spectra: &NamedSpectra, names: &[&str]) -> Result<MaterialKind> {
    Ok(match v.tag("material", &TYPES, None)? {
        "lambert" => {
            let o = v.tagged_object(&["type", "reflectance"])?;
            MaterialKind::Lambert {
                reflectance: match o.get("reflectance") {
                    None => SpectrumRef::Constant(0.5),
                    Some(r) => parse_spectrum(&r, spectra, SpectrumUse::Reflectance)?,
                },
            }
        }
        "conductor" => {
            let o = v.tagged_object(&["type", "metal", "eta", "k", "roughness", "distribution"])?;
            let optics = match (o.get("metal"), o.get("eta"), o.get("k")) {
                (Some(m), None, None) => ConductorOptics::Named(m.one_of("metal", &METAL_NAMES)?),
                (None, Some(eta), Some(k)) => ConductorOptics::Spectra {
                    eta: parse_spectrum(&eta, spectra, SpectrumUse::Positive)?,
                    k: parse_spectrum(&k, spectra, SpectrumUse::NonNegative)?,
                },
                (None, None, None) => ConductorOptics::Named("Al"),
                _ => {
                    return Err(
                        v.err("expected either `metal` or both `eta` and `k` for a conductor")
                    )
                }
            };
            let (roughness, distribution) = roughness_and_distribution(&o)?;
            MaterialKind::Conductor {
                optics,
                roughness,
                distribution,
            }
        }
        "dielectric" => {
            let o = v.tagged_object(&["type", "ior", "roughness", "distribution"])?;
            let ior = match o.get("ior") {
                None => Ior::Constant(1.5),
                Some(i) => parse_ior(&i)?,
            };
            let (roughness, distribution) = roughness_and_distribution(&o)?;
            MaterialKind::Dielectric {
                ior,
                roughness,
                distribution,
            }
        }
        "two_sided" => {
            let o = v.tagged_object(&["type", "material"])?;
            MaterialKind::TwoSided {
                material: material_index(&o.req("material", "a material name")?, names)?,
            }
        }
        _ => {
            let o = v.tagged_object(&["type", "material", "opacity"])?;
            MaterialKind::Mask {
                material: material_index(&o.req("material", "a material name")?, names)?,
                opacity: o.get("opacity").map_or(Ok(1.0), |a| a.in_range(0.0, 1.0))?,
            }
        }
    })
}

fn parse_ior(v: &V) -> Result<Ior> {
    if v.f64().is_ok() {
        return Ok(Ior::Constant(v.positive()?));
    }
    let o = v.object(&["sellmeier", "cauchy"]).map_err(|e| {
        if !v.is_object() {
            v.type_err("a number, {\"sellmeier\": …} or {\"cauchy\": …}")
        } else {
            e
        }
    })?;
    match o.at_most_one(&["sellmeier", "cauchy"])? {
        Some(("sellmeier", s)) => {
            let s = s.object(&["b", "c_um2"])?;
            Ok(Ior::Sellmeier {
                b: s.req("b", "three coefficients B₁, B₂, B₃")?
                    .numbers::<3>()?,
                c_um2: s
                    .req("c_um2", "three coefficients C₁, C₂, C₃ in µm²")?
                    .numbers::<3>()?,
            })
        }
        Some((_, c)) => {
            let c = c.object(&["a", "b_um2"])?;
            Ok(Ior::Cauchy {
                a: c.req("a", "the coefficient A")?.positive()?,
                b_um2: c.req("b_um2", "the coefficient B in µm²")?.f64()?,
            })
        }
        None => Err(v.err("expected `sellmeier` or `cauchy` in an `ior` object")),
    }
}
