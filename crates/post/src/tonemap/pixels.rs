//! The shared plumbing of tone operators: one parallel pass that gathers luminance
//! statistics, and one that maps every pixel. Both sanitise input the same way, so an
//! operator never sees (and never outputs) NaN, ±∞ or negative values:
//! a pixel with any non-finite component is counted and treated as black; a pixel with a
//! negative component is counted and that component clamped to 0.
//!
//! Layout of both passes: rayon tasks of [`CHUNK`] pixels; inside a task, blocks of
//! [`BLOCK`] pixels are de-interleaved into stack planes (R, G, B, L: a few KiB, in L1),
//! the operator's curve runs over a plane, and the result is interleaved back. Every loop
//! over a plane is branch-free, so it vectorises, and each task's kernel is compiled twice
//! (baseline SSE2 and AVX2, chosen by the call's ISA, `Context::simd`: module
//! [`super::kernels`], which also holds the AVX-512 forms of these passes). Operators hand
//! their curve over as a [`LuminanceCurve`] or [`PixelMap`] whose method is
//! `#[inline(always)]`, so it is compiled into the vector loop rather than called per pixel.

use rayon::prelude::*;

use prism_cpu::Simd;

use super::fast_math;
use super::kernels::{self, avx2};
use super::{Context, Input};

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

/// Independent accumulators per chunk (16 f32 = one AVX-512 register, two AVX ones).
pub(crate) const LANES: usize = 16;

/// Pixels per de-interleaved block inside a task (a multiple of [`LANES`]; five planes of
/// 1 KiB).
pub(crate) const BLOCK: usize = 256;

/// A luminance curve L ↦ L_d for [`map_luminance`], given as the ratio L_d / L by which
/// the pixel's colour is scaled: an operator folds the division by L into its own
/// formula (often removing a division or a power: a division costs as much as a fast
/// log here). Implementations mark [`Self::ratio`] `#[inline(always)]`, keep its loop
/// branch-free (module [`super::kernels::avx2`]) and copy their fields into locals before the loop
/// (the compiler cannot tell that `l` does not alias `self`, and would reload the fields
/// per pixel and keep the loop scalar).
pub(crate) trait LuminanceCurve: Sync {
    /// Replaces every `l[j]`, the sanitised luminance of pixel `start + j` (row-major
    /// index), by L_d / L. Only used where L > 0 (black pixels stay black whatever is
    /// written for them).
    fn ratio(&self, start: usize, l: &mut [f32]);
}

/// A per-pixel colour map for [`map_pixels`], on de-interleaved planes; implementations
/// mark [`Self::map`] `#[inline(always)]`.
pub(crate) trait PixelMap: Sync {
    /// Maps the sanitised pixels `start + j`, given as `(r[j], g[j], b[j])`, in place.
    fn map(&self, start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]);
}

/// L_d = factor · L (a linear scale of luminance): the ratio is the factor.
pub(crate) struct Scale(pub f32);

impl LuminanceCurve for Scale {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        l.fill(self.0);
    }
}

/// Sanitised planes of one block: `scale · rgb` clamped to ≥ 0, black for non-finite
/// pixels, and its luminance `w · rgb`; returns the (non-finite, negative) pixel counts.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn load_block(
    input: &[[f32; 3]],
    scale: f32,
    w: [f32; 3],
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
    l: &mut [f32],
) -> (u32, u32) {
    let n = input.len();
    let (r, g, b, l) = (&mut r[..n], &mut g[..n], &mut b[..n], &mut l[..n]);
    let (mut non_finite, mut negative) = (0u32, 0u32);
    for j in 0..n {
        let p = input[j];
        let finite = p[0].is_finite() & p[1].is_finite() & p[2].is_finite();
        non_finite += !finite as u32;
        negative += (finite & ((p[0] < 0.0) | (p[1] < 0.0) | (p[2] < 0.0))) as u32;
        let c = [
            if finite { (p[0] * scale).max(0.0) } else { 0.0 },
            if finite { (p[1] * scale).max(0.0) } else { 0.0 },
            if finite { (p[2] * scale).max(0.0) } else { 0.0 },
        ];
        r[j] = c[0];
        g[j] = c[1];
        b[j] = c[2];
        // As sanitised_luminance: the same sum, in the same order.
        let y = w[0] * (p[0] * scale).max(0.0)
            + w[1] * (p[1] * scale).max(0.0)
            + w[2] * (p[2] * scale).max(0.0);
        l[j] = if finite { y } else { 0.0 };
    }
    (non_finite, negative)
}

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

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Acc {
    pub sum_log: f64,
    pub sum: f64,
    pub max: f32,
    pub min_positive: f32,
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

/// x = 2^e · m, m ∈ [1, 2), for a positive normal (or infinite) f32: (e, m) exactly.
#[inline(always)]
pub(crate) fn split_exponent(x: f32) -> (i32, f32) {
    let bits = x.to_bits();
    (
        (bits >> 23) as i32 - 127,
        f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000),
    )
}

