//! The AVX-512 family: kernels in AVX-512F intrinsics (16 f32 lanes), run where the
//! call's [`prism_cpu::Simd`] allows AVX-512 (`Context::simd`; the dispatch is in
//! [`super`]). Each is the same operations in the same order as the scalar code it
//! replaces, without fused multiply-adds where that has none, so it gives the scalar
//! path's bits (tested for every ISA the machine runs: `kernels::tests` and each
//! operator's `vector_path_gives_the_scalar_bits`).
//!
//! The passes: the luminance mapping pass of [`crate::tonemap::pixels::map_luminance`]
//! written out for 16 pixels per step in registers, for the global operators whose curve
//! has a 16-lane form ([`RegisterCurve`]: exponential, logarithmic, drago03, reinhard02,
//! mean-value, ward94); the pixel pass for maps with a register form ([`RegisterMap`]:
//! agx); the pixel pass over planes ([`map_pixels_chunk_avx512`]: linear, aces,
//! ferwerda96) and the statistics pass ([`stats_chunk_avx512`]: every operator).
//!
//! Why: on the Zen 5 of the fourth pass (docs/history/post-speed.md) the auto-vectorised pass — pixels
//! de-interleaved into stack planes, the curve over a plane, interleaved back, written with
//! ordinary stores — cost 2–3× the copy pass by itself, and compiling those same loops for
//! AVX-512 measured twice as slow again (the compiler's 16-lane de-interleave of
//! `[f32; 3]` is poor). Here 16 pixels are three 64-byte loads, de-interleaved with two
//! `vpermt2ps` per channel, sanitised, mapped through the curve in registers, interleaved
//! back the same way and written with streaming stores (no read for ownership of the
//! output).
//!
//! Bits: every step is the operation of the scalar path (`load_block` and
//! `map_luminance_chunk` in [`crate::tonemap::pixels`], and the curve's `ratio`) in the
//! same order, so the result is the scalar path's bits (tested for every curve, on NaN,
//! ±∞, negative, ±0 and subnormal input). The few pixels before the first 64-byte-aligned
//! output address and after the last whole group of 16 go through the same 16-lane code
//! on a zero-padded group (seventh pass, docs/history/post-speed.md; the scalar path itself before).
//! Register curves and maps take no pixel index: the ones written so far are global
//! (their `ratio` ignores `start`).
//!
//! Each step handles several groups of 16 pixels ([`STEP_GROUPS`]) with their curve or
//! map evaluations written side by side: one group's chain of dependent operations is
//! long (agx: ≈ 25 operations, ≈ 120 cycles), and one group per step left the passes
//! latency-bound (seventh pass).
//!
//! After the passes, the operators' register forms, one section per operator file: the
//! curves' `ratio16`, the curve tables' `eval16`, [`PowerCurve`](crate::tonemap::power_curve::PowerCurve)'s
//! slice evaluation and agx's `map16`.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

#[cfg(target_arch = "x86_64")]
use crate::tonemap::pixels::{
    map_pixels_chunk, stats_block, store_block, store_fence, Acc, StatsLanes, BLOCK, LANES,
    LOG_AVERAGE_DELTA,
};
use crate::tonemap::pixels::{LuminanceCurve, PixelMap, Scale};

/// A [`LuminanceCurve`] with a 16-lane register form.
pub(crate) trait RegisterCurve: LuminanceCurve {
    /// [`LuminanceCurve::ratio`] on 16 lanes, lane by lane the same bits. Implementations
    /// are `#[inline(always)]` and only use AVX-512F intrinsics.
    ///
    /// # Safety
    /// The CPU must have AVX-512F (callers are `#[target_feature(enable = "avx512f")]`).
    #[cfg(target_arch = "x86_64")]
    unsafe fn ratio16(&self, l: __m512) -> __m512;
}

impl RegisterCurve for Scale {
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn ratio16(&self, _l: __m512) -> __m512 {
        _mm512_set1_ps(self.0)
    }
}

/// `vpermt2ps` indices that gather channel `ch` of 16 interleaved pixels from the three
/// registers a, b, c (floats 0–15, 16–31, 32–47): (from a|b, then from that|c).
#[cfg(target_arch = "x86_64")]
const fn deinterleave_indices(ch: usize) -> ([i32; 16], [i32; 16]) {
    let (mut first, mut second) = ([0i32; 16], [0i32; 16]);
    let mut k = 0;
    while k < 16 {
        let f = 3 * k + ch;
        if f < 32 {
            first[k] = f as i32;
            second[k] = k as i32;
        } else {
            second[k] = (16 + f - 32) as i32;
        }
        k += 1;
    }
    (first, second)
}

/// `vpermt2ps` indices that build output register `reg` (floats 16·reg … 16·reg + 15 of
/// the interleaved pixels) from the planes r, g (first) and that|b (second).
#[cfg(target_arch = "x86_64")]
const fn interleave_indices(reg: usize) -> ([i32; 16], [i32; 16]) {
    let (mut first, mut second) = ([0i32; 16], [0i32; 16]);
    let mut j = 0;
    while j < 16 {
        let f = 16 * reg + j;
        let (k, ch) = (f / 3, f % 3);
        match ch {
            0 => {
                first[j] = k as i32;
                second[j] = j as i32;
            }
            1 => {
                first[j] = (16 + k) as i32;
                second[j] = j as i32;
            }
            _ => second[j] = (16 + k) as i32,
        }
        j += 1;
    }
    (first, second)
}

/// Prefetches the three cache lines 16 groups (3 KiB) ahead of `s`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn prefetch_ahead(s: *const f32) {
    let p = s.wrapping_add(PREFETCH_FLOATS) as *const i8;
    _mm_prefetch::<_MM_HINT_T0>(p);
    _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64));
    _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(128));
}

const PREFETCH_FLOATS: usize = 48 * 16;

/// The `vpermt2ps` index pairs that gather channel 0, 1, 2 of 16 interleaved RGB pixels.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn deinterleave_registers() -> IndexPairs {
    [0, 1, 2].map(|ch| {
        let (a, b) = deinterleave_indices(ch);
        (
            _mm512_loadu_si512(a.as_ptr() as *const _),
            _mm512_loadu_si512(b.as_ptr() as *const _),
        )
    })
}

/// The R, G, B planes of the 16 interleaved pixels (48 floats) at `s`: three loads, two
/// `vpermt2ps` per channel. The caller guarantees the 48 floats are readable.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn load_planes16(s: *const f32, de: &IndexPairs) -> [__m512; 3] {
    let v = [
        _mm512_loadu_ps(s),
        _mm512_loadu_ps(s.add(16)),
        _mm512_loadu_ps(s.add(32)),
    ];
    de.map(|(i0, i1)| _mm512_permutex2var_ps(_mm512_permutex2var_ps(v[0], i0, v[1]), i1, v[2]))
}

