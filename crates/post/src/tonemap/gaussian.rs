//! Separable Gaussian blur of a single-channel plane (luminance), edges clamped
//! (replicated), for the local operators' scale spaces.
//!
//! - σ < [`RECURSIVE_MIN_SIGMA`]: direct separable FIR with the sampled Gaussian
//!   exp(−x²/2σ²), |x| ≤ ⌈3σ⌉, normalised to unit sum on the pixel grid.
//! - σ ≥ [`RECURSIVE_MIN_SIGMA`]: the third-order recursive filter of Young & van Vliet 1995,
//!   "Recursive implementation of the Gaussian filter", Signal Processing 44, eqs. 9 (forward),
//!   10 (backward), 11 (q from σ) and 8c (b coefficients): cost independent of σ. Its
//!   2-D impulse response differs from the sampled Gaussian by ≤ 6 % of the peak (5.1 %
//!   measured at σ = 4.2, less for larger σ; tested below), and it preserves constants
//!   (unit DC gain).
//!
//! Both passes are parallel: rows by rayon chunks, columns by strips of
//! [`COLUMN_STRIP`] columns processed row by row (so the vertical recursion streams through
//! memory instead of striding).

use rayon::prelude::*;

/// Below this σ (pixels) the blur is a direct FIR (the recursive filter's q formula is
/// only fitted for σ ≥ 0.5, and is less accurate than a short FIR below a few pixels).
pub const RECURSIVE_MIN_SIGMA: f32 = 3.0;

/// Rows filtered together by the horizontal recursive pass.
const ROW_GROUP: usize = 8;

/// Columns per task of the vertical pass (64 f32 = 256 bytes: four cache lines per row).
const COLUMN_STRIP: usize = 64;

/// Blurs `src` (row-major `width × height`) with a Gaussian of standard deviation
/// `sigma_px` pixels into `dst`; `scratch` must have the same length (reused across
/// calls to avoid allocation). σ ≤ 0 copies.
pub fn gaussian_blur(
    src: &[f32],
    dst: &mut [f32],
    scratch: &mut [f32],
    width: usize,
    height: usize,
    sigma_px: f32,
) {
    debug_assert!(src.len() == width * height && dst.len() == src.len());
    debug_assert!(scratch.len() == src.len());
    if sigma_px.is_nan() || sigma_px <= 0.0 {
        dst.copy_from_slice(src);
        return;
    }
    if sigma_px < RECURSIVE_MIN_SIGMA {
        let kernel = sampled_kernel(sigma_px);
        fir_rows(src, scratch, width, &kernel);
        fir_columns(scratch, dst, width, height, &kernel);
    } else {
        let c = YoungVanVliet::new(sigma_px);
        dst.copy_from_slice(src);
        // Rows in groups of ROW_GROUP: independent recursions interleaved, so the
        // latency of each one's dependency chain is hidden by the others.
        dst.par_chunks_mut(width * ROW_GROUP)
            .for_each(|rows| c.filter_rows(rows, width));
        c.filter_columns(dst, width, height);
    }
}

