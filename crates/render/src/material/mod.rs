#![deny(clippy::wildcard_enum_match_arm)]
//! Runtime materials: a scene material (prism-scene `MaterialKind`) with its spectra built,
//! turned into a `Bsdf` at each hit for the path's wavelengths (`Material::bsdf`).
//!
//! `build_materials` returns one entry per scene material plus, last, the default material
//! (lambert 0.5) that shapes without a material use — matching the `material_id`s that
//! `build_geometry` gives the instances. Wrappers (`two_sided`, `mask`, `normal_map`,
//! `bump_map`) hold their inner material, resolved at build time (prism-scene already
//! refuses cycles).
//!
//! Three closed sets, each matched exhaustively where it is asked about:
//! - `Material`: the wrappers and `Surface` — wrapper-level queries (opacity, shading maps,
//!   two-sidedness) have one arm for every surface;
//! - `SurfaceMaterial` (surface.rs): the kinds with a property of their own (textures,
//!   dispersion, thin glazing, a mix's parts) and `Library`;
//! - `LibraryMaterial` (library.rs): constant-parameter materials, which answer every
//!   surface query alike, so a new one is an arm in library.rs and in no match here.
//!
//! Shading frame: the integrator evaluates BSDFs in `Frame::from_zx(n_shading, dpdu)`: z is
//! the shading normal and x is dP/du projected onto the tangent plane (Gram–Schmidt), y =
//! z × x. So an anisotropic roughness `[α_u, α_v]` has α_u along the surface's u direction
//! and α_v along v (the lobe, and a highlight, stretches along the axis with the larger α;
//! brushed metal whose grooves run along u tilts its normals across them: α_u < α_v).
//! Where dP/du is zero or parallel to the normal, `from_zx` falls back to an arbitrary
//! tangent (Duff et al. 2017), and an anisotropic lobe's orientation is then arbitrary.
//! The two-sided and mask wrappers do not change the frame.
//!
//! The formulas, parameters and validity ranges are in docs/materials.md.
//!
//! Textures (crate::texture): lambert reflectance (RGB images upsampled as albedo),
//! conductor/dielectric roughness and mask opacity (scalar textures) are read at the hit
//! in `bsdf`/`opacity_at`; the `NormalMap` and `BumpMap` wrappers change the hit's shading
//! normal in `apply_shading_maps`, which the integrator calls before it builds the frame.

pub mod fluorescent;
mod glazing;
pub mod ior;
pub mod library;
pub mod merl_export;
pub mod metals;
pub mod mix_weight;
mod surface;

use std::path::Path;
use std::sync::Arc;

use prism_geometry::SurfaceInteraction;
use prism_scene::{
    ConductorOptics, MaterialKind, Microfacet, Roughness, SceneDescription, SpectrumParam,
    SpectrumRef,
};
use prism_spectrum::constants::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use prism_spectrum::{SampledWavelengths, Spectrum};

use crate::bsdf::{Bsdf, BsdfLobe, Bxdf, Lambert, MicrofacetDistribution, MicrofacetModel};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};
use crate::scene_build::SceneBuildError;
use crate::texture::shading_normal::{apply_bump_map, apply_normal_map};
use crate::texture::{
    build_textures, FloatTexture, RgbUse, Texture, TexturePurpose, TextureSet, TexturedSpectrum,
};

pub use fluorescent::FluorescentSurface;
pub use ior::Ior;
pub use library::LibraryMaterial;
pub use metals::{metal_optics, MetalOptics};
pub use mix_weight::MixWeight;
pub use surface::SurfaceMaterial;

/// Wrapper chains deeper than this are refused (prism-scene rejects cycles; a guard).
const MAX_WRAPPER_DEPTH: usize = 16;

/// A material ready to make BSDFs: a surface, or a wrapper that changes how its inner
/// material is seen (sides, coverage, shading normal) without scattering itself. The surface
/// is held in place (a box would cost an indirection at every hit; a scene has few
/// materials, so their size does not matter).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// What scatters (surface.rs; the material library is one of its kinds).
    Surface(SurfaceMaterial),
    /// The inner material on both sides (reflection-only lobes; dielectrics already are).
    TwoSided { material: Box<Material> },
    /// The inner material with coverage `opacity` ∈ [0, 1]; the rest passes straight through.
    Mask {
        material: Box<Material>,
        opacity: f32,
        /// Opacity from a texture (then `opacity` is 1).
        opacity_texture: Option<FloatTexture>,
    },
    /// The inner material with its shading normal from a tangent-space normal map.
    NormalMap {
        material: Box<Material>,
        texture: Arc<Texture>,
    },
    /// The inner material with its shading normal bent by the height `scale_m × height`.
    BumpMap {
        material: Box<Material>,
        height: FloatTexture,
        scale_m: f32,
    },
}

