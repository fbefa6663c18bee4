//! The Perez all-weather sky (Perez, Seals & Michalsky 1993, "All-weather model for sky
//! luminance distribution — preliminary configuration and validation", Solar Energy
//! 50(3):235–245, with its erratum, Solar Energy 51(5):423):
//!
//! ```text
//! l_v(ζ, γ) = (1 + a exp(b / cos ζ)) (1 + c exp(d γ) + e cos²γ)
//! ```
//!
//! ζ the zenith angle of the sky element, γ its angle from the sun; the sky's absolute level
//! is fixed by its diffuse horizontal illuminance, ∫ L cos ζ dω = E_dh. The five parameters
//! x = x1 + x2 Z + Δ (x3 + x4 Z) (Z the sun's zenith angle) come from the table of 8 sky
//! clearness (ε) bins; in bin 1, c = exp((Δ (c1 + c2 Z))^c3) − c4 and
//! d = −exp(Δ (d1 + d2 Z)) + d3 + Δ d4. Sky clearness and brightness (Perez et al. 1990,
//! "Modeling daylight availability and irradiance components from direct and global
//! irradiance", Solar Energy 44(5):271–289, eqs. 1–2):
//!
//! ```text
//! ε = ((D_h + I)/D_h + κ Z³) / (1 + κ Z³),  κ = 1.041 (Z in radians)
//! Δ = D_h m / I_0
//! ```
//!
//! with D_h and I the diffuse horizontal and direct normal irradiance, m the relative optical
//! air mass (Kasten & Young 1989) and I_0 the extraterrestrial normal irradiance. When the
//! illuminances are not given they come from the Perez 1990 luminous efficacy model (its
//! Table 4; precipitable water W = exp(0.07 T_d − 0.075) cm from the dew point T_d).
//! Like Radiance's gendaylit we keep Δ ≥ 0.2 in bins 2–5 and Δ ≥ 0.01 everywhere, limit ε
//! to 11.9, evaluate cos ζ no lower than 0.01 and clamp negative l_v to 0.

/// Upper ε bounds of bins 1–7 (bin 8 is open).
const EPSILON_BINS: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];

/// Perez 1993 Table 1 (with the erratum): per ε bin, (x1, x2, x3, x4) for x = a, b, c, d, e.
const COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// Perez 1990 Table 4, diffuse luminous efficacy a + b W + c cos Z + d ln Δ (lm/W).
const DIFFUSE_EFFICACY: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91],
    [107.22, 1.15, 0.59, -3.95],
    [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90],
    [100.71, 5.94, -22.75, -23.74],
    [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03],
    [152.23, 0.35, -45.27, -7.98],
];

/// Perez 1990 Table 4, direct luminous efficacy a + b W + c exp(5.73 Z − 5) + d Δ (lm/W).
const DIRECT_EFFICACY: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12],
    [98.99, -3.46, -1.21, 12.38],
    [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56],
    [106.36, -3.97, -1.75, -6.16],
    [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44],
    [101.18, 1.58, -1.10, -8.29],
];

/// Sky conditions of a Perez sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerezConditions {
    /// Sky clearness ε and brightness Δ.
    pub epsilon: f64,
    pub delta: f64,
    /// ε bin, 0–7.
    pub bin: usize,
    /// (a, b, c, d, e).
    pub params: [f64; 5],
    /// From the Perez 1990 efficacy model (lx).
    pub diffuse_horizontal_illuminance_lx: f64,
    pub direct_normal_illuminance_lx: f64,
}

/// Relative optical air mass (Kasten & Young 1989), sun zenith angle in radians.
pub fn air_mass(zenith_rad: f64) -> f64 {
    let z_deg = zenith_rad.to_degrees().min(93.0);
    1.0 / (zenith_rad.cos().max(0.0) + 0.50572 * (96.07995 - z_deg).powf(-1.6364))
}

/// Extraterrestrial normal irradiance on day `day_of_year`, W/m² (solar constant 1367 W/m²
/// and the eccentricity correction 1 + 0.033 cos(2π n / 365), Duffie & Beckman eq. 1.4.1a).
pub fn extraterrestrial_irradiance_w_m2(day_of_year: u32) -> f64 {
    1367.0 * (1.0 + 0.033 * (2.0 * std::f64::consts::PI * f64::from(day_of_year) / 365.0).cos())
}

