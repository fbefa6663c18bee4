//! The Preetham sky (Preetham, Shirley & Smits 1999, "A practical analytic model for
//! daylight", SIGGRAPH '99, Appendix A.2): luminance Y and chromaticity (x, y) of a sky
//! element at zenith angle θ and angle γ from the sun, for turbidity T, each as
//!
//! ```text
//! Q(θ, γ) = Q_z · F(θ, γ) / F(0, θ_s)
//! F(θ, γ) = (1 + A exp(B / cos θ)) (1 + C exp(D γ) + E cos²γ)      (Perez et al. 1993)
//! ```
//!
//! with the distribution coefficients linear in T (A.2, eq. 2 matrices), the zenith luminance
//! Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192 kcd/m², χ = (4/9 − T/120)(π − 2θ_s),
//! and the zenith chromaticity cubic in θ_s and quadratic in T. The spectrum of an element is
//! the CIE daylight of its chromaticity, S0 + M1 S1 + M2 S2 (the paper's §A.3 method),
//! scaled to the luminance Y.

/// Distribution coefficients (A, B, C, D, E) = p·T + q for Y, x and y (Preetham 1999 eq. A.2).
const Y_COEFFS: [[f64; 2]; 5] = [
    [0.1787, -1.4630],
    [-0.3554, 0.4275],
    [-0.0227, 5.3251],
    [0.1206, -2.5771],
    [-0.0670, 0.3703],
];
const X_COEFFS: [[f64; 2]; 5] = [
    [-0.0193, -0.2592],
    [-0.0665, 0.0008],
    [-0.0004, 0.2125],
    [-0.0641, -0.8989],
    [-0.0033, 0.0452],
];
const YC_COEFFS: [[f64; 2]; 5] = [
    [-0.0167, -0.2608],
    [-0.0950, 0.0092],
    [-0.0079, 0.2102],
    [-0.0441, -1.6537],
    [-0.0109, 0.0529],
];

/// Zenith chromaticity x_z = [T² T 1] M [θ³ θ² θ 1]ᵀ (Preetham 1999 A.2).
const XZ_MATRIX: [[f64; 4]; 3] = [
    [0.00166, -0.00375, 0.00209, 0.0],
    [-0.02903, 0.06377, -0.03202, 0.00394],
    [0.11693, -0.21196, 0.06052, 0.25886],
];
const YZ_MATRIX: [[f64; 4]; 3] = [
    [0.00275, -0.00610, 0.00317, 0.0],
    [-0.04214, 0.08970, -0.04153, 0.00516],
    [0.15346, -0.26756, 0.06670, 0.26688],
];

#[derive(Clone, Copy, Debug, PartialEq)]
struct Distribution {
    coeffs: [f64; 5],
    /// Q_z / F(0, θ_s).
    scale: f64,
}

impl Distribution {
    fn new(table: &[[f64; 2]; 5], turbidity: f64, sun_zenith: f64, zenith_value: f64) -> Self {
        let coeffs = table.map(|[p, q]| p * turbidity + q);
        let f0 = perez_f(&coeffs, 1.0, sun_zenith.cos());
        Self {
            coeffs,
            scale: zenith_value / f0,
        }
    }

    #[inline]
    fn eval(&self, cos_theta: f64, cos_gamma: f64) -> f64 {
        self.scale * perez_f(&self.coeffs, cos_theta, cos_gamma)
    }
}

#[inline]
fn perez_f(c: &[f64; 5], cos_theta: f64, cos_gamma: f64) -> f64 {
    let gamma = cos_gamma.clamp(-1.0, 1.0).acos();
    // cos θ is kept ≥ 0.01 like the Perez sky (B < 0 for T ≥ 1.2, so this only avoids 0/0).
    (1.0 + c[0] * (c[1] / cos_theta.max(0.01)).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * cos_gamma * cos_gamma)
}

fn zenith_chromaticity(m: &[[f64; 4]; 3], turbidity: f64, theta_s: f64) -> f64 {
    let t = [turbidity * turbidity, turbidity, 1.0];
    let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
    (0..3)
        .map(|i| t[i] * (0..4).map(|j| m[i][j] * th[j]).sum::<f64>())
        .sum()
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreethamSky {
    pub turbidity: f64,
    /// Zenith luminance, cd/m².
    pub zenith_luminance_cd_m2: f64,
    pub zenith_xy: (f64, f64),
    luminance: Distribution,
    x: Distribution,
    y: Distribution,
}

impl PreethamSky {
    /// Turbidity T (≈ 2–10) and the sun's zenith angle θ_s (radians, ≤ 90°).
    pub fn new(turbidity: f64, sun_zenith_rad: f64) -> Self {
        let t = turbidity;
        let ts = sun_zenith_rad.clamp(0.0, std::f64::consts::FRAC_PI_2);
        let chi = (4.0 / 9.0 - t / 120.0) * (std::f64::consts::PI - 2.0 * ts);
        let yz = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192) * 1000.0;
        let xz = zenith_chromaticity(&XZ_MATRIX, t, ts);
        let yzc = zenith_chromaticity(&YZ_MATRIX, t, ts);
        Self {
            turbidity,
            zenith_luminance_cd_m2: yz.max(0.0),
            zenith_xy: (xz, yzc),
            luminance: Distribution::new(&Y_COEFFS, t, ts, yz.max(0.0)),
            x: Distribution::new(&X_COEFFS, t, ts, xz),
            y: Distribution::new(&YC_COEFFS, t, ts, yzc),
        }
    }

    /// Luminance in cd/m² (the model's absolute level) of a direction above the horizon.
    #[inline]
    pub fn luminance_cd_m2(&self, cos_theta: f64, cos_gamma: f64) -> f64 {
        self.luminance.eval(cos_theta, cos_gamma).max(0.0)
    }

    /// Chromaticity (x, y).
    #[inline]
    pub fn chromaticity(&self, cos_theta: f64, cos_gamma: f64) -> (f64, f64) {
        (
            self.x.eval(cos_theta, cos_gamma),
            self.y.eval(cos_theta, cos_gamma),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zenith values by hand from the formulas for T = 3, θ_s = 45°: χ = (4/9 − 1/40)(π/2),
    /// Y_z = (4.0453·3 − 4.9710) tan χ − 0.2155·3 + 2.4192 kcd/m²; and the model returns them
    /// at the zenith.
    #[test]
    fn zenith_values_follow_the_formulas() {
        let ts = std::f64::consts::FRAC_PI_4;
        let sky = PreethamSky::new(3.0, ts);
        let chi = (4.0 / 9.0 - 3.0 / 120.0) * (std::f64::consts::PI - 2.0 * ts);
        let yz = ((4.0453 * 3.0 - 4.9710) * chi.tan() - 0.2155 * 3.0 + 2.4192) * 1e3;
        assert!((sky.zenith_luminance_cd_m2 - yz).abs() < 1e-9);
        assert!((sky.luminance_cd_m2(1.0, ts.cos()) - yz).abs() < 1e-9 * yz);
        let (x, y) = sky.chromaticity(1.0, ts.cos());
        assert!((x - sky.zenith_xy.0).abs() < 1e-12 && (y - sky.zenith_xy.1).abs() < 1e-12);
        // A clear sky's zenith is bluish: x, y below the equal-energy white (1/3, 1/3) and
        // near the daylight locus (x ≈ 0.25–0.31).
        assert!(
            (0.24..0.31).contains(&x) && (0.24..0.33).contains(&y),
            "{x} {y}"
        );
    }
}
