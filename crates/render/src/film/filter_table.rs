//! The 1D filter profile f₁ tabulated for splatting.
//!
//! A splatting film (`Film::with_splatting`, Mitsuba 3's `ImageBlock`) weights every sample
//! into each pixel within the filter radius: for the Cornell box's Gaussian (r = 2 px) 4 + 4
//! profile values per sample, each an `expf` — with the weight bookkeeping, the largest
//! share of the film's cost per sample (callgrind, ≈ 1.4 k instructions per sample). Mitsuba
//! tabulates its filters the same way (`Film::prepare`, `ReconstructionFilter` lookup table
//! of `MI_FILTER_RESOLUTION` = 31 entries, nearest); this table is much finer and
//! interpolates linearly, so it stays within ≈ 10⁻⁶ of the peak (tested for every filter):
//! far below the Monte Carlo noise of any render, and the weights still sum to the same
//! normaliser in numerator and denominator of each pixel.

use super::Filter;

/// Intervals of the table over [0, r]. The linear-interpolation error is at most
/// h²/8 · max |f₁''| with h = r / N; for the Gaussian (σ = 0.5 px, r = 2 px) that is
/// ≈ 2 · 10⁻⁶ of the peak. 1025 f32 values (4 KiB) stay in L1.
const INTERVALS: usize = 1024;

/// f₁ on [0, r] at N + 1 equally spaced points (the profiles are even: f₁(−x) = f₁(x)).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FilterTable {
    radius_px: f32,
    /// N / r.
    inv_step_per_px: f32,
    /// f₁(i · r / N), i = 0..=N, plus one copy of the last value so that the interpolation
    /// at x = r reads inside the table.
    values: Vec<f32>,
    /// max |f₁|²: a bound on the weight of any tap, f₁(x) f₁(y).
    max_weight: f64,
}

impl FilterTable {
    pub fn new(filter: &Filter) -> Self {
        let radius_px = filter.radius_px();
        let step_px = f64::from(radius_px) / INTERVALS as f64;
        let mut values: Vec<f32> = (0..=INTERVALS)
            // The last node is r itself (evaluated at r, not at N·step, which may round past
            // r and read as outside the support).
            .map(|i| {
                let x = if i == INTERVALS {
                    radius_px
                } else {
                    (i as f64 * step_px) as f32
                };
                filter.eval_1d(x)
            })
            .collect();
        values.push(values[INTERVALS]);
        let max_abs = values.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        Self {
            radius_px,
            inv_step_per_px: (INTERVALS as f64 / f64::from(radius_px)) as f32,
            values,
            max_weight: f64::from(max_abs) * f64::from(max_abs),
        }
    }

    /// A bound on |f₁(x) f₁(y)|, the weight of any tap (interpolation stays within the
    /// nodes' range).
    pub fn max_weight(&self) -> f64 {
        self.max_weight
    }

    /// f₁(x) by linear interpolation; exactly 0 for |x| > r (and NaN).
    #[inline(always)]
    pub fn eval(&self, x_px: f32) -> f32 {
        let a = x_px.abs();
        if a.is_nan() || a > self.radius_px {
            return 0.0;
        }
        // 0 ≤ a ≤ r, so s ∈ [0, N] up to rounding; the clamp keeps i + 1 in the table when
        // rounding puts s just past N.
        let s = (a * self.inv_step_per_px).min(INTERVALS as f32);
        // SAFETY: s is finite (a is not NaN and at most r) and in [0, N] ⊂ i32, where the
        // truncating conversion is defined — and is the floor, s being ≥ 0. (`as usize`
        // saturates, which costs ≈ 10 instructions per call; this is called 8 times per
        // splatted sample.)
        let k = unsafe { s.to_int_unchecked::<i32>() };
        let (i, t) = (k as usize, s - k as f32);
        let (v0, v1) = (self.values[i], self.values[i + 1]);
        v0 + t * (v1 - v0)
    }