/// Planes R, G, B of 16 pixels permuted into the three registers of 48 interleaved floats
/// (two `vpermt2ps` each; `load_planes16`'s inverse, `inter` from `interleave_indices`).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn interleave16(p: [__m512; 3], inter: &IndexPairs) -> [__m512; 3] {
    inter.map(|(i0, i1)| _mm512_permutex2var_ps(_mm512_permutex2var_ps(p[0], i0, p[1]), i1, p[2]))
}

/// |x| < ∞ per lane (false for NaN).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn finite_mask(x: __m512) -> __mmask16 {
    _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(x), _mm512_set1_ps(f32::INFINITY))
}

/// load_block on 16 pixels: `scale · rgb` clamped to ≥ 0 (maxps(x, 0) returns its second
/// operand for NaN and ±0, as `f32::max(x, 0)` compiles), black for a pixel with a
/// non-finite component; with the masks of finite pixels and of finite pixels with a
/// negative component.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
/// `SCALED = false` skips the multiplication, for scale = 1 (x · 1 = x for every finite
/// x, ±0 and subnormals included, and non-finite pixels become black either way).
unsafe fn sanitise16<const SCALED: bool>(
    p: [__m512; 3],
    scale: __m512,
) -> ([__m512; 3], __mmask16, __mmask16) {
    let zero = _mm512_setzero_ps();
    let finite = finite_mask(p[0]) & finite_mask(p[1]) & finite_mask(p[2]);
    let neg = (_mm512_cmp_ps_mask::<_CMP_LT_OQ>(p[0], zero)
        | _mm512_cmp_ps_mask::<_CMP_LT_OQ>(p[1], zero)
        | _mm512_cmp_ps_mask::<_CMP_LT_OQ>(p[2], zero))
        & finite;
    let c = |x: __m512| {
        let x = if SCALED { _mm512_mul_ps(x, scale) } else { x };
        _mm512_maskz_mov_ps(finite, _mm512_max_ps(x, zero))
    };
    ([c(p[0]), c(p[1]), c(p[2])], finite, neg)
}

/// G groups of 16 pixels (48 floats each) at `s` through the luminance mapping, as three
/// interleaved output registers each, with the masks of non-finite and of negative
/// input pixels. The caller guarantees the 48 G floats are readable.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn luminance_group16<C: RegisterCurve, const G: usize, const SCALED: bool>(
    curve: &C,
    w: &[__m512; 3],
    de: &IndexPairs,
    inter: &IndexPairs,
    scale: __m512,
    s: *const f32,
) -> ([[__m512; 3]; G], [__mmask16; G], [__mmask16; G]) {
    let zero = _mm512_setzero_ps();
    let (mut c, mut l, mut non_finite, mut neg) = ([[zero; 3]; G], [zero; G], [0; G], [0; G]);
    for g in 0..G {
        // load_block: black for a pixel with a non-finite component, negatives to 0,
        // luminance w · c summed left to right.
        let (cg, finite, ng) = sanitise16::<SCALED>(load_planes16(s.add(48 * g), de), scale);
        (c[g], non_finite[g], neg[g]) = (cg, !finite, ng);
        l[g] = _mm512_add_ps(
            _mm512_add_ps(_mm512_mul_ps(w[0], cg[0]), _mm512_mul_ps(w[1], cg[1])),
            _mm512_mul_ps(w[2], cg[2]),
        );
    }
    // The G curve evaluations next to each other (independent chains).
    let mut ld = [zero; G];
    for g in 0..G {
        ld[g] = curve.ratio16(l[g]);
    }
    let mut o = [[zero; 3]; G];
    for g in 0..G {
        // map_luminance_chunk: the ratio where L > 0 and it is finite, else 0; then
        // max(c · ratio, 0), black where that overflows.
        let keep = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(l[g], zero) & finite_mask(ld[g]);
        let ratio = _mm512_maskz_mov_ps(keep, ld[g]);
        let x = [0, 1, 2].map(|ch| _mm512_max_ps(_mm512_mul_ps(c[g][ch], ratio), zero));
        let ok = finite_mask(x[0]) & finite_mask(x[1]) & finite_mask(x[2]);
        o[g] = interleave16(x.map(|v| _mm512_maskz_mov_ps(ok, v)), inter);
    }
    (o, non_finite, neg)
}

/// One task of [`crate::tonemap::kernels::map_luminance_fast`], without the exposure
/// multiplication where the scale is 1 (the same bits, see [`sanitise16`]).
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
pub(crate) unsafe fn chunk_avx512<C: RegisterCurve>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> (u64, u64) {
    if scale == 1.0 {
        luminance_chunk_avx512::<C, false>(input, out, scale, w, curve)
    } else {
        luminance_chunk_avx512::<C, true>(input, out, scale, w, curve)
    }
}

/// `vpermt2ps` index pairs, one per channel or output register.
#[cfg(target_arch = "x86_64")]
type IndexPairs = [(__m512i, __m512i); 3];

/// The de-interleave and interleave `vpermt2ps` index pairs of the register passes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn group_indices() -> (IndexPairs, IndexPairs) {
    let load_idx = |a: [i32; 16]| _mm512_loadu_si512(a.as_ptr() as *const _);
    let inter = [0, 1, 2].map(|reg| {
        let (a, b) = interleave_indices(reg);
        (load_idx(a), load_idx(b))
    });
    (deinterleave_registers(), inter)
}

