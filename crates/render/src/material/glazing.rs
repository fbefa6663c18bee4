//! Thin glazing: a `thin_dielectric` sheet (window pane) seen as a *null* event for its
//! straight-through part. The sheet's transmitted light leaves along the incident
//! direction, so a shadow ray may cross it with weight T' = (1 − R)/(1 + R) per lane
//! (`PathTracer::transmittance`), and a path that samples the straight-through lobe keeps
//! the MIS state of the vertex before the pane (`PathTracer::trace`). Without this, light
//! sampling stops at every pane: a point light or the sun behind glass would reach nothing
//! directly (only BSDF-sampled paths, never for Dirac lights). The reflection remains an
//! ordinary specular bounce. Both strategies then estimate the same integral, so the MIS
//! weights stay a partition of unity (Veach 1997, §9.2).

use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::{Material, SurfaceMaterial};
use crate::bsdf::ThinDielectric;

impl Material {
    /// The pane when this material is a thin dielectric sheet (also under `two_sided` or
    /// `mask`, whose opacity is applied before): light passes it straight.
    #[inline]
    pub fn thin_glazing(&self, wavelengths: &SampledWavelengths) -> Option<ThinDielectric> {
        match self {
            Material::Surface(surface) => surface.thin_glazing(wavelengths),
            Material::TwoSided { material } | Material::Mask { material, .. } => {
                material.thin_glazing(wavelengths)
            }
            Material::NormalMap { .. } | Material::BumpMap { .. } => None,
        }
    }

    /// True when some hit may be a thin glazing pane (see `thin_glazing`).
    pub fn has_thin_glazing(&self) -> bool {
        match self {
            Material::Surface(surface) => surface.is_thin_glazing(),
            Material::TwoSided { material } | Material::Mask { material, .. } => {
                material.has_thin_glazing()
            }
            Material::NormalMap { .. } | Material::BumpMap { .. } => false,
        }
    }
}

impl SurfaceMaterial {
    /// The pane when this surface is a thin dielectric sheet (a sheet inside a mix is an
    /// ordinary lobe: the mix may scatter where the pane would pass).
    #[inline]
    pub fn thin_glazing(&self, wavelengths: &SampledWavelengths) -> Option<ThinDielectric> {
        match self {
            SurfaceMaterial::ThinDielectric { ior } => Some(ThinDielectric {
                eta: ior.eval(wavelengths),
            }),
            SurfaceMaterial::Lambert { .. }
            | SurfaceMaterial::Conductor { .. }
            | SurfaceMaterial::Dielectric { .. }
            | SurfaceMaterial::Mix { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => None,
        }
    }

    /// True when this surface is a thin glazing pane (see `thin_glazing`).
    pub fn is_thin_glazing(&self) -> bool {
        match self {
            SurfaceMaterial::ThinDielectric { .. } => true,
            SurfaceMaterial::Lambert { .. }
            | SurfaceMaterial::Conductor { .. }
            | SurfaceMaterial::Dielectric { .. }
            | SurfaceMaterial::Mix { .. }
            | SurfaceMaterial::Library(_)
            | SurfaceMaterial::Fluorescent(_) => false,
        }
    }
}

impl ThinDielectric {
    /// Straight-through transmittance T' = 1 − R' per lane for a direction with this
    /// |cos θ| (to the shading normal, as the BSDF's lobe choice uses).
    #[inline]
    pub fn transmittance(&self, cos_theta: f32) -> SampledSpectrum {
        SampledSpectrum::splat(1.0) - self.reflectance(cos_theta)
    }
}
