//! Runtime choice of the vector width for the per-pixel kernels.
//!
//! The workspace builds for the x86-64 baseline (SSE2: 4 f32 lanes, no `roundps`), so the
//! auto-vectorised pixel loops run 4 wide. On CPUs with AVX2 the same loops, compiled a
//! second time inside a `#[target_feature(enable = "avx2,fma")]` function, run 8 wide.
//! Results are bit-identical on both paths: Rust never contracts `a * b + c` into an FMA
//! (only an explicit `mul_add` would use it), and the kernels' reductions have a fixed
//! lane layout ([`crate::tonemap::pixels`]), so only the instruction width changes.
//!
//! The kernels are generic `#[inline(always)]` functions; [`avx2!`] calls the AVX2 instance
//! when the CPU has it. Operator-specific code inside a kernel (a luminance curve, a pixel
//! map) comes through traits whose methods are `#[inline(always)]` as well — closures can
//! not be marked so on stable Rust, and a closure that is not inlined would run at the
//! baseline width.

/// Whether this CPU runs AVX2 and FMA (cached by the standard library after the first
/// query).
#[inline]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether this CPU runs AVX-512 F (16 lanes, two-register permutes), the width of the
/// register-curve and 16-pixel passes (cached by the standard library after the first
/// query).
#[inline]
pub fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `avx2!(kernel(args…))` (1 to 7 arguments): evaluates `kernel(args…)` compiled for
/// AVX2 + FMA when the CPU has them, else at the baseline width. `kernel` must be a
/// function marked `#[inline(always)]`: it is passed as a function item to a local
/// `#[target_feature]` wrapper, which therefore inlines it (and all it inlines) and
/// compiles it for AVX2. (A closure there would be inlined only at the optimiser's
/// discretion, and large kernels were not.)
macro_rules! avx2 {
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A) -> R, R, A>(kernel: K, a: A) -> R {
                kernel(a)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a) }
            } else {
                $kernel $(::<$($g),*>)? ($a)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B) -> R, R, A, B>(kernel: K, a: A, b: B) -> R {
                kernel(a, b)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C) -> R, R, A, B, C>(kernel: K, a: A, b: B, c: C) -> R {
                kernel(a, b, c)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b, $c)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D) -> R, R, A, B, C, D>(kernel: K, a: A, b: B, c: C, d: D) -> R {
                kernel(a, b, c, d)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E) -> R, R, A, B, C, D, E>(kernel: K, a: A, b: B, c: C, d: D, e: E) -> R {
                kernel(a, b, c, d, e)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr, $f2:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E, F2) -> R, R, A, B, C, D, E, F2>(kernel: K, a: A, b: B, c: C, d: D, e: E, f2: F2) -> R {
                kernel(a, b, c, d, e, f2)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e, $f2) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2)
        }
    }};
    ($kernel:ident $(::<$($g:tt),*>)? ($a:expr, $b:expr, $c:expr, $d:expr, $e:expr, $f2:expr, $g7:expr $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<K: FnOnce(A, B, C, D, E, F2, G) -> R, R, A, B, C, D, E, F2, G>(kernel: K, a: A, b: B, c: C, d: D, e: E, f2: F2, g: G) -> R {
                kernel(a, b, c, d, e, f2, g)
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                unsafe { wide($kernel $(::<$($g),*>)?, $a, $b, $c, $d, $e, $f2, $g7) }
            } else {
                $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2, $g7)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($a, $b, $c, $d, $e, $f2, $g7)
        }
    }};
}
pub(crate) use avx2;
