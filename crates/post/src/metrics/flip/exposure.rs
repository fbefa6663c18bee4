//! HDR-FLIP's exposures (Andersson et al. 2021, sec. 4): the reference image is tone-mapped
//! with Narkowicz's ACES fit (with its 0.6 pre-exposure folded into the coefficients) at
//! exposures 2^c for c from c_start, where the brightest reference luminance maps to
//! t = 0.85, to c_stop, where the median luminance does, in ⌈c_stop − c_start⌉ (at least 2)
//! equal steps — the reference implementation's defaults.

use serde::Serialize;

/// ACES fit y = (k0 x² + k1 x + k2) / (k3 x² + k4 x + k5).
const K: [f32; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// The tone-mapped value the extreme luminances map to.
const TARGET: f64 = 0.85;

/// The smallest luminance the range is computed from: the reference implementation's
/// guard for black images, f32 epsilon (2⁻²³; measured: a median of 0 gives its c_stop).
const MIN_LUMINANCE: f64 = f32::EPSILON as f64;

/// The exposures HDR-FLIP evaluates at (exposure factors 2^c).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExposureRange {
    pub start_stops: f64,
    pub stop_stops: f64,
    pub count: usize,
}

impl ExposureRange {
    /// The reference implementation's automatic range for `reference` (linear Rec.709,
    /// non-negative): c_start from its largest luminance, c_stop from its median (the
    /// element at rank ⌊n/2⌋ in ascending order).
    pub fn automatic(reference: impl Iterator<Item = [f32; 3]>) -> Self {
        Self::from_luminances(reference.map(luminance).collect())
    }

    /// [`Self::automatic`] from the reference's luminances ([`luminance`]), in any order.
    pub fn from_luminances(mut y: Vec<f64>) -> Self {
        let max = y.iter().cloned().fold(0.0f64, f64::max);
        let mid = y.len() / 2;
        let (_, median, _) = y.select_nth_unstable_by(mid, f64::total_cmp);
        let x = aces_inverse(TARGET);
        let start = (x / max.max(MIN_LUMINANCE)).log2();
        let stop = (x / median.max(MIN_LUMINANCE)).log2();
        let count = ((stop - start).ceil() as usize).max(2);
        Self {
            start_stops: start,
            stop_stops: stop,
            count,
        }
    }

    /// Exposure `i` of `count`, in stops.
    pub fn stops(&self, i: usize) -> f64 {
        self.start_stops + i as f64 * (self.stop_stops - self.start_stops) / (self.count - 1) as f64
    }
}

/// Rec.709 luminance in f64: a sum near f32::MAX must not round to ∞ (c_start = −∞,
/// endless exposures).
pub fn luminance(p: [f32; 3]) -> f64 {
    let p = p.map(f64::from);
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The ACES fit clamped to [0, 1].
#[inline(always)]
pub(super) fn aces(x: f32) -> f32 {
    let x2 = x * x;
    if !x2.is_finite() {
        // x² overflows (x > 1.8e19) where the curve has long reached its limit k0/k3 > 1:
        // white, not inf/inf = NaN.
        return 1.0;
    }
    ((K[0] * x2 + K[1] * x + K[2]) / (K[3] * x2 + K[4] * x + K[5])).clamp(0.0, 1.0)
}

/// The x ≥ 0 the ACES fit maps to `t` (the positive root of a quadratic).
fn aces_inverse(t: f64) -> f64 {
    let k = K.map(f64::from);
    let c0 = (k[1] - k[4] * t) / (k[0] - k[3] * t);
    let c1 = (k[2] - k[5] * t) / (k[0] - k[3] * t);
    -0.5 * c0 + (0.25 * c0 * c0 - c1).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_inverts_and_range_follows_max_and_median() {
        let x = aces_inverse(TARGET);
        assert!((f64::from(aces(x as f32)) - TARGET).abs() < 1e-5);
        // Luminances 1, 2, 3, 4: max 4, median (rank 2) 3.
        let px: Vec<[f32; 3]> = (1..=4).map(|v| [v as f32; 3]).collect();
        let r = ExposureRange::automatic(px.into_iter());
        assert!((r.start_stops - (x / 4.0).log2()).abs() < 1e-5);
        assert!((r.stop_stops - (x / 3.0).log2()).abs() < 1e-5);
        assert_eq!(r.count, 2);
        assert!((r.stops(1) - r.stop_stops).abs() < 1e-12);
        // A black image stays finite: both ends at the 2⁻²³ floor.
        let black = ExposureRange::automatic([[0.0; 3]; 4].into_iter());
        assert_eq!((aces(1e20), aces(f32::MAX), aces(0.0)), (1.0, 1.0, 0.0));
        // Luminance of f32::MAX white is finite in f64: a bounded exposure count.
        let huge = ExposureRange::automatic([[f32::MAX; 3], [1.0; 3]].into_iter());
        assert!(huge.start_stops.is_finite() && huge.count < 200, "{huge:?}");
        assert!(black.start_stops.is_finite() && black.count == 2);
    }
}
