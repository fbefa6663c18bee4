//! Material albedo for the `albedo` AOV and integrator, as linear Rec.709 RGB.
//!
//! Choice: the albedo is the colour of the material's reflectance spectrum R(λ) seen under
//! CIE D65, the white point of Rec.709: XYZ = Σ R·D65·(x̄, ȳ, z̄) / Σ D65·ȳ (CIE 15:2018
//! eqs. 7.1–7.3, `prism_spectrum::colorimetry::reflectance_to_xyz`, divided by 100), then
//! `RgbColorSpace::srgb().xyz_to_rgb`. A constant reflectance c is exactly (c, c, c) and an
//! `{"rgb": …}` reflectance is its RGB (the upsampled spectrum reproduces it under D65 by
//! construction, Jakob & Hanika 2019), so both skip the integral.
//!
//! Materials without a diffuse reflectance: a dielectric is white (1, 1, 1) (it reflects or
//! transmits all light); a conductor given by η, k spectra has its normal-incidence Fresnel
//! reflectance F₀ = ((η−1)² + k²)/((η+1)² + k²) (Born & Wolf §14.2), and so has a named
//! metal, from the η, k tables render ships (`material::metal_optics`, spectra/metals/);
//! `two_sided` and `mask` take their inner material's albedo, a mix blends its two; the
//! material library's kinds answer in `material::library::albedo_rgb`.

use prism_scene::{ConductorOptics, Material, MaterialKind, SpectrumRef};
use prism_spectrum::colorimetry::reflectance_to_xyz;
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::{DenseSpectrum, Observer};

/// Albedo of shapes without a material: lambert 0.5 (docs/scene-format.md).
pub const DEFAULT_ALBEDO: [f32; 3] = [0.5, 0.5, 0.5];

/// Wrappers deeper than this are cut off (prism-scene rejects cycles; this is a guard).
const MAX_WRAPPER_DEPTH: usize = 16;

/// The spectrum as a dense 1 nm table over 360–830 nm.
fn dense(s: &SpectrumRef) -> DenseSpectrum {
    match s {
        SpectrumRef::Constant(c) => DenseSpectrum::constant(*c),
        SpectrumRef::Blackbody { temperature_k } => DenseSpectrum::from_fn(|wl| {
            prism_spectrum::blackbody::blackbody_normalized(wl, *temperature_k)
        }),
        SpectrumRef::Illuminant { table, .. } | SpectrumRef::File { table, .. } => table.to_dense(),
        SpectrumRef::Rgb { rgb } => {
            // Not reached for albedo (handled exactly below); a grey of the same luminance.
            let y = RgbColorSpace::srgb().rgb_to_xyz * glam::DVec3::from(*rgb);
            DenseSpectrum::constant(y.y)
        }
    }
}

/// Linear Rec.709 RGB of a reflectance spectrum under D65.
pub fn reflectance_rgb(s: &SpectrumRef) -> [f32; 3] {
    match s {
        SpectrumRef::Constant(c) => [*c as f32; 3],
        SpectrumRef::Rgb { rgb } => rgb.map(|v| v as f32),
        other => dense_rgb(&dense(other)),
    }
}

fn dense_rgb(reflectance: &DenseSpectrum) -> [f32; 3] {
    let d65 = prism_spectrum::data::illuminant("D65")
        .map(|t| t.to_dense())
        .unwrap_or_else(|| DenseSpectrum::constant(1.0));
    let xyz = reflectance_to_xyz(reflectance, &d65, Observer::Cie1931) / 100.0;
    let rgb = RgbColorSpace::srgb().xyz_to_rgb * xyz;
    [rgb.x as f32, rgb.y as f32, rgb.z as f32]
}

/// Albedo of `materials[index]`.
pub fn material_albedo(materials: &[Material], index: usize) -> [f32; 3] {
    albedo_at_depth(materials, index, 0)
}