impl Material {
    /// The reflectance of a plain `lambert` with a constant (untextured) reflectance; `None`
    /// for every other material (wrappers included). What the packet tracer and the
    /// radiosity solution can hold.
    pub fn constant_lambert(&self) -> Option<&Spectrum> {
        match self {
            Material::Surface(SurfaceMaterial::Lambert { reflectance }) => reflectance.constant(),
            Material::Surface(
                SurfaceMaterial::Conductor { .. }
                | SurfaceMaterial::Dielectric { .. }
                | SurfaceMaterial::ThinDielectric { .. }
                | SurfaceMaterial::Mix { .. }
                | SurfaceMaterial::Library(_)
                | SurfaceMaterial::Fluorescent(_),
            )
            | Material::TwoSided { .. }
            | Material::Mask { .. }
            | Material::NormalMap { .. }
            | Material::BumpMap { .. } => None,
        }
    }

    /// The default material of shapes without one: lambert, reflectance 0.5.
    pub fn default_material() -> Self {
        Material::Surface(SurfaceMaterial::Lambert {
            reflectance: TexturedSpectrum::Constant(Spectrum::constant(0.5)),
        })
    }

    /// `bsdf` of material number `id`, with a constant Lambertian reflectance from the
    /// path's `cache` (keyed by material id; `crate::spectrum_cache`): the same spectrum,
    /// evaluated once per path instead of at every hit.
    #[inline]
    pub fn bsdf_cached(
        &self,
        id: u32,
        hit: &SurfaceInteraction,
        wavelengths: &impl crate::spectrum_cache::TransportWavelengths,
        cache: &mut crate::spectrum_cache::SpectrumCache,
    ) -> Bsdf<'_> {
        if let Material::Surface(SurfaceMaterial::Lambert { reflectance }) = self {
            if let Some(constant) = reflectance.constant() {
                return Bsdf::new(BsdfLobe::Lambert(Lambert {
                    reflectance: cache.get(id, constant, wavelengths),
                }));
            }
        }
        self.bsdf(hit, wavelengths.transport())
    }

    /// The BSDF at `hit` for `wavelengths` (textures read the hit's uv and differentials).
    /// Wrappers recurse into their (strictly smaller) inner material, so the recursion
    /// ends at a surface, which builds the lobe (`SurfaceMaterial::lobe`, inline).
    #[inline]
    pub fn bsdf(&self, hit: &SurfaceInteraction, wavelengths: &SampledWavelengths) -> Bsdf<'_> {
        match self {
            Material::Surface(surface) => Bsdf::new(surface.lobe(hit, wavelengths)),
            Material::TwoSided { material } => {
                let mut b = material.bsdf(hit, wavelengths);
                b.two_sided = b.lobe.is_reflection_only();
                b
            }
            Material::Mask { material, .. }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.bsdf(hit, wavelengths),
        }
    }

    /// Opacity at `hit`: `opacity()` with opacity textures evaluated.
    #[inline]
    pub fn opacity_at(&self, hit: &SurfaceInteraction) -> f32 {
        match self {
            Material::Mask {
                material,
                opacity,
                opacity_texture,
            } => {
                let t = opacity_texture.as_ref().map_or(1.0, |t| t.eval(hit));
                opacity * t * material.opacity_at(hit)
            }
            Material::TwoSided { material }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.opacity_at(hit),
            Material::Surface(_) => 1.0,
        }
    }

    /// True when some hit may be less than fully opaque (a constant opacity < 1 or an
    /// opacity texture).
    pub fn has_mask(&self) -> bool {
        match self {
            Material::Mask {
                material,
                opacity,
                opacity_texture,
            } => *opacity < 1.0 || opacity_texture.is_some() || material.has_mask(),
            Material::TwoSided { material }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.has_mask(),
            Material::Surface(_) => false,
        }
    }

    /// True when a normal or bump map changes the shading normal (`apply_shading_maps`).
    pub fn has_shading_maps(&self) -> bool {
        match self {
            Material::NormalMap { .. } | Material::BumpMap { .. } => true,
            Material::TwoSided { material } | Material::Mask { material, .. } => {
                material.has_shading_maps()
            }
            Material::Surface(_) => false,
        }
    }

    /// The textures this material's shading varies with across a surface — reflectance,
    /// roughness, opacity, normal and bump maps — for the predictor's texture term t.
    pub fn shading_textures(&self) -> Vec<Arc<Texture>> {
        let mut out = Vec::new();
        self.push_shading_textures(&mut out);
        out
    }

    fn push_shading_textures(&self, out: &mut Vec<Arc<Texture>>) {
        match self {
            Material::Surface(surface) => surface.push_shading_textures(out),
            Material::TwoSided { material } => material.push_shading_textures(out),
            Material::Mask {
                material,
                opacity_texture,
                ..
            } => {
                out.extend(opacity_texture.iter().map(|t| t.texture.clone()));
                material.push_shading_textures(out);
            }
            Material::NormalMap { material, texture } => {
                out.push(texture.clone());
                material.push_shading_textures(out);
            }
            Material::BumpMap {
                material, height, ..
            } => {
                out.push(height.texture.clone());
                material.push_shading_textures(out);
            }
        }
    }

    /// True when any parameter is a texture (lookups want ray differentials).
    pub fn has_textures(&self) -> bool {
        match self {
            Material::Surface(surface) => surface.has_textures(),
            Material::TwoSided { material } => material.has_textures(),
            Material::Mask {
                material,
                opacity_texture,
                ..
            } => opacity_texture.is_some() || material.has_textures(),
            Material::NormalMap { .. } | Material::BumpMap { .. } => true,
        }
    }

    /// Replaces `hit`'s shading normal by the normal/bump maps of this material (outer
    /// wrapper first). Call before building the shading frame.
    #[inline]
    pub fn apply_shading_maps(&self, hit: &mut SurfaceInteraction) {
        match self {
            Material::NormalMap { material, texture } => {
                apply_normal_map(texture, hit);
                material.apply_shading_maps(hit);
            }
            Material::BumpMap {
                material,
                height,
                scale_m,
            } => {
                apply_bump_map(height, *scale_m, hit);
                material.apply_shading_maps(hit);
            }
            Material::TwoSided { material } | Material::Mask { material, .. } => {
                material.apply_shading_maps(hit)
            }
            Material::Surface(_) => {}
        }
    }

    /// Probability that a ray hitting this surface interacts with it (an opacity mask's
    /// α, the product of nested masks' α); otherwise it passes straight through. 1 for
    /// every unmasked material.
    #[inline]
    pub fn opacity(&self) -> f32 {
        match self {
            Material::Mask {
                material, opacity, ..
            } => opacity * material.opacity(),
            Material::TwoSided { material }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.opacity(),
            Material::Surface(_) => 1.0,
        }
    }

    /// The re-radiating surface under the wrappers, if this is a `fluorescent` material
    /// (mixes of one are refused when the scene is built).
    #[inline]
    pub fn fluorescent(&self) -> Option<&FluorescentSurface> {
        match self {
            Material::Surface(SurfaceMaterial::Fluorescent(f)) => Some(f),
            Material::Surface(
                SurfaceMaterial::Lambert { .. }
                | SurfaceMaterial::Conductor { .. }
                | SurfaceMaterial::Dielectric { .. }
                | SurfaceMaterial::ThinDielectric { .. }
                | SurfaceMaterial::Mix { .. }
                | SurfaceMaterial::Library(_),
            ) => None,
            Material::TwoSided { material }
            | Material::Mask { material, .. }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.fluorescent(),
        }
    }

    /// True when the material's BSDF depends on wavelength through its index of refraction
    /// (dispersion): the integrator keeps only the hero wavelength after such a hit.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        match self {
            Material::Surface(surface) => surface.is_dispersive(),
            Material::TwoSided { material }
            | Material::Mask { material, .. }
            | Material::NormalMap { material, .. }
            | Material::BumpMap { material, .. } => material.is_dispersive(),
        }
    }
}