/// Per-lane accumulators of [`stats_chunk`] (pixel i of the chunk in lane i mod
/// [`LANES`]).
#[derive(Clone, Copy)]
pub(crate) struct StatsLanes {
    pub sum_log2: [f32; LANES],
    pub exponents: [i32; LANES],
    pub sum: [f32; LANES],
    pub max: [f32; LANES],
    pub min_positive: [f32; LANES],
}

impl StatsLanes {
    pub(crate) const EMPTY: StatsLanes = StatsLanes {
        sum_log2: [0.0; LANES],
        exponents: [0; LANES],
        sum: [0.0; LANES],
        max: [0.0; LANES],
        min_positive: [f32::INFINITY; LANES],
    };

    /// The chunk's totals: f64 sums across lanes, in lane order.
    pub(crate) fn total(&self) -> Acc {
        let log2_total = self.exponents.iter().map(|e| *e as f64).sum::<f64>()
            + self.sum_log2.iter().map(|v| *v as f64).sum::<f64>();
        Acc {
            sum_log: log2_total * std::f64::consts::LN_2,
            sum: self.sum.iter().map(|v| *v as f64).sum(),
            max: self.max.iter().fold(0.0f32, |a, b| a.max(*b)),
            min_positive: self
                .min_positive
                .iter()
                .fold(f32::INFINITY, |a, b| a.min(*b)),
        }
    }
}

/// One block (≤ [`BLOCK`] pixels) of [`stats_chunk`]: luminance into a stack plane, then
/// the lanes' sums; the mantissa product's log2 once per block and lane.
#[inline(always)]
pub(crate) fn stats_block(lanes: &mut StatsLanes, block: &[[f32; 3]], scale: f32, w: [f32; 3]) {
    let delta = LOG_AVERAGE_DELTA as f32;
    let StatsLanes {
        sum_log2,
        exponents,
        sum,
        max,
        min_positive,
    } = lanes;
    let mut lum = [0.0f32; BLOCK];
    let lum = &mut lum[..block.len()];
    for (l, p) in lum.iter_mut().zip(block) {
        *l = sanitised_luminance(*p, scale, w);
    }
    let mut product = [1.0f32; LANES];
    let mut groups = lum.chunks_exact(LANES);
    for group in &mut groups {
        for k in 0..LANES {
            let l = group[k];
            let (e, m) = split_exponent(delta + l);
            exponents[k] += e;
            product[k] *= m;
            sum[k] += l;
            max[k] = max[k].max(l);
            min_positive[k] = if l > 0.0 {
                min_positive[k].min(l)
            } else {
                min_positive[k]
            };
        }
    }
    // Only the image's last block can leave a remainder (BLOCK and CHUNK are multiples
    // of LANES).
    for (k, l) in groups.remainder().iter().enumerate() {
        let (e, m) = split_exponent(delta + l);
        exponents[k] += e;
        product[k] *= m;
        sum[k] += l;
        max[k] = max[k].max(*l);
        if *l > 0.0 {
            min_positive[k] = min_positive[k].min(*l);
        }
    }
    for k in 0..LANES {
        sum_log2[k] += fast_math::log2(product[k]);
    }
}

/// One task of [`luminance_stats`]: [`stats_block`] per block, in [`LANES`] independent
/// lanes (pixel i of the chunk in lane i mod 16), f64 across lanes.
///
/// The log sum uses the exact identity Σ log2 x_i = Σ e_i + log2 Π m_i (x_i = 2^e_i m_i,
/// m_i ∈ [1, 2)): per lane, the exponents are summed as integers (exactly) and the
/// mantissas multiplied (at most 16 per block and lane, product < 2^16, each product
/// rounded to 2⁻²⁴ relative), and [`fast_math::log2`] runs once per block and lane
/// instead of once per pixel. Error: ≤ 16 · 6e-8 relative on a product, i.e. ≤ 1.4e-6 on
/// its log2 — 9e-8 per term, below the 3e-7 per term of a log per pixel.
#[inline(always)]
pub(crate) fn stats_chunk(chunk: &[[f32; 3]], scale: f32, w: [f32; 3]) -> Acc {
    let mut lanes = StatsLanes::EMPTY;
    for block in chunk.chunks(BLOCK) {
        stats_block(&mut lanes, block, scale, w);
    }
    lanes.total()
}