/// Sampled, unit-sum Gaussian kernel, taps −r…r with r = ⌈3σ⌉.
pub fn sampled_kernel(sigma: f32) -> Vec<f32> {
    let r = (3.0 * sigma).ceil().max(1.0) as i32;
    let mut k: Vec<f32> = (-r..=r)
        .map(|x| (-(x * x) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    k
}

/// Horizontal FIR: each row is copied with `r` replicated edge pixels on both sides, then
/// accumulated tap by tap (out[x] += k_j · padded[x + j]): the inner loop runs along the
/// row and vectorises.
fn fir_rows(src: &[f32], dst: &mut [f32], width: usize, kernel: &[f32]) {
    let r = kernel.len() / 2;
    dst.par_chunks_mut(width)
        .zip(src.par_chunks(width))
        .for_each_init(
            || vec![0.0f32; width + 2 * r],
            |padded, (o, i)| {
                padded[..r].fill(i[0]);
                padded[r..r + width].copy_from_slice(i);
                padded[r + width..].fill(i[width - 1]);
                o.fill(0.0);
                for (j, k) in kernel.iter().enumerate() {
                    for (out, v) in o.iter_mut().zip(&padded[j..j + width]) {
                        *out += k * v;
                    }
                }
            },
        );
}

fn fir_columns(src: &[f32], dst: &mut [f32], width: usize, height: usize, kernel: &[f32]) {
    let r = (kernel.len() / 2) as isize;
    let last = height as isize - 1;
    dst.par_chunks_mut(width).enumerate().for_each(|(y, o)| {
        o.fill(0.0);
        for (j, k) in kernel.iter().enumerate() {
            let yy = (y as isize + j as isize - r).clamp(0, last) as usize;
            let row = &src[yy * width..(yy + 1) * width];
            for (out, v) in o.iter_mut().zip(row) {
                *out += k * v;
            }
        }
    });
}

/// Coefficients of the Young–van Vliet recursive Gaussian, normalised by b0.
#[derive(Debug, Clone, Copy)]
pub struct YoungVanVliet {
    /// B = 1 − (b1 + b2 + b3) / b0 (eq. 9's input weight).
    pub b: f32,
    /// b1/b0, b2/b0, b3/b0.
    pub a: [f32; 3],
}

impl YoungVanVliet {
    pub fn new(sigma: f32) -> Self {
        let s = sigma as f64;
        // Eq. 11.
        let q = if s >= 2.5 {
            0.98711 * s - 0.96330
        } else {
            3.97156 - 4.14554 * (1.0 - 0.26891 * s).max(0.0).sqrt()
        };
        // Eq. 8c.
        let b0 = 1.57825 + 2.44413 * q + 1.4281 * q * q + 0.422205 * q * q * q;
        let b1 = 2.44413 * q + 2.85619 * q * q + 1.26661 * q * q * q;
        let b2 = -(1.4281 * q * q + 1.26661 * q * q * q);
        let b3 = 0.422205 * q * q * q;
        Self {
            b: (1.0 - (b1 + b2 + b3) / b0) as f32,
            a: [(b1 / b0) as f32, (b2 / b0) as f32, (b3 / b0) as f32],
        }
    }

    /// Forward (eq. 9) then backward (eq. 10) recursion along one row, in place; the
    /// state starts at the edge value (the steady state of a constant extension).
    pub fn filter_row(&self, row: &mut [f32]) {
        let (b, [a1, a2, a3]) = (self.b, self.a);
        let Some(&first) = row.first() else { return };
        let (mut w1, mut w2, mut w3) = (first, first, first);
        for v in row.iter_mut() {
            let w = b * *v + a1 * w1 + a2 * w2 + a3 * w3;
            (w3, w2, w1) = (w2, w1, w);
            *v = w;
        }
        let last = *row.last().unwrap_or(&0.0);
        let (mut y1, mut y2, mut y3) = (last, last, last);
        for v in row.iter_mut().rev() {
            let y = b * *v + a1 * y1 + a2 * y2 + a3 * y3;
            (y3, y2, y1) = (y2, y1, y);
            *v = y;
        }
    }

    /// [`Self::filter_row`] on up to [`ROW_GROUP`] consecutive rows (`rows` holds them
    /// back to back, each `width` long), their recursions interleaved.
    #[allow(clippy::needless_range_loop)] // r indexes both the state and the row offset
    pub fn filter_rows(&self, rows: &mut [f32], width: usize) {
        let n = rows.len() / width;
        if n < ROW_GROUP {
            rows.chunks_mut(width).for_each(|row| self.filter_row(row));
            return;
        }
        let (b, [a1, a2, a3]) = (self.b, self.a);
        let mut s = [[0.0f32; ROW_GROUP]; 3];
        for r in 0..ROW_GROUP {
            let v = rows[r * width];
            s[0][r] = v;
            s[1][r] = v;
            s[2][r] = v;
        }
        for x in 0..width {
            for r in 0..ROW_GROUP {
                let i = r * width + x;
                let w = b * rows[i] + a1 * s[0][r] + a2 * s[1][r] + a3 * s[2][r];
                s[2][r] = s[1][r];
                s[1][r] = s[0][r];
                s[0][r] = w;
                rows[i] = w;
            }
        }
        for r in 0..ROW_GROUP {
            let v = rows[r * width + width - 1];
            s[0][r] = v;
            s[1][r] = v;
            s[2][r] = v;
        }
        for x in (0..width).rev() {
            for r in 0..ROW_GROUP {
                let i = r * width + x;
                let w = b * rows[i] + a1 * s[0][r] + a2 * s[1][r] + a3 * s[2][r];
                s[2][r] = s[1][r];
                s[1][r] = s[0][r];
                s[0][r] = w;
                rows[i] = w;
            }
        }
    }

    /// The same recursion down every column, strips of columns in parallel.
    pub fn filter_columns(&self, plane: &mut [f32], width: usize, height: usize) {
        let strips = width.div_ceil(COLUMN_STRIP);
        let ptr = SharedPlane(plane.as_mut_ptr());
        (0..strips).into_par_iter().for_each(|s| {
            let x0 = s * COLUMN_STRIP;
            let n = COLUMN_STRIP.min(width - x0);
            // SAFETY: each task reads and writes only columns x0..x0+n of every row;
            // strips are disjoint and the plane outlives the parallel loop.
            let row = |y: usize| unsafe {
                std::slice::from_raw_parts_mut(ptr.get().add(y * width + x0), n)
            };
            self.columns_strip(row, n, height);
        });
    }

    fn columns_strip<'a>(&self, row: impl Fn(usize) -> &'a mut [f32], n: usize, height: usize) {
        let (b, [a1, a2, a3]) = (self.b, self.a);
        let mut s = [[0.0f32; COLUMN_STRIP]; 3];
        for (k, v) in row(0).iter().enumerate() {
            s[0][k] = *v;
            s[1][k] = *v;
            s[2][k] = *v;
        }
        for y in 0..height {
            let r = row(y);
            for k in 0..n {
                let w = b * r[k] + a1 * s[0][k] + a2 * s[1][k] + a3 * s[2][k];
                s[2][k] = s[1][k];
                s[1][k] = s[0][k];
                s[0][k] = w;
                r[k] = w;
            }
        }
        for (k, v) in row(height - 1).iter().enumerate() {
            s[0][k] = *v;
            s[1][k] = *v;
            s[2][k] = *v;
        }
        for y in (0..height).rev() {
            let r = row(y);
            for k in 0..n {
                let w = b * r[k] + a1 * s[0][k] + a2 * s[1][k] + a3 * s[2][k];
                s[2][k] = s[1][k];
                s[1][k] = s[0][k];
                s[0][k] = w;
                r[k] = w;
            }
        }
    }
}

#[derive(Clone, Copy)]
struct SharedPlane(*mut f32);
// SAFETY: used only to give disjoint column strips to parallel tasks (see filter_columns).
unsafe impl Send for SharedPlane {}
unsafe impl Sync for SharedPlane {}
impl SharedPlane {
    fn get(self) -> *mut f32 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn impulse_response(sigma: f32, size: usize) -> Vec<f32> {
        let mut src = vec![0.0; size * size];
        src[(size / 2) * size + size / 2] = 1.0;
        let mut dst = vec![0.0; src.len()];
        let mut scratch = vec![0.0; src.len()];
        gaussian_blur(&src, &mut dst, &mut scratch, size, size, sigma);
        dst
    }

    #[test]
    fn blur_matches_the_sampled_gaussian_and_keeps_constants() {
        for sigma in [0.25f32, 0.64, 1.6, 2.6, 4.2, 6.7, 10.7] {
            let size = 129;
            let got = impulse_response(sigma, size);
            let k = sampled_kernel(sigma);
            let r = k.len() / 2;
            let c = size / 2;
            let peak = k[r] * k[r];
            let mut worst = 0.0f32;
            for y in 0..size {
                for x in 0..size {
                    let (dx, dy) = (x as isize - c as isize, y as isize - c as isize);
                    let want = if dx.unsigned_abs() <= r && dy.unsigned_abs() <= r {
                        k[(dx + r as isize) as usize] * k[(dy + r as isize) as usize]
                    } else {
                        0.0
                    };
                    worst = worst.max((got[y * size + x] - want).abs());
                }
            }
            // FIR: exact up to f32 rounding. Young–van Vliet: measured 5.1 % (σ = 4.2),
            // 4.2 % (6.7), 3.4 % (10.7) of the 2-D peak, concentrated at the peak (the
            // fitted poles make the response slightly narrower there): bound 6 %.
            let tol = if sigma < RECURSIVE_MIN_SIGMA {
                1e-6
            } else {
                0.06
            };
            assert!(worst <= tol * peak, "σ = {sigma}: {worst} vs peak {peak}");
            let sum: f32 = got.iter().sum();
            // Unit DC gain up to the edge restart of the backward pass: 0.2 % measured.
            assert!((sum - 1.0).abs() < 3e-3, "σ = {sigma}: sum {sum}");
        }
        // Constants are preserved exactly up to rounding (edges replicated).
        let (w, h) = (37, 23);
        let src = vec![3.5f32; w * h];
        let (mut dst, mut scratch) = (vec![0.0; w * h], vec![0.0; w * h]);
        for sigma in [0.5f32, 8.0] {
            gaussian_blur(&src, &mut dst, &mut scratch, w, h, sigma);
            assert!(dst.iter().all(|v| (v - 3.5).abs() < 1e-4), "σ = {sigma}");
        }
    }
}