/// The loop both register passes run over one task's pixels, around `$groups!(G, s)` —
/// a caller's macro giving the G groups of 16 pixels at `s` as (interleaved output
/// registers, non-finite masks, negative masks). Pixels before the first output pixel on
/// a 64-byte boundary (f32s are 4-byte aligned and gcd(12, 64) = 4, so one of the first
/// 16 is) and after the last whole group go through a zero-padded group (zeros count as
/// neither non-finite nor negative); [`STEP_GROUPS`] groups per step, prefetched ahead
/// and stored with streaming stores; the counts kept per lane and added up at the end.
/// A macro, not a generic function over a kernel trait: the kernels must inline into each
/// `#[target_feature]` body, and the trait version cost agx half its speed. Evaluates to
/// the task's (non-finite, negative) pixel counts.
#[cfg(target_arch = "x86_64")]
macro_rules! register_pass {
    ($input:expr, $out:expr, $groups:ident) => {{
        let (input, out): (&[[f32; 3]], &mut [[f32; 3]]) = ($input, $out);
        let n = input.len().min(out.len());
        let addr = out.as_ptr() as usize;
        let head = (0..16)
            .find(|k| (addr + 12 * k).is_multiple_of(64))
            .unwrap_or(0)
            .min(n);
        let groups = (n - head) / 16;
        let tail = head + 16 * groups;
        // Per-lane counts (≤ CHUNK / 16 per lane) instead of two popcounts per group
        // (the baseline build has no `popcnt`: each is a dozen instructions).
        let one = _mm512_set1_epi32(1);
        let (mut nf_lanes, mut neg_lanes) = (_mm512_setzero_si512(), _mm512_setzero_si512());
        let partial = |i: &[[f32; 3]], o: &mut [[f32; 3]]| {
            let mut buf = [[0.0f32; 3]; 16];
            buf[..i.len()].copy_from_slice(i);
            // SAFETY: buf holds 48 floats.
            let ([v], [nf], [neg]) = $groups!(1, buf.as_ptr() as *const f32);
            let d = buf.as_mut_ptr() as *mut f32;
            for (reg, v) in v.into_iter().enumerate() {
                // SAFETY: buf holds 48 floats.
                _mm512_storeu_ps(d.add(16 * reg), v);
            }
            o.copy_from_slice(&buf[..o.len()]);
            (nf.count_ones() as u64, neg.count_ones() as u64)
        };
        let (non_finite, negative) = partial(&input[..head], &mut out[..head]);
        let src = input.as_ptr().add(head) as *const f32;
        let dst = out.as_mut_ptr().add(head) as *mut f32;
        let mut g = 0;
        while g < groups {
            // SAFETY: pixels head + 16 g … head + 16 (g + k) − 1 lie inside both slices
            // for the k ≤ groups − g groups handled below (floats 48 g … 48 (g + k) − 1
            // from src and dst); the prefetches do not fault.
            let s = src.add(48 * g);
            for k in 0..STEP_GROUPS {
                prefetch_ahead(s.add(48 * k));
            }
            let d = dst.add(48 * g);
            let mut store = |k: usize, v: [__m512; 3], nf: __mmask16, neg: __mmask16| {
                nf_lanes = _mm512_mask_add_epi32(nf_lanes, nf, nf_lanes, one);
                neg_lanes = _mm512_mask_add_epi32(neg_lanes, neg, neg_lanes, one);
                for (reg, v) in v.into_iter().enumerate() {
                    // SAFETY: d + 48 k + 16 reg is 64-byte aligned (head chosen so) and
                    // inside `out`.
                    _mm512_stream_ps(d.add(48 * k + 16 * reg), v);
                }
            };
            if g + STEP_GROUPS <= groups {
                let (v, nf, neg) = $groups!(STEP_GROUPS, s);
                for k in 0..STEP_GROUPS {
                    store(k, v[k], nf[k], neg[k]);
                }
                g += STEP_GROUPS;
            } else {
                let ([v], [nf], [neg]) = $groups!(1, s);
                store(0, v, nf, neg);
                g += 1;
            }
        }
        // Streaming stores are weakly ordered: fence them before the task reports done.
        _mm_sfence();
        let (nf, neg) = partial(&input[tail..n], &mut out[tail..n]);
        let lanes = |v: __m512i| _mm512_reduce_add_epi32(v) as u32 as u64;
        (
            non_finite + nf + lanes(nf_lanes),
            negative + neg + lanes(neg_lanes),
        )
    }};
}

/// The body of [`chunk_avx512`]: [`register_pass!`] around the curve of
/// [`STEP_GROUPS`] groups of 16 pixels side by side (a zero-padded group is black, and
/// maps to black).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn luminance_chunk_avx512<C: RegisterCurve, const SCALED: bool>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    scale: f32,
    w: [f32; 3],
    curve: &C,
) -> (u64, u64) {
    let (de, inter) = group_indices();
    let scale_v = _mm512_set1_ps(scale);
    let w_v = w.map(|x| _mm512_set1_ps(x));
    macro_rules! luminance_groups {
        ($g:expr, $s:expr) => {
            luminance_group16::<C, { $g }, SCALED>(curve, &w_v, &de, &inter, scale_v, $s)
        };
    }
    register_pass!(input, out, luminance_groups)
}

/// A [`PixelMap`] with a 16-lane register form, for
/// [`crate::tonemap::kernels::map_pixels_registers`]: the map
/// runs inside the 16-pixel load/store loop on registers, with its constants loaded once
/// per task, instead of over stack planes staged through memory (docs/history/post-speed.md, seventh
/// pass).
pub(crate) trait RegisterMap: PixelMap {
    /// The map's constants, held in registers (or wherever the compiler keeps them)
    /// across a task.
    #[cfg(target_arch = "x86_64")]
    type Regs;
    /// Whether [`Self::map16`] returns only finite values for sanitised input (finite,
    /// ≥ 0), so that the pass can skip turning non-finite results into 0 (which then
    /// changes no bits). Implementations that set it say why it holds.
    const FINITE_OUTPUT: bool = false;
    /// Loads the constants. Implementations are `#[inline(always)]` and only use
    /// AVX-512F intrinsics.
    ///
    /// # Safety
    /// The CPU must have AVX-512F (callers are `#[target_feature(enable = "avx512f")]`).
    #[cfg(target_arch = "x86_64")]
    unsafe fn regs16(&self) -> Self::Regs;
    /// [`PixelMap::map`] on G groups of 16 sanitised pixels (R, G, B planes in
    /// registers), lane by lane the same bits; the pass hands over [`STEP_GROUPS`] groups
    /// at a time so that a map can interleave their (independent) dependency chains.
    /// `#[inline(always)]`, AVX-512F intrinsics only.
    ///
    /// # Safety
    /// As [`Self::regs16`]; `regs` comes from `self.regs16()`.
    #[cfg(target_arch = "x86_64")]
    unsafe fn map16<const G: usize>(
        &self,
        regs: &Self::Regs,
        rgb: [[__m512; 3]; G],
    ) -> [[__m512; 3]; G];
}

/// The G groups of 16 pixels (48 floats each) at `s` through `f`, as three interleaved
/// output registers each, with the masks of non-finite and of negative input pixels.
/// The caller guarantees the 48 G floats are readable.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn group16<M: RegisterMap, const G: usize, const SCALED: bool>(
    f: &M,
    regs: &M::Regs,
    de: &IndexPairs,
    inter: &IndexPairs,
    scale: __m512,
    s: *const f32,
) -> ([[__m512; 3]; G], [__mmask16; G], [__mmask16; G]) {
    let zero = _mm512_setzero_ps();
    let (mut c, mut non_finite, mut neg) = ([[zero; 3]; G], [0; G], [0; G]);
    for g in 0..G {
        let (cg, finite, ng) = sanitise16::<SCALED>(load_planes16(s.add(48 * g), de), scale);
        (c[g], non_finite[g], neg[g]) = (cg, !finite, ng);
    }
    let mut o = f.map16(regs, c);
    if !M::FINITE_OUTPUT {
        // map_pixels_chunk: non-finite results become 0, per component.
        for x in o.iter_mut().flatten() {
            *x = _mm512_maskz_mov_ps(finite_mask(*x), *x);
        }
    }
    for x in &mut o {
        *x = interleave16(*x, inter);
    }
    (o, non_finite, neg)
}

