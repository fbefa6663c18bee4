//! Every ISA's kernels against the scalar path, bit for bit: each ISA the machine runs
//! (`prism_cpu::each_isa`, which reports the others as skipped with the missing feature),
//! each through the same task functions the passes use, each compared with the scalar
//! plumbing called directly (compiled for the baseline).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use prism_cpu::Simd;

use super::*;
use crate::tonemap::pixels::{map_pixels_chunk, stats_chunk, CHUNK};
use crate::tonemap::test_support::{bit_test_image, sweep_image};
use crate::tonemap::{ToneOperator, ToneParams};
use prism_image::Image;

/// The luminance pass at every ISA gives the scalar pass's bits and counts on `image`:
/// the whole pass ([`map_luminance_fast`]), and single tasks ([`luminance_task`]) at every
/// output alignment and several lengths (so the register pass's zero-padded head and tail
/// groups of 0–15 pixels occur), with and without the exposure multiplication.
/// `curve_at(simd)` is the curve an operator builds for that ISA (the same curve, whose
/// slice evaluation runs that ISA's kernels where it has its own).
pub(crate) fn same_bits_as_scalar<C: RegisterCurve>(
    image: &Image,
    scale: f32,
    curve_at: impl Fn(Simd) -> C,
) {
    let params = ToneParams::default();
    let w = image.luminance_weights();
    let pixels = image.pixels();
    let n = pixels.len();
    let mut scalar = vec![[0f32; 3]; n];
    let reference = curve_at(Simd::SCALAR);
    let counts = map_luminance_chunk(pixels, &mut scalar, 0, scale, w, &reference);
    let mut fast_buf = vec![[0f32; 3]; n + 16];
    for simd in prism_cpu::each_isa() {
        let curve = &curve_at(simd);
        let ctx = Context {
            image,
            input: crate::tonemap::Input::Borrowed(image.pixels()),
            params: &params,
            info: &crate::tonemap::linear::INFO,
            exposure: scale,
            weights: w,
            buffer: std::sync::Mutex::new(None),
            simd,
        };
        let wide = map_luminance_fast(&ctx, scale, w, curve);
        assert_eq!(
            (wide.non_finite_pixels, wide.negative_pixels),
            counts,
            "{simd}"
        );
        for (i, (a, b)) in wide.pixels.iter().zip(&scalar).enumerate() {
            assert_eq!(
                a.map(f32::to_bits),
                b.map(f32::to_bits),
                "{simd} pixel {i}: {a:?} vs {b:?} (input {:?})",
                pixels[i]
            );
        }
        let mut slow = vec![[0f32; 3]; n];
        for scale in [scale, 1.0, 0.37] {
            for len in [0, 1, 15, 16, 17, 100, n] {
                for offset in 0..16 {
                    let (input, out) = (&pixels[..len], &mut fast_buf[offset..offset + len]);
                    let fast = luminance_task(simd, input, out, 0, scale, w, curve);
                    let slow_counts =
                        map_luminance_chunk(input, &mut slow[..len], 0, scale, w, &reference);
                    assert_eq!(fast, slow_counts, "{simd} len {len}, offset {offset}");
                    for (i, (a, b)) in fast_buf[offset..offset + len].iter().zip(&slow).enumerate()
                    {
                        assert_eq!(
                            a.map(f32::to_bits),
                            b.map(f32::to_bits),
                            "{simd} pixel {i} (len {len}, offset {offset}, scale {scale})"
                        );
                    }
                }
            }
        }
    }
}

/// The pixel pass of a map with a register form ([`register_pixels_task`]) at every ISA
/// gives the scalar pass's bits and counts on `pixels`, for every output alignment (so
/// head and tail groups of 0–15 pixels occur) and for tasks of several lengths. `f_at(simd)`
/// is the map an operator builds for that ISA.
pub(crate) fn register_pass_gives_the_scalar_bits<M: RegisterMap>(
    pixels: &[[f32; 3]],
    scale: f32,
    f_at: impl Fn(Simd) -> M,
) {
    let n = pixels.len();
    let mut fast_buf = vec![[0f32; 3]; n + 16];
    let mut slow = vec![[0f32; 3]; n];
    let reference = f_at(Simd::SCALAR);
    for simd in prism_cpu::each_isa() {
        let f = &f_at(simd);
        for len in [0, 1, 15, 16, 17, 100, n] {
            for offset in 0..16 {
                let (input, out) = (&pixels[..len], &mut fast_buf[offset..offset + len]);
                let fast = register_pixels_task(simd, input, out, 0, scale, f);
                let slow_counts =
                    map_pixels_chunk(input, &mut slow[..len], 0, scale, &reference, Simd::SCALAR);
                assert_eq!(fast, slow_counts, "{simd} len {len}, offset {offset}");
                for (i, (a, b)) in fast_buf[offset..offset + len].iter().zip(&slow).enumerate() {
                    assert_eq!(
                        a.map(f32::to_bits),
                        b.map(f32::to_bits),
                        "{simd} pixel {i} (len {len}, offset {offset}): {a:?} vs {b:?}, \
                         input {:?}",
                        pixels[i]
                    );
                }
            }
        }
    }
}

