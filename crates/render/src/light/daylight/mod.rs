//! Daylight: the CIE standard general sky (`cie_sky`), the Perez all-weather sky (`perez`),
//! the Preetham sky (`preetham`), the sun's position (`sun_position`) and the emitter that
//! samples any of them (`sky_light`). `build_daylight` turns a scene's sky description into
//! the sky emitter and, when it has one, the sun: a `DirectionalLight` of angular diameter
//! 0.533° (the sun's mean apparent diameter) carrying the direct normal illuminance.
//!
//! Frame: +Y is the zenith; north is −Z rotated by `north_deg` towards +X, east is 90°
//! clockwise from north seen from above (+X when `north_deg` = 0). Azimuths count from north
//! towards east.

pub mod cie_sky;
pub mod perez;
pub mod preetham;
pub mod sky_light;
pub mod sun_position;

use glam::Vec3A;
use prism_scene::{DaylightSky, SkyModel, SkyNormalisation, SunPosition};
use prism_spectrum::daylight::{daylight_basis, daylight_m1_m2, daylight_spectrum, daylight_xy};
use prism_spectrum::{DenseSpectrum, Spectrum};

use self::cie_sky::CieSky;
use self::perez::{extraterrestrial_irradiance_w_m2, PerezConditions};
use self::preetham::PreethamSky;
use self::sky_light::{DaylightSkyLight, SkyColour};
use super::photometry::photometric_scale;
use super::point::integrate_nm;
use super::scene_sphere::SceneSphere;
use super::DirectionalLight;

/// Apparent diameter of the sun, degrees (mean; 0.524°–0.542° over the year).
pub const SUN_ANGULAR_DIAMETER_DEG: f64 = 0.533;

/// The illuminance in lx that the scene's daylight sky alone (without the sun disk and the
/// ground) gives on an unobstructed horizontal plane — the denominator of the daylight factor
/// DF = E_inside / E_outside (CIE: under the overcast sky; reported for any daylight sky) —
/// when the scene has exactly one daylight sky, else `None`.
pub fn outdoor_horizontal_illuminance_lx(lights: &super::LightSet) -> Option<f64> {
    let mut skies = (0..lights.len() as u32).filter_map(|i| match lights.light(i) {
        super::Light::Daylight(d) => Some(d.horizontal_illuminance_lx),
        super::Light::Point(_)
        | super::Light::Spot(_)
        | super::Light::Directional(_)
        | super::Light::Area(_)
        | super::Light::Environment(_)
        | super::Light::Sky(_)
        | super::Light::Goniometric(_) => None,
    });
    let first = skies.next()?;
    skies.next().is_none().then_some(first)
}

/// The luminance distribution of a sky for one sun position.
#[derive(Clone, Debug, PartialEq)]
pub enum SkyShape {
    /// Relative to the zenith (L/L_z).
    Cie(CieSky),
    /// Relative (l_v).
    Perez(PerezConditions),
    /// Absolute, cd/m².
    Preetham(PreethamSky),
}

impl SkyShape {
    /// The shape's luminance for cos Z = `cos_z` (> 0) at angle χ from the sun (`cos_chi`).
    #[inline]
    pub fn relative_luminance(&self, cos_z: f64, cos_chi: f64) -> f64 {
        match self {
            SkyShape::Cie(s) => s.relative_luminance(cos_z, cos_chi),
            SkyShape::Perez(s) => s.relative_luminance(cos_z, cos_chi),
            SkyShape::Preetham(s) => s.luminance_cd_m2(cos_z, cos_chi),
        }
    }

    /// Chromaticity (Preetham; the others return D65's, unused).
    #[inline]
    pub fn chromaticity(&self, cos_z: f64, cos_chi: f64) -> (f64, f64) {
        match self {
            SkyShape::Preetham(s) => s.chromaticity(cos_z, cos_chi),
            SkyShape::Cie(_) | SkyShape::Perez(_) => (0.3127, 0.3290),
        }
    }
}