    /// `eval` at four points: the same arithmetic lane by lane (so the same bits), four
    /// lanes at once on x86-64 (SSE2, part of the baseline), where only the table reads
    /// stay scalar. A splat reads one row and one column of four taps per sample.
    #[inline(always)]
    pub fn eval4(&self, x_px: [f32; 4]) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // SAFETY: SSE2 is always present on x86-64; the loads and stores address the
            // four f32 of `x_px` and of the local `out`.
            unsafe {
                let x = _mm_loadu_ps(x_px.as_ptr());
                // |x|, and the lanes inside the support (false for NaN, like `eval`).
                let a = _mm_andnot_ps(_mm_set1_ps(-0.0), x);
                let inside = _mm_cmple_ps(a, _mm_set1_ps(self.radius_px));
                // As in `eval`; a NaN lane becomes N here (minps returns its second operand
                // when the first is NaN) and is masked out below.
                let s = _mm_min_ps(
                    _mm_mul_ps(a, _mm_set1_ps(self.inv_step_per_px)),
                    _mm_set1_ps(INTERVALS as f32),
                );
                // In [0, N]: the truncation is the floor, as in `eval`.
                let k = _mm_cvttps_epi32(s);
                let t = _mm_sub_ps(s, _mm_cvtepi32_ps(k));
                let mut k_lanes = [0i32; 4];
                _mm_storeu_si128(k_lanes.as_mut_ptr().cast(), k);
                // Lanes outside the support read index 0..=N like the others (any value;
                // masked below): k ∈ [0, N] in every lane, since s is.
                let pair = |lane: usize| {
                    let i = k_lanes[lane] as usize;
                    debug_assert!(i < self.values.len() - 1);
                    // SAFETY: i ∈ [0, N] (above) and the table holds N + 2 values.
                    (
                        *self.values.get_unchecked(i),
                        *self.values.get_unchecked(i + 1),
                    )
                };
                let (p0, p1, p2, p3) = (pair(0), pair(1), pair(2), pair(3));
                let v0 = _mm_setr_ps(p0.0, p1.0, p2.0, p3.0);
                let v1 = _mm_setr_ps(p0.1, p1.1, p2.1, p3.1);
                let v = _mm_add_ps(v0, _mm_mul_ps(t, _mm_sub_ps(v1, v0)));
                let mut out = [0.0f32; 4];
                _mm_storeu_ps(out.as_mut_ptr(), _mm_and_ps(v, inside));
                out
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        x_px.map(|x| self.eval(x))
    }
}

