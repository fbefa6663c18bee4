//! The shared plumbing of tone operators: one parallel pass that gathers luminance
//! statistics, and one that maps every pixel. Both sanitise input the same way, so an
//! operator never sees (and never outputs) NaN, ±∞ or negative values:
//! a pixel with any non-finite component is counted and treated as black; a pixel with a
//! negative component is counted and that component clamped to 0.

use rayon::prelude::*;

use super::fast_math;
use super::Context;
use crate::image::Image;

/// Pixels per rayon task (≈ 48 KiB of RGB f32: big enough to amortise scheduling, small
/// enough to balance 2–16 threads on a 4K image).
pub(crate) const CHUNK: usize = 4096;

/// δ of the log-average (Reinhard et al. 2002, eq. 1), avoiding ln 0 on black pixels.
pub const LOG_AVERAGE_DELTA: f64 = 1e-6;

/// Sanitised input: `scale · rgb`, black for non-finite, negatives clamped to 0.
#[inline(always)]
pub(crate) fn sanitise(p: [f32; 3], scale: f32) -> [f32; 3] {
    if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
        return [0.0; 3];
    }
    [
        (p[0] * scale).max(0.0),
        (p[1] * scale).max(0.0),
        (p[2] * scale).max(0.0),
    ]
}

/// Independent accumulators per chunk (8 f32 = one AVX register).
const LANES: usize = 8;

/// `w · sanitise(p, scale)` without branches (a select instead), so loops over it
/// vectorise.
#[inline(always)]
pub(crate) fn sanitised_luminance(p: [f32; 3], scale: f32, w: [f32; 3]) -> f32 {
    let finite = p[0].is_finite() & p[1].is_finite() & p[2].is_finite();
    // f32::max returns the other operand for NaN, so every term is ≥ 0 or +∞.
    let l = w[0] * (p[0] * scale).max(0.0)
        + w[1] * (p[1] * scale).max(0.0)
        + w[2] * (p[2] * scale).max(0.0);
    if finite {
        l
    } else {
        0.0
    }
}

/// Counts (non-finite, negative) input pixels of a chunk (integer sums, vectorisable).
#[inline(always)]
fn count_problems(chunk: &[[f32; 3]]) -> (u64, u64) {
    let (mut non_finite, mut negative) = (0u32, 0u32);
    for p in chunk {
        let finite = p[0].is_finite() & p[1].is_finite() & p[2].is_finite();
        non_finite += !finite as u32;
        negative += (finite & ((p[0] < 0.0) | (p[1] < 0.0) | (p[2] < 0.0))) as u32;
    }
    (non_finite as u64, negative as u64)
}

#[inline(always)]
pub(crate) fn dot(w: [f32; 3], c: [f32; 3]) -> f32 {
    w[0] * c[0] + w[1] * c[1] + w[2] * c[2]
}

/// Luminance statistics of the sanitised, exposure-scaled image (relative Y).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuminanceStats {
    /// exp(mean ln(δ + L)), δ = [`LOG_AVERAGE_DELTA`] (Reinhard et al. 2002, eq. 1).
    pub log_average: f64,
    /// Arithmetic mean of L.
    pub mean: f64,
    pub max: f64,
    /// Smallest L > 0 (0 when the image is black).
    pub min_positive: f64,
}

#[derive(Clone, Copy)]
struct Acc {
    sum_log: f64,
    sum: f64,
    max: f32,
    min_positive: f32,
}

impl Acc {
    const EMPTY: Acc = Acc {
        sum_log: 0.0,
        sum: 0.0,
        max: 0.0,
        min_positive: f32::INFINITY,
    };

    fn merge(self, o: Acc) -> Acc {
        Acc {
            sum_log: self.sum_log + o.sum_log,
            sum: self.sum + o.sum,
            max: self.max.max(o.max),
            min_positive: self.min_positive.min(o.min_positive),
        }
    }
}

/// Statistics of `w · sanitise(p, scale)` over the image (one parallel pass; the log sum
/// uses [`fast_math::ln`], error ≤ 3e-7 per term plus rounding, so ~3e-7 relative on
/// L_avg). Per chunk, luminance goes to a stack array first and the sums run in
/// [`LANES`] independent lanes, so the compiler can vectorise both loops.
pub(crate) fn luminance_stats(image: &Image, scale: f32, w: [f32; 3]) -> LuminanceStats {
    let delta = LOG_AVERAGE_DELTA as f32;
    let acc = image
        .pixels()
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut lum = [0.0f32; CHUNK];
            let lum = &mut lum[..chunk.len()];
            for (l, p) in lum.iter_mut().zip(chunk) {
                *l = sanitised_luminance(*p, scale, w);
            }
            // f32 partial sums per lane (≤ 512 terms), f64 across lanes and chunks.
            let mut sum_log = [0.0f32; LANES];
            let mut sum = [0.0f32; LANES];
            let mut max = [0.0f32; LANES];
            let mut min_positive = [f32::INFINITY; LANES];
            let mut lanes = lum.chunks_exact(LANES);
            for group in &mut lanes {
                for k in 0..LANES {
                    let l = group[k];
                    sum_log[k] += fast_math::ln(delta + l);
                    sum[k] += l;
                    max[k] = max[k].max(l);
                    min_positive[k] = if l > 0.0 {
                        min_positive[k].min(l)
                    } else {
                        min_positive[k]
                    };
                }
            }
            for (k, l) in lanes.remainder().iter().enumerate() {
                sum_log[k] += fast_math::ln(delta + l);
                sum[k] += l;
                max[k] = max[k].max(*l);
                if *l > 0.0 {
                    min_positive[k] = min_positive[k].min(*l);
                }
            }
            Acc {
                sum_log: sum_log.iter().map(|v| *v as f64).sum(),
                sum: sum.iter().map(|v| *v as f64).sum(),
                max: max.iter().fold(0.0f32, |a, b| a.max(*b)),
                min_positive: min_positive.iter().fold(f32::INFINITY, |a, b| a.min(*b)),
            }
        })
        .reduce(|| Acc::EMPTY, Acc::merge);
    let n = image.pixels().len() as f64;
    LuminanceStats {
        log_average: (acc.sum_log / n).exp(),
        mean: acc.sum / n,
        max: acc.max as f64,
        min_positive: if acc.min_positive.is_finite() {
            acc.min_positive as f64
        } else {
            0.0
        },
    }
}

