//! Mitchell–Netravali cubic filter (Mitchell & Netravali 1988, "Reconstruction filters in
//! computer graphics", SIGGRAPH; pbrt-v4 §8.8.4). The cubic k(t) on |t| < 2 has unit
//! integral for every (B, C); it is stretched to radius r as f₁(x) = (2/r) k(2x/r).
//! B = C = ⅓ is the authors' recommendation; B + 2C = 1 keeps it interpolating a constant.

use super::check_radius;
use crate::InvalidParameter;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MitchellFilter {
    radius_px: f32,
    b: f32,
    c: f32,
}

impl Default for MitchellFilter {
    /// Radius 2 px, B = C = ⅓.
    fn default() -> Self {
        Self {
            radius_px: 2.0,
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        }
    }
}

impl MitchellFilter {
    /// `radius_px` > 0; `b`, `c` finite (the useful region is 0 ≤ B, C ≤ 1).
    pub fn new(radius_px: f32, b: f32, c: f32) -> Result<Self, InvalidParameter> {
        let radius_px = check_radius("Mitchell filter", radius_px)?;
        for (name, v) in [("b", b), ("c", c)] {
            if !v.is_finite() {
                return Err(InvalidParameter::new(
                    "Mitchell filter",
                    name,
                    v,
                    "a finite number (usually in [0, 1])",
                ));
            }
        }
        Ok(Self { radius_px, b, c })
    }

    pub fn radius_px(&self) -> f32 {
        self.radius_px
    }

    pub fn b(&self) -> f32 {
        self.b
    }

    pub fn c(&self) -> f32 {
        self.c
    }

    /// The cubic k(t), |t| < 2 (pbrt-v4 `MitchellFilter::Mitchell1D`).
    #[inline]
    fn kernel(&self, t: f32) -> f32 {
        let (b, c) = (self.b, self.c);
        let x = t.abs();
        if x <= 1.0 {
            ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
                + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                + (6.0 - 2.0 * b))
                / 6.0
        } else if x <= 2.0 {
            ((-b - 6.0 * c) * x * x * x
                + (6.0 * b + 30.0 * c) * x * x
                + (-12.0 * b - 48.0 * c) * x
                + (8.0 * b + 24.0 * c))
                / 6.0
        } else {
            0.0
        }
    }

    #[inline]
    pub fn eval_1d(&self, x_px: f32) -> f32 {
        if x_px.abs() > self.radius_px {
            return 0.0;
        }
        2.0 / self.radius_px * self.kernel(2.0 * x_px / self.radius_px)
    }
}
