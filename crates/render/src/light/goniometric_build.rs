//! Scene `luminaire` → `GoniometricLight`: the luminaire frame, the interpolated table, the
//! strength (the file's candela × `scale`, or scaled to `power_lm`), TILT and the spectrum
//! normalised to 1 cd per table candela (docs/lighting.md).

use glam::DVec3;
use prism_scene::photometric::IntensityDistribution;
use prism_scene::Strength;
use prism_spectrum::Spectrum;

use super::build::LightBuilder;
use super::goniometric::{tilt_factor, GoniometricLight, IntensityTable};
use super::photometry::photometric_scale;
use super::point::integrate_nm;
use super::Light;
use crate::scene_build::SceneBuildError;

#[allow(clippy::too_many_arguments)]
pub(super) fn build(
    b: &LightBuilder,
    strength: Strength,
    value: f64,
    distribution: &IntensityDistribution,
    position_m: &[f64; 3],
    aim: &[f64; 3],
    c0_direction: &[f64; 3],
    spectrum: Spectrum,
) -> Result<Light, SceneBuildError> {
    let a = DVec3::from(*aim).normalize();
    let l = DVec3::from(*c0_direction).normalize();
    let w = l.cross(a);
    let table = IntensityTable::from_distribution(distribution);
    let table_flux = table.flux();
    if !(table_flux > 0.0 && table_flux.is_finite()) {
        return Err(b.err(
            "file",
            format!(
                "{}: the intensity distribution emits no light (all candela values are 0)",
                distribution.file.display()
            ),
        ));
    }
    // Lamp tilt: the aim's angle from straight down, as the luminaire was measured.
    let tilt = match &distribution.tilt {
        Some(t) => tilt_factor(t, a.dot(DVec3::NEG_Y).clamp(-1.0, 1.0).acos().to_degrees()),
        None => 1.0,
    };
    let factor = match strength {
        Strength::Scale(_) => value * tilt,
        Strength::LuminousFluxLm(_) => value / table_flux,
        Strength::IntensityCd(_) | Strength::LuminanceCdM2(_) | Strength::IlluminanceLx(_) => {
            return Err(b.unsupported())
        }
    };
    // s(λ) carries 1 cd per unit: K_m Σ s ȳ Δλ = 1.
    let k = photometric_scale(&spectrum, 1.0).map_err(|e| b.err("spectrum", e))?;
    let k = k * factor;
    if !(k.is_finite() && (k as f32).is_finite()) {
        return Err(b.err(
            "scale",
            format!("the spectrum scaled by {k:e} is beyond single precision"),
        ));
    }
    let spectrum = spectrum.scaled(k as f32);
    let power_w = table_flux * integrate_nm(&spectrum);
    Ok(Light::Goniometric(Box::new(GoniometricLight::new(
        DVec3::from(*position_m).as_vec3a(),
        [l, w, a],
        table,
        spectrum,
        table_flux * factor,
        power_w,
    ))))
}