/// Statistics of `w · sanitise(p, scale)` over the image in one parallel pass (the log
/// sum as in [`stats_chunk`]: ≲ 1e-7 per term, so ~1e-7 relative on L_avg). The
/// per-task partial sums are added in image order, so the result does not depend on the
/// thread count.
///
/// Every operator takes this one pass, log-average or not: a variant without the log sum
/// measured slower (its loop vectorised worse), and the identity makes the log nearly free.
pub(crate) fn luminance_stats(ctx: &Context, scale: f32, w: [f32; 3]) -> LuminanceStats {
    let simd = ctx.simd;
    let (partial, n): (Vec<Acc>, usize) = ctx.read_pixels(|pixels| {
        let partial = pixels
            .par_chunks(CHUNK)
            .map(|chunk| kernels::stats_task(simd, chunk, scale, w))
            .collect();
        (partial, pixels.len())
    });
    let acc = partial.into_iter().fold(Acc::EMPTY, Acc::merge);
    let n = n as f64;
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

/// One task of [`map_luminance`] (pixels `start …` of the image).
#[inline(always)]
pub(crate) fn map_luminance_chunk<C: LuminanceCurve>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> (u64, u64) {
    let mut r = [0.0f32; BLOCK];
    let mut g = [0.0f32; BLOCK];
    let mut b = [0.0f32; BLOCK];
    let mut l = [0.0f32; BLOCK];
    let mut ld = [0.0f32; BLOCK];
    let (mut non_finite, mut negative) = (0u64, 0u64);
    for (k, (i, o)) in input.chunks(BLOCK).zip(out.chunks_mut(BLOCK)).enumerate() {
        let n = i.len();
        let (nf, neg) = load_block(i, scale, w, &mut r, &mut g, &mut b, &mut l);
        non_finite += nf as u64;
        negative += neg as u64;
        ld[..n].copy_from_slice(&l[..n]);
        curve.ratio(start + k * BLOCK, &mut ld[..n]);
        let (r, g, b, l, ld, o) = (&r[..n], &g[..n], &b[..n], &l[..n], &ld[..n], &mut o[..n]);
        for j in 0..n {
            let v = ld[j];
            // Black (and non-finite input, whose L is 0) stays black.
            let ratio = if l[j] > 0.0 && v.is_finite() { v } else { 0.0 };
            // max(0) turns ∞ · 0 = NaN into 0, as for a non-finite input.
            let c = [
                (r[j] * ratio).max(0.0),
                (g[j] * ratio).max(0.0),
                (b[j] * ratio).max(0.0),
            ];
            let finite = c[0].is_finite() & c[1].is_finite() & c[2].is_finite();
            o[j] = if finite { c } else { [0.0; 3] };
        }
    }
    (non_finite, negative)
}

/// The image's pixels through `task` in parallel chunks of `CHUNK` pixels — `task(start,
/// input, output)` with `start` the index of the chunk's first pixel, returning its
/// (non-finite, negative) input pixel counts — into a new output buffer, or, for an owned
/// input, into the input itself (each chunk copied aside first: the same bits).
pub(crate) fn map_chunks(
    ctx: &Context,
    task: impl Fn(usize, &[[f32; 3]], &mut [[f32; 3]]) -> (u64, u64) + Sync,
) -> Mapped {
    let (pixels, (non_finite, negative)) = match &ctx.input {
        Input::Borrowed(input) => {
            let mut pixels = ctx.output_buffer(input.len());
            let counts = pixels
                .par_chunks_mut(CHUNK)
                .zip(input.par_chunks(CHUNK))
                .enumerate()
                .map(|(k, (o, i))| task(k * CHUNK, i, o))
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            (pixels, counts)
        }
        Input::Owned(input) => {
            let mut pixels = input
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take()
                .unwrap_or_default();
            let counts = pixels
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(k, o)| {
                    let i = o.to_vec();
                    task(k * CHUNK, &i, o)
                })
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            (pixels, counts)
        }
    };
    Mapped {
        pixels,
        non_finite_pixels: non_finite,
        negative_pixels: negative,
    }
}