/// One task of [`crate::tonemap::kernels::map_pixels_registers`], without the exposure
/// multiplication where the scale is 1 (the default exposure: the same bits, see
/// [`sanitise16`]).
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
pub(crate) unsafe fn pixels_registers_task<M: RegisterMap>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    scale: f32,
    f: &M,
) -> (u64, u64) {
    if scale == 1.0 {
        pixels_registers_avx512::<M, false>(input, out, scale, f)
    } else {
        pixels_registers_avx512::<M, true>(input, out, scale, f)
    }
}

/// Groups of 16 pixels per step of [`pixels_registers_avx512`] and
/// [`luminance_chunk_avx512`].
#[cfg(target_arch = "x86_64")]
const STEP_GROUPS: usize = 3;

/// One task of [`crate::tonemap::kernels::map_pixels_registers`]: [`register_pass!`]
/// around the map. The head and tail pixels go through the 16-lane code on a zero-padded
/// copy, not the scalar path: a few scalar pixels per task cost more than the rest of it
/// where `f32::mul_add` is a library call (the baseline build has no FMA).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn pixels_registers_avx512<M: RegisterMap, const SCALED: bool>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    scale: f32,
    f: &M,
) -> (u64, u64) {
    let (de, inter) = group_indices();
    let scale_v = _mm512_set1_ps(scale);
    let regs = f.regs16();
    macro_rules! map_groups {
        ($g:expr, $s:expr) => {
            group16::<M, { $g }, SCALED>(f, &regs, &de, &inter, scale_v, $s)
        };
    }
    register_pass!(input, out, map_groups)
}

/// One task of [`crate::tonemap::pixels::map_pixels`] with AVX-512F: whole blocks are
/// de-interleaved into the stack planes and interleaved back in registers (two
/// `vpermt2ps` per channel and 16 pixels) instead of the compiler's AVX2 shuffles, the
/// pixel map runs on the planes as before, and the block goes out with streaming stores;
/// the same operations on every value, so the same bits as
/// [`crate::tonemap::pixels::map_pixels_chunk`] (which handles a partial last block).
///
/// # Safety
/// The CPU must have AVX-512F: `simd` allows AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn map_pixels_chunk_avx512<M: PixelMap>(
    input: &[[f32; 3]],
    out: &mut [[f32; 3]],
    start: usize,
    scale: f32,
    f: &M,
    simd: prism_cpu::Simd,
) -> (u64, u64) {
    let (de, inter) = group_indices();
    let scale_v = _mm512_set1_ps(scale);
    let mut planes = [[0.0f32; BLOCK]; 3];
    let mut staged = [[0.0f32; 3]; BLOCK];
    let (mut non_finite, mut negative) = (0u64, 0u64);
    let n = input.len().min(out.len());
    let whole = n / BLOCK * BLOCK;
    for (k, (i, o)) in input[..whole]
        .chunks_exact(BLOCK)
        .zip(out[..whole].chunks_exact_mut(BLOCK))
        .enumerate()
    {
        let src = i.as_ptr() as *const f32;
        for g in 0..BLOCK / 16 {
            // SAFETY: the block holds BLOCK pixels: floats 48 g … 48 g + 47 lie inside.
            let s = src.add(48 * g);
            prefetch_ahead(s);
            let (c, finite, neg) = sanitise16::<true>(load_planes16(s, &de), scale_v);
            non_finite += (!finite).count_ones() as u64;
            negative += neg.count_ones() as u64;
            for (plane, c) in planes.iter_mut().zip(c) {
                // SAFETY: 16 g + 15 < BLOCK.
                _mm512_storeu_ps(plane.as_mut_ptr().add(16 * g), c);
            }
        }
        let [r, gp, b] = &mut planes;
        f.map(start + k * BLOCK, r, gp, b);
        let dst = staged.as_mut_ptr() as *mut f32;
        for g in 0..BLOCK / 16 {
            // Non-finite results become 0, per component.
            let c = planes.each_ref().map(|plane| {
                // SAFETY: 16 g + 15 < BLOCK.
                let x = _mm512_loadu_ps(plane.as_ptr().add(16 * g));
                _mm512_maskz_mov_ps(finite_mask(x), x)
            });
            for (reg, v) in interleave16(c, &inter).into_iter().enumerate() {
                // SAFETY: floats 48 g + 16 reg … + 15 lie inside the staged block.
                _mm512_storeu_ps(dst.add(48 * g + 16 * reg), v);
            }
        }
        store_block(o, &staged, simd);
    }
    store_fence();
    let (nf, neg) = map_pixels_chunk(
        &input[whole..n],
        &mut out[whole..n],
        start + whole,
        scale,
        f,
        simd,
    );
    (non_finite + nf, negative + neg)
}

/// One task of [`crate::tonemap::pixels::luminance_stats`] with AVX-512F: the same
/// accumulators, lane layout and order of operations as
/// [`crate::tonemap::pixels::stats_chunk`] (so the same bits), each whole block of 16
/// groups of 16 pixels de-interleaved and summed in registers in one pass instead of a
/// luminance plane and a second loop over it.
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn stats_chunk_avx512(chunk: &[[f32; 3]], scale: f32, w: [f32; 3]) -> Acc {
    const _: () = assert!(LANES == 16 && BLOCK.is_multiple_of(16));
    let mut lanes = StatsLanes::EMPTY;
    let de = deinterleave_registers();
    let zero = _mm512_setzero_ps();
    let scale_v = _mm512_set1_ps(scale);
    let w_v = w.map(|x| _mm512_set1_ps(x));
    let delta = _mm512_set1_ps(LOG_AVERAGE_DELTA as f32);
    let (mantissa_mask, one_bits) = (
        _mm512_set1_epi32(0x007f_ffff),
        _mm512_set1_epi32(0x3f80_0000),
    );
    let bias = _mm512_set1_epi32(127);
    for block in chunk.chunks(BLOCK) {
        if block.len() < BLOCK {
            stats_block(&mut lanes, block, scale, w);
            continue;
        }
        let mut exponents = _mm512_loadu_si512(lanes.exponents.as_ptr() as *const _);
        let mut sum = _mm512_loadu_ps(lanes.sum.as_ptr());
        let mut max = _mm512_loadu_ps(lanes.max.as_ptr());
        let mut min_positive = _mm512_loadu_ps(lanes.min_positive.as_ptr());
        let mut product = _mm512_set1_ps(1.0);
        let src = block.as_ptr() as *const f32;
        for g in 0..BLOCK / 16 {
            // SAFETY: the block holds BLOCK pixels (checked above): floats 48 g …
            // 48 g + 47 lie inside it.
            let s = src.add(48 * g);
            prefetch_ahead(s);
            let p = load_planes16(s, &de);
            // sanitised_luminance: 0 for a pixel with a non-finite component, else
            // w · max(c · scale, 0) summed left to right.
            let finite = finite_mask(p[0]) & finite_mask(p[1]) & finite_mask(p[2]);
            let c = p.map(|x| _mm512_max_ps(_mm512_mul_ps(x, scale_v), zero));
            let l = _mm512_add_ps(
                _mm512_add_ps(_mm512_mul_ps(w_v[0], c[0]), _mm512_mul_ps(w_v[1], c[1])),
                _mm512_mul_ps(w_v[2], c[2]),
            );
            let l = _mm512_maskz_mov_ps(finite, l);
            // split_exponent(δ + L): biased exponent − 127 and the mantissa in [1, 2).
            let bits = _mm512_castps_si512(_mm512_add_ps(delta, l));
            exponents = _mm512_add_epi32(
                exponents,
                _mm512_sub_epi32(_mm512_srli_epi32::<23>(bits), bias),
            );
            let m = _mm512_or_si512(_mm512_and_si512(bits, mantissa_mask), one_bits);
            product = _mm512_mul_ps(product, _mm512_castsi512_ps(m));
            sum = _mm512_add_ps(sum, l);
            max = _mm512_max_ps(max, l);
            let positive = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(l, zero);
            min_positive = _mm512_mask_min_ps(min_positive, positive, min_positive, l);
        }
        let sum_log2 = _mm512_add_ps(_mm512_loadu_ps(lanes.sum_log2.as_ptr()), log2_16(product));
        _mm512_storeu_ps(lanes.sum_log2.as_mut_ptr(), sum_log2);
        _mm512_storeu_si512(lanes.exponents.as_mut_ptr() as *mut _, exponents);
        _mm512_storeu_ps(lanes.sum.as_mut_ptr(), sum);
        _mm512_storeu_ps(lanes.max.as_mut_ptr(), max);
        _mm512_storeu_ps(lanes.min_positive.as_mut_ptr(), min_positive);
    }
    lanes.total()
}

