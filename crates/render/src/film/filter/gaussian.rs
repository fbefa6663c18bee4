//! Truncated Gaussian filter (pbrt-v3 §7.8.2 "Gaussian filter"; pbrt-v4 §8.8.2 uses σ with
//! α = 1/(2σ²)): f₁(x) ∝ exp(−α x²) − exp(−α r²), shifted so it reaches 0 at the radius.

use super::{check_radius, simpson};
use crate::InvalidParameter;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianFilter {
    radius_px: f32,
    alpha_per_px2: f32,
    exp_at_radius: f32,
    /// 1 / ∫ (exp(−α x²) − exp(−α r²)) dx over [−r, r].
    inv_integral: f32,
}

impl Default for GaussianFilter {
    /// pbrt-v4's default: radius 1.5 px, σ = ½ px (α = 2 px⁻²).
    fn default() -> Self {
        Self::new(1.5, 2.0).expect("valid default")
    }
}

impl GaussianFilter {
    /// `radius_px` > 0, `alpha_per_px2` > 0 (falloff rate; α = 1/(2σ²)).
    pub fn new(radius_px: f32, alpha_per_px2: f32) -> Result<Self, InvalidParameter> {
        let r = check_radius("Gaussian filter", radius_px)?;
        let a = crate::error::positive("Gaussian filter", "alpha_per_px2", alpha_per_px2)?;
        let e = (-(a as f64) * (r as f64).powi(2)).exp();
        let integral = simpson(
            |x| (-(a as f64) * x * x).exp() - e,
            -(r as f64),
            r as f64,
            2048,
        );
        if !(integral > 0.0 && integral.is_finite()) {
            return Err(InvalidParameter::new(
                "Gaussian filter",
                "alpha_per_px2",
                alpha_per_px2,
                "large enough that exp(−α r²) < 1 in f32 (α r² ≳ 1e-6)",
            ));
        }
        Ok(Self {
            radius_px: r,
            alpha_per_px2: a,
            exp_at_radius: e as f32,
            inv_integral: (1.0 / integral) as f32,
        })
    }

    pub fn radius_px(&self) -> f32 {
        self.radius_px
    }

    pub fn alpha_per_px2(&self) -> f32 {
        self.alpha_per_px2
    }

    #[inline]
    pub fn eval_1d(&self, x_px: f32) -> f32 {
        if x_px.abs() > self.radius_px {
            return 0.0;
        }
        ((-self.alpha_per_px2 * x_px * x_px).exp() - self.exp_at_radius).max(0.0)
            * self.inv_integral
    }
}
