//! Display encoding of linear values to integer codes without a transcendental per sample:
//! code(v) = round(encode(clamp(v, 0, 1)) · max_code), computed exactly (up to f64
//! rounding at exact half-code ties) from the decision thresholds
//! t_c = decode((c + ½) / max_code): code(v) = #{c : t_c ≤ v}. A table indexed by the top
//! bits of v's f32 representation (2⁻¹⁴ relative buckets) gives the code at the bucket's
//! lower edge; a fixed number of threshold comparisons (the most thresholds one bucket
//! holds: 2 for 16-bit sRGB) finishes it, in f32 against thresholds rounded up to f32
//! (exact for f32 inputs). Non-finite values encode as 0, as before.

use prism_spectrum::rgb_space::TransferFunction;

/// f32 bits dropped for the bucket index: 23 − 9 = 14 mantissa bits kept → buckets of
/// 2⁻¹⁴ relative width (6e-5), narrower than a 16-bit code step of the sRGB curve
/// everywhere, so the threshold loops below run at most once or twice. (With 2⁻¹⁰ a bucket
/// near 1 spanned ~25 codes and the loop made the quantiser 16 ns per sample, half the
/// time of a 4K PNG write.) The table has ~22 octaves × 2¹⁴ entries (0.7 MB for 16 bits)
/// and is filled by one merge of buckets and thresholds.
const SHIFT: u32 = 9;

/// Exact quantiser for one transfer function and code range.
pub struct Quantiser {
    /// t_c rounded up to f32 (the smallest f32 ≥ t_c: for an f32 v, v ≥ t_c ⟺ v ≥ this),
    /// followed by `spread` copies of +∞ so that the fixed number of comparisons in
    /// [`Self::code`] never reads past the end.
    thresholds: Vec<f32>,
    /// The most thresholds any bucket holds (above its lower edge): the number of
    /// comparisons per sample (2 for the sRGB and BT.2020 curves at 16 bits).
    spread: usize,
    base: u32,
    table: Vec<u16>,
    max_code: u16,
}

/// The smallest f32 ≥ t (t ≥ 0 finite).
fn ceil_f32(t: f64) -> f32 {
    let f = t as f32;
    if (f as f64) < t {
        f.next_up()
    } else {
        f
    }
}

impl Quantiser {
    pub fn new(transfer: TransferFunction, max_code: u16) -> Self {
        let m = max_code as f64;
        let exact: Vec<f64> = (0..max_code)
            .map(|c| transfer.decode((c as f64 + 0.5) / m))
            .collect();
        let mut thresholds: Vec<f32> = exact.iter().map(|t| ceil_f32(*t)).collect();
        let first = thresholds[0].max(f32::MIN_POSITIVE).to_bits() >> SHIFT;
        let last = 1f32.to_bits() >> SHIFT;
        // Buckets and thresholds both ascend: one merge gives each bucket the number of
        // thresholds at or below its lower edge.
        let mut c = 0usize;
        let table: Vec<u16> = (first..=last + 1)
            .map(|b| {
                let lower = f32::from_bits(b << SHIFT);
                while c < thresholds.len() && thresholds[c] <= lower {
                    c += 1;
                }
                c as u16
            })
            .collect();
        let spread = table
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .max()
            .unwrap_or(0)
            .max(1);
        thresholds.extend(std::iter::repeat_n(f32::INFINITY, spread));
        Self {
            thresholds,
            spread,
            base: first,
            table,
            max_code,
        }
    }

    /// round(encode(clamp(v, 0, 1)) · max_code); 0 for NaN and ±∞.
    #[inline]
    pub fn code(&self, v: f32) -> u16 {
        // NaN, ±∞ and values below the first threshold give 0.
        if v.is_nan() || v < self.thresholds[0] || v == f32::INFINITY {
            return 0;
        }
        if v >= 1.0 {
            return self.max_code;
        }
        // v ≥ t_0 ≥ the base bucket's lower edge and v < 1: inside the table.
        let bucket = ((v.to_bits() >> SHIFT) - self.base) as usize;
        let c = self.table[bucket] as usize;
        // The thresholds in v's bucket above its lower edge are t_c … t_{c+spread−1} at
        // most (the rest lie beyond the bucket): count those ≤ v, branch-free (a
        // data-dependent loop exit mispredicts about every other sample).
        let t = &self.thresholds[c..c + self.spread];
        if self.spread == 2 {
            return (c + (t[0] <= v) as usize + (t[1] <= v) as usize) as u16;
        }
        (c + t.iter().filter(|t| **t <= v).count()) as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(t: TransferFunction, v: f32, max: f64) -> u16 {
        let v = if v.is_finite() {
            (v as f64).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t.encode(v).clamp(0.0, 1.0) * max).round() as u16
    }

    #[test]
    fn codes_equal_the_direct_formula() {
        for t in [
            prism_spectrum::rgb_space::RgbColorSpace::srgb().transfer,
            prism_spectrum::rgb_space::RgbColorSpace::rec2020().transfer,
        ] {
            for max in [255u16, 65535] {
                let q = Quantiser::new(t, max);
                // Dense sweep in log and linear spacing, plus edge cases.
                let mut values: Vec<f32> = (0..400_000)
                    .map(|i| 10f32.powf(-12.0 + 12.0 * i as f32 / 400_000.0))
                    .chain((0..200_000).map(|i| i as f32 / 200_000.0))
                    .collect();
                values.extend([0.0, -1.0, 1.0, 2.0, f32::NAN, f32::INFINITY, 1e-45]);
                values.push(f32::NEG_INFINITY);
                // Both sides of every decision threshold (the f32 at or just above t_c,
                // and the one below), where a wrong comparison would show.
                for c in 0..max {
                    let t = t.decode((c as f64 + 0.5) / max as f64);
                    let up = super::ceil_f32(t);
                    values.extend([up, up.next_down(), up.next_up()]);
                }
                for v in values {
                    assert_eq!(q.code(v), reference(t, v, max as f64), "{t:?} {max} {v:e}");
                }
            }
        }
    }
}
