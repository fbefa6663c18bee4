//! Runtime materials: a scene material (prism-scene `MaterialKind`) with its spectra built,
//! turned into a `Bsdf` at each hit for the path's wavelengths (`Material::bsdf`).
//!
//! `build_materials` returns one entry per scene material plus, last, the default material
//! (lambert 0.5) that shapes without a material use — matching the `material_id`s that
//! `build_geometry` gives the instances.

use std::path::Path;

use prism_geometry::SurfaceInteraction;
use prism_scene::{MaterialKind, SceneDescription};
use prism_spectrum::{SampledWavelengths, Spectrum};

use crate::bsdf::{Bsdf, BsdfLobe, Lambert};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};
use crate::scene_build::SceneBuildError;

/// A material ready to make BSDFs.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    Lambert { reflectance: Spectrum },
}

impl Material {
    /// The default material of shapes without one: lambert, reflectance 0.5.
    pub fn default_material() -> Self {
        Material::Lambert {
            reflectance: Spectrum::constant(0.5),
        }
    }

    /// The BSDF at `hit` for `wavelengths`.
    #[inline]
    pub fn bsdf(&self, _hit: &SurfaceInteraction, wavelengths: &SampledWavelengths) -> Bsdf {
        match self {
            Material::Lambert { reflectance } => Bsdf::new(BsdfLobe::Lambert(Lambert {
                reflectance: reflectance.eval(wavelengths),
            })),
        }
    }

    /// Probability that a ray hitting this surface interacts with it (an opacity mask's
    /// α); otherwise it passes straight through. 1 for every unmasked material.
    #[inline]
    pub fn opacity(&self) -> f32 {
        1.0
    }

    /// True when the material's BSDF depends on wavelength through its index of refraction
    /// (dispersion): the integrator keeps only the hero wavelength after such a hit.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        false
    }
}

/// Every scene material, then the default one.
pub fn build_materials(scene: &SceneDescription) -> Result<Vec<Material>, SceneBuildError> {
    let file: &Path = &scene.file;
    let mut out = Vec::with_capacity(scene.materials.len() + 1);
    for (i, m) in scene.materials.iter().enumerate() {
        let place = format!("materials.{}", m.name);
        let material = match &m.kind {
            MaterialKind::Lambert { reflectance } => Material::Lambert {
                reflectance: build_spectrum(reflectance, SpectrumRole::Albedo)
                    .map_err(|e| SceneBuildError::new(file, format!("{place}.reflectance"), e))?,
            },
            // Interface skeleton: the BSDF work replaces this fallback.
            _ => {
                let _ = i;
                Material::default_material()
            }
        };
        out.push(material);
    }
    out.push(Material::default_material());
    Ok(out)
}