fn distribution(r: &Roughness, d: Microfacet) -> Result<MicrofacetDistribution, String> {
    // `contains` is false for NaN.
    if !((0.0..=1.0).contains(&r.alpha_u) && (0.0..=1.0).contains(&r.alpha_v)) {
        return Err(format!(
            "roughness α must be finite and in [0, 1], got [{}, {}]",
            r.alpha_u, r.alpha_v
        ));
    }
    let model = match d {
        Microfacet::Ggx => MicrofacetModel::Ggx,
        Microfacet::Beckmann => MicrofacetModel::Beckmann,
    };
    Ok(MicrofacetDistribution::new(
        model,
        r.alpha_u as f32,
        r.alpha_v as f32,
    ))
}

/// Checks a conductor's η (> 0) or k (≥ 0) over the whole rendered range, every 1 nm.
fn check_optical_constant(s: &Spectrum, what: &str, positive: bool) -> Result<(), String> {
    let (lo, hi) = (LAMBDA_MIN_NM as u32, LAMBDA_MAX_NM as u32);
    for wl in lo..=hi {
        let v = s.eval_nm(f64::from(wl));
        let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
        if !ok {
            let need = if positive { "> 0" } else { "≥ 0" };
            return Err(format!(
                "{what} is {v} at {wl} nm; it must be {need} over {lo}–{hi} nm (a table that \
                 stops short of that range is 0 outside it: extend it to cover {lo}–{hi} nm)"
            ));
        }
    }
    Ok(())
}

