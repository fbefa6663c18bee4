//! Fast bilateral filter by the bilateral grid: Paris & Durand 2006, "A Fast Approximation
//! of the Bilateral Filter using a Signal Processing Approach", ECCV (IJCV 81(1), 2009), §4;
//! Chen, Paris & Durand 2007, "Real-time Edge-Aware Image Processing with the Bilateral
//! Grid", SIGGRAPH.
//!
//! The bilateral filter of a plane I, b(p) = Σ_q G_σs(‖p − q‖) G_σr(|I_p − I_q|) I_q /
//! Σ_q G_σs G_σr, is a 3-D Gaussian convolution of the homogeneous pair (w·I, w) in
//! (x, y, I) space, sampled at (p, I_p). The grid samples that space every σ_s pixels and
//! every σ_r intensity units (the sampling rates of Paris & Durand, §4.1): each pixel is
//! splatted to its nearest grid node (box downsampling), the grid is convolved with a
//! sampled unit-σ Gaussian per axis (radius 2 nodes), and each pixel reads the result back
//! by trilinear interpolation and divides (slicing). Cost: two passes over the pixels plus
//! a grid of (W/σ_s)(H/σ_r)(range/σ_r) nodes, independent of σ_s.
//!
//! NaN values are absent: they add nothing to the grid and read back as NaN.

use rayon::prelude::*;

use prism_cpu::Simd;

use super::kernels::avx2;

/// Grid nodes of padding on each side of every axis (covers the radius-2 blur and the
/// trilinear neighbour).
const PAD: usize = 3;

/// Row bands the splat is cut into at most (work for up to this many threads; their grids
/// are summed in band order, whatever the thread count).
const SPLAT_BANDS: usize = 16;

/// Unit-σ (in grid nodes) Gaussian, radius 2, normalised: exp(−k²/2) for k = −2 … 2.
const GRID_KERNEL: [f32; 5] = [
    0.054_488_685,
    0.244_201_34,
    0.402_619_95,
    0.244_201_34,
    0.054_488_685,
];

/// The bilateral filter of `values` (row-major `width × height`) with spatial σ
/// `sigma_space_px` (pixels) and range σ `sigma_range` (units of the values), by the
/// bilateral grid. Returns the filtered plane and the (min, max) of its finite values.
/// `simd`: the widest kernels to run (`prism_cpu::active()` for the process's choice).
pub fn bilateral_grid(
    values: &[f32],
    width: usize,
    height: usize,
    sigma_space_px: f32,
    sigma_range: f32,
    simd: Simd,
) -> (Vec<f32>, [f32; 2]) {
    let (lo, hi) = values
        .par_chunks(4096)
        .map(|c| {
            c.iter()
                .filter(|v| v.is_finite())
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
                    (a.min(*v), b.max(*v))
                })
        })
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    if lo > hi {
        return (vec![f32::NAN; values.len()], [0.0, 0.0]);
    }
    let ss = sigma_space_px.max(1.0);
    let sr = sigma_range.max(1e-6);
    let gx = (width as f32 / ss).ceil() as usize + 2 * PAD;
    let gy = (height as f32 / ss).ceil() as usize + 2 * PAD;
    let gz = ((hi - lo) / sr).ceil() as usize + 2 * PAD;
    let cells = gx * gy * gz;
    let index = |x: usize, y: usize, z: usize| (z * gy + y) * gx + x;
    let coord = |x: usize, y: usize, v: f32| {
        (
            x as f32 / ss + PAD as f32,
            y as f32 / ss + PAD as f32,
            (v - lo) / sr + PAD as f32,
        )
    };

    // Per column and per row, the grid coordinate and its nearest node / lower corner and
    // weight: the same values the per-pixel expressions gave, computed once.
    let fxs: Vec<f32> = (0..width).map(|x| coord(x, 0, lo).0).collect();
    let fys: Vec<f32> = (0..height).map(|y| coord(0, y, lo).1).collect();
    let nearest_x: Vec<usize> = fxs.iter().map(|fx| (fx + 0.5) as usize).collect();

    // Splat (nearest node): bands of rows in parallel, each into its own grid, then the
    // band grids summed in band order — a fixed order, so the f32 sums (and the image) do
    // not depend on the thread count or on how rayon splits the work. Per row the z
    // coordinates are computed first in a vectorisable loop (`avx2!`), then the scatter
    // runs.
    // Fewer bands when the grid is large against the image (a small σ_s): the band grids
    // then hold at most about as many cells as the image has pixels.
    let bands = (values.len() / cells.max(1)).clamp(1, SPLAT_BANDS);
    let band_rows = height.div_ceil(bands).max(1);
    let band_grids: Vec<Vec<[f32; 2]>> = values
        .par_chunks(width * band_rows)
        .enumerate()
        .map(|(band, rows)| {
            let mut g = vec![[0.0f32; 2]; cells];
            let mut fz = vec![0.0f32; width];
            for (r, row) in rows.chunks(width).enumerate() {
                avx2!(simd, z_coordinates(row, &mut fz, lo, sr));
                let ny = (fys[band * band_rows + r] + 0.5) as usize;
                for ((v, fz), nx) in row.iter().zip(&fz).zip(&nearest_x) {
                    if v.is_finite() {
                        let cell = &mut g[index(*nx, ny, (fz + 0.5) as usize)];
                        cell[0] += v;
                        cell[1] += 1.0;
                    }
                }
            }
            g
        })
        .collect();
    let mut grid = vec![[0.0f32; 2]; cells];
    for band in &band_grids {
        grid.iter_mut().zip(band).for_each(|(a, b)| {
            a[0] += b[0];
            a[1] += b[1];
        });
    }

    // Separable blur along x, y, z (the grid is small: serial).
    let mut tmp = vec![[0.0f32; 2]; cells];
    for (stride, len) in [(1, gx), (gx, gy), (gx * gy, gz)] {
        for (i, out) in tmp.iter_mut().enumerate() {
            let pos = (i / stride) % len;
            let mut acc = [0.0f32; 2];
            for (k, w) in GRID_KERNEL.iter().enumerate() {
                let p = pos as isize + k as isize - 2;
                if p >= 0 && (p as usize) < len {
                    let c = grid[(i as isize + (k as isize - 2) * stride as isize) as usize];
                    acc[0] += w * c[0];
                    acc[1] += w * c[1];
                }
            }
            *out = acc;
        }
        std::mem::swap(&mut grid, &mut tmp);
    }

    // Slice: trilinear interpolation of (Σ w I, Σ w), then divide.
    let corner_x: Vec<(usize, [f32; 2])> = fxs
        .iter()
        .map(|fx| {
            let x0 = *fx as usize;
            let tx = fx - x0 as f32;
            (x0, [1.0 - tx, tx])
        })
        .collect();
    let mut out = vec![0.0f32; values.len()];
    let range = out
        .par_chunks_mut(width)
        .zip(values.par_chunks(width))
        .enumerate()
        .map_init(
            || vec![0.0f32; width],
            |fz, (y, (o, row))| {
                avx2!(simd, z_coordinates(row, fz, lo, sr));
                let fy = fys[y];
                let y0 = fy as usize;
                let ty = fy - y0 as f32;
                let wys = [(0, 1.0 - ty), (1, ty)];
                let (mut lo_b, mut hi_b) = (f32::INFINITY, f32::NEG_INFINITY);
                for (((o, v), fz), (x0, wxs)) in o.iter_mut().zip(row).zip(fz.iter()).zip(&corner_x)
                {
                    if !v.is_finite() {
                        *o = f32::NAN;
                        continue;
                    }
                    let z0 = *fz as usize;
                    let tz = fz - z0 as f32;
                    let mut acc = [0.0f32; 2];
                    for (dz, wz) in [(0, 1.0 - tz), (1, tz)] {
                        for (dy, wy) in wys {
                            // The two x neighbours are adjacent in the grid.
                            let base = index(*x0, y0 + dy, z0 + dz);
                            for (dx, wx) in wxs.iter().enumerate() {
                                let c = grid[base + dx];
                                let w = wx * wy * wz;
                                acc[0] += w * c[0];
                                acc[1] += w * c[1];
                            }
                        }
                    }
                    // The pixel's own node is one of the 8 corners (weight ≥ 1/8) and holds
                    // its own splat, so acc[1] > 0; the guard is for safety only.
                    let b = if acc[1] > 0.0 { acc[0] / acc[1] } else { *v };
                    *o = b;
                    lo_b = lo_b.min(b);
                    hi_b = hi_b.max(b);
                }
                (lo_b, hi_b)
            },
        )
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    (out, [range.0, range.1])
}

