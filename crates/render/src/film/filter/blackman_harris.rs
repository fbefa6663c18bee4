//! 4-term Blackman–Harris window as a pixel filter (Harris 1978, "On the use of windows for
//! harmonic analysis with the discrete Fourier transform", Proc. IEEE 66(1), the
//! −92 dB window; used as Cycles' default pixel filter). Centred on [−r, r]:
//! f₁(x) ∝ a₀ + a₁ cos(πx/r) + a₂ cos(2πx/r) + a₃ cos(3πx/r), whose integral is 2r a₀
//! (the cosines integrate to zero over whole periods).

use std::f32::consts::PI;

use super::check_radius;
use crate::InvalidParameter;

const A0: f32 = 0.35875;
const A1: f32 = 0.48829;
const A2: f32 = 0.14128;
const A3: f32 = 0.01168;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlackmanHarrisFilter {
    radius_px: f32,
}

impl Default for BlackmanHarrisFilter {
    /// Radius 2 px (support 4 px; the window's FWHM is then ≈ 1.3 px).
    fn default() -> Self {
        Self { radius_px: 2.0 }
    }
}

impl BlackmanHarrisFilter {
    /// `radius_px` > 0.
    pub fn new(radius_px: f32) -> Result<Self, InvalidParameter> {
        Ok(Self {
            radius_px: check_radius("Blackman–Harris filter", radius_px)?,
        })
    }

    pub fn radius_px(&self) -> f32 {
        self.radius_px
    }

    #[inline]
    pub fn eval_1d(&self, x_px: f32) -> f32 {
        if x_px.abs() > self.radius_px {
            return 0.0;
        }
        let t = PI * x_px / self.radius_px;
        let w = A0 + A1 * t.cos() + A2 * (2.0 * t).cos() + A3 * (3.0 * t).cos();
        w.max(0.0) / (2.0 * self.radius_px * A0)
    }
}
