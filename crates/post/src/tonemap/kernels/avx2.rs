//! The AVX2 family: kernels compiled for AVX2 + FMA (8 f32 lanes), run where the call's
//! [`prism_cpu::Simd`] allows AVX2 (`Context::simd` for the tone operators).
//!
//! The workspace builds for the x86-64 baseline (SSE2: 4 f32 lanes, no `roundps`), so the
//! auto-vectorised pixel loops of [`crate::tonemap::pixels`] run 4 wide. Where the ISA
//! allows AVX2 the same loops, compiled a second time inside a
//! `#[target_feature(enable = "avx2,fma")]` function by [`avx2!`], run 8 wide. Results are
//! bit-identical on both paths: Rust never contracts `a * b + c` into an FMA (only an
//! explicit `mul_add` would use it, and that is fused on both), and the kernels'
//! reductions have a fixed lane layout ([`crate::tonemap::pixels`]), so only the
//! instruction width changes (tested for every ISA the machine runs).
//!
//! The kernels are generic `#[inline(always)]` functions; operator-specific code inside a
//! kernel (a luminance curve, a pixel map) comes through traits whose methods are
//! `#[inline(always)]` as well — closures can not be marked so on stable Rust, and a
//! closure that is not inlined would run at the baseline width.
//!
//! Below the macro: the hand-written AVX2 kernels (intrinsics), each the same operations
//! in the same order as the scalar code it replaces: the streaming store of the mapping
//! passes, [`CurveTable`](crate::tonemap::curve_table::CurveTable)'s lookup and agx's
//! pixel map.

/// `avx2!(simd, kernel(args…))` (1 to 7 arguments): evaluates `kernel(args…)` compiled
/// for AVX2 + FMA where `simd` (a `prism_cpu::Simd`) allows them, else at the baseline
/// width. `kernel` must be a
/// function marked `#[inline(always)]`: it is passed as a function item to a local
/// `#[target_feature]` wrapper, which therefore inlines it (and all it inlines) and
/// compiles it for AVX2. (A closure there would be inlined only at the optimiser's
/// discretion, and large kernels were not.)
macro_rules! avx2 {
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A) -> R, R, A>(kernel: K, a: A) -> R {
                kernel(a)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a) }
            } else {
                $kernel $(::<$($g),*>)? ($a)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B) -> R, R, A, B>(kernel: K, a: A, b: B) -> R {
                kernel(a, b)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C) -> R, R, A, B, C>(kernel: K, a: A, b: B, c: C) -> R {
                kernel(a, b, c)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b, $c)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D) -> R, R, A, B, C, D>(kernel: K, a: A, b: B, c: C, d: D) -> R {
                kernel(a, b, c, d)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E) -> R, R, A, B, C, D, E>(kernel: K, a: A, b: B, c: C, d: D, e: E) -> R {
                kernel(a, b, c, d, e)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr, $f2:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E, F2) -> R, R, A, B, C, D, E, F2>(kernel: K, a: A, b: B, c: C, d: D, e: E, f2: F2) -> R {
                kernel(a, b, c, d, e, f2)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e, $f2) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2)
        }
    }};
    ($simd:expr, $kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr, $f2:expr, $g7:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E, F2, G) -> R, R, A, B, C, D, E, F2, G>(kernel: K, a: A, b: B, c: C, d: D, e: E, f2: F2, g: G) -> R {
                kernel(a, b, c, d, e, f2, g)
            }
            if prism_cpu::Simd::avx2($simd) {
                // SAFETY: a `Simd` allows AVX2 and FMA only on a CPU that has them.
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e, $f2, $g7) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2, $g7)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $simd;
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2, $g7)
        }
    }};
}
pub(crate) use avx2;