impl PerezConditions {
    /// From the diffuse horizontal and direct normal irradiance (W/m², D_h > 0), the sun's
    /// zenith angle (radians, < 90°), the extraterrestrial normal irradiance (W/m²) and the
    /// dew point (°C).
    pub fn new(
        diffuse_horizontal_w_m2: f64,
        direct_normal_w_m2: f64,
        sun_zenith_rad: f64,
        extraterrestrial_w_m2: f64,
        dew_point_c: f64,
    ) -> Self {
        let z = sun_zenith_rad.clamp(0.0, std::f64::consts::FRAC_PI_2);
        let k = 1.041 * z.powi(3);
        let epsilon = (((diffuse_horizontal_w_m2 + direct_normal_w_m2) / diffuse_horizontal_w_m2
            + k)
            / (1.0 + k))
            .clamp(1.0, 11.9);
        let bin = EPSILON_BINS.iter().take_while(|&&b| epsilon >= b).count();
        let mut delta = (diffuse_horizontal_w_m2 * air_mass(z) / extraterrestrial_w_m2).max(0.01);
        let water_cm = (0.07 * dew_point_c - 0.075).exp();
        let e = DIFFUSE_EFFICACY[bin];
        let diffuse_efficacy = e[0] + e[1] * water_cm + e[2] * z.cos() + e[3] * delta.ln();
        let e = DIRECT_EFFICACY[bin];
        let direct_efficacy =
            (e[0] + e[1] * water_cm + e[2] * (5.73 * z - 5.0).exp() + e[3] * delta).max(0.0);
        if (1..=4).contains(&bin) && delta < 0.2 {
            delta = 0.2;
        }
        let x = &COEFFICIENTS[bin];
        let lin = |c: &[f64; 4]| c[0] + c[1] * z + delta * (c[2] + c[3] * z);
        let params = if bin == 0 {
            [
                lin(&x[0]),
                lin(&x[1]),
                (delta * (x[2][0] + x[2][1] * z)).powf(x[2][2]).exp() - x[2][3],
                -(delta * (x[3][0] + x[3][1] * z)).exp() + x[3][2] + delta * x[3][3],
                lin(&x[4]),
            ]
        } else {
            [lin(&x[0]), lin(&x[1]), lin(&x[2]), lin(&x[3]), lin(&x[4])]
        };
        Self {
            epsilon,
            delta,
            bin,
            params,
            diffuse_horizontal_illuminance_lx: diffuse_horizontal_w_m2 * diffuse_efficacy.max(0.0),
            direct_normal_illuminance_lx: direct_normal_w_m2 * direct_efficacy,
        }
    }

    /// l_v for a direction with cos ζ = `cos_z` at angle γ (`cos_gamma`) from the sun.
    #[inline]
    pub fn relative_luminance(&self, cos_z: f64, cos_gamma: f64) -> f64 {
        let [a, b, c, d, e] = self.params;
        let gamma = cos_gamma.clamp(-1.0, 1.0).acos();
        let l = (1.0 + a * (b / cos_z.max(0.01)).exp())
            * (1.0 + c * (d * gamma).exp() + e * cos_gamma * cos_gamma);
        l.max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clearness_bins_and_overcast_limit() {
        // Nothing direct: ε = 1, bin 1 (overcast).
        let c = PerezConditions::new(200.0, 0.0, 0.6, 1367.0, 11.0);
        assert_eq!(c.bin, 0);
        assert!((c.epsilon - 1.0).abs() < 1e-12);
        // A clear sky: D_h = 100, I = 800 at Z = 30°: ε = (9 + 0.15)/(1.15) ≈ 7.96, bin 8.
        let z = 30f64.to_radians();
        let c = PerezConditions::new(100.0, 800.0, z, 1367.0, 11.0);
        let k = 1.041 * z.powi(3);
        assert!((c.epsilon - (9.0 + k) / (1.0 + k)).abs() < 1e-12);
        assert_eq!(c.bin, 7);
        // Efficacies in the range daylight has (≈ 90–130 lm/W).
        let eff = c.diffuse_horizontal_illuminance_lx / 100.0;
        assert!((90.0..150.0).contains(&eff), "{eff}");
        let eff = c.direct_normal_illuminance_lx / 800.0;
        assert!((80.0..120.0).contains(&eff), "{eff}");
        // Clear sky: brighter near the sun than 90° away, and the horizon brighter than the
        // zenith away from the sun (horizon brightening, b < 0 with a < 0).
        let near = c.relative_luminance(z.cos(), (5f64).to_radians().cos());
        let far = c.relative_luminance(z.cos(), (90f64).to_radians().cos());
        assert!(near > 3.0 * far, "{near} {far}");
    }

    #[test]
    fn air_mass_is_one_overhead_and_about_38_at_the_horizon() {
        assert!((air_mass(0.0) - 1.0).abs() < 1e-3);
        let m = air_mass(std::f64::consts::FRAC_PI_2);
        assert!((m - 37.9).abs() < 0.5, "{m}");
    }
}