/// A register map that makes some values non-finite (so the cleaning runs).
struct RegisterProbe;
impl PixelMap for RegisterProbe {
    #[inline(always)]
    fn map(&self, _start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        for j in 0..r.len() {
            (r[j], g[j], b[j]) = (r[j] * 1e30 + g[j], g[j] - b[j] * 0.5, b[j] / (g[j] - r[j]));
        }
    }
}
impl RegisterMap for RegisterProbe {
    #[cfg(target_arch = "x86_64")]
    type Regs = __m512;
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn regs16(&self) -> __m512 {
        _mm512_set1_ps(0.5)
    }
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn map16<const G: usize>(
        &self,
        half: &__m512,
        rgb: [[__m512; 3]; G],
    ) -> [[__m512; 3]; G] {
        let mut out = rgb;
        for (o, [r, g, b]) in out.iter_mut().zip(rgb) {
            *o = [
                _mm512_add_ps(_mm512_mul_ps(r, _mm512_set1_ps(1e30)), g),
                _mm512_sub_ps(g, _mm512_mul_ps(b, *half)),
                _mm512_div_ps(b, _mm512_sub_ps(g, r)),
            ];
        }
        out
    }
}

#[test]
fn register_pass_gives_the_scalar_bits_and_counts() {
    let special = bit_test_image();
    for scale in [1.0f32, 3e30] {
        register_pass_gives_the_scalar_bits(special.pixels(), scale, |_| RegisterProbe);
    }
}

/// A pixel map that touches every value (and makes some non-finite).
struct Probe;
impl PixelMap for Probe {
    #[inline(always)]
    fn map(&self, start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        for j in 0..r.len() {
            let k = (start + j) as f32;
            (r[j], g[j], b[j]) = (r[j] * 1e30 + k, g[j] - b[j] * 0.5, b[j] / (g[j] - r[j]));
        }
    }
}

#[test]
fn pixel_pass_gives_the_scalar_bits() {
    let special = bit_test_image();
    let pixels: Vec<[f32; 3]> = (0..5000)
        .map(|i| special.pixels()[(i * 7) % 1000])
        .collect();
    for simd in prism_cpu::each_isa() {
        for scale in [1.0f32, 3e30] {
            for (k, chunk) in pixels.chunks(CHUNK).enumerate() {
                let (mut a, mut b) = (vec![[0f32; 3]; chunk.len()], vec![[0f32; 3]; chunk.len()]);
                let fast = pixels_task(simd, chunk, &mut a, k * CHUNK, scale, &Probe);
                let slow = map_pixels_chunk(chunk, &mut b, k * CHUNK, scale, &Probe, Simd::SCALAR);
                assert_eq!(fast, slow, "{simd}");
                for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                    assert_eq!(x.map(f32::to_bits), y.map(f32::to_bits), "{simd} pixel {i}");
                }
            }
        }
    }
}

#[test]
fn stats_pass_gives_the_scalar_bits() {
    // Whole blocks, a partial block, and the special values of the bit-test image
    // spread over a chunk and a half.
    let special = bit_test_image();
    let pixels: Vec<[f32; 3]> = (0..6000)
        .map(|i| {
            let v = (i as f32 * 0.37).sin().abs() * 40.0 + 1e-9 * i as f32;
            if i % 5 == 0 {
                special.pixels()[i % 1000]
            } else {
                [v, 0.5 * v, 2.0 * v]
            }
        })
        .collect();
    let w = special.luminance_weights();
    for simd in prism_cpu::each_isa() {
        for scale in [1.0f32, 0.25, 3e30] {
            for chunk in pixels.chunks(CHUNK) {
                assert_eq!(
                    stats_task(simd, chunk, scale, w),
                    stats_chunk(chunk, scale, w),
                    "{simd} scale {scale}"
                );
            }
        }
    }
}

