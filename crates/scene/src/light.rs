//! Light descriptions: point, spot, directional (sun), area (an emitting shape),
//! environment map and uniform sky. Each has a spectrum and a strength in photometric
//! units (lm, cd, cd/m², lx) or as a plain radiometric scale on the spectrum.

use std::path::PathBuf;

use glam::DVec3;

use crate::daylight::{parse_daylight, DaylightSky};
use crate::photometric::{load_photometric_file, IntensityDistribution};
use crate::reader::{quoted_list, suggest, Obj, Result, V};
use crate::schema::schema;
use crate::shape::Shape;
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};
use crate::transform::{parse_transform, Transform};

#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    /// Relative spectral power distribution; `strength` sets its absolute level.
    pub spectrum: SpectrumRef,
    pub strength: Strength,
}

/// How bright a light is. Photometric strengths fix the spectrum's scale so that the light
/// has exactly that flux/intensity/luminance/illuminance (683.002 lm/W × ∫ S V dλ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Strength {
    /// Total luminous flux in lm.
    LuminousFluxLm(f64),
    /// Luminous intensity in cd (on the axis, for a spot).
    IntensityCd(f64),
    /// Luminance of the emitting surface or sky in cd/m².
    LuminanceCdM2(f64),
    /// Illuminance on a surface facing the light, in lx.
    IlluminanceLx(f64),
    /// The spectrum taken as radiance/intensity in W·m⁻²·sr⁻¹·nm⁻¹ (or W·sr⁻¹·nm⁻¹), times this.
    Scale(f64),
}

/// How an environment map is read between texel centres (`filter`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EnvironmentFilter {
    /// The texel a direction falls in (the default): a step at every texel edge.
    #[default]
    Nearest,
    /// Bilinear between the four nearest texel centres, sampled to follow it.
    Bilinear,
}

// Scenes hold few lights; boxing the environment's transform would only add noise.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum LightKind {
    Point {
        position_m: [f64; 3],
    },
    Spot {
        position_m: [f64; 3],
        /// Unit vector along the beam axis.
        direction: [f64; 3],
        /// Half-angle of the full cone, radians.
        cone_angle_rad: f64,
        /// Half-angle where the falloff to the cone's edge begins, radians.
        falloff_start_rad: f64,
    },
    /// Parallel light travelling along `direction` (unit vector), e.g. the sun.
    Directional {
        direction: [f64; 3],
        /// Apparent diameter of the source (0.53° for the sun); 0 for ideal parallel light.
        angular_diameter_rad: f64,
    },
    /// Emission from a named shape (index into `SceneDescription::shapes`).
    Area {
        shape: usize,
        two_sided: bool,
    },
    /// An environment map (.exr or .hdr, equirectangular), rotated by `transform`.
    Environment {
        path: PathBuf,
        transform: Transform,
        filter: EnvironmentFilter,
    },
    /// A sky of the same radiance in every direction.
    UniformSky,
    /// A CIE, Perez or Preetham sky with its sun (crate::daylight).
    Daylight(Box<DaylightSky>),
    /// A point luminaire with the intensity distribution of an IES/EULUMDAT file.
    Luminaire {
        distribution: Box<IntensityDistribution>,
        position_m: [f64; 3],
        /// Unit vector of the luminaire's γ = 0 axis (nadir as measured).
        aim: [f64; 3],
        /// Unit vector of the C = 0 plane's direction, perpendicular to `aim`.
        c0_direction: [f64; 3],
    },
}

pub const LIGHT_TYPES: [&str; 10] = [
    "point",
    "spot",
    "directional",
    "area",
    "environment",
    "sky",
    "cie_sky",
    "perez_sky",
    "preetham_sky",
    "luminaire",
];

fn unit_vector(v: &V) -> Result<[f64; 3]> {
    let d = DVec3::from(v.numbers::<3>()?);
    if d.length() < 1e-12 {
        return Err(v.err("expected a non-zero direction"));
    }
    Ok(d.normalize().to_array())
}

