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

/// `avx2!(kernel(args…))`: evaluates `kernel(args…)` compiled for AVX2 + FMA when the CPU
/// has them, else at the baseline width. `kernel` must be `#[inline(always)]` so that it,
/// and everything it inlines, is compiled inside the AVX2 wrapper.
macro_rules! avx2 {
    ($kernel:ident $(::<$($g:tt),*>)? ($($arg:expr),* $(,)?)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            #[inline]
            fn wide<R>(f: impl FnOnce() -> R) -> R {
                f()
            }
            if $crate::tonemap::simd::has_avx2() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                // The closure has this one call site, so LLVM inlines it (and with it the
                // `#[inline(always)]` kernel) into `wide`, compiling it for AVX2.
                unsafe { wide(|| $kernel $(::<$($g),*>)? ($($arg),*)) }
            } else {
                $kernel $(::<$($g),*>)? ($($arg),*)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $kernel $(::<$($g),*>)? ($($arg),*)
        }
    }};
}
pub(crate) use avx2;