/// [`crate::tonemap::fast_math::exp2`] on 16 lanes, the same operations in the same order.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
#[allow(clippy::excessive_precision, clippy::approx_constant)]
pub(crate) unsafe fn exp2_16(x: __m512) -> __m512 {
    // clamp: maxps(lo, x) = lo > x ? lo : x (NaN stays), then the same for hi.
    let x = _mm512_max_ps(_mm512_set1_ps(-126.0), x);
    let x = _mm512_min_ps(_mm512_set1_ps(127.0), x);
    let xi = _mm512_max_ps(x, _mm512_set1_ps(-126.0));
    let sign = _mm512_and_si512(_mm512_castps_si512(xi), _mm512_set1_epi32(i32::MIN));
    let half = _mm512_or_si512(_mm512_set1_epi32(0x3eff_ffff), sign);
    let t = _mm512_add_ps(xi, _mm512_castsi512_ps(half));
    let ni = _mm512_cvttps_epi32(t);
    let n = _mm512_cvtepi32_ps(ni);
    let f = _mm512_sub_ps(x, n);
    let step = |r: __m512, c: f32| _mm512_add_ps(_mm512_mul_ps(r, f), _mm512_set1_ps(c));
    let r = _mm512_set1_ps(0.001_326_472);
    let r = step(r, 0.009_671_513);
    let r = step(r, 0.055_507_34);
    let r = step(r, 0.240_222_42);
    let r = step(r, 0.693_147);
    let p = step(r, 1.0);
    let scale = _mm512_slli_epi32::<23>(_mm512_add_epi32(ni, _mm512_set1_epi32(127)));
    _mm512_mul_ps(p, _mm512_castsi512_ps(scale))
}

/// [`crate::tonemap::fast_math::log2`] on 16 lanes, the same operations in the same order.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
#[allow(clippy::excessive_precision)]
pub(crate) unsafe fn log2_16(x: __m512) -> __m512 {
    let x = _mm512_max_ps(x, _mm512_set1_ps(f32::MIN_POSITIVE));
    let bits = _mm512_castps_si512(x);
    let offset = _mm512_sub_epi32(bits, _mm512_set1_epi32(0x3f35_04f3));
    let e = _mm512_cvtepi32_ps(_mm512_srai_epi32::<23>(offset));
    let m = _mm512_sub_epi32(
        bits,
        _mm512_and_si512(offset, _mm512_set1_epi32(0xff80_0000u32 as i32)),
    );
    let u = _mm512_sub_ps(_mm512_castsi512_ps(m), _mm512_set1_ps(1.0));
    let step = |q: __m512, c: f32| _mm512_add_ps(_mm512_mul_ps(q, u), _mm512_set1_ps(c));
    let q = _mm512_set1_ps(-0.145_741_06);
    let q = step(q, 0.236_889_03);
    let q = step(q, -0.250_069_65);
    let q = step(q, 0.286_707_67);
    let q = step(q, -0.360_087_2);
    let q = step(q, 0.480_939_45);
    let q = step(q, -0.721_357_17);
    let q = step(q, 1.442_694_8);
    _mm512_add_ps(e, _mm512_mul_ps(u, q))
}

/// The luminance curves' register forms (exponential.rs, logarithmic.rs, reinhard02.rs,
/// drago03.rs): each [`LuminanceCurve::ratio`] on 16 lanes, the same operations in the
/// same order.
mod curves {
    use super::RegisterCurve;
    use crate::tonemap::{drago03, exponential, logarithmic, reinhard02};

    impl RegisterCurve for exponential::Curve {
        /// [`LuminanceCurve::ratio`] on 16 lanes (same operations, same order).
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
            use std::arch::x86_64::*;
            let (one, rate) = (_mm512_set1_ps(1.0), _mm512_set1_ps(self.rate));
            let x = _mm512_mul_ps(rate, l);
            let small = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, _mm512_set1_ps(0.01));
            // Each branch only where some lane selects it (dark and bright pixels come in
            // runs, so the branches predict well); a lane's value is that of the scalar path
            // either way, since the blend below only reads the selected side.
            let series = if small != 0 {
                let inner = _mm512_sub_ps(one, _mm512_mul_ps(_mm512_set1_ps(0.25), x));
                let third =
                    _mm512_mul_ps(_mm512_mul_ps(x, _mm512_set1_ps(exponential::THIRD)), inner);
                let half = _mm512_mul_ps(
                    _mm512_mul_ps(_mm512_set1_ps(0.5), x),
                    _mm512_sub_ps(one, third),
                );
                _mm512_mul_ps(rate, _mm512_sub_ps(one, half))
            } else {
                one
            };
            let e = if small != 0xffff {
                // exp(−x) = exp2((−x) · log2 e), −x by flipping the sign bit as `-x` does.
                let minus_x = _mm512_castsi512_ps(_mm512_xor_si512(
                    _mm512_castps_si512(x),
                    _mm512_set1_epi32(i32::MIN),
                ));
                super::exp2_16(_mm512_mul_ps(
                    minus_x,
                    _mm512_set1_ps(std::f32::consts::LOG2_E),
                ))
            } else {
                one
            };
            let numerator = _mm512_mask_blend_ps(small, _mm512_sub_ps(one, e), series);
            let denominator = _mm512_mask_blend_ps(small, l, one);
            _mm512_div_ps(numerator, denominator)
        }
    }

    impl RegisterCurve for logarithmic::Curve {
        /// [`LuminanceCurve::ratio`] on 16 lanes (same operations, same order).
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
            use std::arch::x86_64::*;
            let one = _mm512_set1_ps(1.0);
            let inv = _mm512_set1_ps(self.inv * std::f32::consts::LN_2);
            let log = super::log2_16(_mm512_add_ps(one, _mm512_mul_ps(_mm512_set1_ps(self.q), l)));
            let recip = _mm512_div_ps(one, l);
            _mm512_mul_ps(_mm512_mul_ps(log, inv), recip)
        }
    }

    impl RegisterCurve for reinhard02::Curve {
        /// [`LuminanceCurve::ratio`] on 16 lanes (same operations, same order).
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
            use std::arch::x86_64::*;
            let (one, s) = (_mm512_set1_ps(1.0), _mm512_set1_ps(self.s));
            let x = _mm512_mul_ps(s, l);
            let num = _mm512_mul_ps(
                s,
                _mm512_add_ps(one, _mm512_mul_ps(x, _mm512_set1_ps(self.inv_white2))),
            );
            _mm512_div_ps(num, _mm512_add_ps(one, x))
        }
    }

    impl RegisterCurve for drago03::Octaves {
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
            self.0.eval16(l)
        }
    }

    impl RegisterCurve for drago03::Table {
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn ratio16(&self, l: std::arch::x86_64::__m512) -> std::arch::x86_64::__m512 {
            self.0.eval16(l)
        }
    }
}