impl FilterTable {
    /// `eval` at eight points, the table reads as two AVX2 gathers: the same arithmetic
    /// lane by lane (so the same bits) — a radius-2 splat's four columns and four rows in
    /// one call, where `eval4`'s sixteen scalar reads cost ≈ 5 % of a Cornell box render.
    ///
    /// # Safety
    /// The CPU must run AVX2 (a `prism_cpu::Simd` that allows it).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    pub unsafe fn eval8_avx2(&self, x_px: [f32; 8]) -> [f32; 8] {
        use std::arch::x86_64::*;
        let x = _mm256_loadu_ps(x_px.as_ptr());
        // As `eval4`: |x|, the lanes inside the support (false for NaN), s clamped to N
        // (a NaN lane becomes N and is masked out).
        let a = _mm256_andnot_ps(_mm256_set1_ps(-0.0), x);
        let inside = _mm256_cmp_ps::<_CMP_LE_OQ>(a, _mm256_set1_ps(self.radius_px));
        let s = _mm256_min_ps(
            _mm256_mul_ps(a, _mm256_set1_ps(self.inv_step_per_px)),
            _mm256_set1_ps(INTERVALS as f32),
        );
        let k = _mm256_cvttps_epi32(s);
        let t = _mm256_sub_ps(s, _mm256_cvtepi32_ps(k));
        // k ∈ [0, N] in every lane and the table holds N + 2 values: both reads in bounds.
        let v0 = _mm256_i32gather_ps::<4>(self.values.as_ptr(), k);
        let v1 = _mm256_i32gather_ps::<4>(self.values.as_ptr().add(1), k);
        let v = _mm256_add_ps(v0, _mm256_mul_ps(t, _mm256_sub_ps(v1, v0)));
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), _mm256_and_ps(v, inside));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::filter::{BlackmanHarrisFilter, BoxFilter, GaussianFilter, MitchellFilter};

    fn filters() -> Vec<Filter> {
        vec![
            Filter::Box(BoxFilter::new(0.5).unwrap()),
            Filter::Box(BoxFilter::new(1.5).unwrap()),
            Filter::Gaussian(GaussianFilter::new(2.0, 2.0).unwrap()),
            Filter::Gaussian(GaussianFilter::new(1.5, 2.0).unwrap()),
            Filter::Gaussian(GaussianFilter::new(3.0, 0.5).unwrap()),
            Filter::BlackmanHarris(BlackmanHarrisFilter::new(2.0).unwrap()),
            Filter::Mitchell(MitchellFilter::new(2.0, 1.0 / 3.0, 1.0 / 3.0).unwrap()),
        ]
    }

    #[test]
    fn table_matches_the_profile_within_its_interpolation_bound() {
        for filter in filters() {
            let table = FilterTable::new(&filter);
            let r = filter.radius_px();
            let peak = (0..=1000)
                .map(|i| filter.eval_1d(r * i as f32 / 1000.0).abs())
                .fold(0.0f32, f32::max);
            let mut worst = 0.0f32;
            // 100 003 points (not a multiple of the table's step) across [−1.1 r, 1.1 r].
            let n = 100_003;
            for i in 0..=n {
                let x = r * (-1.1 + 2.2 * i as f32 / n as f32);
                let (exact, tabulated) = (filter.eval_1d(x), table.eval(x));
                if x.abs() > r {
                    assert_eq!(tabulated, 0.0, "{filter:?} at {x}");
                }
                worst = worst.max((exact - tabulated).abs());
            }
            assert!(worst <= 1e-5 * peak, "{filter:?}: {worst} vs peak {peak}");
            // At the nodes, including 0 and the radius itself, the table is the profile.
            assert_eq!(table.eval(0.0), filter.eval_1d(0.0));
            assert_eq!(table.eval(r), filter.eval_1d(r));
            assert_eq!(table.eval(-r), filter.eval_1d(r));
        }
    }

    /// `eval_w` (a W-wide form of `eval`) gives `eval`'s bits in every lane, for every
    /// filter: inside, outside, the edge itself, ±0 and non-finite inputs.
    fn lanes_are_eval<const W: usize>(eval_w: impl Fn(&FilterTable, [f32; W]) -> [f32; W]) {
        for filter in filters() {
            let table = FilterTable::new(&filter);
            let r = filter.radius_px();
            let mut xs: Vec<f32> = (0..=8001)
                .map(|i| r * (-1.2 + 2.4 * i as f32 / 8001.0))
                .collect();
            xs.extend([0.0, -0.0, r, -r, f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
            for chunk in xs.chunks(W) {
                let mut x = [f32::NAN; W];
                x[..chunk.len()].copy_from_slice(chunk);
                let got = eval_w(&table, x);
                for (g, &xi) in got.iter().zip(&x) {
                    assert_eq!(g.to_bits(), table.eval(xi).to_bits(), "{filter:?} at {xi}");
                }
            }
        }
    }

    /// The AVX2 gathers (each ISA the machine runs that has them; skipped, and reported
    /// by `prism_cpu::each_isa`, where it has none).
    #[test]
    fn eval8_is_eval_in_every_lane() {
        for simd in prism_cpu::each_isa() {
            if simd.avx2() {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
                lanes_are_eval::<8>(|t, x| unsafe { t.eval8_avx2(x) });
            }
        }
    }

    #[test]
    fn eval4_is_eval_in_every_lane() {
        lanes_are_eval::<4>(|t, x| t.eval4(x));
    }

    #[test]
    fn box_profile_is_exact_up_to_its_edge() {
        let filter = Filter::Box(BoxFilter::new(0.5).unwrap());
        let table = FilterTable::new(&filter);
        for x in [0.0, 0.1, 0.25, 0.49999, 0.5, -0.5] {
            assert_eq!(table.eval(x), filter.eval_1d(x), "{x}");
        }
        assert_eq!(table.eval(0.50001), 0.0);
        assert_eq!(table.eval(f32::NAN), 0.0);
    }
}
