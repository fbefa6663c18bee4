//! What a thin lens does to a pixel's per-sample variance (beyond the paper). A camera
//! sample of an out-of-focus pixel takes a lens point, and its ray meets the scene where a
//! pinhole pixel up to half a circle of confusion away would look. By the law of total
//! variance over the lens point, the pixel's per-sample variance is the mean of those
//! pixels' own variances plus the variance of their means:
//!
//!   V̂′_p = mean_{q ∈ W_p} V̂_q + var_{q ∈ W_p} L_q,   L̂′_p = mean_{q ∈ W_p} L̂_q,
//!
//! with W_p the square of half-width ⌊c_p/2⌋ px around p (the circle of confusion c_p at
//! the pixel's centre hit, as a box), clipped to the image, and L_q each pixel's own mean
//! (not the pooled L̂, which the pooling window has already spread across edges). The
//! pinhole probe sees one point per pixel, so without this a defocused pixel over an edge
//! in the scene is predicted as smooth as either side, and its variance is the lens's
//! mixing of the two.
//! The image's blur itself is `defocus_low_pass` in the renderer (Soler et al. 2009).
//!
//! The window sums come from summed-area tables (f64), so any circle of confusion costs
//! the same per pixel.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};

/// Per-pixel planes the mixing reads and rewrites, row-major, as long as the image.
pub struct DefocusPlanes<'a> {
    /// Circle of confusion per pixel, diameter in pixels (≤ 2: in focus, left alone).
    pub circle_of_confusion_px: &'a [f32],
    /// V̂_p (with the colour term), Y² per camera sample.
    pub variance: &'a mut [f32],
    /// V̂_p's luminance part, Y² per camera sample.
    pub luminance_variance: &'a mut [f32],
    /// L̂_p (pooled), Y.
    pub mean_y: &'a mut [f32],
    /// Each pixel's own mean L_p (its probe's, unpooled), Y: the spread of these over the
    /// window is the lens's mixing term.
    pub own_mean_y: &'a [f32],
}

/// Prefix sums of `values` over the image: entry (x, y) of a (W+1)×(H+1) table holds the
/// sum over [0, x) × [0, y).
fn summed_area(resolution: UVec2, values: impl Fn(usize) -> f64) -> Vec<f64> {
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let mut table = vec![0.0; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0.0;
        for x in 0..w {
            row += values(y * w + x);
            table[(y + 1) * (w + 1) + x + 1] = table[y * (w + 1) + x + 1] + row;
        }
    }
    table
}

/// The sum of a table's values over [x0, x1) × [y0, y1).
fn window_sum(
    table: &[f64],
    width: usize,
    (x0, x1): (usize, usize),
    (y0, y1): (usize, usize),
) -> f64 {
    let at = |x: usize, y: usize| table[y * (width + 1) + x];
    at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0)
}

