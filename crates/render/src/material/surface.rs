//! The surfaces: what a `Material` scatters with once its wrappers (two-sided, mask,
//! normal and bump maps) are peeled off. The kinds here each have a property the renderer
//! asks about — lambert's textured reflectance and constant-reflectance fast paths, the
//! textured roughness and dispersive index of conductors and dielectrics, the thin sheet's
//! glazing, the mix's parts — so every query below lists them; the material library
//! (`LibraryMaterial`, constant parameters only) answers every query the same way and is
//! one variant, so a new library BSDF adds no arm here.

use prism_geometry::SurfaceInteraction;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use std::sync::Arc;

use super::fluorescent::FluorescentSurface;
use super::library::LibraryMaterial;
use super::{Ior, MixWeight};
use crate::bsdf::{
    BsdfLobe, Conductor, Dielectric, Lambert, LeafLobe, MicrofacetDistribution, Mix,
    ThinDielectric, MIX_MAX_COMPONENTS,
};
use crate::texture::{FloatTexture, Texture, TexturedSpectrum};

/// A surface ready to make lobes: the closed set of kinds that are not wrappers.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceMaterial {
    Lambert {
        reflectance: TexturedSpectrum,
    },
    /// A metal: complex index η + ik relative to the outside medium; a Dirac mirror when
    /// the distribution is effectively smooth.
    Conductor {
        eta: Spectrum,
        k: Spectrum,
        distribution: MicrofacetDistribution,
        /// Isotropic α from a texture, replacing `distribution`'s α at each hit.
        roughness_texture: Option<FloatTexture>,
    },
    /// Glass-like interface; `ior` is the index of the inside (below the shading normal,
    /// i.e. opposite the geometric normal's side for closed shapes) relative to the
    /// outside.
    Dielectric {
        ior: Ior,
        distribution: MicrofacetDistribution,
        /// As for `Conductor`.
        roughness_texture: Option<FloatTexture>,
    },
    /// Thin dielectric sheet (Mitsuba `thindielectric`); thin glazing (glazing.rs).
    ThinDielectric {
        ior: Ior,
    },
    /// (1 − weight)·first + weight·second: surfaces, so never a wrapper.
    Mix {
        materials: Box<[SurfaceMaterial; 2]>,
        weight: MixWeight,
    },
    /// A material of the library (library.rs): constant parameters, one lobe.
    Library(LibraryMaterial),
    /// Lambertian with re-radiation (fluorescent.rs): its lobe is the reflected part
    /// R(λ)/π; the path tracer adds M through `Material::fluorescent`.
    Fluorescent(Arc<FluorescentSurface>),
}

impl From<SurfaceMaterial> for super::Material {
    fn from(surface: SurfaceMaterial) -> Self {
        super::Material::Surface(surface)
    }
}

impl From<LibraryMaterial> for SurfaceMaterial {
    fn from(library: LibraryMaterial) -> Self {
        SurfaceMaterial::Library(library)
    }
}

impl SurfaceMaterial {
    /// The lobe at `hit` for `wavelengths` (textures read the hit's uv and differentials).
    /// The core lobes are built here, inline (the integrator's hot path); the sheet, a
    /// mix's blend and the library's lobes out of line.
    #[inline]
    pub fn lobe(&self, hit: &SurfaceInteraction, wavelengths: &SampledWavelengths) -> BsdfLobe<'_> {
        match self {
            SurfaceMaterial::Lambert { reflectance } => {
                BsdfLobe::Lambert(lambert_lobe(reflectance, hit, wavelengths))
            }
            SurfaceMaterial::Conductor {
                eta,
                k,
                distribution,
                roughness_texture,
            } => BsdfLobe::Conductor(conductor_lobe(
                eta,
                k,
                distribution,
                roughness_texture,
                hit,
                wavelengths,
            )),
            SurfaceMaterial::Dielectric {
                ior,
                distribution,
                roughness_texture,
            } => BsdfLobe::Dielectric(dielectric_lobe(
                ior,
                distribution,
                roughness_texture,
                hit,
                wavelengths,
            )),
            SurfaceMaterial::ThinDielectric { .. }
            | SurfaceMaterial::Mix { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => self.other_lobe(hit, wavelengths),
        }
    }

