//! Material descriptions (BSDFs are built from them by render): lambert, conductor,
//! dielectric, two-sided wrapper, opacity mask, and the normal-map and bump-map wrappers.
//! Materials are named in the `materials` section and referenced by name. Parameters that
//! accept textures (`{"texture": …}`, see `texture.rs`): lambert `reflectance`, conductor
//! and dielectric `roughness`, mask `opacity`.

use crate::reader::{quoted_list, suggest, Obj, Result, V};
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};
use crate::texture::{is_texture_ref, parse_spectrum_param, parse_texture_ref};
use crate::texture::{SpectrumParam, TextureTable};

#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MaterialKind {
    /// Ideal diffuse reflector.
    Lambert { reflectance: SpectrumParam },
    Conductor {
        optics: ConductorOptics,
        roughness: Roughness,
        distribution: Microfacet,
        /// An isotropic α texture (index into `SceneDescription::textures`) that replaces
        /// `roughness`.
        roughness_texture: Option<usize>,
    },
    Dielectric {
        ior: Ior,
        roughness: Roughness,
        distribution: Microfacet,
        /// As for `Conductor`.
        roughness_texture: Option<usize>,
    },
    /// The referenced material on both sides of the surface (index into `materials`).
    TwoSided { material: usize },
    /// The referenced material with this opacity; the rest passes straight through.
    Mask {
        material: usize,
        opacity: f64,
        /// An opacity texture in [0, 1] that replaces `opacity`.
        opacity_texture: Option<usize>,
    },
    /// The referenced material with its shading normal from a tangent-space normal map
    /// (texture index; RGB = (n + 1)/2 in the frame (dP/du, n × dP/du, n)).
    NormalMap { material: usize, texture: usize },
    /// The referenced material with its shading normal bent by the height field
    /// `scale_m × texture` along the normal (pbrt-v4 §10.5.2).
    BumpMap {
        material: usize,
        texture: usize,
        scale_m: f64,
    },
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

const TYPES: [&str; 7] = [
    "lambert",
    "conductor",
    "dielectric",
    "two_sided",
    "mask",
    "normal_map",
    "bump_map",
];

/// Parses the `materials` section: names in file order, references between materials
/// resolved, cycles refused.
pub(crate) fn parse_materials(
    v: &V,
    spectra: &NamedSpectra,
    textures: &mut TextureTable,
) -> Result<Vec<Material>> {
    let entries = v.map()?;
    let names: Vec<&str> = entries.iter().map(|(n, _)| *n).collect();
    let mut materials = Vec::with_capacity(entries.len());
    for (name, entry) in &entries {
        materials.push(Material {
            name: name.to_string(),
            kind: parse_material(entry, spectra, &names, textures)?,
        });
    }
    // A wrapper chain must end in a real material.
    for (start, (_, entry)) in entries.iter().enumerate() {
        let mut current = start;
        for _ in 0..=materials.len() {
            match materials[current].kind {
                MaterialKind::TwoSided { material }
                | MaterialKind::Mask { material, .. }
                | MaterialKind::NormalMap { material, .. }
                | MaterialKind::BumpMap { material, .. } => {
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

fn roughness_and_distribution(
    o: &Obj,
    spectra: &NamedSpectra,
    textures: &mut TextureTable,
) -> Result<(Roughness, Microfacet, Option<usize>)> {
    let mut roughness_texture = None;
    let roughness = match o.get("roughness") {
        None => Roughness {
            alpha_u: 0.0,
            alpha_v: 0.0,
        },
        Some(r) if is_texture_ref(&r) => {
            roughness_texture = Some(parse_texture_ref(&r, spectra, textures)?);
            Roughness {
                alpha_u: 0.0,
                alpha_v: 0.0,
            }
        }
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
    Ok((roughness, distribution, roughness_texture))
}

fn parse_material(
    v: &V,
    spectra: &NamedSpectra,
    names: &[&str],
    textures: &mut TextureTable,
) -> Result<MaterialKind> {
    Ok(match v.tag("material", &TYPES, None)? {
        "lambert" => {
            let o = v.tagged_object(&["type", "reflectance"])?;
            MaterialKind::Lambert {
                reflectance: match o.get("reflectance") {
                    None => SpectrumParam::Spectrum(SpectrumRef::Constant(0.5)),
                    Some(r) => {
                        parse_spectrum_param(&r, spectra, SpectrumUse::Reflectance, textures)?
                    }
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
            let (roughness, distribution, roughness_texture) =
                roughness_and_distribution(&o, spectra, textures)?;
            MaterialKind::Conductor {
                optics,
                roughness,
                distribution,
                roughness_texture,
            }
        }
        "dielectric" => {
            let o = v.tagged_object(&["type", "ior", "roughness", "distribution"])?;
            let ior = match o.get("ior") {
                None => Ior::Constant(1.5),
                Some(i) => parse_ior(&i)?,
            };
            let (roughness, distribution, roughness_texture) =
                roughness_and_distribution(&o, spectra, textures)?;
            MaterialKind::Dielectric {
                ior,
                roughness,
                distribution,
                roughness_texture,
            }
        }
        "two_sided" => {
            let o = v.tagged_object(&["type", "material"])?;
            MaterialKind::TwoSided {
                material: material_index(&o.req("material", "a material name")?, names)?,
            }
        }
        "normal_map" => {
            let o = v.tagged_object(&["type", "material", "texture"])?;
            let t = o.req("texture", "a texture name or an image texture object")?;
            MaterialKind::NormalMap {
                material: material_index(&o.req("material", "a material name")?, names)?,
                texture: texture_field(&t, spectra, textures)?,
            }
        }
        "bump_map" => {
            let o = v.tagged_object(&["type", "material", "texture", "scale_m"])?;
            let t = o.req(
                "texture",
                "a texture name or texture object (the height field)",
            )?;
            MaterialKind::BumpMap {
                material: material_index(&o.req("material", "a material name")?, names)?,
                texture: texture_field(&t, spectra, textures)?,
                scale_m: o
                    .req("scale_m", "the height in metres of a texture value of 1")?
                    .f64()?,
            }
        }
        _ => {
            let o = v.tagged_object(&["type", "material", "opacity"])?;
            let (opacity, opacity_texture) = match o.get("opacity") {
                Some(a) if is_texture_ref(&a) => {
                    (1.0, Some(parse_texture_ref(&a, spectra, textures)?))
                }
                Some(a) => (a.in_range(0.0, 1.0)?, None),
                None => (1.0, None),
            };
            MaterialKind::Mask {
                material: material_index(&o.req("material", "a material name")?, names)?,
                opacity,
                opacity_texture,
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

/// The `texture` field of a normal or bump map: a texture name, or an inline definition
/// (given directly, or as `{"texture": …}` like other parameters).
fn texture_field(t: &V, spectra: &NamedSpectra, textures: &mut TextureTable) -> Result<usize> {
    if t.is_object() && !is_texture_ref(t) {
        // `{"type": "image", …}`: wrap it as an inline reference.
        let (kind, uv) = crate::texture::parse_texture_definition(t, spectra)?;
        textures.textures.push(crate::texture::Texture {
            place: t.path.to_string(),
            kind,
            uv,
        });
        return Ok(textures.textures.len() - 1);
    }
    if t.str().is_ok() {
        return crate::texture::texture_by_name(t, textures);
    }
    parse_texture_ref(t, spectra, textures)
}