/// Replaces V̂, its luminance part and L̂ of every pixel whose circle of confusion is wider
/// than 2 px by the lens's mixture over its window (module docs); the others keep theirs.
pub fn mix_over_circles_of_confusion(
    resolution: UVec2,
    planes: DefocusPlanes<'_>,
) -> Result<(), BandwidthError> {
    let n = pixel_count("defocus mixing", resolution)?;
    check_lengths(
        resolution,
        n,
        &[
            (
                "defocus circle of confusion",
                planes.circle_of_confusion_px.len(),
            ),
            ("defocus variance", planes.variance.len()),
            (
                "defocus luminance variance",
                planes.luminance_variance.len(),
            ),
            ("defocus mean", planes.mean_y.len()),
            ("defocus own mean", planes.own_mean_y.len()),
        ],
    )?;
    let finite = |v: f32| if v.is_finite() { f64::from(v) } else { 0.0 };
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let v_sum = summed_area(resolution, |i| finite(planes.variance[i]));
    let vy_sum = summed_area(resolution, |i| finite(planes.luminance_variance[i]));
    let l_sum = summed_area(resolution, |i| finite(planes.mean_y[i]));
    let own_sum = summed_area(resolution, |i| finite(planes.own_mean_y[i]));
    let own2_sum = summed_area(resolution, |i| finite(planes.own_mean_y[i]).powi(2));
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let coc = planes.circle_of_confusion_px[i];
            // NaN (no circle) and circles up to 2 px leave the pixel alone.
            if coc.is_nan() || coc <= 2.0 {
                continue;
            }
            // Half-width in whole pixels; a circle wider than the image covers all of it.
            let half = (0.5 * coc).min((w + h) as f32) as usize;
            let xs = (x.saturating_sub(half), (x + half + 1).min(w));
            let ys = (y.saturating_sub(half), (y + half + 1).min(h));
            let count = ((xs.1 - xs.0) * (ys.1 - ys.0)) as f64;
            let mean_l = window_sum(&l_sum, w, xs, ys) / count;
            let mean_own = window_sum(&own_sum, w, xs, ys) / count;
            let spread = (window_sum(&own2_sum, w, xs, ys) / count - mean_own * mean_own).max(0.0);
            planes.variance[i] = (window_sum(&v_sum, w, xs, ys) / count + spread) as f32;
            planes.luminance_variance[i] = (window_sum(&vy_sum, w, xs, ys) / count + spread) as f32;
            planes.mean_y[i] = mean_l as f32;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Planes {
        coc: Vec<f32>,
        v: Vec<f32>,
        vy: Vec<f32>,
        l: Vec<f32>,
        own: Vec<f32>,
    }

    impl Planes {
        fn new(n: usize, coc: f32) -> Self {
            Self {
                coc: vec![coc; n],
                v: vec![0.0; n],
                vy: vec![0.0; n],
                l: vec![0.0; n],
                own: vec![0.0; n],
            }
        }

        /// Mixes with each pixel's own mean equal to its pooled one.
        fn mix(&mut self, resolution: UVec2) -> Result<(), BandwidthError> {
            self.own = self.l.clone();
            self.mix_with_own_means(resolution)
        }

        /// Mixes with the own means in `self.own` as they are.
        fn mix_with_own_means(&mut self, resolution: UVec2) -> Result<(), BandwidthError> {
            mix_over_circles_of_confusion(
                resolution,
                DefocusPlanes {
                    circle_of_confusion_px: &self.coc,
                    variance: &mut self.v,
                    luminance_variance: &mut self.vy,
                    mean_y: &mut self.l,
                    own_mean_y: &self.own,
                },
            )
        }
    }

    #[test]
    fn a_uniform_image_keeps_its_variance_and_mean() {
        let mut p = Planes::new(108, 7.0);
        p.v.fill(0.3);
        p.vy.fill(0.2);
        p.l.fill(0.5);
        p.mix(UVec2::new(12, 9)).unwrap();
        assert!(p.v.iter().all(|&v| (v - 0.3).abs() < 1e-6));
        assert!(p.vy.iter().all(|&v| (v - 0.2).abs() < 1e-6));
        assert!(p.l.iter().all(|&l| (l - 0.5).abs() < 1e-6));
    }

    /// A noiseless step from 0 to 1 seen through a 6-px circle (a 7 × 7 window): a pixel
    /// whose window holds k columns of the bright side has mean k/7 and variance
    /// (k/7)(1 − k/7); pixels whose window lies on one side stay noiseless.
    #[test]
    fn a_step_mixes_into_the_variance_of_its_two_sides() {
        let mut p = Planes::new(200, 6.0);
        for y in 0..10 {
            for x in 10..20 {
                p.l[y * 20 + x] = 1.0;
            }
        }
        p.mix(UVec2::new(20, 10)).unwrap();
        for x in 0..20usize {
            let i = 5 * 20 + x;
            let k = (x + 4).saturating_sub(10).min(7) as f32;
            let m = k / 7.0;
            assert!((p.l[i] - m).abs() < 1e-6, "x {x}: mean {}", p.l[i]);
            assert!(
                (p.v[i] - m * (1.0 - m)).abs() < 1e-6,
                "x {x}: variance {}",
                p.v[i]
            );
            assert_eq!(p.v[i], p.vy[i]);
        }
    }

    /// The spread comes from the pixels' own means, not from the pooled ones (which the
    /// pooling has already smoothed): a flat pooled L̂ over a step in the own means still
    /// mixes into the step's variance, and L̂′ is the pooled one's window mean.
    #[test]
    fn the_spread_is_of_the_pixels_own_means() {
        let (r, n) = (UVec2::new(20, 10), 200);
        let mut p = Planes::new(n, 6.0);
        p.l.fill(0.5);
        p.own = (0..n)
            .map(|i| if i % 20 >= 10 { 1.0 } else { 0.0 })
            .collect();
        p.mix_with_own_means(r).unwrap();
        let i = 5 * 20 + 10; // 4 of 7 columns bright
        let m = 4.0 / 7.0;
        assert!((p.v[i] - m * (1.0 - m)).abs() < 1e-6, "{}", p.v[i]);
        assert!((p.l[i] - 0.5).abs() < 1e-6);
    }

    #[test]
    fn pixels_in_focus_are_left_alone() {
        let mut p = Planes::new(64, 2.0);
        for (i, l) in p.l.iter_mut().enumerate() {
            *l = i as f32;
        }
        let before = p.l.clone();
        p.mix(UVec2::new(8, 8)).unwrap();
        assert_eq!(p.l, before);
        assert!(p.v.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn planes_of_the_wrong_length_are_refused() {
        let mut p = Planes::new(10, 4.0);
        assert!(p.mix(UVec2::new(4, 4)).is_err());
    }
}
