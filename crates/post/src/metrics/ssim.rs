//! Structural similarity, Wang, Bovik, Sheikh & Simoncelli 2004, "Image Quality
//! Assessment: From Error Visibility to Structural Similarity", IEEE TIP 13(4), eq. 13 with
//! the paper's settings: 11×11 circular-symmetric Gaussian window, σ = 1.5 (normalised to
//! unit sum), K1 = 0.01, K2 = 0.03, C1 = (K1 L)², C2 = (K2 L)², mean over the positions
//! where the window fits inside the image (as the authors' reference code, 'valid').

use rayon::prelude::*;

use super::ordered_sum::OrderedSum;

const RADIUS: usize = 5;
const SIGMA: f64 = 1.5;

fn kernel() -> [f32; 2 * RADIUS + 1] {
    let mut k = [0.0f64; 2 * RADIUS + 1];
    for (i, v) in k.iter_mut().enumerate() {
        let x = i as f64 - RADIUS as f64;
        *v = (-x * x / (2.0 * SIGMA * SIGMA)).exp();
    }
    let sum: f64 = k.iter().sum();
    k.map(|v| (v / sum) as f32)
}

/// Separable 'valid' Gaussian blur of a w×h plane → (w−10)×(h−10).
fn blur_valid(plane: &[f32], w: usize, h: usize, k: &[f32; 2 * RADIUS + 1]) -> Vec<f32> {
    let (ow, oh) = (w - 2 * RADIUS, h - 2 * RADIUS);
    let mut horizontal = vec![0.0f32; ow * h];
    horizontal
        .par_chunks_mut(ow)
        .zip(plane.par_chunks(w))
        .for_each(|(out, row)| {
            for (x, o) in out.iter_mut().enumerate() {
                *o = row[x..x + 2 * RADIUS + 1]
                    .iter()
                    .zip(k)
                    .map(|(a, b)| a * b)
                    .sum();
            }
        });
    let mut out = vec![0.0f32; ow * oh];
    out.par_chunks_mut(ow).enumerate().for_each(|(y, row)| {
        for (t, kt) in k.iter().enumerate() {
            let src = &horizontal[(y + t) * ow..(y + t + 1) * ow];
            for (o, s) in row.iter_mut().zip(src) {
                *o += kt * s;
            }
        }
    });
    out
}

/// Side of the window: SSIM has a value for the positions where it fits in the image.
pub(crate) const WINDOW: usize = 2 * RADIUS + 1;

/// Whether a w×h image has at least one window position.
pub(crate) fn fits(w: usize, h: usize) -> bool {
    w >= WINDOW && h >= WINDOW
}

/// Mean SSIM of two w×h planes with dynamic range `l`; `None` when the image is smaller
/// than the 11×11 window.
pub(crate) fn ssim(x: &[f32], y: &[f32], w: usize, h: usize, l: f64) -> Option<f64> {
    if !fits(w, h) {
        return None;
    }
    // Moments of x − mean(x): variances are shift-invariant, and centring keeps the f32
    // moments E[x²] − μ² from cancelling catastrophically (exact for flat regions).
    let mean = |v: &[f32]| {
        let mut sum = OrderedSum::new();
        sum.add_range(0, v.len(), |i| v[i] as f64);
        (sum.finish() / v.len() as f64) as f32
    };
    let (mean_x, mean_y) = (mean(x), mean(y));
    let x: Vec<f32> = x.par_iter().map(|a| a - mean_x).collect();
    let y: Vec<f32> = y.par_iter().map(|a| a - mean_y).collect();
    let mut sum = OrderedSum::new();
    add_window_terms(&x, &y, w, (mean_x, mean_y), l, 0, &mut sum);
    let positions = (w - 2 * RADIUS) * (h - 2 * RADIUS);
    Some(sum.finish() / positions as f64)
}

