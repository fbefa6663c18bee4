//! Daylight sky descriptions: the CIE standard general sky (ISO 15469:2004 / CIE S 011/E:2003,
//! 15 types, plus the traditional CIE overcast sky), the Perez all-weather sky (Perez, Seals &
//! Michalsky 1993) and the Preetham sky (Preetham, Shirley & Smits 1999), each with the sun's
//! position (angles, or date, time and place) and an optional sun disk. prism-render turns
//! them into emitters; docs/lights.md (Daylight) has the formulas.

use crate::reader::{Obj, Result, V};
use crate::schema::schema;

/// Which luminance distribution.
#[derive(Debug, Clone, PartialEq)]
pub enum SkyModel {
    /// CIE standard general sky `sky_type` (1–15), or the traditional CIE overcast sky
    /// (Moon & Spencer 1942, L = L_z (1 + 2 cos Z)/3) when `sky_type` is 0 (`"overcast"`).
    Cie {
        sky_type: u8,
        normalisation: SkyNormalisation,
    },
    /// Perez all-weather model from measured irradiances (W/m²) and optional illuminances (lx).
    Perez {
        diffuse_horizontal_irradiance_w_m2: f64,
        direct_normal_irradiance_w_m2: f64,
        /// Dew point for the precipitable water of the Perez 1990 luminous efficacy, °C.
        dew_point_c: f64,
        diffuse_horizontal_illuminance_lx: Option<f64>,
        direct_normal_illuminance_lx: Option<f64>,
    },
    /// Preetham analytic sky of atmospheric turbidity T (2–10); absolute luminance from the
    /// model unless `diffuse_horizontal_illuminance_lx` renormalises it.
    Preetham {
        turbidity: f64,
        diffuse_horizontal_illuminance_lx: Option<f64>,
    },
}

/// How a CIE sky's relative distribution becomes absolute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SkyNormalisation {
    ZenithLuminanceCdM2(f64),
    /// Illuminance of the sky (without sun) on an unobstructed horizontal plane.
    DiffuseHorizontalIlluminanceLx(f64),
}

/// A civil date and time with its offset from UTC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DateTime {
    pub year: i32,
    pub month: u32,
    pub day: u32,
    pub hour: u32,
    pub minute: u32,
    pub second: f64,
    /// Local time minus UTC, hours (+2 for CEST).
    pub utc_offset_h: f64,
}

impl DateTime {
    /// Day of the year, 1 = 1 January.
    pub fn day_of_year(&self) -> u32 {
        let leap = (self.year % 4 == 0 && self.year % 100 != 0) || self.year % 400 == 0;
        let days = [
            31,
            if leap { 29 } else { 28 },
            31,
            30,
            31,
            30,
            31,
            31,
            30,
            31,
            30,
            31,
        ];
        days[..(self.month as usize - 1)].iter().sum::<u32>() + self.day
    }
}