/// Every operator at every ISA the machine runs gives the scalar kernels' image bit for
/// bit, except where its curve has a different form with AVX-512 (drago03's octave
/// polynomials, tumblin-rushmeier's power curve against their memory tables): there the
/// two approximations of the same formula agree to a small fraction of a 16-bit code.
/// One thread, so that durand02's bilateral grid (whose result depends on how rayon
/// splits its work) is compared with itself.
#[test]
fn every_operator_gives_the_scalar_image_at_every_isa() {
    let sweep = sweep_image(3000);
    let special = bit_test_image();
    // Luminances within 2^±10 of 1 (drago03's octave polynomials and tumblin-rushmeier's
    // power curve need the range within 32 binary exponents).
    let narrow = Image::new(
        2000,
        1,
        (0..2000)
            .map(|i| {
                let v = 2f32.powf(-10.0 + 20.0 * i as f32 / 1999.0);
                [v, 0.6 * v, 0.3 * v]
            })
            .collect(),
        prism_spectrum::rgb_space::RgbColorSpace::srgb(),
    )
    .unwrap();
    // On the test's thread, so that skipped ISAs are reported under its name.
    let isas = prism_cpu::each_isa();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let params = ToneParams {
        exposure_ev: 0.5,
        luminance_scale_cd_m2: Some(120.0),
        ..ToneParams::default()
    };
    pool.install(|| {
        for op in ToneOperator::ALL {
            for image in [&sweep, &special, &narrow] {
                let apply = |simd| {
                    op.apply_with(image, &params, Vec::new(), simd)
                        .unwrap()
                        .image
                };
                let scalar = apply(Simd::SCALAR);
                for &simd in &isas {
                    let wide = apply(simd);
                    let bits = |i: &Image| -> Vec<u32> {
                        i.pixels().iter().flatten().map(|v| v.to_bits()).collect()
                    };
                    let other_form = simd.avx512()
                        && matches!(op, ToneOperator::Drago03 | ToneOperator::TumblinRushmeier);
                    if other_form {
                        // Relative to the value (tumblin-rushmeier's outputs exceed 1 on
                        // the sweep), floored at 1e-3 of full scale.
                        let worst = wide
                            .pixels()
                            .iter()
                            .flatten()
                            .zip(scalar.pixels().iter().flatten())
                            .map(|(a, b)| f64::from((a - b).abs() / b.abs().max(1e-3)))
                            .fold(0.0f64, f64::max);
                        eprintln!("{} {simd}: {worst:e} from the scalar image", op.name());
                        // Each form is within ~4e-7 of the formula (power_curve.rs,
                        // curve_table.rs) plus the f32 roundings of the pass.
                        assert!(worst < 2e-6, "{} {simd}: {worst:e}", op.name());
                    } else {
                        assert!(bits(&wide) == bits(&scalar), "{} {simd}", op.name());
                    }
                }
            }
        }
    });
}

/// The octave curve's 16-lane `eval16` gives its scalar `eval`'s bits (the curve exists
/// only where the ISA allows AVX-512; `each_isa` reports it skipped elsewhere).
#[test]
fn octave_curve_eval16_gives_the_scalar_bits() {
    use crate::tonemap::octave_curve::{tests::eq4_like, OctaveCurve};
    let (f, lo, hi, xs) = eq4_like();
    for simd in prism_cpu::each_isa().into_iter().filter(|s| s.avx512()) {
        let curve = OctaveCurve::new(simd, lo, hi, &f).expect("eq. 4-like curve should fit");
        #[cfg(target_arch = "x86_64")]
        for chunk in xs.chunks_exact(16) {
            // SAFETY: `simd` allows AVX-512, so the CPU has it.
            let got: [f32; 16] =
                unsafe { std::mem::transmute(curve.eval16(_mm512_loadu_ps(chunk.as_ptr()))) };
            for (x, g) in chunk.iter().zip(got) {
                assert_eq!(g.to_bits(), curve.eval(*x).to_bits(), "x = {x:e}");
            }
        }
    }
}
