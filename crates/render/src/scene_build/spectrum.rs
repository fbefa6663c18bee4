//! Scene spectrum references (prism-scene `SpectrumRef`) → runtime `Spectrum`s, by use:
//! an RGB reflectance is upsampled as a bounded albedo, an RGB emission as an illuminant
//! (pbrt-v4 `RGBIlluminantSpectrum`: sigmoid polynomial × the gamut's white, D65 for
//! sRGB), an RGB coefficient (IOR, scattering) as an unbounded spectrum (Jakob & Hanika
//! 2019). RGB values are linear Rec.709 (the scene format's convention).

use prism_scene::SpectrumRef;
use prism_spectrum::{RgbGamut, Spectrum};

/// What a spectrum describes; decides how RGB is upsampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumRole {
    /// Reflectance or transmittance in [0, 1].
    Albedo,
    /// Emission (relative spectral power).
    Illuminant,
    /// Anything else ≥ 0 (η, k, coefficients).
    Unbounded,
}

/// The runtime spectrum of `r`; errors are messages for a `SceneBuildError`.
pub fn build_spectrum(r: &SpectrumRef, role: SpectrumRole) -> Result<Spectrum, String> {
    match r {
        SpectrumRef::Constant(c) => Ok(Spectrum::constant(*c as f32)),
        SpectrumRef::Blackbody { temperature_k } => {
            Spectrum::blackbody_normalized(*temperature_k as f32).map_err(|e| e.to_string())
        }
        SpectrumRef::Illuminant { table, .. } | SpectrumRef::File { table, .. } => {
            Spectrum::from_tabulated(table).map_err(|e| e.to_string())
        }
        SpectrumRef::Rgb { rgb } => {
            let rgb = rgb.map(|v| v as f32);
            match role {
                SpectrumRole::Albedo => Spectrum::rgb_albedo(RgbGamut::Srgb, rgb),
                SpectrumRole::Illuminant => Spectrum::rgb_illuminant(RgbGamut::Srgb, rgb),
                SpectrumRole::Unbounded => Spectrum::rgb_unbounded(RgbGamut::Srgb, rgb),
            }
            .map_err(|e| e.to_string())
        }
    }
}
