//! The tone operators' vector kernels, one file per ISA family, and the one place that
//! says which runs for which ISA.
//!
//! An operator file (`exponential.rs`, `agx.rs`, …) keeps the operator: formula,
//! parameters, reference and scalar curve. Its register and vector forms live here, as
//! `impl` blocks for the operator's own types (so both forms share its struct and
//! constants), as the packet tracer lives apart in render's `integrator/packet/`:
//!
//! - [`avx2`]: the `avx2!` macro, which compiles the auto-vectorised loops of
//!   `pixels.rs` and of the local operators a second time for AVX2 + FMA, and the
//!   hand-written AVX2 kernels (streaming stores, the curve table's lookup, agx);
//! - [`avx512`]: the AVX-512 register passes and each operator's 16-lane form.
//!
//! Which kernel runs is the call's [`prism_cpu::Simd`]: `Context::simd`, read once per
//! tone-mapping call from `prism_cpu::active()` (so `PRISM_SIMD` and `--simd` reach every
//! kernel) and carried to the worker threads, never looked up there, so tests run every
//! ISA side by side (`tests`). Every kernel gives the scalar path's bits; the operators
//! whose curve has a register form only with AVX-512 (drago03's octave polynomials,
//! tumblin-rushmeier's power curve) approximate their formula differently there, to
//! ~1e-7 either way.

pub(crate) mod avx2;
pub(crate) mod avx512;

pub(crate) use avx2::avx2;
pub(crate) use avx512::{RegisterCurve, RegisterMap};

use prism_cpu::Simd;

use super::pixels::{
    map_chunks, map_luminance_chunk, map_pixels_chunk, stats_chunk, Acc, Mapped, PixelMap,
};
use super::Context;

/// One task of the luminance mapping pass (pixels `start …` of the image) with the widest
/// kernel `simd` allows: the AVX-512 register pass (16 pixels per step; register curves
/// take no pixel index), else the scalar plumbing compiled for AVX2 or the baseline.
#[inline]
pub(crate) fn luminance_task<C: RegisterCurve>(
    simd: Simd,
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> (u64, u64) {
    #[cfg(target_arch = "x86_64")]
    if simd.avx512() {
        // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
        return unsafe { avx512::chunk_avx512(input, out, scale, w, curve) };
    }
    avx2!(
        simd,
        map_luminance_chunk(input, out, start, scale, w, curve)
    )
}

/// [`super::pixels::map_luminance`] (same contract, same bits) for a curve with a register
/// form, each task through [`luminance_task`].
pub(crate) fn map_luminance_fast<C: RegisterCurve>(
    ctx: &Context,
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> Mapped {
    let simd = ctx.simd;
    map_chunks(ctx, |start, i, o| {
        luminance_task(simd, i, o, start, scale, w, curve)
    })
}

/// One task of [`super::pixels::map_pixels`] with the widest kernel `simd` allows: with
/// AVX-512 the blocks are de-interleaved and interleaved in registers around the map on
/// planes, else the scalar plumbing compiled for AVX2 or the baseline.
#[inline]
pub(crate) fn pixels_task<M: PixelMap>(
    simd: Simd,
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    f: &M,
) -> (u64, u64) {
    #[cfg(target_arch = "x86_64")]
    if simd.avx512() {
        // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
        return unsafe { avx512::map_pixels_chunk_avx512(input, out, start, scale, f, simd) };
    }
    avx2!(simd, map_pixels_chunk(input, out, start, scale, f, simd))
}

/// One task of [`map_pixels_registers`]: with AVX-512 the map's register form inside the
/// 16-pixel load/store loop, else [`pixels_task`].
#[inline]
pub(crate) fn register_pixels_task<M: RegisterMap>(
    simd: Simd,
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    f: &M,
) -> (u64, u64) {
    #[cfg(target_arch = "x86_64")]
    if simd.avx512() {
        // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
        return unsafe { avx512::pixels_registers_task(input, out, scale, f) };
    }
    pixels_task(simd, input, out, start, scale, f)
}

/// [`super::pixels::map_pixels`] (same contract, same bits) for a map with a register
/// form: per 16 pixels three loads, the de-interleave, sanitising, the map, cleaning
/// (non-finite results to 0), the interleave and three streaming stores, all in
/// registers, where `ctx.simd` allows AVX-512 ([`register_pixels_task`]).
pub(crate) fn map_pixels_registers<M: RegisterMap>(ctx: &Context, scale: f32, f: &M) -> Mapped {
    let simd = ctx.simd;
    map_chunks(ctx, |start, i, o| {
        register_pixels_task(simd, i, o, start, scale, f)
    })
}

/// One task of [`super::pixels::luminance_stats`] with the widest kernel `simd` allows
/// (the same accumulators and lane layout, so the same bits, on every path).
#[inline]
pub(crate) fn stats_task(simd: Simd, chunk: &[[f32; 3]], scale: f32, w: [f32; 3]) -> Acc {
    #[cfg(target_arch = "x86_64")]
    if simd.avx512() {
        // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
        return unsafe { avx512::stats_chunk_avx512(chunk, scale, w) };
    }
    avx2!(simd, stats_chunk(chunk, scale, w))
}

#[cfg(test)]
pub(crate) mod tests;