fn build_one(
    scene: &SceneDescription,
    index: usize,
    depth: usize,
    textures: &mut TextureSet,
) -> Result<Material, SceneBuildError> {
    let file: &Path = &scene.file;
    let m = &scene.materials[index];
    let place = format!("materials.{}", m.name);
    let err = |field: &str, message: String| {
        let place = if field.is_empty() {
            place.clone()
        } else {
            format!("{place}.{field}")
        };
        SceneBuildError::new(file, place, message)
    };
    if depth > MAX_WRAPPER_DEPTH {
        return Err(err(
            "material",
            format!("wrappers nested deeper than {MAX_WRAPPER_DEPTH} levels"),
        ));
    }
    Ok(match &m.kind {
        MaterialKind::Lambert { reflectance } => Material::Surface(SurfaceMaterial::Lambert {
            reflectance: match reflectance {
                SpectrumParam::Spectrum(r) => TexturedSpectrum::Constant(
                    build_spectrum(r, SpectrumRole::Albedo).map_err(|e| err("reflectance", e))?,
                ),
                SpectrumParam::Texture(t) => TexturedSpectrum::Texture {
                    texture: textures.get(
                        *t,
                        TexturePurpose::Albedo,
                        &format!("{place}.reflectance"),
                    )?,
                    rgb: RgbUse::Albedo,
                },
            },
        }),
        MaterialKind::Conductor {
            optics,
            roughness,
            distribution: d,
            roughness_texture,
        } => {
            let distribution = distribution(roughness, *d).map_err(|e| err("roughness", e))?;
            let (eta, k) = match optics {
                ConductorOptics::Named(symbol) => metal_optics(symbol)
                    .ok_or_else(|| {
                        err(
                            "metal",
                            format!("no optical constants are shipped for metal `{symbol}`"),
                        )
                    })?
                    .spectra(),
                ConductorOptics::Spectra { eta, k } => {
                    let build = |s: &SpectrumRef, field: &str, positive: bool| {
                        let spectrum = build_spectrum(s, SpectrumRole::Unbounded)
                            .map_err(|e| err(field, e))?;
                        check_optical_constant(&spectrum, field, positive)
                            .map_err(|e| err(field, e))?;
                        Ok::<_, SceneBuildError>(spectrum)
                    };
                    (build(eta, "eta", true)?, build(k, "k", false)?)
                }
            };
            Material::Surface(SurfaceMaterial::Conductor {
                eta,
                k,
                distribution,
                roughness_texture: roughness_texture
                    .map(|t| scalar_texture(textures, t, 0.0, 1.0, &place, "roughness"))
                    .transpose()?,
            })
        }
        MaterialKind::Dielectric {
            ior,
            roughness,
            distribution: d,
            roughness_texture,
        } => Material::Surface(SurfaceMaterial::Dielectric {
            ior: Ior::from_scene(ior).map_err(|e| err("ior", e))?,
            distribution: distribution(roughness, *d).map_err(|e| err("roughness", e))?,
            roughness_texture: roughness_texture
                .map(|t| scalar_texture(textures, t, 0.0, 1.0, &place, "roughness"))
                .transpose()?,
        }),
        // Scatters nothing: a mask of coverage 0 is exactly that for every estimator (paths
        // pass it as a null event, not a bounce; shadow rays cross it), and the medium
        // transport reads the interface from `MediaScene::is_interface`.
        MaterialKind::Interface => Material::Mask {
            material: Box::new(Material::default_material()),
            opacity: 0.0,
            opacity_texture: None,
        },
        // Never shaded: hits on a tiled carrier report the tile's faces with their own
        // materials (prism-geometry `Shape::Tiled`). The default stands in, so that no
        // wrapper's flag (masks in shadow rays) is raised for it.
        MaterialKind::Tiled { .. } => Material::default_material(),
        MaterialKind::ThinDielectric { ior } => {
            Material::Surface(SurfaceMaterial::ThinDielectric {
                ior: Ior::from_scene(ior).map_err(|e| err("ior", e))?,
            })
        }
        MaterialKind::Library(kind) => Material::Surface(SurfaceMaterial::Library(
            LibraryMaterial::build(kind).map_err(|(f, e)| err(f, e))?,
        )),
        MaterialKind::Fluorescent {
            reradiation,
            reflectance,
        } => Material::Surface(SurfaceMaterial::Fluorescent(Arc::new(
            FluorescentSurface::build(scene, *reradiation, reflectance.as_ref())
                .map_err(|(f, e)| err(f, e))?,
        ))),
        MaterialKind::Mix { materials, weight } => {
            let mut build = |k: usize| match build_one(scene, materials[k], depth + 1, textures)? {
                Material::Surface(SurfaceMaterial::Fluorescent(_)) => Err(err(
                    "materials",
                    format!(
                        "`{}` is fluorescent: a mix of a fluorescent material is not supported \
                         yet (a mix blends lobes at one wavelength per lane)",
                        scene.materials[materials[k]].name
                    ),
                )),
                Material::Surface(surface) => Ok(surface),
                Material::TwoSided { .. }
                | Material::Mask { .. }
                | Material::NormalMap { .. }
                | Material::BumpMap { .. } => Err(err(
                    "materials",
                    format!(
                        "`{}` is a two_sided, mask, normal_map or bump_map wrapper; a mix \
                         blends BSDFs, so wrap the mix instead",
                        scene.materials[materials[k]].name
                    ),
                )),
            };
            let mix = SurfaceMaterial::Mix {
                materials: Box::new([build(0)?, build(1)?]),
                weight: MixWeight::Constant(*weight as f32),
            };
            if mix.leaf_count() > crate::bsdf::MIX_MAX_COMPONENTS {
                return Err(err(
                    "materials",
                    format!(
                        "nested mixes blend {} materials; at most {} are supported",
                        mix.leaf_count(),
                        crate::bsdf::MIX_MAX_COMPONENTS
                    ),
                ));
            }
            Material::Surface(mix)
        }
        MaterialKind::TwoSided { material } => Material::TwoSided {
            material: Box::new(build_one(scene, *material, depth + 1, textures)?),
        },
        MaterialKind::NormalMap { material, texture } => Material::NormalMap {
            texture: textures.get(
                *texture,
                TexturePurpose::NormalMap,
                &format!("{place}.texture"),
            )?,
            material: Box::new(build_one(scene, *material, depth + 1, textures)?),
        },
        MaterialKind::BumpMap {
            material,
            texture,
            scale_m,
        } => Material::BumpMap {
            height: scalar_texture(
                textures,
                *texture,
                f64::NEG_INFINITY,
                f64::INFINITY,
                &place,
                "texture",
            )?,
            scale_m: *scale_m as f32,
            material: Box::new(build_one(scene, *material, depth + 1, textures)?),
        },
        MaterialKind::Mask {
            material,
            opacity,
            opacity_texture,
        } => {
            if !(opacity.is_finite() && (0.0..=1.0).contains(opacity)) {
                return Err(err(
                    "opacity",
                    format!("opacity must be in [0, 1], got {opacity}"),
                ));
            }
            Material::Mask {
                material: Box::new(build_one(scene, *material, depth + 1, textures)?),
                opacity: *opacity as f32,
                opacity_texture: opacity_texture
                    .map(|t| scalar_texture(textures, t, 0.0, 1.0, &place, "opacity"))
                    .transpose()?,
            }
        }
    })
}

/// A scalar texture whose values must lie in [lo, hi], used by `place.field`.
fn scalar_texture(
    textures: &mut TextureSet,
    index: usize,
    lo: f64,
    hi: f64,
    place: &str,
    field: &str,
) -> Result<FloatTexture, SceneBuildError> {
    Ok(FloatTexture {
        texture: textures.get(
            index,
            TexturePurpose::scalar(lo, hi),
            &format!("{place}.{field}"),
        )?,
    })
}

/// Every scene material, then the default one.
pub fn build_materials(scene: &SceneDescription) -> Result<Vec<Material>, SceneBuildError> {
    let mut out = Vec::with_capacity(scene.materials.len() + 1);
    let mut textures = build_textures(scene);
    for i in 0..scene.materials.len() {
        out.push(build_one(scene, i, 0, &mut textures)?);
    }
    out.push(Material::default_material());
    Ok(out)
}

#[cfg(test)]
mod tests;