/// ∫ f(cos Z, cos χ) cos Z dω over the upper hemisphere for a sun at zenith angle
/// `sun_zenith_rad`: midpoint rule in cos Z (`n` cells) and in azimuth over [0, π] (`2n`
/// cells, doubled by the symmetry about the sun's vertical plane).
pub fn horizontal_quadrature(
    sun_zenith_rad: f64,
    n: usize,
    mut f: impl FnMut(f64, f64) -> f64,
) -> f64 {
    let (sin_s, cos_s) = sun_zenith_rad.sin_cos();
    let (dmu, dphi) = (1.0 / n as f64, std::f64::consts::PI / (2 * n) as f64);
    let mut sum = 0.0;
    for i in 0..n {
        let mu = (i as f64 + 0.5) * dmu;
        let sin_z = (1.0 - mu * mu).sqrt();
        let mut row = 0.0;
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) * dphi;
            let cos_chi = mu * cos_s + sin_z * sin_s * phi.cos();
            row += f(mu, cos_chi);
        }
        sum += row * mu;
    }
    2.0 * sum * dmu * dphi
}

/// Unit direction of elevation `el` and azimuth `az` (radians, from north towards east) for
/// north at `north_rad` from −Z towards +X.
pub fn sky_direction(elevation_rad: f64, azimuth_rad: f64, north_rad: f64) -> Vec3A {
    let (se, ce) = elevation_rad.sin_cos();
    let a = azimuth_rad + north_rad;
    Vec3A::new((ce * a.sin()) as f32, se as f32, (-ce * a.cos()) as f32)
}

/// What `build_daylight` makes.
pub struct BuiltDaylight {
    pub sky: DaylightSkyLight,
    pub sun: Option<DirectionalLight>,
    /// Elevation and azimuth of the sun actually used, degrees.
    pub sun_elevation_deg: f64,
    pub sun_azimuth_deg: f64,
}

/// A D-series spectrum of CCT `cct_k` scaled to unit photometric value; with
/// `ultraviolet`, continued below 360 nm (`with_ultraviolet`).
fn unit_daylight(cct_k: f64, ultraviolet: bool) -> Result<Spectrum, String> {
    let dense = daylight_spectrum(cct_k)?;
    let s = Spectrum::from_dense(&dense).map_err(|e| e.to_string())?;
    let k = photometric_scale(&s, 1.0)?;
    if ultraviolet {
        let (x, y) = daylight_xy(cct_k)?;
        let (m1, m2) = daylight_m1_m2(x, y);
        return with_ultraviolet(&dense, [1.0, m1, m2], k);
    }
    Ok(s.scaled(k as f32))
}

/// `k`·`dense` over 360–830 nm continued below 360 nm by k·Σ cᵢSᵢ of the daylight basis
/// tables, which start at 300 nm: the daylight that excites fluorescent materials there
/// (the dense grid stops at 360 nm). Used only in scenes with re-radiation, so other scenes
/// keep their dense spectra (and images) exactly.
fn with_ultraviolet(dense: &DenseSpectrum, c: [f64; 3], k: f64) -> Result<Spectrum, String> {
    let basis = prism_spectrum::data::embedded_file("cie-daylight-basis")
        .expect("the daylight basis is embedded");
    let mut wavelengths_nm = Vec::new();
    let mut values = Vec::new();
    for (row, &nm) in basis.wavelengths_nm.iter().enumerate() {
        if nm >= 360.0 {
            break;
        }
        wavelengths_nm.push(nm);
        values.push(k * (0..3).map(|i| c[i] * basis.columns[i][row]).sum::<f64>());
    }
    for (i, v) in dense.values().iter().enumerate() {
        wavelengths_nm.push(DenseSpectrum::wavelength_nm(i));
        values.push(k * v);
    }
    Spectrum::piecewise_linear(&wavelengths_nm, &values).map_err(|e| e.to_string())
}

/// The quadrature resolution of normalisations and ground illuminance.
const QUADRATURE_N: usize = 384;