/// Adds to `sum` the SSIM of every window position inside rows of the centred planes `x`
/// and `y` (w wide, at least 11 rows: one output row per input row but the last 10), as
/// terms `first …` of the image's sum (positions row-major over the image's
/// (w − 10)-wide grid of windows). `means` are the means the planes were centred on.
pub(crate) fn add_window_terms(
    x: &[f32],
    y: &[f32],
    w: usize,
    (mean_x, mean_y): (f32, f32),
    l: f64,
    first: usize,
    sum: &mut OrderedSum,
) {
    let h = x.len() / w;
    let k = kernel();
    let product = |a: &[f32], b: &[f32]| -> Vec<f32> {
        a.par_iter().zip(b.par_iter()).map(|(p, q)| p * q).collect()
    };
    let mu_x = blur_valid(x, w, h, &k);
    let mu_y = blur_valid(y, w, h, &k);
    let xx = blur_valid(&product(x, x), w, h, &k);
    let yy = blur_valid(&product(y, y), w, h, &k);
    let xy = blur_valid(&product(x, y), w, h, &k);
    let c1 = (0.01 * l).powi(2);
    let c2 = (0.03 * l).powi(2);
    sum.add_range(first, mu_x.len(), |i| {
        let (cx, cy) = (mu_x[i] as f64, mu_y[i] as f64);
        let sxx = xx[i] as f64 - cx * cx;
        let syy = yy[i] as f64 - cy * cy;
        let sxy = xy[i] as f64 - cx * cy;
        let (mx, my) = (cx + mean_x as f64, cy + mean_y as f64);
        ((2.0 * mx * my + c1) * (2.0 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise_plane(w: usize, h: usize, seed: u32) -> Vec<f32> {
        let mut s = seed;
        (0..w * h)
            .map(|_| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1u32 << 24) as f32
            })
            .collect()
    }

    #[test]
    fn identical_images_have_ssim_one() {
        let a = noise_plane(40, 30, 7);
        // Each term is (2μ²+C1)(2σ²+C2)/((2μ²+C1)(2σ²+C2)) = 1 up to f32 rounding of the
        // blurred moments.
        assert!((ssim(&a, &a, 40, 30, 1.0).unwrap() - 1.0).abs() < 1e-6);
        assert_eq!(ssim(&a[..100], &a[..100], 10, 10, 1.0), None);
    }

    #[test]
    fn constant_images_follow_the_luminance_term() {
        // Flat images: σ = 0, so SSIM = (2 μx μy + C1) / (μx² + μy² + C1) exactly.
        let (w, h) = (16, 12);
        let (a, b) = (vec![0.2f32; w * h], vec![0.6f32; w * h]);
        let c1 = 0.01f64.powi(2);
        let want = (2.0 * 0.2 * 0.6 + c1) / (0.04 + 0.36 + c1);
        let got = ssim(&a, &b, w, h, 1.0).unwrap();
        // Blurring a constant in f32 reproduces it to ~1e-7 relative.
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
    }

    #[test]
    fn noise_lowers_ssim_and_it_is_symmetric() {
        let (w, h) = (48, 48);
        let a = noise_plane(w, h, 1);
        let b: Vec<f32> = a
            .iter()
            .zip(noise_plane(w, h, 2))
            .map(|(x, n)| x + 0.3 * (n - 0.5))
            .collect();
        let ab = ssim(&a, &b, w, h, 1.0).unwrap();
        let ba = ssim(&b, &a, w, h, 1.0).unwrap();
        // Independent noise n (variance 0.09/12) on uniform x (variance 1/12): σxy = σx²,
        // σy² = σx² + σn², so the structure term ≈ 2σx² / (2σx² + σn²) = 2 / 2.09 = 0.957
        // (means equal: luminance term ≈ 1). Windows hold ~4πσ² ≈ 28 effective samples,
        // so local estimates scatter; 0.02 bounds the bias of their 38² average.
        assert!((ab - 2.0 / 2.09).abs() < 0.02, "{ab}");
        assert!((ab - ba).abs() < 1e-9);
    }
}