/// curve_table.rs: the memory table's lookup on 16 lanes.
#[cfg(target_arch = "x86_64")]
mod curve_table {
    use crate::tonemap::curve_table::{CurveTable, LOW_BITS, LOW_MASK, T_SCALE};

    impl CurveTable {
        /// [`Self::eval`] on 16 lanes with AVX-512F: the same bits (the same operations in the
        /// same order).
        ///
        /// # Safety
        /// The CPU must have AVX-512F.
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        pub(crate) unsafe fn eval16(
            &self,
            x: std::arch::x86_64::__m512,
        ) -> std::arch::x86_64::__m512 {
            use std::arch::x86_64::*;
            let base = self.coeffs.as_ptr() as *const f32;
            let bits = _mm512_castps_si512(x);
            // Logical shift: negative arguments land above the last segment, as in `eval`.
            let s = _mm512_sub_epi32(
                _mm512_srli_epi32::<{ LOW_BITS }>(bits),
                _mm512_set1_epi32(self.first as i32),
            );
            let s = _mm512_min_epi32(
                _mm512_max_epi32(s, _mm512_setzero_si512()),
                _mm512_set1_epi32(self.coeffs.len() as i32 - 1),
            );
            // Each lane's four coefficients are one 16-byte load; four rows per register
            // (lanes j, j + 4, j + 8, j + 12 of register j), then a 4×4 transpose inside
            // each 128-bit slot turns them into c0..c3 (16 loads and 20 shuffles: measured
            // cheaper than four 16-lane gathers, as on 8 lanes).
            let mut idx = [0i32; 16];
            _mm512_storeu_si512(idx.as_mut_ptr() as *mut _, s);
            // SAFETY: 0 ≤ idx[k] < coeffs.len() (clamped above), so each row's four floats
            // lie inside the coefficient table.
            let row = |k: usize| _mm_loadu_ps(base.add(4 * idx[k] as usize));
            let reg = |j: usize| {
                let z = _mm512_castps128_ps512(row(j));
                let z = _mm512_insertf32x4::<1>(z, row(j + 4));
                let z = _mm512_insertf32x4::<2>(z, row(j + 8));
                _mm512_insertf32x4::<3>(z, row(j + 12))
            };
            let (r0, r1, r2, r3) = (reg(0), reg(1), reg(2), reg(3));
            let t0 = _mm512_unpacklo_ps(r0, r1);
            let t1 = _mm512_unpackhi_ps(r0, r1);
            let t2 = _mm512_unpacklo_ps(r2, r3);
            let t3 = _mm512_unpackhi_ps(r2, r3);
            let lo = |a: __m512, b: __m512| {
                _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(a), _mm512_castps_pd(b)))
            };
            let hi = |a: __m512, b: __m512| {
                _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(a), _mm512_castps_pd(b)))
            };
            let c = [lo(t0, t2), hi(t0, t2), lo(t1, t3), hi(t1, t3)];
            let t = _mm512_mul_ps(
                _mm512_cvtepi32_ps(_mm512_and_si512(bits, _mm512_set1_epi32(LOW_MASK as i32))),
                _mm512_set1_ps(T_SCALE),
            );
            let p = _mm512_add_ps(c[2], _mm512_mul_ps(t, c[3]));
            let p = _mm512_add_ps(c[1], _mm512_mul_ps(t, p));
            _mm512_add_ps(c[0], _mm512_mul_ps(t, p))
        }
    }
}

/// octave_curve.rs: one polynomial per octave, coefficients from registers.
#[cfg(target_arch = "x86_64")]
mod octave_curve {
    use crate::tonemap::octave_curve::{OctaveCurve, MANTISSA_MASK, ONE_BITS, TERMS};

    impl OctaveCurve {
        /// [`Self::eval`] on 16 lanes: the same bits.
        ///
        /// # Safety
        /// The CPU must have AVX-512F (which `new` checked).
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        pub(crate) unsafe fn eval16(
            &self,
            x: std::arch::x86_64::__m512,
        ) -> std::arch::x86_64::__m512 {
            use std::arch::x86_64::*;
            // maxps returns its second operand when the first is NaN (as f32::max).
            let x = _mm512_min_ps(
                _mm512_max_ps(x, _mm512_set1_ps(self.lo)),
                _mm512_set1_ps(self.hi),
            );
            let bits = _mm512_castps_si512(x);
            // vpermt2ps reads the low 5 bits of the index: the biased exponent modulo 32
            // (x > 0 after the clamp, so the sign bit is clear).
            let b = _mm512_srli_epi32::<23>(bits);
            // (bits & MANTISSA_MASK) | ONE_BITS in one vpternlogd (truth table 0xEA: a & b | c).
            let m = _mm512_ternarylogic_epi32::<0xEA>(
                bits,
                _mm512_set1_epi32(MANTISSA_MASK as i32),
                _mm512_set1_epi32(ONE_BITS as i32),
            );
            let s = _mm512_sub_ps(_mm512_castsi512_ps(m), _mm512_set1_ps(1.5));
            // SAFETY: each row holds 32 f32s (two 16-lane loads).
            let coeff = |j: usize| {
                let row = self.coeffs[j].as_ptr();
                _mm512_permutex2var_ps(_mm512_loadu_ps(row), b, _mm512_loadu_ps(row.add(16)))
            };
            let mut p = coeff(TERMS - 1);
            for j in (0..TERMS - 1).rev() {
                p = _mm512_fmadd_ps(p, s, coeff(j));
            }
            p
        }
    }
}