    /// `lobe` of the kinds it does not build inline. Every recursion is into a strictly
    /// smaller material (a mix's parts), so it ends.
    fn other_lobe(
        &self,
        hit: &SurfaceInteraction,
        wavelengths: &SampledWavelengths,
    ) -> BsdfLobe<'_> {
        match self {
            SurfaceMaterial::ThinDielectric { ior } => BsdfLobe::ThinDielectric(ThinDielectric {
                eta: ior.eval(wavelengths),
            }),
            SurfaceMaterial::Mix { .. } => self.mix_lobe(hit, wavelengths),
            SurfaceMaterial::Library(library) => library.lobe(wavelengths),
            SurfaceMaterial::Fluorescent(f) => BsdfLobe::Lambert(Lambert {
                reflectance: f.reflectance.eval(wavelengths),
            }),
            SurfaceMaterial::Lambert { .. }
            | SurfaceMaterial::Conductor { .. }
            | SurfaceMaterial::Dielectric { .. } => self.lobe(hit, wavelengths),
        }
    }

    /// True when the lobe depends on wavelength through its index of refraction
    /// (dispersion): the integrator keeps only the hero wavelength after such a hit.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        match self {
            SurfaceMaterial::Dielectric { ior, .. } => ior.is_dispersive(),
            SurfaceMaterial::Mix { materials, .. } => {
                materials.iter().any(SurfaceMaterial::is_dispersive)
            }
            // The sheet keeps all wavelengths: its straight-through path does not bend.
            SurfaceMaterial::Lambert { .. }
            | SurfaceMaterial::Conductor { .. }
            | SurfaceMaterial::ThinDielectric { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => false,
        }
    }

    /// Appends the textures this surface's parameters read (`Material::shading_textures`).
    pub(super) fn push_shading_textures(&self, out: &mut Vec<Arc<Texture>>) {
        match self {
            SurfaceMaterial::Lambert { reflectance } => match reflectance {
                TexturedSpectrum::Texture { texture, .. } => out.push(texture.clone()),
                TexturedSpectrum::Constant(_) => {}
            },
            SurfaceMaterial::Conductor {
                roughness_texture, ..
            }
            | SurfaceMaterial::Dielectric {
                roughness_texture, ..
            } => out.extend(roughness_texture.iter().map(|t| t.texture.clone())),
            SurfaceMaterial::Mix { materials, .. } => {
                materials.iter().for_each(|m| m.push_shading_textures(out))
            }
            SurfaceMaterial::ThinDielectric { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => {}
        }
    }

    /// True when any parameter is a texture (lookups want ray differentials).
    pub fn has_textures(&self) -> bool {
        match self {
            SurfaceMaterial::Lambert { reflectance } => reflectance.constant().is_none(),
            SurfaceMaterial::Conductor {
                roughness_texture, ..
            }
            | SurfaceMaterial::Dielectric {
                roughness_texture, ..
            } => roughness_texture.is_some(),
            SurfaceMaterial::Mix { materials, .. } => {
                materials.iter().any(SurfaceMaterial::has_textures)
            }
            SurfaceMaterial::ThinDielectric { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => false,
        }
    }

    /// Non-mix surfaces a mix flattens into (1 for anything else).
    pub fn leaf_count(&self) -> usize {
        match self {
            SurfaceMaterial::Mix { materials, .. } => {
                materials.iter().map(SurfaceMaterial::leaf_count).sum()
            }
            SurfaceMaterial::Lambert { .. }
            | SurfaceMaterial::Conductor { .. }
            | SurfaceMaterial::Dielectric { .. }
            | SurfaceMaterial::ThinDielectric { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => 1,
        }
    }

    /// Appends this surface's leaves, each with `weight` times its share.
    fn push_leaves<'a>(
        &'a self,
        hit: &SurfaceInteraction,
        wavelengths: &SampledWavelengths,
        weight: f32,
        out: &mut [(LeafLobe<'a>, f32); MIX_MAX_COMPONENTS],
        count: &mut usize,
    ) {
        if let SurfaceMaterial::Mix {
            materials,
            weight: w,
        } = self
        {
            let w = w.eval(hit).clamp(0.0, 1.0);
            materials[0].push_leaves(hit, wavelengths, weight * (1.0 - w), out, count);
            materials[1].push_leaves(hit, wavelengths, weight * w, out, count);
            return;
        }
        if *count < MIX_MAX_COMPONENTS {
            if let Some(c) = LeafLobe::from_lobe(self.lobe(hit, wavelengths)) {
                out[*count] = (c, weight);
                *count += 1;
            }
        }
    }

    /// The flattened blend of a mix's leaves (`lobe` of `SurfaceMaterial::Mix`).
    fn mix_lobe(&self, hit: &SurfaceInteraction, wavelengths: &SampledWavelengths) -> BsdfLobe<'_> {
        let filler = (
            LeafLobe::Lambert(Lambert {
                reflectance: SampledSpectrum::zero(),
            }),
            0.0,
        );
        let mut parts = [filler; MIX_MAX_COMPONENTS];
        let mut count = 0;
        self.push_leaves(hit, wavelengths, 1.0, &mut parts, &mut count);
        match Mix::new(&parts[..count]) {
            Some(m) => BsdfLobe::Mix(m),
            // All weights zero cannot happen (they sum to 1); a black lobe if it did.
            None => BsdfLobe::Lambert(Lambert {
                reflectance: SampledSpectrum::zero(),
            }),
        }
    }
}

/// The core lobes at a hit; always inlined, so `SurfaceMaterial::lobe` builds them in place
/// (a call here cost 0.03% of the glossy-env render's instructions).
#[inline(always)]
fn lambert_lobe(
    reflectance: &TexturedSpectrum,
    hit: &SurfaceInteraction,
    wavelengths: &SampledWavelengths,
) -> Lambert {
    Lambert {
        reflectance: reflectance.eval(hit, wavelengths),
    }
}

#[inline(always)]
fn conductor_lobe(
    eta: &Spectrum,
    k: &Spectrum,
    distribution: &MicrofacetDistribution,
    roughness_texture: &Option<FloatTexture>,
    hit: &SurfaceInteraction,
    wavelengths: &SampledWavelengths,
) -> Conductor {
    Conductor {
        eta: eta.eval(wavelengths),
        k: k.eval(wavelengths),
        distribution: textured_distribution(distribution, roughness_texture, hit),
    }
}

#[inline(always)]
fn dielectric_lobe(
    ior: &Ior,
    distribution: &MicrofacetDistribution,
    roughness_texture: &Option<FloatTexture>,
    hit: &SurfaceInteraction,
    wavelengths: &SampledWavelengths,
) -> Dielectric {
    Dielectric {
        eta: ior.eval(wavelengths),
        distribution: textured_distribution(distribution, roughness_texture, hit),
    }
}

/// The distribution at `hit`: the constant one, or one with the texture's isotropic α.
#[inline]
fn textured_distribution(
    constant: &MicrofacetDistribution,
    texture: &Option<FloatTexture>,
    hit: &SurfaceInteraction,
) -> MicrofacetDistribution {
    match texture {
        None => *constant,
        Some(t) => {
            let alpha = t.eval(hit);
            MicrofacetDistribution::new(constant.model, alpha, alpha)
        }
    }
}
