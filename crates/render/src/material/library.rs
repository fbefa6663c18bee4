//! Building the material library of issue 8 (Oren–Nayar, Phong, Blinn–Phong, Ward,
//! Lafortune, coated, thin dielectric, measured MERL, mix) from scene descriptions, and the
//! longer parts of turning them into lobes at a hit (a mix's flattened leaves, a Lafortune
//! lobe's rows; `Material::lobe` builds the rest). Formulas and references: the `bsdf`
//! files and docs/materials.md.

use std::sync::Arc;

use prism_geometry::SurfaceInteraction;
use prism_scene::MaterialKind;
use prism_spectrum::constants::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::{Ior, Material};
use crate::bsdf::{
    internal_diffuse_reflectance, BsdfLobe, Lafortune, LafortuneLobe, Lambert, LeafLobe, MerlBrdf,
    MerlTable, Mix, OrenNayarForm, LAFORTUNE_MAX_LOBES, MIX_MAX_COMPONENTS,
};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};

/// An error at a field of the material: (field, message).
pub type FieldError = (&'static str, String);

/// Checks diffuse + specular ≤ 1 at every nm of 360–830 (energy conservation of the
/// normalised Phong, Blinn–Phong and Ward lobes).
fn check_energy(diffuse: &Spectrum, specular: &Spectrum, model: &str) -> Result<(), FieldError> {
    let (lo, hi) = (LAMBDA_MIN_NM as u32, LAMBDA_MAX_NM as u32);
    for wl in lo..=hi {
        let sum = diffuse.eval_nm(f64::from(wl)) + specular.eval_nm(f64::from(wl));
        if sum > 1.0 + 1e-6 {
            return Err((
                "specular",
                format!(
                    "diffuse + specular is {sum:.4} at {wl} nm; {model} conserves energy only \
                     when it is ≤ 1 at every wavelength"
                ),
            ));
        }
    }
    Ok(())
}

fn albedo(r: &prism_scene::SpectrumRef, field: &'static str) -> Result<Spectrum, FieldError> {
    build_spectrum(r, SpectrumRole::Albedo).map_err(|e| (field, e))
}

/// The runtime material of a library `kind` (not `mix`, which needs the other materials).
pub fn build_library(kind: &MaterialKind) -> Result<Material, FieldError> {
    Ok(match kind {
        MaterialKind::OrenNayar {
            reflectance,
            sigma_deg,
            qualitative,
        } => Material::OrenNayar {
            reflectance: albedo(reflectance, "reflectance")?,
            sigma_rad: sigma_deg.to_radians() as f32,
            form: if *qualitative {
                OrenNayarForm::Qualitative
            } else {
                OrenNayarForm::Full
            },
        },
        MaterialKind::Phong {
            diffuse,
            specular,
            exponent,
        }
        | MaterialKind::BlinnPhong {
            diffuse,
            specular,
            exponent,
        } => {
            let (d, s) = (albedo(diffuse, "diffuse")?, albedo(specular, "specular")?);
            let phong = matches!(kind, MaterialKind::Phong { .. });
            check_energy(&d, &s, if phong { "phong" } else { "blinn_phong" })?;
            if phong {
                Material::Phong {
                    diffuse: d,
                    specular: s,
                    exponent: *exponent as f32,
                }
            } else {
                Material::BlinnPhong {
                    diffuse: d,
                    specular: s,
                    exponent: *exponent as f32,
                }
            }
        }
        MaterialKind::Ward {
            diffuse,
            specular,
            alpha_u,
            alpha_v,
        } => {
            let (d, s) = (albedo(diffuse, "diffuse")?, albedo(specular, "specular")?);
            check_energy(&d, &s, "ward")?;
            Material::Ward {
                diffuse: d,
                specular: s,
                alpha_x: *alpha_u as f32,
                alpha_y: *alpha_v as f32,
            }
        }
        MaterialKind::Lafortune { diffuse, lobes } => {
            if lobes.len() > LAFORTUNE_MAX_LOBES {
                return Err((
                    "lobes",
                    format!("at most {LAFORTUNE_MAX_LOBES} lobes, found {}", lobes.len()),
                ));
            }
            let mut out = Vec::with_capacity(lobes.len());
            for l in lobes {
                let a =
                    build_spectrum(&l.albedo, SpectrumRole::Unbounded).map_err(|e| ("lobes", e))?;
                out.push((
                    [l.cx as f32, l.cy as f32, l.cz as f32, l.exponent as f32],
                    a,
                ));
            }
            Material::Lafortune {
                diffuse: albedo(diffuse, "diffuse")?,
                lobes: out,
            }
        }
        MaterialKind::Coated {
            diffuse,
            ior,
            nonlinear,
        } => Material::Coated {
            diffuse: albedo(diffuse, "diffuse")?,
            eta: *ior as f32,
            fdr_internal: internal_diffuse_reflectance(*ior as f32),
            nonlinear: *nonlinear,
        },
        MaterialKind::ThinDielectric { ior } => Material::ThinDielectric {
            ior: Ior::from_scene(ior).map_err(|e| ("ior", e))?,
        },
        MaterialKind::Merl {
            file,
            clamp_negative,
        } => {
            let table =
                MerlTable::read(file, *clamp_negative).map_err(|e| ("file", e.to_string()))?;
            Material::Measured {
                brdf: Arc::new(MerlBrdf::new(&table)),
            }
        }
        MaterialKind::Lambert { .. }
        | MaterialKind::Conductor { .. }
        | MaterialKind::Dielectric { .. }
        | MaterialKind::TwoSided { .. }
        | MaterialKind::Mix { .. }
        | MaterialKind::NormalMap { .. }
        | MaterialKind::BumpMap { .. }
        | MaterialKind::Mask { .. } => {
            return Err(("type", format!("not a material-library type: {kind:?}")))
        }
    })
}

impl Material {
    /// Non-mix materials a mix flattens into (1 for anything else).
    pub fn leaf_count(&self) -> usize {
        match self {
            Material::Mix { materials, .. } => materials.iter().map(Material::leaf_count).sum(),
            Material::Lambert { .. }
            | Material::Conductor { .. }
            | Material::Dielectric { .. }
            | Material::TwoSided { .. }
            | Material::Mask { .. }
            | Material::NormalMap { .. }
            | Material::BumpMap { .. }
            | Material::OrenNayar { .. }
            | Material::Phong { .. }
            | Material::BlinnPhong { .. }
            | Material::Ward { .. }
            | Material::Lafortune { .. }
            | Material::Coated { .. }
            | Material::ThinDielectric { .. }
            | Material::Measured { .. } => 1,
        }
    }

    /// Appends this material's leaves, each with `weight` times its share.
    fn push_leaves<'a>(
        &'a self,
        hit: &SurfaceInteraction,
        wavelengths: &SampledWavelengths,
        weight: f32,
        out: &mut [(LeafLobe<'a>, f32); MIX_MAX_COMPONENTS],
        count: &mut usize,
    ) {
        if let Material::Mix {
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
            if let Some(c) = LeafLobe::from_lobe(self.bsdf(hit, wavelengths).lobe) {
                out[*count] = (c, weight);
                *count += 1;
            }
        }
    }

    /// The flattened blend of a mix's leaves (`lobe` of `Material::Mix`).
    pub(super) fn mix_lobe(
        &self,
        hit: &SurfaceInteraction,
        wavelengths: &SampledWavelengths,
    ) -> BsdfLobe<'_> {
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

/// The Lafortune lobe of `(C_x, C_y, C_z, n)` and albedo rows at `wavelengths` (at most
/// `LAFORTUNE_MAX_LOBES`; the builder refuses more).
pub(super) fn lafortune_lobe(
    diffuse: &Spectrum,
    lobes: &[([f32; 4], Spectrum)],
    wavelengths: &SampledWavelengths,
) -> Lafortune {
    let mut l = Lafortune {
        diffuse: diffuse.eval(wavelengths),
        lobes: [LafortuneLobe::NONE; LAFORTUNE_MAX_LOBES],
        count: lobes.len().min(LAFORTUNE_MAX_LOBES),
    };
    for (slot, (c, a)) in l.lobes.iter_mut().zip(lobes) {
        *slot = LafortuneLobe {
            cx: c[0],
            cy: c[1],
            cz: c[2],
            exponent: c[3],
            albedo: a.eval(wavelengths),
        };
    }
    l
}