/// power_curve.rs: c · x^a on 16 lanes.
#[cfg(target_arch = "x86_64")]
mod power_curve {
    use crate::tonemap::power_curve::{PowerCurve, T_BITS, T_MASK, T_SCALE};

    impl PowerCurve {
        /// [`PowerCurve::eval_slice`] on 16 lanes: the same bits as
        /// [`PowerCurve::eval`].
        ///
        /// # Safety
        /// The CPU must have AVX-512F.
        #[target_feature(enable = "avx512f")]
        pub(crate) unsafe fn eval_slice_avx512(&self, v: &mut [f32]) {
            use std::arch::x86_64::*;
            // SAFETY (loads): each row holds 16 f32s, `scales` 32.
            let c: [__m512; 4] = std::array::from_fn(|j| _mm512_loadu_ps(self.coeffs[j].as_ptr()));
            let s_lo = _mm512_loadu_ps(self.scales.as_ptr());
            let s_hi = _mm512_loadu_ps(self.scales.as_ptr().add(16));
            let (lo, hi) = (_mm512_set1_ps(self.lo), _mm512_set1_ps(self.hi));
            let t_mask = _mm512_set1_epi32(T_MASK as i32);
            let t_scale = _mm512_set1_ps(T_SCALE);
            let mut chunks = v.chunks_exact_mut(16);
            for chunk in &mut chunks {
                // maxps returns its second operand when the first is NaN (as f32::max).
                let x = _mm512_min_ps(_mm512_max_ps(_mm512_loadu_ps(chunk.as_ptr()), lo), hi);
                let bits = _mm512_castps_si512(x);
                // vpermps reads the low 4 bits of the index (the segment), vpermt2ps the low
                // 5 (the biased exponent modulo 32).
                let k = _mm512_srli_epi32::<{ T_BITS }>(bits);
                let t = _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_and_si512(bits, t_mask)), t_scale);
                let p = _mm512_fmadd_ps(
                    _mm512_permutexvar_ps(k, c[3]),
                    t,
                    _mm512_permutexvar_ps(k, c[2]),
                );
                let p = _mm512_fmadd_ps(p, t, _mm512_permutexvar_ps(k, c[1]));
                let p = _mm512_fmadd_ps(p, t, _mm512_permutexvar_ps(k, c[0]));
                let s = _mm512_permutex2var_ps(s_lo, _mm512_srli_epi32::<23>(bits), s_hi);
                _mm512_storeu_ps(chunk.as_mut_ptr(), _mm512_mul_ps(p, s));
            }
            for x in chunks.into_remainder() {
                *x = self.eval(*x);
            }
        }
    }
}

/// agx.rs: the whole transform on 16 lanes, over planes and in the register pass.
mod agx {
    use super::RegisterMap;
    use crate::tonemap::agx::Map;
    #[cfg(target_arch = "x86_64")]
    use crate::tonemap::agx::{
        Curves, Mat, ENCODE_TERMS, ONE_BITS, POWER_TERMS, S_CENTRE, T_BITS, T_MASK, Y_ZERO,
    };

    impl Map {
        /// [`PixelMap::map`] on 16 lanes over planes ([`RegisterMap::map16`] per 16 pixels;
        /// the tone-mapping pass itself runs the register form directly, this serves
        /// [`PixelMap::map`] callers).
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        pub(crate) unsafe fn map_avx512(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
            use std::arch::x86_64::*;
            let n = r.len().min(g.len()).min(b.len());
            let regs = self.regs16();
            let mut j = 0;
            while j + 16 <= n {
                // SAFETY: j + 16 ≤ n ≤ the length of each plane.
                let (pr, pg, pb) = (
                    r.as_mut_ptr().add(j),
                    g.as_mut_ptr().add(j),
                    b.as_mut_ptr().add(j),
                );
                let [[x, y, z]] = self.map16(
                    &regs,
                    [[
                        _mm512_loadu_ps(pr),
                        _mm512_loadu_ps(pg),
                        _mm512_loadu_ps(pb),
                    ]],
                );
                _mm512_storeu_ps(pr, x);
                _mm512_storeu_ps(pg, y);
                _mm512_storeu_ps(pb, z);
                j += 16;
            }
            for j in j..n {
                [r[j], g[j], b[j]] = self.pixel(r[j], g[j], b[j]);
            }
        }
    }

    /// The constants of [`Map`]'s 16-lane form, loaded once per task.
    #[cfg(target_arch = "x86_64")]
    pub(crate) struct Regs16 {
        inset: [std::arch::x86_64::__m512; 9],
        outset: [std::arch::x86_64::__m512; 9],
        from: Option<[std::arch::x86_64::__m512; 9]>,
        encode: [std::arch::x86_64::__m512; ENCODE_TERMS],
        power: [std::arch::x86_64::__m512; POWER_TERMS],
        contrast: [std::arch::x86_64::__m512; 7],
        scales: [std::arch::x86_64::__m512; 2],
    }

    impl RegisterMap for Map {
        #[cfg(target_arch = "x86_64")]
        type Regs = Regs16;
        /// The power curve's input is ≥ Y_ZERO and < Y_MAX (`outset_values_stay_below_y_max`:
        /// the encoding's clamp and the contrast polynomial bound it), its cubic and scale
        /// are finite there, and the matrix back from sRGB of such values is finite.
        const FINITE_OUTPUT: bool = true;

        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn regs16(&self) -> Regs16 {
            use std::arch::x86_64::*;
            let c = self.curves;
            let splat = |m: &Mat| m.map(|v| _mm512_set1_ps(v));
            // SAFETY (loads): each array holds 16 f32s.
            let load = |a: &[f32; 16]| _mm512_loadu_ps(a.as_ptr());
            Regs16 {
                inset: splat(&self.inset),
                outset: splat(&self.outset),
                from: self.from_srgb.as_ref().map(splat),
                encode: std::array::from_fn(|j| load(&c.encode16[j])),
                power: std::array::from_fn(|j| load(&c.power16[j])),
                contrast: c.contrast.map(|v| _mm512_set1_ps(v)),
                scales: [
                    _mm512_loadu_ps(c.scales.as_ptr()),
                    _mm512_loadu_ps(c.scales.as_ptr().add(16)),
                ],
            }
        }