/// The strength: at most one of the fields `allowed` (plus `scale`); `Scale(1)` if none.
fn strength(o: &Obj, allowed: &[&'static str]) -> Result<Strength> {
    let mut keys = allowed.to_vec();
    keys.push("scale");
    Ok(match o.at_most_one(&keys)? {
        None => Strength::Scale(1.0),
        Some((key, v)) => {
            let x = v.non_negative()?;
            match key {
                "power_lm" => Strength::LuminousFluxLm(x),
                "intensity_cd" => Strength::IntensityCd(x),
                "luminance_cd_m2" => Strength::LuminanceCdM2(x),
                "illuminance_lx" => Strength::IlluminanceLx(x),
                _ => Strength::Scale(x),
            }
        }
    })
}

fn angle_deg(o: &Obj, key: &str, lo: f64, hi: f64, default: f64) -> Result<f64> {
    Ok(match o.get(key) {
        None => default,
        Some(a) => a.in_range(lo, hi)?,
    }
    .to_radians())
}

pub(crate) fn parse_light(v: &V, spectra: &NamedSpectra, shapes: &[Shape]) -> Result<Light> {
    let kind = v.tag("light", &LIGHT_TYPES, None)?;
    let (o, kind, strength) = match kind {
        "point" => {
            let o = v.object(schema!("lights[]<point>"))?;
            let s = strength(&o, &["power_lm", "intensity_cd"])?;
            let position_m = o.vec3_or("position_m", [0.0; 3])?;
            (o, LightKind::Point { position_m }, s)
        }
        "spot" => {
            let o = v.object(schema!("lights[]<spot>"))?;
            let s = strength(&o, &["power_lm", "intensity_cd"])?;
            let position_m = o.vec3_or("position_m", [0.0; 3])?;
            let direction = match o.at_most_one(&["direction", "target_m"])? {
                None => [0.0, -1.0, 0.0],
                Some(("direction", d)) => unit_vector(&d)?,
                Some((_, t)) => {
                    let to = DVec3::from(t.numbers::<3>()?) - DVec3::from(position_m);
                    if to.length() < 1e-12 {
                        return Err(t.err("expected `target_m` away from `position_m`"));
                    }
                    to.normalize().to_array()
                }
            };
            let cone_angle_rad = angle_deg(&o, "cone_angle_deg", 0.0, 90.0, 30.0)?;
            if cone_angle_rad == 0.0 {
                if let Some(c) = o.get("cone_angle_deg") {
                    return Err(c.err("expected a cone half-angle in (0, 90] degrees, found 0"));
                }
            }
            let falloff_start_rad = match o.get("falloff_start_deg") {
                None => (cone_angle_rad.to_degrees() - 5.0).max(0.0).to_radians(),
                Some(f) => f.in_range(0.0, cone_angle_rad.to_degrees())?.to_radians(),
            };
            (
                o,
                LightKind::Spot {
                    position_m,
                    direction,
                    cone_angle_rad,
                    falloff_start_rad,
                },
                s,
            )
        }
        "directional" => {
            let o = v.object(schema!("lights[]<directional>"))?;
            let s = strength(&o, &["illuminance_lx"])?;
            let direction = match o.get("direction") {
                None => [0.0, -1.0, 0.0],
                Some(d) => unit_vector(&d)?,
            };
            let angular_diameter_rad = angle_deg(&o, "angular_diameter_deg", 0.0, 180.0, 0.0)?;
            (
                o,
                LightKind::Directional {
                    direction,
                    angular_diameter_rad,
                },
                s,
            )
        }
        "area" => {
            let o = v.object(schema!("lights[]<area>"))?;
            let s = strength(&o, &["power_lm", "luminance_cd_m2"])?;
            let shape_v = o.req("shape", "the `name` of a shape")?;
            let wanted = shape_v.str()?;
            let names: Vec<&str> = shapes.iter().filter_map(|s| s.name.as_deref()).collect();
            let shape = shapes
                .iter()
                .position(|s| s.name.as_deref() == Some(wanted))
                .ok_or_else(|| {
                    let known = if names.is_empty() {
                        "no shape has a `name`".to_string()
                    } else {
                        format!("named shapes: {}", quoted_list(&names))
                    };
                    shape_v.err(format!(
                        "unknown shape `{wanted}` ({known}){}",
                        suggest(wanted, names.iter().copied())
                    ))
                })?;
            let two_sided = o.bool_or("two_sided", false)?;
            (o, LightKind::Area { shape, two_sided }, s)
        }
        "environment" => {
            let o = v.object(schema!("lights[]<environment>"))?;
            let s = strength(&o, &[])?;
            let path = o
                .req("file", "an .exr or .hdr environment map")?
                .asset("environment map", &["exr", "hdr"])?;
            let transform = o
                .get("transform")
                .map_or(Ok(Transform::IDENTITY), |t| parse_transform(&t))?;
            let filter = match o.one_of_or(
                "filter",
                "environment map filter",
                &["nearest", "bilinear"],
                "nearest",
            )? {
                "bilinear" => EnvironmentFilter::Bilinear,
                _ => EnvironmentFilter::Nearest,
            };
            (
                o,
                LightKind::Environment {
                    path,
                    transform,
                    filter,
                },
                s,
            )
        }
        "cie_sky" | "perez_sky" | "preetham_sky" => {
            let sky = parse_daylight(v, kind)?;
            return Ok(Light {
                kind: LightKind::Daylight(Box::new(sky)),
                spectrum: default_spectrum(v)?,
                strength: Strength::Scale(1.0),
            });
        }
        "luminaire" => {
            let o = v.object(schema!("lights[]<luminaire>"))?;
            let s = strength(&o, &["power_lm"])?;
            let file_v = o.req("file", "an .ies or .ldt photometric file")?;
            let path = file_v.asset("photometric", &["ies", "ldt"])?;
            let distribution = load_photometric_file(&path)
                .map_err(|e| file_v.err(format!("cannot use the photometric file: {e}")))?;
            let position_m = o.vec3_or("position_m", [0.0; 3])?;
            let aim = match o.get("aim") {
                None => [0.0, -1.0, 0.0],
                Some(a) => unit_vector(&a)?,
            };
            let c0_v = o.get("c0_direction");
            let c0 = match &c0_v {
                None => {
                    // +X, or +Z when aiming along X.
                    if aim[0].abs() > 0.9 {
                        [0.0, 0.0, 1.0]
                    } else {
                        [1.0, 0.0, 0.0]
                    }
                }
                Some(c) => unit_vector(c)?,
            };
            // Gram–Schmidt: the C = 0 direction perpendicular to the aim.
            let (a, c) = (DVec3::from(aim), DVec3::from(c0));
            let perp = c - a * a.dot(c);
            if perp.length() < 1e-6 {
                let at = c0_v.as_ref().unwrap_or(v);
                return Err(at.err("expected `c0_direction` not parallel to `aim`"));
            }
            (
                o,
                LightKind::Luminaire {
                    distribution: Box::new(distribution),
                    position_m,
                    aim,
                    c0_direction: perp.normalize().to_array(),
                },
                s,
            )
        }
        _ => {
            let o = v.object(schema!("lights[]<sky>"))?;
            let s = strength(&o, &["luminance_cd_m2"])?;
            (o, LightKind::UniformSky, s)
        }
    };
    let spectrum = match o.get("spectrum") {
        None => default_spectrum(v)?,
        Some(sv) => parse_spectrum(&sv, spectra, SpectrumUse::NonNegative)?,
    };
    Ok(Light {
        kind,
        spectrum,
        strength,
    })
}

/// CIE D65, the usual white for emitters given without a spectrum.
fn default_spectrum(v: &V) -> Result<SpectrumRef> {
    let table = prism_spectrum::data::illuminant("D65")
        .ok_or_else(|| v.err("CIE illuminant `D65` has no embedded table"))?;
    Ok(SpectrumRef::Illuminant { name: "D65", table })
}