/// Output pixels of a mapping pass, with the input problems it met.
pub(crate) struct Mapped {
    pub pixels: Vec<[f32; 3]>,
    pub non_finite_pixels: u64,
    pub negative_pixels: u64,
}

/// Maps every pixel through `curve` on luminance: c_out = c · curve(L) / L (hue and
/// saturation kept, Reinhard et al. 2002 §3 "colour scaled by L_d / L_w"); black stays
/// black and any non-finite result becomes 0.
pub(crate) fn map_luminance(
    ctx: &Context,
    scale: f32,
    w: [f32; 3],
    curve: impl Fn(f32) -> f32 + Sync,
) -> Mapped {
    map_luminance_indexed(ctx, scale, w, |_, l| curve(l))
}

/// Maps every sanitised pixel through `f`; non-finite results become 0.
pub(crate) fn map_pixels(
    ctx: &Context,
    scale: f32,
    f: impl Fn([f32; 3]) -> [f32; 3] + Sync,
) -> Mapped {
    map_pixels_indexed(ctx, scale, |_, c| f(c))
}

/// The sanitised luminance plane `w · sanitise(p, scale)` (row-major), for local operators.
pub(crate) fn luminance_plane(image: &Image, scale: f32, w: [f32; 3]) -> Vec<f32> {
    let mut plane = vec![0.0f32; image.pixels().len()];
    plane
        .par_chunks_mut(CHUNK)
        .zip(image.pixels().par_chunks(CHUNK))
        .for_each(|(o, i)| {
            for (o, p) in o.iter_mut().zip(i) {
                *o = dot(w, sanitise(*p, scale));
            }
        });
    plane
}

/// As [`map_luminance`], with the pixel index passed to `curve` (local operators look up
/// their per-pixel adaptation by index). Per chunk: luminance into a stack array, the
/// curve's ratio L_d / L over that array (a tight loop the compiler can vectorise when the
/// curve is branch-free), then the colour scaled by the ratio.
pub(crate) fn map_luminance_indexed(
    ctx: &Context,
    scale: f32,
    w: [f32; 3],
    curve: impl Fn(usize, f32) -> f32 + Sync,
) -> Mapped {
    let image = ctx.image;
    let mut pixels = ctx.output_buffer(image.pixels().len());
    let (non_finite, negative) = pixels
        .par_chunks_mut(CHUNK)
        .zip(image.pixels().par_chunks(CHUNK))
        .enumerate()
        .map(|(k, (o, i))| {
            let mut ratio = [0.0f32; CHUNK];
            let ratio = &mut ratio[..i.len()];
            for (r, p) in ratio.iter_mut().zip(i) {
                *r = sanitised_luminance(*p, scale, w);
            }
            let base = k * CHUNK;
            for (j, r) in ratio.iter_mut().enumerate() {
                let l = *r;
                let v = curve(base + j, l) / l;
                *r = if l > 0.0 && v.is_finite() { v } else { 0.0 };
            }
            for ((o, p), r) in o.iter_mut().zip(i).zip(ratio.iter()) {
                let finite = p[0].is_finite() & p[1].is_finite() & p[2].is_finite();
                let r = if finite { *r } else { 0.0 };
                // r = 0 for non-finite pixels; max(0) clamps negatives (and NaN·0).
                *o = [
                    ((p[0] * scale).max(0.0) * r).max(0.0),
                    ((p[1] * scale).max(0.0) * r).max(0.0),
                    ((p[2] * scale).max(0.0) * r).max(0.0),
                ];
                if !o.iter().all(|c| c.is_finite()) {
                    *o = [0.0; 3];
                }
            }
            count_problems(i)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    Mapped {
        pixels,
        non_finite_pixels: non_finite,
        negative_pixels: negative,
    }
}

/// Maps every sanitised pixel through `f(index, rgb)`; non-finite results become 0.
pub(crate) fn map_pixels_indexed(
    ctx: &Context,
    scale: f32,
    f: impl Fn(usize, [f32; 3]) -> [f32; 3] + Sync,
) -> Mapped {
    let image = ctx.image;
    let mut pixels = ctx.output_buffer(image.pixels().len());
    let (non_finite, negative) = pixels
        .par_chunks_mut(CHUNK)
        .zip(image.pixels().par_chunks(CHUNK))
        .enumerate()
        .map(|(k, (o, i))| {
            let (mut non_finite, mut negative) = (0u64, 0u64);
            for (j, (o, p)) in o.iter_mut().zip(i).enumerate() {
                let finite = p[0].is_finite() && p[1].is_finite() && p[2].is_finite();
                non_finite += !finite as u64;
                negative += (finite && (p[0] < 0.0 || p[1] < 0.0 || p[2] < 0.0)) as u64;
                let v = f(k * CHUNK + j, sanitise(*p, scale));
                *o = v.map(|x| if x.is_finite() { x } else { 0.0 });
            }
            (non_finite, negative)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    Mapped {
        pixels,
        non_finite_pixels: non_finite,
        negative_pixels: negative,
    }
}