/// Maps every pixel through `curve` on luminance: c_out = c · L_d / L (hue and
/// saturation kept, Reinhard et al. 2002 §3 "colour scaled by L_d / L_w"); black stays
/// black and any non-finite result becomes 0. Curves that need the pixel index (local
/// operators' adaptation planes) get it as `start + j`.
pub(crate) fn map_luminance<C: LuminanceCurve>(
    ctx: &Context,
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> Mapped {
    let simd = ctx.simd;
    map_chunks(ctx, |start, i, o| {
        avx2!(simd, map_luminance_chunk(i, o, start, scale, w, curve))
    })
}

/// One task of [`map_pixels`] (`simd`: for the streaming stores of [`store_block`]).
#[inline(always)]
pub(crate) fn map_pixels_chunk<M: PixelMap>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    f: &M,
    simd: Simd,
) -> (u64, u64) {
    let mut r = [0.0f32; BLOCK];
    let mut g = [0.0f32; BLOCK];
    let mut b = [0.0f32; BLOCK];
    let mut l = [0.0f32; BLOCK];
    let mut staged = [[0.0f32; 3]; BLOCK];
    let (mut non_finite, mut negative) = (0u64, 0u64);
    for (k, (i, o)) in input.chunks(BLOCK).zip(out.chunks_mut(BLOCK)).enumerate() {
        let n = i.len();
        let (nf, neg) = load_block(i, scale, [0.0; 3], &mut r, &mut g, &mut b, &mut l);
        non_finite += nf as u64;
        negative += neg as u64;
        f.map(start + k * BLOCK, &mut r[..n], &mut g[..n], &mut b[..n]);
        let clean = |x: f32| if x.is_finite() { x } else { 0.0 };
        for (j, s) in staged[..n].iter_mut().enumerate() {
            *s = [clean(r[j]), clean(g[j]), clean(b[j])];
        }
        store_block(o, &staged[..n], simd);
    }
    store_fence();
    (non_finite, negative)
}

/// Copies a finished block to the output with non-temporal stores where `simd` allows AVX:
/// the output (100 MB at 4K) is written once and not read again in the pass, so ordinary
/// stores would first read every cache line of it from memory (read for ownership) and
/// evict the input from the caches.
#[inline(always)]
pub(crate) fn store_block(dst: &mut [[f32; 3]], src: &[[f32; 3]], simd: Simd) {
    #[cfg(target_arch = "x86_64")]
    if simd.avx2() {
        // SAFETY: a `Simd` allows AVX2 (and so AVX) only on a CPU that has it.
        unsafe { kernels::avx2::store_streaming(dst, src) };
        return;
    }
    dst.copy_from_slice(src);
}

/// Orders a task's non-temporal stores before whatever signals its completion (they are
/// weakly ordered: another thread could otherwise read the output before it lands).
#[inline(always)]
pub(crate) fn store_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: sfence is part of SSE, in the x86-64 baseline.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

/// Maps every sanitised pixel through `f` (on de-interleaved planes); non-finite results
/// become 0.
pub(crate) fn map_pixels<M: PixelMap>(ctx: &Context, scale: f32, f: &M) -> Mapped {
    let simd = ctx.simd;
    map_chunks(ctx, |start, i, o| {
        kernels::pixels_task(simd, i, o, start, scale, f)
    })
}

/// `out[i] = w · sanitise(input[i], scale)`: one row of [`luminance_plane`], or of a plane
/// computed a row at a time where it is needed.
#[inline(always)]
pub(crate) fn luminance_chunk(input: &[[f32; 3]], out: &mut [f32], scale: f32, w: [f32; 3]) {
    for (o, p) in out.iter_mut().zip(input) {
        *o = sanitised_luminance(*p, scale, w);
    }
}

/// The sanitised luminance plane `w · sanitise(p, scale)` (row-major), for local operators.
pub(crate) fn luminance_plane(ctx: &Context, scale: f32, w: [f32; 3]) -> Vec<f32> {
    let simd = ctx.simd;
    ctx.read_pixels(|pixels| {
        let mut plane = vec![0.0f32; pixels.len()];
        plane
            .par_chunks_mut(CHUNK)
            .zip(pixels.par_chunks(CHUNK))
            .for_each(|(o, i)| avx2!(simd, luminance_chunk(i, o, scale, w)));
        plane
    })
}
