//! Pixel reconstruction filters (pbrt-v4 §8.8 "Image reconstruction"). Every filter is
//! separable, f(x, y) = f₁(x) f₁(y), supported on [−r, r]² with r = `radius_px`, and
//! `eval` is normalised so that ∫∫ f = 1 (the Mitchell–Netravali filter has negative lobes;
//! its integral is still 1).

mod blackman_harris;
mod box_filter;
mod gaussian;
mod mitchell;

pub use blackman_harris::BlackmanHarrisFilter;
pub use box_filter::BoxFilter;
pub use gaussian::GaussianFilter;
pub use mitchell::MitchellFilter;

use glam::Vec2;

/// A pixel filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    Box(BoxFilter),
    Gaussian(GaussianFilter),
    BlackmanHarris(BlackmanHarrisFilter),
    Mitchell(MitchellFilter),
}

impl Default for Filter {
    /// A box of radius ½ px: each sample counts for its own pixel only, with equal weight.
    fn default() -> Self {
        Filter::Box(BoxFilter::default())
    }
}

impl Filter {
    /// Support radius in pixels (same in x and y).
    pub fn radius_px(&self) -> f32 {
        match self {
            Filter::Box(f) => f.radius_px(),
            Filter::Gaussian(f) => f.radius_px(),
            Filter::BlackmanHarris(f) => f.radius_px(),
            Filter::Mitchell(f) => f.radius_px(),
        }
    }

    /// The normalised 1D profile f₁(x) (∫ f₁ = 1 over [−r, r]; 0 outside).
    pub fn eval_1d(&self, x_px: f32) -> f32 {
        match self {
            Filter::Box(f) => f.eval_1d(x_px),
            Filter::Gaussian(f) => f.eval_1d(x_px),
            Filter::BlackmanHarris(f) => f.eval_1d(x_px),
            Filter::Mitchell(f) => f.eval_1d(x_px),
        }
    }

    /// f(offset) = f₁(x) f₁(y), offset in pixels from the pixel centre.
    #[inline]
    pub fn eval(&self, offset_px: Vec2) -> f32 {
        self.eval_1d(offset_px.x) * self.eval_1d(offset_px.y)
    }
}

/// ∫ g over [a, b] by composite Simpson's rule with `n` (even) intervals.
pub(crate) fn simpson(g: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = g(a) + g(b);
    for i in 1..n {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * g(a + i as f64 * h);
    }
    sum * h / 3.0
}

/// Checks a filter radius: finite and > 0.
pub(crate) fn check_radius(
    context: &'static str,
    radius_px: f32,
) -> Result<f32, crate::InvalidParameter> {
    crate::error::positive(context, "radius_px", radius_px)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_filters() -> Vec<Filter> {
        vec![
            Filter::Box(BoxFilter::new(0.5).unwrap()),
            Filter::Box(BoxFilter::new(1.3).unwrap()),
            Filter::Gaussian(GaussianFilter::default()),
            Filter::Gaussian(GaussianFilter::new(2.5, 0.7).unwrap()),
            Filter::BlackmanHarris(BlackmanHarrisFilter::default()),
            Filter::Mitchell(MitchellFilter::default()),
            Filter::Mitchell(MitchellFilter::new(1.5, 0.0, 0.5).unwrap()),
        ]
    }

    #[test]
    fn filters_integrate_to_one_in_2d() {
        for f in all_filters() {
            let r = f.radius_px() as f64;
            // Midpoint rule on a fine grid (the box's edges are grid-aligned).
            let n = 800;
            let h = 2.0 * r / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let p = Vec2::new(
                        (-r + (i as f64 + 0.5) * h) as f32,
                        (-r + (j as f64 + 0.5) * h) as f32,
                    );
                    sum += f.eval(p) as f64;
                }
            }
            let integral = sum * h * h;
            assert!((integral - 1.0).abs() < 2e-3, "{f:?}: {integral}");
        }
    }

    #[test]
    fn filters_vanish_outside_their_radius_and_are_symmetric() {
        for f in all_filters() {
            let r = f.radius_px();
            assert_eq!(f.eval(Vec2::new(r * 1.01, 0.0)), 0.0, "{f:?}");
            assert_eq!(f.eval(Vec2::new(0.0, -r * 1.01)), 0.0, "{f:?}");
            for x in [0.1, 0.37, 0.8] {
                let x = x * r;
                assert!((f.eval_1d(x) - f.eval_1d(-x)).abs() < 1e-6, "{f:?}");
            }
            assert!(f.eval(Vec2::ZERO) > 0.0);
        }
    }
}
