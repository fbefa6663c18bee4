//! The `fluorescent` material: a Lambertian surface that reflects R(λ)/π and re-radiates
//! M(λ_in, λ_out)/π (a Donaldson matrix, prism-spectrum `reradiation.rs`), so the BRDF
//! from excitation λ_in to emission λ_out is (R(λ_out)·δ(λ_in − λ_out) + M(λ_in, λ_out))/π.
//!
//! Wavelength-preserving code (the light tracer, BDPT, the packet tracer, the albedo AOV)
//! sees only R: its lobe is the Lambertian R(λ)/π. The path tracer asks `Material::
//! fluorescent` and chooses per lane between R and M (integrator/fluorescent_vertex.rs);
//! estimators that cannot shift wavelengths refuse such scenes (`RenderScene::
//! reradiating_material`).

use prism_scene::{ReradiationKind, SceneDescription, SpectrumRef};
use prism_spectrum::bfc::NegativesPolicy;
use prism_spectrum::{ReradiationMatrix, Spectrum};

use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};

/// What the path tracer needs at a fluorescent vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct FluorescentSurface {
    /// R(λ): reflected without change of wavelength.
    pub reflectance: Spectrum,
    /// M(λ_in, λ_out) in nm⁻¹ (signed when `negatives` is `keep` and the file had some).
    pub matrix: ReradiationMatrix,
    /// The `reradiation` entry's name (for `--explain`).
    pub reradiation: String,
    /// What happened to negative entries (BFC files; `None` for dyes): `--explain` prints it.
    pub negatives: Option<(NegativesPolicy, String)>,
}

impl FluorescentSurface {
    /// The surface of a `fluorescent` material using entry `reradiation` of the scene, with
    /// the material's own `reflectance` if it gives one; errors are messages for the
    /// material's `SceneBuildError`.
    pub fn build(
        scene: &SceneDescription,
        reradiation: usize,
        reflectance: Option<&SpectrumRef>,
    ) -> Result<Self, (&'static str, String)> {
        let entry = &scene.reradiation[reradiation];
        let (default_reflectance, negatives) = match &entry.kind {
            ReradiationKind::Bfc { data, .. } => (
                Spectrum::from_tabulated(&data.reflectance)
                    .map_err(|e| ("reradiation", e.to_string()))?,
                Some((data.policy, data.negatives.to_string())),
            ),
            ReradiationKind::Dye { dye, .. } => {
                // 1 − a(λ), linear between the 5 nm excitation nodes and 1 outside them:
                // sampled on the 5 nm grid over 300–830 nm, exact.
                let wavelengths: Vec<f64> = (0..=106).map(|k| 300.0 + 5.0 * k as f64).collect();
                let values: Vec<f64> = wavelengths
                    .iter()
                    .map(|&nm| dye.default_reflectance(nm))
                    .collect();
                (
                    Spectrum::piecewise_linear(&wavelengths, &values)
                        .map_err(|e| ("reradiation", e.to_string()))?,
                    None,
                )
            }
        };
        let reflectance = match reflectance {
            Some(r) => build_spectrum(r, SpectrumRole::Albedo).map_err(|e| ("reflectance", e))?,
            None => default_reflectance,
        };
        Ok(Self {
            reflectance,
            matrix: entry.matrix().clone(),
            reradiation: entry.name.clone(),
            negatives,
        })
    }
}