/// z grid coordinates (v − lo)/σ_r + PAD of a row (NaN stays NaN; such pixels are
/// skipped by the callers).
#[inline(always)]
fn z_coordinates(row: &[f32], fz: &mut [f32], lo: f32, sr: f32) {
    for (z, v) in fz.iter_mut().zip(row) {
        *z = (v - lo) / sr + PAD as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_filtered_plane_is_the_same_bits_for_any_thread_count() {
        // A noisy plane whose splat sums round differently in different orders.
        let (w, h) = (203, 157);
        let v: Vec<f32> = (0..w * h)
            .map(|i| ((i as f32 * 0.618_034).fract() * 7.3).sin() * 3.0 + (i % w) as f32 * 0.01)
            .collect();
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| bilateral_grid(&v, w, h, 6.0, 0.35, prism_cpu::active()))
        };
        let one = run(1);
        for threads in [2, 3, 5, 8] {
            let other = run(threads);
            assert!(
                one.0
                    .iter()
                    .zip(&other.0)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{threads} threads"
            );
            assert_eq!(one.1, other.1);
        }
    }

    #[test]
    fn keeps_edges_far_apart_in_range_and_smooths_within_a_region() {
        // Two regions 3 units apart with σ_r = 0.4: no cross-talk, each region's value
        // comes back exactly (up to f32 rounding).
        let (w, h) = (40, 20);
        let v: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 20 { -2.0 } else { 1.0 })
            .collect();
        let (b, [lo, hi]) = bilateral_grid(&v, w, h, 4.0, 0.4, prism_cpu::active());
        for (got, want) in b.iter().zip(&v) {
            assert!((got - want).abs() < 1e-5, "{got} vs {want}");
        }
        assert_eq!((lo, hi), (-2.0, 1.0));
        // Small ±0.02 texture on one level (σ_r = 0.4 ≫ 0.02): smoothed towards the mean.
        let t: Vec<f32> = (0..w * h)
            .map(|i| {
                if (i % w + i / w) % 2 == 0 {
                    0.02
                } else {
                    -0.02
                }
            })
            .collect();
        let (b, _) = bilateral_grid(&t, w, h, 4.0, 0.4, prism_cpu::active());
        assert!(b.iter().all(|x| x.abs() < 0.005), "{:?}", &b[..4]);
        // NaN in → NaN out, and nothing else disturbed.
        let mut n = v.clone();
        n[5] = f32::NAN;
        let (b, _) = bilateral_grid(&n, w, h, 4.0, 0.4, prism_cpu::active());
        assert!(b[5].is_nan() && (b[6] + 2.0).abs() < 1e-5);
    }
}
