//! `--exposure auto`: the exposure (in stops) that maps the image's log-average luminance
//! to middle grey, as a camera's averaging meter would.
//!
//! Prism's renders are absolute (W·m⁻²·sr⁻¹ per unit, luminances of 10⁻³ or 10⁴ are both
//! normal), so operators that are not scale invariant (linear, aces, agx, …) need an
//! exposure before they show anything. The key is Reinhard et al. 2002's middle grey
//! (eq. 2, a = 0.18); the average is the geometric mean over pixels with a finite, positive
//! luminance (black and non-finite pixels carry no information about the exposure, and a
//! δ offset as in eq. 1 would make the result depend on the image's units).

use rayon::prelude::*;

use prism_image::Image;

/// Middle grey that the log-average luminance is mapped to (Reinhard et al. 2002, eq. 2).
pub const AUTO_EXPOSURE_KEY: f64 = 0.18;

/// The exposure in stops, EV = log2(key / L̄) with L̄ = exp(mean ln Y) over the pixels
/// whose luminance Y is finite and > 0; `None` when no pixel has one (a black image).
pub fn auto_exposure_ev(image: &Image) -> Option<f64> {
    let (sum_ln, count) = log_luminance_sums(image.pixels(), image.luminance_weights());
    exposure_ev_from_sums(sum_ln, count)
}

/// Σ ln Y and the count over the pixels whose luminance Y = `weights` · RGB is finite and
/// > 0: sums of bands of an image add up to the whole image's.
pub fn log_luminance_sums(pixels: &[[f32; 3]], weights: [f32; 3]) -> (f64, u64) {
    let w = weights;
    pixels
        .par_chunks(4096)
        .map(|chunk| {
            chunk.iter().fold((0.0f64, 0u64), |(sum, n), p| {
                let y = w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
                if y.is_finite() && y > 0.0 {
                    (sum + f64::from(y).ln(), n + 1)
                } else {
                    (sum, n)
                }
            })
        })
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// [`auto_exposure_ev`] from [`log_luminance_sums`].
pub fn exposure_ev_from_sums(sum_ln: f64, count: u64) -> Option<f64> {
    if count == 0 {
        return None;
    }
    let log_average = (sum_ln / count as f64).exp();
    Some((AUTO_EXPOSURE_KEY / log_average).log2())
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::rgb_space::RgbColorSpace;

    fn grey_image(values: &[f32]) -> Image {
        let pixels = values.iter().map(|&v| [v, v, v]).collect();
        Image::new(values.len(), 1, pixels, RgbColorSpace::srgb()).unwrap()
    }

    #[test]
    fn maps_the_geometric_mean_to_middle_grey() {
        // Geometric mean of 1e-3 and 4e-3 is 2e-3: EV = log2(0.18 / 2e-3).
        let image = grey_image(&[1e-3, 4e-3, 0.0, f32::NAN, -1.0]);
        let ev = auto_exposure_ev(&image).unwrap();
        let expected = (0.18f64 / 2e-3).log2();
        assert!((ev - expected).abs() < 1e-5, "{ev} vs {expected}");
    }

    #[test]
    fn is_independent_of_the_units() {
        let a = auto_exposure_ev(&grey_image(&[0.5, 2.0, 8.0])).unwrap();
        let b = auto_exposure_ev(&grey_image(&[500.0, 2000.0, 8000.0])).unwrap();
        assert!((a - b - 1000f64.log2()).abs() < 1e-5);
    }

    #[test]
    fn black_image_has_no_exposure() {
        assert_eq!(auto_exposure_ev(&grey_image(&[0.0, 0.0])), None);
    }
}
