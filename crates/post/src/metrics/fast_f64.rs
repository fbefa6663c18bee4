//! Branch-free f64 cube root, atan2, exp and sine for the comparison kernel
//! ([`super::ciede2000`]): the library functions are calls that the compiler cannot
//! inline or vectorise; these are selects, shifts and polynomials, so a loop over a block
//! of pixels runs four lanes wide under AVX2. Each is accurate to a few ulp on the domain
//! stated (the tests measure against the standard library), far below what CIEDE2000's
//! 4-decimal reference data resolve.
//!
//! The polynomials are truncated Taylor series (exact rational coefficients, no fitting):
//! on the reduced ranges used, the first omitted term is below 1e-17 relative.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Cube root for 1e-40 ≤ x ≤ 1e70 (0 gives 0; CIELAB's argument is a ratio to the white,
/// ≤ 1e39 for finite f32 pixels). The first guess comes from the f32 bit pattern divided by
/// 3 (musl's `cbrtf` bias, B1 = 709958130 = (127 − 127/3 − 0.03306235651) · 2²³; < 1/32
/// error) — the division done in f32 arithmetic, which vectorises where integer division
/// does not — after scaling x by 2^±120 into f32's range. Then two Halley steps
/// y ← y (y³ + 2x)/(2y³ + x) (cubic convergence: 3e-2 → 1e-5 → 1e-14) and one Newton step
/// y ← y − (y³ − x)/(3y²) (to the rounding of y³): ≤ 2 ulp measured.
#[inline(always)]
pub fn cbrt(x: f64) -> f64 {
    const B1: i32 = 709_958_130;
    const TWO_60: f64 = 1_152_921_504_606_846_976.0; // 2⁶⁰
    let big = x > TWO_60;
    let small = x < 1.0 / TWO_60;
    // 2^±120 scales the cube root by exactly 2^±40.
    let scale_in = if big {
        f64::from_bits((1023 - 120) << 52)
    } else if small {
        f64::from_bits((1023 + 120) << 52)
    } else {
        1.0
    };
    let scale_out = if big {
        f64::from_bits((1023 + 40) << 52)
    } else if small {
        f64::from_bits((1023 - 40) << 52)
    } else {
        1.0
    };
    let xs = (x * scale_in).max(1e-30);
    let bits = (xs as f32).to_bits() as i32;
    // wrapping_add: no overflow check (a branch, which would stop vectorisation in debug
    // builds); the sum stays below 2³¹ for every input.
    let guess = (((bits as f32) * (1.0 / 3.0)) as i32).wrapping_add(B1);
    let mut y = f64::from(f32::from_bits(guess as u32));
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * xs) / (2.0 * y3 + xs);
    }
    y -= (y * y * y - xs) / (3.0 * y * y);
    if x > 0.0 {
        y * scale_out
    } else {
        0.0
    }
}

/// atan(u) for |u| ≤ tan(π/8): u · Σₖ (−1)ᵏ u²ᵏ/(2k+1), k ≤ 19 (the next term is
/// < 0.4143⁴¹/41 ≈ 5e-18).
#[inline(always)]
fn atan_reduced(u: f64) -> f64 {
    /// (−1)ᵏ/(2k+1).
    const C: [f64; 20] = {
        let mut c = [0.0; 20];
        let mut k = 0;
        while k < 20 {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            c[k] = sign / (2 * k + 1) as f64;
            k += 1;
        }
        c
    };
    let u2 = u * u;
    let mut p = C[19];
    for c in C[..19].iter().rev() {
        p = p * u2 + c;
    }
    u * p
}

/// atan2(y, x) in degrees in [0°, 360°) (−0 for y = −0, x > 0, like `f64::atan2` followed
/// by adding 360° to negative angles; 0 for x = y = 0). Reduction: t = min/max(|x|, |y|)
/// ∈ [0, 1]; above tan(π/8), atan t = π/4 + atan((t − 1)/(t + 1)), both forms one division.
#[inline(always)]
pub fn atan2_deg(y: f64, x: f64) -> f64 {
    const TAN_PI_8: f64 = 0.414_213_562_373_095_03;
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let big = num > TAN_PI_8 * den;
    let n = if big { num - den } else { num };
    let d = if big { num + den } else { den };
    let u = if d > 0.0 { n / d } else { 0.0 };
    let mut r = atan_reduced(u) + if big { FRAC_PI_4 } else { 0.0 };
    r = if swap { FRAC_PI_2 - r } else { r };
    r = if x < 0.0 { PI - r } else { r };
    r = if y < 0.0 { 2.0 * PI - r } else { r };
    r * (180.0 / PI)
}