/// Copies `src` to `dst` with non-temporal 32-byte stores ([`crate::tonemap::pixels::store_block`]).
///
/// # Safety
/// The CPU must have AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub(crate) unsafe fn store_streaming(dst: &mut [[f32; 3]], src: &[[f32; 3]]) {
    use std::arch::x86_64::*;
    let n = 3 * dst.len().min(src.len());
    let (d, s) = (dst.as_mut_ptr() as *mut f32, src.as_ptr() as *const f32);
    // Plain stores up to the first 32-byte boundary (f32s are 4-byte aligned), streaming
    // 32-byte stores after it, plain stores for the tail.
    let head = (((32 - (d as usize & 31)) & 31) / 4).min(n);
    for i in 0..head {
        // SAFETY: i < n, inside both slices.
        *d.add(i) = *s.add(i);
    }
    let mut i = head;
    while i + 8 <= n {
        // SAFETY: i + 8 ≤ n, inside both slices; d + i is 32-byte aligned.
        _mm256_stream_ps(d.add(i), _mm256_loadu_ps(s.add(i)));
        i += 8;
    }
    for i in i..n {
        // SAFETY: i < n.
        *d.add(i) = *s.add(i);
    }
}

/// curve_table.rs: the 8-lane lookup.
#[cfg(target_arch = "x86_64")]
mod curve_table {
    use crate::tonemap::curve_table::{CurveTable, LOW_BITS, LOW_MASK, T_SCALE};

    impl CurveTable {
        /// [`Self::eval_slice_clamped`] on 8 lanes.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        pub(crate) unsafe fn eval_slice_avx2<const ZERO_BELOW: bool>(
            &self,
            v: &mut [f32],
            lo: f32,
            hi: f32,
        ) {
            use std::arch::x86_64::*;
            let base = self.coeffs.as_ptr() as *const f32;
            let first = _mm256_set1_epi32(self.first as i32);
            let last = _mm256_set1_epi32(self.coeffs.len() as i32 - 1);
            let zero = _mm256_setzero_si256();
            let low_mask = _mm256_set1_epi32(LOW_MASK as i32);
            let t_scale = _mm256_set1_ps(T_SCALE);
            let (lo_v, hi_v) = (_mm256_set1_ps(lo), _mm256_set1_ps(hi));
            let mut chunks = v.chunks_exact_mut(8);
            for chunk in &mut chunks {
                let raw = _mm256_loadu_ps(chunk.as_ptr());
                // maxps returns its second operand for a NaN first one: NaN → lo, as
                // f32::max in `eval_clamped`.
                let x = _mm256_min_ps(_mm256_max_ps(raw, lo_v), hi_v);
                let bits = _mm256_castps_si256(x);
                // Logical shift: negative arguments (sign bit set) land above the last
                // segment and are clamped to it, as in `eval`.
                let s = _mm256_sub_epi32(_mm256_srli_epi32::<{ LOW_BITS as i32 }>(bits), first);
                let s = _mm256_min_epi32(_mm256_max_epi32(s, zero), last);
                // Each lane's four coefficients are one 16-byte load; a 4×4 transpose per
                // 128-bit half turns the eight rows into c0..c3 (eight loads and eight
                // shuffles: several times cheaper than four 8-lane gathers on Zen 3).
                let mut idx = [0i32; 8];
                _mm256_storeu_si256(idx.as_mut_ptr() as *mut __m256i, s);
                let row = |k: usize| base.add(4 * idx[k] as usize);
                let pair = |lo: usize, hi: usize| {
                    _mm256_insertf128_ps::<1>(
                        _mm256_castps128_ps256(_mm_loadu_ps(row(lo))),
                        _mm_loadu_ps(row(hi)),
                    )
                };
                let (r0, r1, r2, r3) = (pair(0, 4), pair(1, 5), pair(2, 6), pair(3, 7));
                let t0 = _mm256_unpacklo_ps(r0, r1); // a0 b0 a1 b1
                let t1 = _mm256_unpackhi_ps(r0, r1); // a2 b2 a3 b3
                let t2 = _mm256_unpacklo_ps(r2, r3); // c0 d0 c1 d1
                let t3 = _mm256_unpackhi_ps(r2, r3); // c2 d2 c3 d3
                let c0 = _mm256_castpd_ps(_mm256_unpacklo_pd(
                    _mm256_castps_pd(t0),
                    _mm256_castps_pd(t2),
                ));
                let c1 = _mm256_castpd_ps(_mm256_unpackhi_pd(
                    _mm256_castps_pd(t0),
                    _mm256_castps_pd(t2),
                ));
                let c2 = _mm256_castpd_ps(_mm256_unpacklo_pd(
                    _mm256_castps_pd(t1),
                    _mm256_castps_pd(t3),
                ));
                let c3 = _mm256_castpd_ps(_mm256_unpackhi_pd(
                    _mm256_castps_pd(t1),
                    _mm256_castps_pd(t3),
                ));
                let t = _mm256_mul_ps(
                    _mm256_cvtepi32_ps(_mm256_and_si256(bits, low_mask)),
                    t_scale,
                );
                let p = _mm256_add_ps(c2, _mm256_mul_ps(t, c3));
                let p = _mm256_add_ps(c1, _mm256_mul_ps(t, p));
                let p = _mm256_add_ps(c0, _mm256_mul_ps(t, p));
                let p = if ZERO_BELOW {
                    _mm256_and_ps(p, _mm256_cmp_ps::<_CMP_GE_OQ>(raw, lo_v))
                } else {
                    p
                };
                _mm256_storeu_ps(chunk.as_mut_ptr(), p);
            }
            for x in chunks.into_remainder() {
                *x = self.eval_clamped::<ZERO_BELOW>(*x, lo, hi);
            }
        }
    }
}

