//! x^y for the per-pixel FLIP value (x ≥ 0, |y log₂ x| moderate) without a libm call, so
//! the loop that calls it vectorises: 2^(y log₂ x) with log₂ from the exponent bits and
//! the atanh series of the mantissa, 2^f from its Taylor polynomial (Cody & Waite's
//! range reduction, "Software Manual for the Elementary Functions", 1980, ch. 6 and 10).
//! Relative error a few f32 ulps (tested against `powf`); results below 2⁻¹²⁶ are 0, and
//! subnormal x is read as 2⁻¹²⁶ (FLIP values that small are 0 on every scale shown).

use std::f32::consts::{LN_2, LOG2_E};

/// log₂ x for x ≥ 2⁻¹²⁶ (normal, finite).
#[inline(always)]
fn log2_normal(x: f32) -> f32 {
    let bits = x.to_bits();
    // Mantissa m in [√½, √2): take the exponent of x·√2 so that m = x / 2ⁿ is centred on 1.
    let n = ((bits + (0x3F80_0000 - 0x3F35_04F3)) >> 23) as i32 - 127;
    let m = f32::from_bits((bits as i32 - (n << 23)) as u32);
    // ln m = 2 atanh s = 2 (s + s³/3 + s⁵/5 + …), s = (m − 1)/(m + 1), |s| ≤ 0.1716:
    // the s¹¹ term is below 4e-10.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0))));
    n as f32 + 2.0 * LOG2_E * s * series
}

/// 2^z for z ≥ −126 and finite (z below gives 0).
#[inline(always)]
fn exp2_limited(z: f32) -> f32 {
    let zc = z.clamp(-126.0, 127.0);
    let n = zc.round();
    // e^(f ln 2) for f in [−½, ½]: Taylor to degree 7 (the next term is below 6e-9).
    let t = (zc - n) * LN_2;
    let p = 1.0
        + t * (1.0
            + t * (1.0 / 2.0
                + t * (1.0 / 6.0
                    + t * (1.0 / 24.0
                        + t * (1.0 / 120.0 + t * (1.0 / 720.0 + t * (1.0 / 5040.0)))))));
    let scale = f32::from_bits(((n as i32 + 127) << 23) as u32);
    if z < -126.0 {
        0.0
    } else {
        p * scale
    }
}

/// x^y for x ≥ 0 and y ≥ 0 with y log₂ x ≤ 127 (0⁰ = 1, as `powf`).
#[inline(always)]
pub(super) fn pow_non_negative(x: f32, y: f32) -> f32 {
    let v = exp2_limited(y * log2_normal(x.max(f32::MIN_POSITIVE)));
    if x == 0.0 {
        if y == 0.0 {
            1.0
        } else {
            0.0
        }
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_powf_to_a_few_ulps() {
        let mut worst = 0.0f64;
        let mut x = 1e-30f32;
        while x < 400.0 {
            for y in [0.0f32, 1e-4, 0.05, 0.3, 0.5, 0.7, 0.93, 1.0] {
                let (fast, libm) = (pow_non_negative(x, y), x.powf(y));
                if libm < f32::MIN_POSITIVE {
                    assert!(fast < 2.0 * f32::MIN_POSITIVE, "{x}^{y}: {fast} {libm}");
                    continue;
                }
                // f32 rounding of z = y log₂ x moves the result by ~1e-7 |z| relative.
                let z = f64::from(y) * f64::from(x).log2().abs();
                let rel = ((f64::from(fast) - f64::from(libm)) / f64::from(libm)).abs();
                worst = worst.max(rel / (1e-6 + 2e-7 * z));
            }
            x *= 1.0037;
        }
        assert!(worst < 1.0, "worst relative error / bound {worst}");
        assert_eq!(pow_non_negative(0.0, 0.0), 1.0);
        assert_eq!(pow_non_negative(0.0, 0.7), 0.0);
        assert_eq!(pow_non_negative(1.0, 0.3), 1.0);
        assert_eq!(pow_non_negative(1e-30, 5.0), 0.0);
    }
}