/// eˣ for −700 ≤ x ≤ 700 (below −700 it returns e⁻⁷⁰⁰). x = n ln 2 + r with |r| ≤ ln 2 / 2
/// (Cody–Waite with fdlibm's split of ln 2), eʳ by its Taylor series to r¹³/13! (next term
/// < 4e-18), times 2ⁿ added to the exponent bits (n rounded by the 1.5 · 2⁵² trick, whose
/// low bits then hold n: no float → int conversion, which AVX2 lacks for 64-bit integers).
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5 · 2⁵²
                                                // fdlibm's split: ln 2 = LN2_HI + LN2_LO, LN2_HI with 32 trailing zero bits so n · LN2_HI
                                                // is exact for |n| < 2¹¹.
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    let x = x.clamp(-700.0, 700.0);
    let k = x * std::f64::consts::LOG2_E + MAGIC;
    let n = k - MAGIC;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    /// 1/k!, k = 0…13.
    const C: [f64; 14] = {
        let mut c = [1.0; 14];
        let mut k = 1;
        let mut f = 1.0;
        while k < 14 {
            f *= k as f64;
            c[k] = 1.0 / f;
            k += 1;
        }
        c
    };
    let mut p = C[13];
    for c in C[1..13].iter().rev() {
        p = p * r + c;
    }
    p = p * r + 1.0;
    f64::from_bits(p.to_bits().wrapping_add(k.to_bits() << 52))
}

/// sin x for |x| ≤ π/3 by its Taylor series to x¹⁹/19! (next term < 6e-20).
#[inline(always)]
pub fn sin_small(x: f64) -> f64 {
    let x2 = x * x;
    /// (−1)ᵏ/(2k+1)!, k = 0…9.
    const C: [f64; 10] = {
        let mut c = [0.0; 10];
        let mut k = 0;
        let mut f = 1.0;
        while k < 10 {
            if k > 0 {
                f *= (2 * k) as f64 * (2 * k + 1) as f64;
            }
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            c[k] = sign / f;
            k += 1;
        }
        c
    };
    let mut p = C[9];
    for c in C[..9].iter().rev() {
        p = p * x2 + c;
    }
    x * p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(got: f64, want: f64) -> f64 {
        if got == want {
            return 0.0;
        }
        (got - want).abs() / (want.abs().max(f64::MIN_POSITIVE) * f64::EPSILON)
    }

    /// Deterministic inputs: a low-discrepancy sweep (golden-ratio sequence).
    fn sweep(n: usize) -> impl Iterator<Item = f64> {
        (0..n).map(|i| (i as f64 * 0.618_033_988_749_894_9).fract())
    }

    #[test]
    fn cbrt_is_within_two_ulp_of_the_library() {
        let mut worst = 0.0f64;
        let mut xs: Vec<f64> = sweep(200_000)
            .map(|u| 10f64.powf(-40.0 + 110.0 * u))
            .collect();
        xs.extend((-40..70).map(|k| 10f64.powi(k)));
        xs.extend((-40..40).map(|k| 8f64.powi(k)));
        xs.extend([216.0 / 24389.0, 1.0, 27.0, 3.4e38 / 0.95]);
        for x in xs {
            worst = worst.max(ulps(cbrt(x), x.cbrt()));
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        assert_eq!(cbrt(0.0), 0.0);
    }

    #[test]
    fn atan2_deg_matches_the_library_in_every_octant() {
        let mut worst = 0.0f64;
        for (u, v) in sweep(100_000).zip(sweep(100_000).skip(7)) {
            let angle = 2.0 * PI * u;
            let r = 10f64.powf(-8.0 + 12.0 * v);
            let (y, x) = (r * angle.sin(), r * angle.cos());
            let mut want = y.atan2(x).to_degrees();
            if want < 0.0 {
                want += 360.0;
            }
            // Absolute error in degrees (the angle's ulp at 360° is 6e-14).
            worst = worst.max((atan2_deg(y, x) - want).abs());
        }
        assert!(worst < 2e-13, "worst {worst}°");
        // Axes and signed zeros as f64::atan2 (then + 360° when negative).
        assert_eq!(atan2_deg(0.0, 1.0), 0.0);
        assert_eq!(atan2_deg(1.0, 0.0), 90.0);
        assert_eq!(atan2_deg(0.0, -1.0), 180.0);
        assert_eq!(atan2_deg(-1.0, 0.0), 270.0);
        assert_eq!(atan2_deg(1.0, 1.0), 45.0);
        assert_eq!(atan2_deg(0.0, 0.0), 0.0);
    }

    #[test]
    fn exp_and_sin_are_within_a_few_ulp() {
        let (mut we, mut ws) = (0.0f64, 0.0f64);
        for u in sweep(200_000) {
            let x = -130.0 + 140.0 * u;
            we = we.max(ulps(exp(x), x.exp()));
            let s = u * PI / 3.0;
            ws = ws.max(ulps(sin_small(s), s.sin()));
        }
        assert!(we <= 4.0, "exp: worst {we} ulp");
        assert!(ws <= 2.0, "sin: worst {ws} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(sin_small(0.0), 0.0);
    }
}
