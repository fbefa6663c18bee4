//! Branch-free f32 log2 / exp2 (and ln, exp, powf built on them) for the per-pixel curves
//! of tone operators: the library `ln`/`powf` are calls the compiler cannot inline or
//! vectorise, and cost 5–20 ns each, several times the memory time of a pixel.
//!
//! Both are polynomials without a division (a vector division costs as much as the rest
//! of a log on the CPUs measured, docs/history/post-speed.md), near-minimax polynomials fitted by
//! tools/bench-post/fit_fast_math.py (Lawson's reweighted least squares on Chebyshev
//! nodes, coefficients rounded to f32) and evaluated by Horner's rule:
//!
//! - [`log2`]: x = 2^e · m with m ∈ [√½, √2), u = m − 1 ∈ [−0.293, 0.414];
//!   log2(1 + u) ≈ u · q(u), q of degree 7 (f32 fit error 9.4e-8). Measured: |error|
//!   ≤ 7e-8 absolute plus half an ulp of the result (|log2 x| · 2⁻²⁴) over the normal f32
//!   range (the test asserts 1.5e-7). Subnormal and zero inputs are treated as the smallest normal
//!   (log2 = −126); the callers never pass them where it matters (δ-offset logs, positive
//!   luminances).
//! - [`exp2`]: x = n + f, n = round(x), f ∈ [−½, ½]; 2^f ≈ 1 + f · r(f), r of degree 4
//!   (fit error 1.9e-7 relative in f32), times 2^n built in the exponent bits. Measured
//!   relative error ≤ 1.9e-7 (the test asserts 3e-7). x is clamped to [−126, 127]:
//!   results below 2^−126 become 2^−126 (≈ 1.2e-38), above 2^127 (≈ 1.7e38) become 2^127.
//!
//! (Until 2026-11-22 log2 used the atanh series in t = (m − 1)/(m + 1), one division per
//! log, and exp2 a degree-7 Taylor series. The polynomials are as accurate or better;
//! on the shared benchmark machine drago03 and tumblin-rushmeier measured the same speed
//! within noise, agx (9 logs/exps per pixel) 5–10 % faster: docs/history/post-speed.md.)
//!
//! With both, powf(x, y) = exp2(y log2 x) has relative error ≈ ln 2 · |y log2 x| · 2e-7 +
//! 3e-7: 1e-5 for |y log2 x| ≤ 60, i.e. far below one 16-bit display code (1.5e-5).

const SQRT_HALF_BITS: u32 = 0x3f35_04f3; // √½ as f32 bits

/// x = 2^e · m with m ∈ [√½, √2): (e, m).
#[inline(always)]
fn reduce(x: f32) -> (f32, f32) {
    let x = x.max(f32::MIN_POSITIVE);
    let bits = x.to_bits();
    // Re-centre the mantissa on [√½, √2): subtract √½'s bits so the exponent steps there.
    let offset = bits.wrapping_sub(SQRT_HALF_BITS);
    let e = (offset as i32 >> 23) as f32;
    let m = f32::from_bits(bits.wrapping_sub(offset & 0xff80_0000));
    (e, m)
}

/// log2 of a positive finite f32 (see the module text for accuracy).
#[inline(always)]
#[allow(clippy::excessive_precision)] // the fitted f32 coefficients, printed in full
pub fn log2(x: f32) -> f32 {
    let (e, m) = reduce(x);
    let u = m - 1.0;
    let q = -0.145_741_06;
    let q = q * u + 0.236_889_03;
    let q = q * u - 0.250_069_65;
    let q = q * u + 0.286_707_67;
    let q = q * u - 0.360_087_2;
    let q = q * u + 0.480_939_45;
    let q = q * u - 0.721_357_17;
    let q = q * u + 1.442_694_8;
    e + u * q
}

/// (log2 a, log2 b). (Once a way to share one division between two logs; [`log2`] needs
/// none now.)
#[inline(always)]
pub fn log2_pair(a: f32, b: f32) -> (f32, f32) {
    (log2(a), log2(b))
}

/// (log2 x, 1/y), for curves of the form log(…) / L.
#[inline(always)]
pub fn log2_and_recip(x: f32, y: f32) -> (f32, f32) {
    (log2(x), 1.0 / y)
}

/// 2^x (see the module text for accuracy and range).
#[inline(always)]
#[allow(clippy::approx_constant)] // 0.693147 is the fitted coefficient, not ln 2 (0.6931472)
pub fn exp2(x: f32) -> f32 {
    let x = x.clamp(-126.0, 127.0);
    // n = round(x) (half away from zero), written as LLVM lowers `round` with SSE4.1:
    // trunc(x + copysign(pred(½), x)), the truncation by the int conversion. The same
    // value for every input, but without a call to `roundf` on the SSE2 baseline, so
    // loops over exp2 vectorise there too.
    // The conversion runs on a NaN-free copy (f32::max returns the number when one side
    // is NaN) so it can be the plain, vectorisable `cvttps2dq` instead of Rust's
    // saturating `as`; a NaN x still gives NaN through f below.
    let xi = x.max(-126.0);
    let t = xi + f32::from_bits(0x3eff_ffff).copysign(xi);
    // SAFETY: t is finite and |t| < 128, inside i32's range.
    let ni: i32 = unsafe { t.to_int_unchecked() };
    let n = ni as f32;
    let f = x - n;
    // 2^f = 1 + f · r(f) on [−½, ½] (module text).
    let r = 0.001_326_472;
    let r = r * f + 0.009_671_513;
    let r = r * f + 0.055_507_34;
    let r = r * f + 0.240_222_42;
    let r = r * f + 0.693_147;
    let p = r * f + 1.0;
    let scale = f32::from_bits(((ni + 127) as u32) << 23);
    p * scale
}