fn albedo_at_depth(materials: &[Material], index: usize, depth: usize) -> [f32; 3] {
    let Some(m) = materials.get(index) else {
        return DEFAULT_ALBEDO;
    };
    if depth > MAX_WRAPPER_DEPTH {
        return DEFAULT_ALBEDO;
    }
    match &m.kind {
        MaterialKind::Lambert {
            reflectance: prism_scene::SpectrumParam::Spectrum(reflectance),
        } => reflectance_rgb(reflectance),
        // The AOV holds one albedo per material; a textured one varies over the surface.
        MaterialKind::Lambert { .. } => DEFAULT_ALBEDO,
        MaterialKind::Dielectric { .. } => [1.0; 3],
        MaterialKind::Conductor { optics, .. } => match optics {
            ConductorOptics::Named(symbol) => match crate::material::metal_optics(symbol) {
                Some(metal) => dense_rgb(&metal.normal_reflectance()),
                None => [1.0; 3],
            },
            ConductorOptics::Spectra { eta, k } => {
                let (eta, k) = (dense(eta), dense(k));
                dense_rgb(&DenseSpectrum::from_fn(|wl| {
                    let (n, k) = (eta.eval(wl), k.eval(wl));
                    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
                }))
            }
        },
        MaterialKind::TwoSided { material }
        | MaterialKind::Mask { material, .. }
        | MaterialKind::NormalMap { material, .. }
        | MaterialKind::BumpMap { material, .. } => {
            albedo_at_depth(materials, *material, depth + 1)
        }
        MaterialKind::ThinDielectric { .. } => [1.0; 3],
        // Reflects nothing.
        MaterialKind::Interface => [0.0; 3],
        // Never hit: the tile's faces report their own materials.
        MaterialKind::Tiled { .. } => [0.0; 3],
        MaterialKind::Library(kind) => crate::material::library::albedo_rgb(kind),
        // The reflected part only (the re-radiated part depends on the light); a BFC's or
        // dye's own R is not at hand here.
        MaterialKind::Fluorescent {
            reflectance: Some(reflectance),
            ..
        } => reflectance_rgb(reflectance),
        MaterialKind::Fluorescent {
            reflectance: None, ..
        } => DEFAULT_ALBEDO,
        MaterialKind::Mix {
            materials: [a, b],
            weight,
        } => {
            let (a, b) = (
                albedo_at_depth(materials, *a, depth + 1),
                albedo_at_depth(materials, *b, depth + 1),
            );
            let w = *weight as f32;
            [0, 1, 2].map(|c| (1.0 - w) * a[c] + w * b[c])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_metals_get_the_colour_of_their_normal_reflectance() {
        let metal = |symbol: &'static str| Material {
            name: symbol.to_string(),
            kind: MaterialKind::Conductor {
                optics: ConductorOptics::Named(symbol),
                roughness: prism_scene::Roughness {
                    alpha_u: 0.0,
                    alpha_v: 0.0,
                },
                distribution: prism_scene::Microfacet::Ggx,
                roughness_texture: None,
            },
        };
        let materials = [metal("Au"), metal("Ag"), metal("Cu")];
        let [au, ag, cu] = [0, 1, 2].map(|i| material_albedo(&materials, i));
        // Gold and copper: red > green > blue; silver: near-white, neutral.
        assert!(au[0] > au[1] && au[1] > au[2] && au[2] < 0.5, "{au:?}");
        assert!(cu[0] > cu[1] && cu[1] > cu[2], "{cu:?}");
        assert!(ag.iter().all(|&c| (0.9..1.05).contains(&c)), "{ag:?}");
    }

    #[test]
    fn constant_and_rgb_reflectances_are_exact_and_a_flat_table_matches_the_constant() {
        assert_eq!(reflectance_rgb(&SpectrumRef::Constant(0.8)), [0.8; 3]);
        assert_eq!(
            reflectance_rgb(&SpectrumRef::Rgb {
                rgb: [0.6, 0.08, 0.06]
            }),
            [0.6, 0.08, 0.06]
        );
        // A flat 0.8 table under D65 is grey 0.8 up to the D65 table vs. its rounded xy.
        let rgb = dense_rgb(&DenseSpectrum::constant(0.8));
        for c in rgb {
            assert!((c - 0.8).abs() < 2e-3, "{rgb:?}");
        }
    }
}
