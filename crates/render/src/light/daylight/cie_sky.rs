//! The CIE standard general sky (ISO 15469:2004 / CIE S 011/E:2003): the luminance of a sky
//! element at zenith angle Z and angular distance χ from the sun, relative to the zenith,
//!
//! ```text
//! L/L_z = f(χ) φ(Z) / (f(Z_s) φ(0))
//! φ(Z) = 1 + a exp(b / cos Z)        (gradation; φ(π/2) = 1)
//! f(χ) = 1 + c [exp(d χ) − exp(d π/2)] + e cos²χ     (scattering indicatrix)
//! ```
//!
//! with Z_s the sun's zenith angle and (a, b, c, d, e) from the standard's Table 1 for the
//! 15 sky types. Type 0 here is the traditional CIE overcast sky (Moon & Spencer 1942; CIE
//! 1955), L/L_z = (1 + 2 cos Z)/3, whose horizontal illuminance is E_h = 7π L_z / 9.

/// (a, b, c, d, e) of sky types 1–15 (ISO 15469:2004 Table 1: six gradation groups I–VI,
/// six indicatrix groups 1–6).
pub const CIE_SKY_PARAMETERS: [[f64; 5]; 15] = [
    [4.0, -0.70, 0.0, -1.0, 0.00], // 1  overcast, steep gradation, azimuthal uniformity
    [4.0, -0.70, 2.0, -1.5, 0.15], // 2  overcast, steep gradation, slight brightening to the sun
    [1.1, -0.80, 0.0, -1.0, 0.00], // 3  overcast, moderate gradation, azimuthal uniformity
    [1.1, -0.80, 2.0, -1.5, 0.15], // 4  overcast, moderate gradation, slight brightening
    [0.0, -1.00, 0.0, -1.0, 0.00], // 5  sky of uniform luminance
    [0.0, -1.00, 2.0, -1.5, 0.15], // 6  partly cloudy, no gradation, slight brightening
    [0.0, -1.00, 5.0, -2.5, 0.30], // 7  partly cloudy, no gradation, brighter circumsolar
    [0.0, -1.00, 10.0, -3.0, 0.45], // 8  partly cloudy, no gradation, distinct solar corona
    [-1.0, -0.55, 2.0, -1.5, 0.15], // 9  partly cloudy, obscured sun
    [-1.0, -0.55, 5.0, -2.5, 0.30], // 10 partly cloudy, brighter circumsolar region
    [-1.0, -0.55, 10.0, -3.0, 0.45], // 11 white-blue sky, distinct solar corona
    [-1.0, -0.32, 10.0, -3.0, 0.45], // 12 CIE standard clear sky, low turbidity
    [-1.0, -0.32, 16.0, -3.0, 0.30], // 13 CIE standard clear sky, polluted atmosphere
    [-1.0, -0.15, 16.0, -3.0, 0.30], // 14 cloudless turbid sky, broad solar corona
    [-1.0, -0.15, 24.0, -2.8, 0.15], // 15 white-blue turbid sky, broad solar corona
];

/// φ(Z) from cos Z (≥ 0); exp(b / cos Z) → 0 at the horizon since b < 0 for every type.
#[inline]
pub fn gradation(a: f64, b: f64, cos_z: f64) -> f64 {
    if cos_z <= 0.0 {
        1.0
    } else {
        1.0 + a * (b / cos_z).exp()
    }
}

/// f(χ), χ in radians.
#[inline]
pub fn indicatrix(c: f64, d: f64, e: f64, chi: f64) -> f64 {
    let cos_chi = chi.cos();
    1.0 + c * ((d * chi).exp() - (d * std::f64::consts::FRAC_PI_2).exp()) + e * cos_chi * cos_chi
}

/// A CIE sky of one type for one sun position: L/L_z as a function of direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CieSky {
    /// 0: traditional overcast; 1–15: the standard types.
    pub sky_type: u8,
    params: [f64; 5],
    /// 1 / (f(Z_s) φ(0)).
    norm: f64,
}

impl CieSky {
    /// `sky_type` 0–15, `sun_zenith_rad` the sun's zenith angle Z_s.
    pub fn new(sky_type: u8, sun_zenith_rad: f64) -> Self {
        if sky_type == 0 {
            return Self {
                sky_type,
                params: [0.0; 5],
                norm: 1.0,
            };
        }
        let p = CIE_SKY_PARAMETERS[usize::from(sky_type.clamp(1, 15)) - 1];
        let norm =
            1.0 / (indicatrix(p[2], p[3], p[4], sun_zenith_rad) * gradation(p[0], p[1], 1.0));
        Self {
            sky_type,
            params: p,
            norm,
        }
    }

    /// L/L_z for a direction with cos Z = `cos_z` (> 0) at angle χ (`cos_chi`) from the sun.
    #[inline]
    pub fn relative_luminance(&self, cos_z: f64, cos_chi: f64) -> f64 {
        if self.sky_type == 0 {
            return (1.0 + 2.0 * cos_z.max(0.0)) / 3.0;
        }
        let [a, b, c, d, e] = self.params;
        let chi = cos_chi.clamp(-1.0, 1.0).acos();
        indicatrix(c, d, e, chi) * gradation(a, b, cos_z) * self.norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every type is 1 at the zenith (χ = Z_s there) and the traditional overcast sky is 1/3
    /// at the horizon.
    #[test]
    fn zenith_is_one_for_every_type() {
        for t in 0..=15u8 {
            for zs_deg in [0.0f64, 30.0, 60.0, 85.0] {
                let zs = zs_deg.to_radians();
                let sky = CieSky::new(t, zs);
                let r = sky.relative_luminance(1.0, zs.cos());
                assert!((r - 1.0).abs() < 1e-12, "type {t}, Z_s {zs_deg}: {r}");
            }
        }
        assert!((CieSky::new(0, 0.3).relative_luminance(0.0, 0.5) - 1.0 / 3.0).abs() < 1e-12);
    }
}