/// Builds the sky (and sun) of `desc`; errors are plain messages (the caller adds the place).
/// `ultraviolet`: the sky's and the sun's spectra reach down to 300 nm (scenes with
/// re-radiation, whose lanes may be excited there); otherwise they stop at 360 nm.
pub fn build_daylight(
    desc: &DaylightSky,
    scene: SceneSphere,
    ultraviolet: bool,
) -> Result<BuiltDaylight, String> {
    let (elevation_deg, azimuth_deg) = match desc.sun_position {
        SunPosition::Angles {
            elevation_rad,
            azimuth_rad,
        } => (elevation_rad.to_degrees(), azimuth_rad.to_degrees()),
        SunPosition::Time {
            date_time,
            latitude_deg,
            longitude_deg,
        } => {
            let a = sun_position::solar_angles(&date_time, latitude_deg, longitude_deg);
            (a.elevation_deg, a.azimuth_deg)
        }
    };
    let sun_zenith = (90.0 - elevation_deg).to_radians();
    let sun_dir = sky_direction(
        elevation_deg.to_radians(),
        azimuth_deg.to_radians(),
        desc.north_rad,
    );
    let day_of_year = match desc.sun_position {
        SunPosition::Time { date_time, .. } => Some(date_time.day_of_year()),
        SunPosition::Angles { .. } => None,
    };
    let sky_unit = unit_daylight(desc.sky_cct_k, ultraviolet)?;
    let sun_unit = unit_daylight(desc.sun_cct_k, ultraviolet)?;
    let radiant_per_luminance_nm = integrate_nm(&sky_unit);
    let needs_sun_up = |model: &str| -> Result<(), String> {
        if elevation_deg <= 0.0 {
            Err(format!(
                "the {model} sky needs the sun above the horizon; it is at {elevation_deg:.2}° \
                 elevation"
            ))
        } else {
            Ok(())
        }
    };
    let (shape, scale, colour, sun_lx) = match &desc.model {
        SkyModel::Cie {
            sky_type,
            normalisation,
        } => {
            let shape = SkyShape::Cie(CieSky::new(*sky_type, sun_zenith));
            let scale = match *normalisation {
                SkyNormalisation::ZenithLuminanceCdM2(lz) => lz,
                SkyNormalisation::DiffuseHorizontalIlluminanceLx(e) => {
                    e / horizontal_quadrature(sun_zenith, QUADRATURE_N, |m, c| {
                        shape.relative_luminance(m, c)
                    })
                }
            };
            (
                shape,
                scale,
                SkyColour::Fixed(sky_unit.clone()),
                desc.sun_normal_illuminance_lx,
            )
        }
        SkyModel::Perez {
            diffuse_horizontal_irradiance_w_m2,
            direct_normal_irradiance_w_m2,
            dew_point_c,
            diffuse_horizontal_illuminance_lx,
            direct_normal_illuminance_lx,
        } => {
            needs_sun_up("Perez")?;
            let i0 = day_of_year.map_or(1367.0, extraterrestrial_irradiance_w_m2);
            let c = PerezConditions::new(
                *diffuse_horizontal_irradiance_w_m2,
                *direct_normal_irradiance_w_m2,
                sun_zenith,
                i0,
                *dew_point_c,
            );
            let edh =
                diffuse_horizontal_illuminance_lx.unwrap_or(c.diffuse_horizontal_illuminance_lx);
            let edn = direct_normal_illuminance_lx.unwrap_or(c.direct_normal_illuminance_lx);
            let shape = SkyShape::Perez(c);
            let integral = horizontal_quadrature(sun_zenith, QUADRATURE_N, |m, c| {
                shape.relative_luminance(m, c)
            });
            if integral.is_nan() || integral <= 0.0 {
                return Err("the Perez sky distribution integrates to zero".into());
            }
            (
                shape,
                edh / integral,
                SkyColour::Fixed(sky_unit.clone()),
                Some(edn),
            )
        }
        SkyModel::Preetham {
            turbidity,
            diffuse_horizontal_illuminance_lx,
        } => {
            needs_sun_up("Preetham")?;
            let shape = SkyShape::Preetham(PreethamSky::new(*turbidity, sun_zenith));
            let scale = match diffuse_horizontal_illuminance_lx {
                None => 1.0,
                Some(e) => {
                    e / horizontal_quadrature(sun_zenith, QUADRATURE_N, |m, c| {
                        shape.relative_luminance(m, c)
                    })
                }
            };
            let b = daylight_basis();
            let basis = if ultraviolet {
                let unit = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let mut out = Vec::with_capacity(3);
                for (s, c) in b.s.iter().zip(unit) {
                    out.push(with_ultraviolet(s, c, 1.0)?);
                }
                [out[0].clone(), out[1].clone(), out[2].clone()]
            } else {
                b.s.clone()
                    .map(|s| Spectrum::from_dense(&s).expect("the daylight basis is finite"))
            };
            (
                shape,
                scale,
                SkyColour::Daylight {
                    basis: Box::new(basis),
                    basis_luminance: b.luminance.map(|v| v as f32),
                },
                desc.sun_normal_illuminance_lx,
            )
        }
    };
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(format!("the sky's luminance scale is {scale}"));
    }
    // Spectral horizontal irradiance of the sky per unit: the fixed colour is one spectrum;
    // the Preetham sky's is a combination c0 S0 + c1 S1 + c2 S2 (linear in the basis).
    let (sky_e_lx, sky_e_spectrum) = match (&colour, &shape) {
        (
            SkyColour::Daylight {
                basis_luminance, ..
            },
            SkyShape::Preetham(p),
        ) => {
            let mut c = [0.0f64; 3];
            let e = horizontal_quadrature(sun_zenith, QUADRATURE_N, |m, cc| {
                let lv = scale * p.luminance_cd_m2(m, cc);
                let (x, y) = p.chromaticity(m, cc);
                let (m1, m2) = prism_spectrum::daylight::daylight_m1_m2(x, y);
                let norm = f64::from(basis_luminance[0])
                    + m1 * f64::from(basis_luminance[1])
                    + m2 * f64::from(basis_luminance[2]);
                // Weighted by cos Z like the quadrature's own terms (its constant factors
                // cancel in the normalisation below).
                if norm > 0.0 {
                    c[0] += m * lv / norm;
                    c[1] += m * lv * m1 / norm;
                    c[2] += m * lv * m2 / norm;
                }
                lv
            });
            // The sky's spectral horizontal irradiance ∝ c0 S0 + c1 S1 + c2 S2; scaled to unit
            // illuminance here, to E lx by the caller.
            let b = daylight_basis();
            let dense = {
                let (s0, s1, s2) = (b.s[0].values(), b.s[1].values(), b.s[2].values());
                let mut i = 0;
                DenseSpectrum::from_fn(|_| {
                    let v = c[0] * s0[i] + c[1] * s1[i] + c[2] * s2[i];
                    i += 1;
                    v
                })
            };
            let s = Spectrum::from_dense(&dense).map_err(|e| e.to_string())?;
            let k = photometric_scale(&s, 1.0).unwrap_or(0.0);
            (e, s.scaled(k as f32))
        }
        _ => (
            scale
                * horizontal_quadrature(sun_zenith, QUADRATURE_N, |m, c| {
                    shape.relative_luminance(m, c)
                }),
            sky_unit.clone(),
        ),
    };
    let sun_lx = match sun_lx {
        Some(e) if e > 0.0 => {
            if elevation_deg <= 0.0 {
                return Err(format!(
                    "the sun has a direct normal illuminance of {e} lx but is below the horizon \
                     ({elevation_deg:.2}° elevation)"
                ));
            }
            e
        }
        _ => 0.0,
    };
    let sun_h_lx = sun_lx * elevation_deg.to_radians().sin().max(0.0);
    let (ground, ground_lv) = if desc.ground_albedo > 0.0 {
        let rho_pi = desc.ground_albedo / std::f64::consts::PI;
        let lv = rho_pi * (sky_e_lx + sun_h_lx);
        let sky_part = sky_e_spectrum.to_dense().scaled(rho_pi * sky_e_lx);
        let sun_part = sun_unit.to_dense().scaled(rho_pi * sun_h_lx);
        let dense = {
            let (a, b) = (sky_part.values(), sun_part.values());
            let mut i = 0;
            DenseSpectrum::from_fn(|_| {
                let v = a[i] + b[i];
                i += 1;
                v
            })
        };
        (
            Some(Spectrum::from_dense(&dense).map_err(|e| e.to_string())?),
            lv,
        )
    } else {
        (None, 0.0)
    };
    let sky = DaylightSkyLight::new(
        shape,
        scale,
        sun_dir,
        colour,
        ground,
        ground_lv,
        sky_e_lx,
        radiant_per_luminance_nm,
        scene,
    );
    let sun = (sun_lx > 0.0).then(|| {
        DirectionalLight::new(
            -sun_dir,
            SUN_ANGULAR_DIAMETER_DEG.to_radians(),
            sun_unit.clone().scaled(sun_lx as f32),
            scene,
        )
    });
    Ok(BuiltDaylight {
        sky,
        sun,
        sun_elevation_deg: elevation_deg,
        sun_azimuth_deg: azimuth_deg,
    })
}

#[cfg(test)]
mod tests;