        /// [`Map::pixel`] on 16 lanes: the same operations in the same order, with four
        /// AVX-512 shortcuts that give the same values: the exponent by `vgetexpps` (⌊log2 v⌋
        /// of a positive normal v, the integer the scalar path extracts), each 8-entry
        /// coefficient register repeated in both halves of a 16-entry `vpermps` (its index,
        /// bits >> 20, then carries the exponent's lowest bit above the segment), s by one
        /// `vpternlogd`, and 2^(2.2e) read from the 32-entry table [`Curves::scales`] with
        /// one two-register `vpermt2ps` (biased exponents 103…128 are distinct modulo 32),
        /// whose 0 at exponent 102 ([`Y_ZERO`]) stands for the scalar path's y < Y_MIN test.
        #[cfg(target_arch = "x86_64")]
        #[inline(always)]
        unsafe fn map16<const G: usize>(
            &self,
            k: &Regs16,
            rgb: [[std::arch::x86_64::__m512; 3]; G],
        ) -> [[std::arch::x86_64::__m512; 3]; G] {
            // No closures here: this function has no target features of its own, and a
            // closure the optimiser does not inline would be compiled without AVX-512 (every
            // intrinsic a call). The helpers are `#[inline(always)]` functions instead.
            let mut v = rgb;
            for x in &mut v {
                *x = mat16(&k.inset, *x);
            }
            encode16(k, self.curves, &mut v);
            for x in &mut v {
                *x = mat16(&k.outset, *x);
            }
            power16(k, &mut v);
            if let Some(m) = &k.from {
                for x in &mut v {
                    *x = mat16(m, *x);
                }
            }
            v
        }
    }

    /// `m · (x, y, z)` on 16 lanes, the operations of [`mat3`].
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn mat16(
        m: &[std::arch::x86_64::__m512; 9],
        [x, y, z]: [std::arch::x86_64::__m512; 3],
    ) -> [std::arch::x86_64::__m512; 3] {
        use std::arch::x86_64::*;
        let mut out = [x; 3];
        for (row, o) in out.iter_mut().enumerate() {
            *o = _mm512_fmadd_ps(
                m[6 + row],
                z,
                _mm512_fmadd_ps(m[3 + row], y, _mm512_mul_ps(m[row], x)),
            );
        }
        out
    }

    /// [`centred_position`] on 16 lanes: (bits & T_MASK) | ONE_BITS in one `vpternlogd`
    /// (truth table 0xEA: (a & b) | c), then the exact subtraction.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn position16(bits: std::arch::x86_64::__m512i) -> std::arch::x86_64::__m512 {
        use std::arch::x86_64::*;
        let m = _mm512_ternarylogic_epi32::<0xEA>(
            bits,
            _mm512_set1_epi32(T_MASK as i32),
            _mm512_set1_epi32(ONE_BITS as i32),
        );
        _mm512_sub_ps(_mm512_castsi512_ps(m), _mm512_set1_ps(S_CENTRE))
    }

    // The curves below run each step over all 3·G vectors before the next step: the steps
    // of one value form a chain of ~25 dependent operations (≈ 100 cycles), and written
    // value by value the scheduler fills with one chain before it reaches independent work
    // (the pass measured latency-bound: ≈ 150 cycles per 16 pixels for ≈ 45 cycles of
    // issue).

    /// Per lane the polynomial of its segment `seg` (coefficient j of every segment in
    /// register `coeffs[j]`, picked by `vpermps`) at position `s`, Horner from the top term,
    /// each step over all 3·G vectors (see above).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn segment_poly16<const G: usize, const T: usize>(
        seg: &[[std::arch::x86_64::__m512i; 3]; G],
        s: &[[std::arch::x86_64::__m512; 3]; G],
        coeffs: &[std::arch::x86_64::__m512; T],
    ) -> [[std::arch::x86_64::__m512; 3]; G] {
        use std::arch::x86_64::*;
        let mut p = [[_mm512_setzero_ps(); 3]; G];
        for g in 0..G {
            for ch in 0..3 {
                p[g][ch] = _mm512_permutexvar_ps(seg[g][ch], coeffs[T - 1]);
            }
        }
        for j in (0..T - 1).rev() {
            for g in 0..G {
                for ch in 0..3 {
                    p[g][ch] = _mm512_fmadd_ps(
                        p[g][ch],
                        s[g][ch],
                        _mm512_permutexvar_ps(seg[g][ch], coeffs[j]),
                    );
                }
            }
        }
        p
    }

    /// [`Map::encode`] on 16 lanes, every vector of `v`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn encode16<const G: usize>(
        k: &Regs16,
        c: &Curves,
        v: &mut [[std::arch::x86_64::__m512; 3]; G],
    ) {
        use std::arch::x86_64::*;
        let (x_min, x_max) = (_mm512_set1_ps(c.x_min), _mm512_set1_ps(c.x_max));
        let zero = _mm512_setzero_ps();
        let (mut e, mut seg, mut s) = (
            [[zero; 3]; G],
            [[_mm512_setzero_si512(); 3]; G],
            [[zero; 3]; G],
        );
        for g in 0..G {
            for ch in 0..3 {
                let x = _mm512_min_ps(_mm512_max_ps(v[g][ch], x_min), x_max);
                let bits = _mm512_castps_si512(x);
                e[g][ch] = _mm512_getexp_ps(x);
                seg[g][ch] = _mm512_srli_epi32::<{ T_BITS }>(bits);
                s[g][ch] = position16(bits);
            }
        }
        let p = segment_poly16(&seg, &s, &k.encode);
        for g in 0..G {
            for ch in 0..3 {
                // w, then the contrast polynomial's top coefficient into v.
                s[g][ch] = _mm512_add_ps(e[g][ch], p[g][ch]);
                v[g][ch] = k.contrast[6];
            }
        }
        for j in (0..6).rev() {
            for g in 0..G {
                for ch in 0..3 {
                    v[g][ch] = _mm512_fmadd_ps(v[g][ch], s[g][ch], k.contrast[j]);
                }
            }
        }
    }

    /// [`Map::power`] on 16 lanes, every vector of `v`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn power16<const G: usize>(k: &Regs16, v: &mut [[std::arch::x86_64::__m512; 3]; G]) {
        use std::arch::x86_64::*;
        let y_zero = _mm512_set1_ps(Y_ZERO);
        let zero = _mm512_setzero_ps();
        let (mut bits, mut seg, mut s) = (
            [[_mm512_setzero_si512(); 3]; G],
            [[_mm512_setzero_si512(); 3]; G],
            [[zero; 3]; G],
        );
        for g in 0..G {
            for ch in 0..3 {
                // Below Y_MIN (and NaN) to Y_ZERO, whose scale is 0.
                bits[g][ch] = _mm512_castps_si512(_mm512_max_ps(v[g][ch], y_zero));
                seg[g][ch] = _mm512_srli_epi32::<{ T_BITS }>(bits[g][ch]);
                s[g][ch] = position16(bits[g][ch]);
            }
        }
        let p = segment_poly16(&seg, &s, &k.power);
        for g in 0..G {
            for ch in 0..3 {
                let scale = _mm512_permutex2var_ps(
                    k.scales[0],
                    _mm512_srli_epi32::<23>(bits[g][ch]),
                    k.scales[1],
                );
                v[g][ch] = _mm512_mul_ps(p[g][ch], scale);
            }
        }
    }
}