/// agx.rs: the whole transform per pixel, 8 lanes.
#[cfg(target_arch = "x86_64")]
mod agx {
    use crate::tonemap::agx::{
        Map, Mat, ENCODE_TERMS, ONE_BITS, POWER_TERMS, S_CENTRE, T_BITS, T_MASK, Y_MIN,
    };

    impl Map {
        /// [`PixelMap::map`] on 8 lanes, the same operations in the same order as
        /// [`Self::pixel`].
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        pub(crate) unsafe fn map_avx2(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
            use std::arch::x86_64::*;
            let n = r.len().min(g.len()).min(b.len());
            let c = self.curves;
            let splat = |m: &Mat| m.map(|v| _mm256_set1_ps(v));
            let (inset, outset) = (splat(&self.inset), splat(&self.outset));
            let from = self.from_srgb.as_ref().map(splat);
            // SAFETY (all loads of constants below): each array holds 8 f32s.
            let load8 = |a: &[f32; 8]| _mm256_loadu_ps(a.as_ptr());
            let encode: [__m256; ENCODE_TERMS] = std::array::from_fn(|j| load8(&c.encode[j]));
            let power: [__m256; POWER_TERMS] = std::array::from_fn(|j| load8(&c.power[j]));
            let contrast = c.contrast.map(|v| _mm256_set1_ps(v));
            let fifths = load8(&c.fifths);
            let (x_min, x_max) = (_mm256_set1_ps(c.x_min), _mm256_set1_ps(c.x_max));
            let y_min = _mm256_set1_ps(Y_MIN);
            let t_mask = _mm256_set1_epi32(T_MASK as i32);
            let (one_bits, centre) = (_mm256_set1_epi32(ONE_BITS as i32), _mm256_set1_ps(S_CENTRE));
            let bias = _mm256_set1_epi32(127);
            let (i5, i25, i205, i127m5) = (
                _mm256_set1_epi32(5),
                _mm256_set1_epi32(25),
                _mm256_set1_epi32(205),
                _mm256_set1_epi32(127 - 5),
            );
            let mat = |m: &[__m256; 9], x: __m256, y: __m256, z: __m256| -> [__m256; 3] {
                std::array::from_fn(|row| {
                    _mm256_fmadd_ps(
                        m[6 + row],
                        z,
                        _mm256_fmadd_ps(m[3 + row], y, _mm256_mul_ps(m[row], x)),
                    )
                })
            };
            // s from the low mantissa bits, exactly (centred_position).
            let position = |bits: __m256i| {
                let m = _mm256_or_si256(_mm256_and_si256(bits, t_mask), one_bits);
                _mm256_sub_ps(_mm256_castsi256_ps(m), centre)
            };
            let encode_curve = |v: __m256| {
                // maxps returns its second operand when the first is NaN.
                let v = _mm256_min_ps(_mm256_max_ps(v, x_min), x_max);
                let bits = _mm256_castps_si256(v);
                let e = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_srli_epi32::<23>(bits), bias));
                // vpermps reads the low 3 bits of each index: the segment k.
                let k = _mm256_srli_epi32::<{ T_BITS as i32 }>(bits);
                let t = position(bits);
                let mut p = _mm256_permutevar8x32_ps(encode[ENCODE_TERMS - 1], k);
                for j in (0..ENCODE_TERMS - 1).rev() {
                    p = _mm256_fmadd_ps(p, t, _mm256_permutevar8x32_ps(encode[j], k));
                }
                let w = _mm256_add_ps(e, p);
                let mut s = contrast[6];
                for j in (0..6).rev() {
                    s = _mm256_fmadd_ps(s, w, contrast[j]);
                }
                s
            };
            let power_curve = |y: __m256| {
                let keep = _mm256_cmp_ps::<_CMP_GE_OQ>(y, y_min);
                let bits = _mm256_castps_si256(_mm256_max_ps(y, y_min));
                let e = _mm256_sub_epi32(_mm256_srli_epi32::<23>(bits), bias);
                // e + 25 = 5q + r as in `split_fifths`.
                let e25 = _mm256_add_epi32(e, i25);
                let q = _mm256_srli_epi32::<10>(_mm256_mullo_epi32(e25, i205));
                let r = _mm256_sub_epi32(e25, _mm256_mullo_epi32(q, i5));
                let k = _mm256_srli_epi32::<{ T_BITS as i32 }>(bits);
                let t = position(bits);
                let mut p = _mm256_permutevar8x32_ps(power[POWER_TERMS - 1], k);
                for j in (0..POWER_TERMS - 1).rev() {
                    p = _mm256_fmadd_ps(p, t, _mm256_permutevar8x32_ps(power[j], k));
                }
                let exponent =
                    _mm256_add_epi32(_mm256_add_epi32(_mm256_add_epi32(e, e), q), i127m5);
                let scale = _mm256_mul_ps(
                    _mm256_castsi256_ps(_mm256_slli_epi32::<23>(exponent)),
                    _mm256_permutevar8x32_ps(fifths, r),
                );
                _mm256_and_ps(_mm256_mul_ps(p, scale), keep)
            };
            let mut j = 0;
            while j + 8 <= n {
                // SAFETY: j + 8 ≤ n ≤ the length of each plane.
                let (pr, pg, pb) = (
                    r.as_mut_ptr().add(j),
                    g.as_mut_ptr().add(j),
                    b.as_mut_ptr().add(j),
                );
                let [x, y, z] = mat(
                    &inset,
                    _mm256_loadu_ps(pr),
                    _mm256_loadu_ps(pg),
                    _mm256_loadu_ps(pb),
                );
                let (x, y, z) = (encode_curve(x), encode_curve(y), encode_curve(z));
                let [x, y, z] = mat(&outset, x, y, z);
                let (x, y, z) = (power_curve(x), power_curve(y), power_curve(z));
                let [x, y, z] = match &from {
                    Some(m) => mat(m, x, y, z),
                    None => [x, y, z],
                };
                _mm256_storeu_ps(pr, x);
                _mm256_storeu_ps(pg, y);
                _mm256_storeu_ps(pb, z);
                j += 8;
            }
            for j in j..n {
                [r[j], g[j], b[j]] = self.pixel(r[j], g[j], b[j]);
            }
        }
    }
}
