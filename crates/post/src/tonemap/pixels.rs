//! The shared plumbing of tone operators: one parallel pass that gathers luminance
//! statistics, and one that maps every pixel. Both sanitise input the same way, so an
//! operator never sees (and never outputs) NaN, ±∞ or negative values:
//! a pixel with any non-finite component is counted and treated as black; a pixel with a
//! negative component is counted and that component clamped to 0.

use rayon::prelude::*;

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

/// Statistics of `w · sanitise(p, scale)` over the image (one parallel pass).
pub(crate) fn luminance_stats(image: &Image, scale: f32, w: [f32; 3]) -> LuminanceStats {
    let delta = LOG_AVERAGE_DELTA as f32;
    let acc = image
        .pixels()
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut a = Acc::EMPTY;
            // f32 partial sums per chunk (≤ 4096 terms), f64 across chunks.
            let (mut sum_log, mut sum) = (0.0f32, 0.0f32);
            for p in chunk {
                let l = dot(w, sanitise(*p, scale));
                sum_log += (delta + l).ln();
                sum += l;
                a.max = a.max.max(l);
                if l > 0.0 {
                    a.min_positive = a.min_positive.min(l);
                }
            }
            a.sum_log = sum_log as f64;
            a.sum = sum as f64;
            a
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
    image: &Image,
    scale: f32,
    w: [f32; 3],
    curve: impl Fn(f32) -> f32 + Sync,
) -> Mapped {
    map_pixels(image, scale, |c| {
        let l = dot(w, c);
        if l > 0.0 {
            let ratio = curve(l) / l;
            [c[0] * ratio, c[1] * ratio, c[2] * ratio]
        } else {
            [0.0; 3]
        }
    })
}

/// Maps every sanitised pixel through `f`; non-finite results become 0.
pub(crate) fn map_pixels(
    image: &Image,
    scale: f32,
    f: impl Fn([f32; 3]) -> [f32; 3] + Sync,
) -> Mapped {
    map_pixels_indexed(image, scale, |_, c| f(c))
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
/// their per-pixel adaptation by index).
pub(crate) fn map_luminance_indexed(
    image: &Image,
    scale: f32,
    w: [f32; 3],
    curve: impl Fn(usize, f32) -> f32 + Sync,
) -> Mapped {
    map_pixels_indexed(image, scale, |i, c| {
        let l = dot(w, c);
        if l > 0.0 {
            let ratio = curve(i, l) / l;
            [c[0] * ratio, c[1] * ratio, c[2] * ratio]
        } else {
            [0.0; 3]
        }
    })
}

/// Maps every sanitised pixel through `f(index, rgb)`; non-finite results become 0.
pub(crate) fn map_pixels_indexed(
    image: &Image,
    scale: f32,
    f: impl Fn(usize, [f32; 3]) -> [f32; 3] + Sync,
) -> Mapped {
    let mut pixels = vec![[0.0f32; 3]; image.pixels().len()];
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
