//! The sun's apparent position from date, time and place: the Astronomical Almanac's
//! low-precision algorithm as given by Michalsky (1988), "The Astronomical Almanac's algorithm
//! for approximate solar position (1950–2050)", Solar Energy 40(3):227–235 — stated accuracy
//! 0.01° in 1950–2050 — with its refraction correction (standard atmosphere) and the azimuth
//! computed by atan2, which avoids the quadrant corrections of the paper's erratum
//! (Solar Energy 41(1):113, 1988; Spencer 1989).

use prism_scene::DateTime;

/// Apparent solar elevation (refraction included) and azimuth from north towards east, both
/// in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolarAngles {
    pub elevation_deg: f64,
    pub azimuth_deg: f64,
}

/// Julian date (days since −4712-01-01 12:00 UT) of a civil date and time, Meeus (1998)
/// ch. 7 for the Gregorian calendar.
pub fn julian_date(t: &DateTime) -> f64 {
    let ut_h = f64::from(t.hour) + f64::from(t.minute) / 60.0 + t.second / 3600.0 - t.utc_offset_h;
    let (mut y, mut m) = (t.year, t.month as i32);
    if m <= 2 {
        y -= 1;
        m += 12;
    }
    let a = (f64::from(y) / 100.0).floor();
    let b = 2.0 - a + (a / 4.0).floor();
    (365.25 * (f64::from(y) + 4716.0)).floor()
        + (30.6001 * f64::from(m + 1)).floor()
        + f64::from(t.day)
        + b
        - 1524.5
        + ut_h / 24.0
}

fn wrap_deg(x: f64) -> f64 {
    x.rem_euclid(360.0)
}

/// Solar angles at `t` for latitude `lat_deg` (north +) and longitude `lon_deg` (east +).
pub fn solar_angles(t: &DateTime, lat_deg: f64, lon_deg: f64) -> SolarAngles {
    let jd = julian_date(t);
    // Michalsky 1988 eqs.: time from J2000.0 in days.
    let n = jd - 2_451_545.0;
    let mean_longitude = wrap_deg(280.460 + 0.985_647_4 * n);
    let mean_anomaly = wrap_deg(357.528 + 0.985_600_3 * n).to_radians();
    let ecliptic_longitude =
        (mean_longitude + 1.915 * mean_anomaly.sin() + 0.020 * (2.0 * mean_anomaly).sin())
            .to_radians();
    let obliquity = (23.439 - 0.000_000_4 * n).to_radians();
    let right_ascension =
        (obliquity.cos() * ecliptic_longitude.sin()).atan2(ecliptic_longitude.cos());
    let declination = (obliquity.sin() * ecliptic_longitude.sin()).asin();
    // Greenwich mean sidereal time in hours (n counts the fraction of the day too, so the
    // sidereal rate is 1 + 0.0657098242/24 per UT hour), then the local hour angle.
    let ut_h = (jd + 0.5).fract() * 24.0;
    let gmst_h = (6.697_375 + 0.065_709_824_2 * n + ut_h).rem_euclid(24.0);
    let lmst_deg = wrap_deg((gmst_h + lon_deg / 15.0) * 15.0);
    let mut hour_angle = lmst_deg.to_radians() - right_ascension;
    hour_angle = (hour_angle + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
        - std::f64::consts::PI;
    let lat = lat_deg.to_radians();
    let sin_el = declination.sin() * lat.sin() + declination.cos() * lat.cos() * hour_angle.cos();
    let elevation = sin_el.clamp(-1.0, 1.0).asin();
    // Azimuth from north towards east.
    let azimuth = (-declination.cos() * hour_angle.sin())
        .atan2(declination.sin() * lat.cos() - declination.cos() * lat.sin() * hour_angle.cos());
    let el_deg = elevation.to_degrees();
    // Michalsky 1988 refraction (standard pressure and temperature), degrees.
    let refraction = if el_deg > -0.56 {
        3.51561 * (0.1594 + 0.0196 * el_deg + 0.000_02 * el_deg * el_deg)
            / (1.0 + 0.505 * el_deg + 0.0845 * el_deg * el_deg)
    } else {
        0.56
    };
    SolarAngles {
        elevation_deg: (el_deg + refraction).min(90.0),
        azimuth_deg: wrap_deg(azimuth.to_degrees()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(y: i32, mo: u32, d: u32, h: u32, mi: u32, s: f64, off: f64) -> DateTime {
        DateTime {
            year: y,
            month: mo,
            day: d,
            hour: h,
            minute: mi,
            second: s,
            utc_offset_h: off,
        }
    }

    #[test]
    fn julian_date_of_j2000() {
        assert_eq!(julian_date(&at(2000, 1, 1, 12, 0, 0.0, 0.0)), 2_451_545.0);
        // Meeus example 7.a: 1957 October 4.81 = JD 2436116.31.
        let jd = julian_date(&at(1957, 10, 4, 19, 26, 24.0, 0.0));
        assert!((jd - 2_436_116.31).abs() < 1e-6, "{jd}");
    }

    /// The worked example of the NREL Solar Position Algorithm report (Reda & Andreas 2004,
    /// NREL/TP-560-34302, Table A5.1): Golden, Colorado, 2003-10-17 12:30:30 local (UTC−7),
    /// 39.742476° N, 105.1786° W: topocentric zenith 50.11162° (refraction at 820 mbar,
    /// 11 °C), azimuth 194.34024°. Michalsky's 0.01° accuracy, the parallax (0.002°) and the
    /// refraction at standard instead of 820 mbar (0.004°) keep us within 0.02°.
    #[test]
    fn matches_the_spa_report_example() {
        let a = solar_angles(&at(2003, 10, 17, 12, 30, 30.0, -7.0), 39.742476, -105.1786);
        let zenith = 90.0 - a.elevation_deg;
        assert!((zenith - 50.11162).abs() < 0.02, "zenith {zenith}");
        assert!(
            (a.azimuth_deg - 194.34024).abs() < 0.02,
            "azimuth {}",
            a.azimuth_deg
        );
    }

    /// At the June solstice the noon sun on the Tropic of Cancer stands at the zenith, and on
    /// the equator at the equinox it is 90° − |δ| high.
    #[test]
    fn solstice_noon_on_the_tropic_is_overhead() {
        // 2024-06-20 20:51 UT is the solstice; solar noon at 0° E is about 12:02 UT (equation
        // of time −1.7 min).
        let a = solar_angles(&at(2024, 6, 20, 12, 2, 0.0, 0.0), 23.44, 0.0);
        assert!(a.elevation_deg > 89.8, "{a:?}");
        let b = solar_angles(&at(2024, 12, 21, 12, 0, 0.0, 0.0), 51.48, 0.0);
        // Greenwich at the winter solstice: 90 − 51.48 − 23.44 = 15.08° (+ 0.06° refraction).
        assert!((b.elevation_deg - 15.14).abs() < 0.1, "{b:?}");
        assert!((b.azimuth_deg - 180.0).abs() < 1.0, "{b:?}");
    }
}