/// Natural log via [`log2`].
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    log2(x) * std::f32::consts::LN_2
}

/// e^x via [`exp2`].
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    exp2(x * std::f32::consts::LOG2_E)
}

/// x^y for x > 0 via [`exp2`] and [`log2`]; 0 for x ≤ 0 when y > 0.
#[inline(always)]
pub fn powf(x: f32, y: f32) -> f32 {
    if x > 0.0 {
        exp2(y * log2(x))
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log2_and_exp2_meet_their_stated_accuracy() {
        let mut worst_log = 0.0f64;
        let mut x = 1.2e-38f32;
        while x < 3e38 {
            let want = (x as f64).log2();
            // Beyond 3e-7, half an ulp of the f32 result itself (|want| · 2⁻²⁴).
            let err = (log2(x) as f64 - want).abs() - want.abs() * 2f64.powi(-24);
            worst_log = worst_log.max(err);
            x *= 1.000_37;
        }
        eprintln!("log2: worst error beyond half an ulp {worst_log:e}");
        assert!(worst_log <= 1.5e-7, "log2 error {worst_log}");
        // The pair, with partners across the whole range (a prime stride through it).
        let mut worst_pair = 0.0f64;
        let mut x = 1.2e-38f32;
        let mut y = 7.7e11f32;
        while x < 3e38 {
            let (gx, gy) = log2_pair(x, y);
            for (got, v) in [(gx, x), (gy, y)] {
                let want = (v as f64).log2();
                let err = (got as f64 - want).abs() - want.abs() * 2f64.powi(-24);
                worst_pair = worst_pair.max(err);
            }
            x *= 1.000_37;
            y *= 1.013_1;
            if y > 3e38 {
                y = 1.3e-38;
            }
        }
        assert!(worst_pair <= 3e-7, "log2_pair error {worst_pair}");
        // log2_and_recip: the log within the same bound, the reciprocal within 3 ulp.
        let mut x = 1.2e-38f32;
        let mut y = 3.3e-7f32;
        while x < 3e38 {
            let (l, r) = log2_and_recip(x, y);
            let want = (x as f64).log2();
            let err = (l as f64 - want).abs() - want.abs() * 2f64.powi(-24);
            assert!(err <= 3e-7, "log2_and_recip({x:e}, {y:e}): {l} vs {want}");
            assert!(
                (r as f64 * y as f64 - 1.0).abs() <= 3.0 * 2f64.powi(-24),
                "1/{y:e}"
            );
            x *= 1.000_37;
            y *= 1.007_3;
            if y > 1e30 {
                y = 2.1e-30;
            }
        }
        let mut worst_exp = 0.0f64;
        let mut y = -125.9f32;
        while y < 127.0 {
            let want = 2f64.powf(y as f64);
            worst_exp = worst_exp.max((exp2(y) as f64 / want - 1.0).abs());
            y += 0.000_731;
        }
        eprintln!("exp2: worst relative error {worst_exp:e}");
        assert!(worst_exp <= 3e-7, "exp2 error {worst_exp}");
        assert_eq!(exp2(-1000.0), f32::MIN_POSITIVE);
        assert!(exp2(1000.0).is_finite());
        assert_eq!(log2(0.0), -126.0);
        assert!(exp2(f32::NAN).is_nan());
        assert!((powf(2.0, 0.5) - std::f32::consts::SQRT_2).abs() < 1e-6);
        assert_eq!(powf(0.0, 2.2), 0.0);
    }

    #[test]
    fn exp2_rounding_equals_round_half_away_from_zero() {
        let pred_half = f32::from_bits(0x3eff_ffff);
        let mut xs = vec![
            0.0f32, -0.0, 0.5, -0.5, pred_half, -pred_half, 126.5, -125.5,
        ];
        for k in -126..=127 {
            for base in [k as f32, k as f32 + 0.5] {
                let mut x = base;
                for _ in 0..4 {
                    xs.extend([x, x.next_up(), x.next_down()]);
                    x = x.next_down();
                }
            }
        }
        let mut y = -126.0f32;
        while y <= 127.0 {
            xs.push(y);
            y += 0.000_917;
        }
        for x in xs.into_iter().filter(|x| (-126.0..=127.0).contains(x)) {
            let n = (x + pred_half.copysign(x)) as i32;
            assert_eq!(n as f32, x.round(), "x = {x:e}");
        }
    }
}
