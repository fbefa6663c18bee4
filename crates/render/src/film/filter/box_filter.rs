//! Box filter (pbrt-v4 §8.8.1): constant over [−r, r].

use super::check_radius;
use crate::InvalidParameter;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxFilter {
    radius_px: f32,
}

impl Default for BoxFilter {
    fn default() -> Self {
        Self { radius_px: 0.5 }
    }
}

impl BoxFilter {
    /// `radius_px` > 0 (½ covers exactly one pixel).
    pub fn new(radius_px: f32) -> Result<Self, InvalidParameter> {
        Ok(Self {
            radius_px: check_radius("box filter", radius_px)?,
        })
    }

    pub fn radius_px(&self) -> f32 {
        self.radius_px
    }

    /// 1/(2r) on [−r, r].
    #[inline]
    pub fn eval_1d(&self, x_px: f32) -> f32 {
        if x_px.abs() <= self.radius_px {
            0.5 / self.radius_px
        } else {
            0.0
        }
    }
}