/// Where the sun is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SunPosition {
    /// Elevation above the horizon and azimuth from north towards east, radians.
    Angles {
        elevation_rad: f64,
        azimuth_rad: f64,
    },
    /// Computed (Michalsky 1988) for this time at latitude (north +) and longitude (east +).
    Time {
        date_time: DateTime,
        latitude_deg: f64,
        longitude_deg: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct DaylightSky {
    pub model: SkyModel,
    pub sun_position: SunPosition,
    /// Direct normal illuminance of the sun disk, lx (CIE and Preetham skies); `None`: no sun.
    pub sun_normal_illuminance_lx: Option<f64>,
    /// Correlated colour temperature of the stated D-series spectrum of the sky (CIE, Perez), K.
    pub sky_cct_k: f64,
    /// Correlated colour temperature of the D-series spectrum of the sun disk, K.
    pub sun_cct_k: f64,
    /// Lambertian ground albedo below the horizon (0: black ground).
    pub ground_albedo: f64,
    /// Azimuth of north measured from the scene's −Z axis towards +X, radians.
    pub north_rad: f64,
}

pub const DAYLIGHT_TYPES: [&str; 3] = ["cie_sky", "perez_sky", "preetham_sky"];

fn parse_date_time(v: &V) -> Result<DateTime> {
    let s = v.str()?;
    let bad = || {
        v.err(format!(
            "expected an ISO 8601 date and time with its UTC offset such as \
             \"2024-06-21T12:00:00+02:00\" or \"2024-06-21T10:00Z\", found {s:?}"
        ))
    };
    let (date, rest) = s.split_once('T').ok_or_else(bad)?;
    let d: Vec<&str> = date.split('-').collect();
    if d.len() != 3 {
        return Err(bad());
    }
    let year: i32 = d[0].parse().map_err(|_| bad())?;
    let month: u32 = d[1].parse().map_err(|_| bad())?;
    let day: u32 = d[2].parse().map_err(|_| bad())?;
    let (time, offset) = if let Some(t) = rest.strip_suffix('Z') {
        (t, 0.0)
    } else if let Some(i) = rest.rfind(['+', '-']) {
        let (t, o) = rest.split_at(i);
        let sign = if o.starts_with('-') { -1.0 } else { 1.0 };
        let (oh, om) = o[1..].split_once(':').unwrap_or((&o[1..], "0"));
        let oh: f64 = oh.parse().map_err(|_| bad())?;
        let om: f64 = om.parse().map_err(|_| bad())?;
        (t, sign * (oh + om / 60.0))
    } else {
        return Err(bad());
    };
    let t: Vec<&str> = time.split(':').collect();
    if !(2..=3).contains(&t.len()) {
        return Err(bad());
    }
    let hour: u32 = t[0].parse().map_err(|_| bad())?;
    let minute: u32 = t[1].parse().map_err(|_| bad())?;
    let second: f64 = t.get(2).map_or(Ok(0.0), |x| x.parse()).map_err(|_| bad())?;
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    let month_days = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    let ok = (1..=12).contains(&month)
        && day >= 1
        && day <= month_days[month as usize - 1]
        && hour < 24
        && minute < 60
        && (0.0..61.0).contains(&second)
        && offset.abs() <= 14.0
        && (1900..=2100).contains(&year);
    if !ok {
        return Err(v.err(format!(
            "{s:?} is not a valid date and time between the years 1900 and 2100"
        )));
    }
    Ok(DateTime {
        year,
        month,
        day,
        hour,
        minute,
        second,
        utc_offset_h: offset,
    })
}

fn parse_sun_position(v: &V) -> Result<SunPosition> {
    let o = v.object(schema!("@sun"))?;
    if let Some(t) = o.get("date_time") {
        for k in ["elevation_deg", "azimuth_deg"] {
            if let Some(x) = o.get(k) {
                return Err(x.err(format!(
                    "give the sun either by `date_time`, `latitude_deg` and `longitude_deg` \
                     or by `elevation_deg` and `azimuth_deg`, not `{k}` with `date_time`"
                )));
            }
        }
        Ok(SunPosition::Time {
            date_time: parse_date_time(&t)?,
            latitude_deg: o
                .req("latitude_deg", "the latitude in degrees (north +)")?
                .in_range(-90.0, 90.0)?,
            longitude_deg: o
                .req("longitude_deg", "the longitude in degrees (east +)")?
                .in_range(-180.0, 180.0)?,
        })
    } else {
        Ok(SunPosition::Angles {
            elevation_rad: o
                .req(
                    "elevation_deg",
                    "the sun's elevation above the horizon in degrees (or `date_time`)",
                )?
                .in_range(-90.0, 90.0)?
                .to_radians(),
            azimuth_rad: o
                .req(
                    "azimuth_deg",
                    "the sun's azimuth in degrees from north towards east",
                )?
                .in_range(-360.0, 360.0)?
                .to_radians(),
        })
    }
}

fn optional_non_negative(o: &Obj, key: &str) -> Result<Option<f64>> {
    o.get(key).map(|v| v.non_negative()).transpose()
}

/// Parses a `cie_sky`, `perez_sky` or `preetham_sky` light object.
pub(crate) fn parse_daylight(v: &V, kind: &str) -> Result<DaylightSky> {
    let o = v.object(match kind {
        "cie_sky" => schema!("lights[]<cie_sky>"),
        "perez_sky" => schema!("lights[]<perez_sky>"),
        _ => schema!("lights[]<preetham_sky>"),
    })?;
    for k in ["spectrum", "scale"] {
        if let Some(x) = o.get(k) {
            return Err(x.err(format!(
                "a {kind} light takes no `{k}`: its spectrum and level come from the sky \
                 model (see docs/lights.md, Daylight)"
            )));
        }
    }
    let model = match kind {
        "cie_sky" => {
            let t = o.req(
                "sky_type",
                "a CIE standard general sky type 1–15 or \"overcast\"",
            )?;
            let sky_type = match t.str() {
                Ok("overcast") => 0,
                Ok(_) => return Err(t.type_err("a sky type 1–15 or \"overcast\"")),
                Err(_) => {
                    let n = t.f64()?;
                    if n.fract() != 0.0 || !(1.0..=15.0).contains(&n) {
                        return Err(t.err(format!(
                            "expected a CIE standard general sky type 1–15 or \"overcast\", found {n}"
                        )));
                    }
                    n as u8
                }
            };
            let normalisation = match o.at_most_one(&[
                "zenith_luminance_cd_m2",
                "diffuse_horizontal_illuminance_lx",
            ])? {
                Some(("zenith_luminance_cd_m2", x)) => {
                    SkyNormalisation::ZenithLuminanceCdM2(x.non_negative()?)
                }
                Some((_, x)) => SkyNormalisation::DiffuseHorizontalIlluminanceLx(x.non_negative()?),
                None => {
                    return Err(o.v.err(
                        "missing field: give `zenith_luminance_cd_m2` or \
                         `diffuse_horizontal_illuminance_lx`",
                    ))
                }
            };
            SkyModel::Cie {
                sky_type,
                normalisation,
            }
        }
        "perez_sky" => {
            let dh = o
                .req(
                    "diffuse_horizontal_irradiance_w_m2",
                    "the diffuse horizontal irradiance in W/m²",
                )?
                .positive()?;
            let dn = o
                .req(
                    "direct_normal_irradiance_w_m2",
                    "the direct normal irradiance in W/m²",
                )?
                .non_negative()?;
            SkyModel::Perez {
                diffuse_horizontal_irradiance_w_m2: dh,
                direct_normal_irradiance_w_m2: dn,
                dew_point_c: match o.get("dew_point_c") {
                    None => 11.0,
                    Some(x) => x.in_range(-60.0, 40.0)?,
                },
                diffuse_horizontal_illuminance_lx: optional_non_negative(
                    &o,
                    "diffuse_horizontal_illuminance_lx",
                )?,
                direct_normal_illuminance_lx: optional_non_negative(
                    &o,
                    "direct_normal_illuminance_lx",
                )?,
            }
        }
        _ => SkyModel::Preetham {
            turbidity: match o.get("turbidity") {
                None => 3.0,
                Some(x) => x.in_range(1.7, 10.0)?,
            },
            diffuse_horizontal_illuminance_lx: optional_non_negative(
                &o,
                "diffuse_horizontal_illuminance_lx",
            )?,
        },
    };
    let sun_position = parse_sun_position(&o.req(
        "sun",
        "the sun's position: {\"elevation_deg\", \"azimuth_deg\"} or \
         {\"date_time\", \"latitude_deg\", \"longitude_deg\"}",
    )?)?;
    let cct = |key: &str, default: f64| -> Result<f64> {
        o.get(key)
            .map_or(Ok(default), |x| x.in_range(4000.0, 25_000.0))
    };
    Ok(DaylightSky {
        model,
        sun_position,
        sun_normal_illuminance_lx: optional_non_negative(&o, "sun_normal_illuminance_lx")?,
        sky_cct_k: cct("sky_cct_k", 6500.0)?,
        sun_cct_k: cct("sun_cct_k", 5500.0)?,
        ground_albedo: o
            .get("ground_albedo")
            .map_or(Ok(0.0), |x| x.in_range(0.0, 1.0))?,
        north_rad: o
            .get("north_deg")
            .map_or(Ok(0.0), |x| x.in_range(-360.0, 360.0))?
            .to_radians(),
    })
}
