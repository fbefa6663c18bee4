//! Drago, Myszkowski, Annen & Chiba 2003, "Adaptive Logarithmic Mapping For Displaying High
//! Contrast Scenes", Eurographics, eq. 4:
//! L_d = (L_dmax · 0.01 / log10(L_wmax + 1)) · ln(L_w + 1) / ln(2 + 8 (L_w / L_wmax)^(ln b / ln 0.5)),
//! with world luminances divided by the log-average L_wa first (§3.2; as in pfstmo), bias
//! b = 0.85 and L_dmax = 100 cd/m² (so the prefactor is 1/log10(L_wmax + 1) and the
//! brightest pixel maps to 1).

use super::curve_table::CurveTable;
use super::kernels;
use super::octave_curve::OctaveCurve;
use super::pixels::{luminance_stats, LuminanceCurve};
use super::{Context, OperatorInfo, Output, ParamSpec};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "drago03",
    reference: "Drago, Myszkowski, Annen, Chiba 2003, Adaptive Logarithmic Mapping For \
                Displaying High Contrast Scenes, Eurographics (eq. 4)",
    absolute: false,
    params: &[
        ParamSpec {
            name: "bias",
            default: Some(0.85),
            min: 0.5,
            max: 1.0,
            doc: "bias b of the adaptive log base (0.7–0.9 recommended)",
        },
        ParamSpec {
            name: "display_max",
            default: Some(100.0),
            min: 1.0,
            max: 1e5,
            doc: "L_dmax, maximum display luminance in cd/m² (100 maps L_wmax to 1)",
        },
    ],
};

/// Eq. 4 on L_w / L_wa, as the ratio L_d / L, approximated over the image's luminance
/// range from the formula in f64 (the closed form costs three logarithms, a power and a
/// division per pixel in f32): in registers, one degree-9 polynomial per octave
/// ([`OctaveCurve`]: ten `vpermt2ps` and nine FMAs per 16 pixels), where the range spans
/// ≤ 32 binary exponents and the ISA is AVX-512; otherwise the memory table of
/// [`super::curve_table`] (a 16-byte row per pixel and three multiply-adds). The two
/// approximate eq. 4 to ~1e-7 each, so `PRISM_SIMD` changes drago03's output by that
/// much (`kernels::tests`).
/// (Two types, not an enum: the pass is generic over the curve, so each loop is compiled
/// for one of them and keeps the octave coefficients' loads out of the pixel loop.)
pub(super) struct Octaves(pub(super) OctaveCurve);

/// The memory-table form of the curve (see [`Octaves`]), with the ISA its slice lookup
/// runs.
pub(super) struct Table(pub(super) CurveTable, pub(super) prism_cpu::Simd);

impl LuminanceCurve for Octaves {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        self.0.eval_slice(l);
    }
}

impl LuminanceCurve for Table {
    #[inline(always)]
    fn ratio(&self, _start: usize, l: &mut [f32]) {
        self.0.eval_slice(l, self.1);
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let stats = luminance_stats(ctx, ctx.exposure, ctx.weights);
    let bias = ctx.value("bias");
    let display_max = ctx.value("display_max");
    let l_wa = stats.log_average;
    let l_wmax = stats.max / l_wa;
    let exponent = bias.ln() / 0.5f64.ln();
    let prefactor = display_max * 0.01 / (l_wmax + 1.0).log10();
    // A black image (L_wmax = 0) or an overflowing one (L_wmax = ∞) maps to black.
    let usable = l_wmax > 0.0 && prefactor.is_finite() && prefactor > 0.0;
    let ratio = move |l: f64| {
        let lw = l / l_wa;
        let ld = prefactor * lw.ln_1p() / (2.0 + 8.0 * (lw / l_wmax).powf(exponent)).ln();
        if usable {
            ld / l
        } else {
            0.0
        }
    };
    let (lo, hi) = (stats.min_positive as f32, stats.max as f32);
    let mapped = match OctaveCurve::new(ctx.simd, lo, hi, ratio) {
        Some(c) => kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &Octaves(c)),
        None => {
            let table = Table(CurveTable::new(lo, hi, ratio), ctx.simd);
            kernels::map_luminance_fast(ctx, ctx.exposure, ctx.weights, &table)
        }
    };
    Output {
        mapped,
        values: vec![
            ("log_average", stats.log_average),
            ("max_scaled_luminance", l_wmax),
            ("bias", bias),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::super::curve_table::CurveTable;
    use super::super::octave_curve::OctaveCurve;
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn matches_equation_4() {
        let img = small_image();
        let out = ToneOperator::Drago03
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        let lw: Vec<f64> = img.pixels().iter().map(|p| luminance(&img, *p)).collect();
        let l_wa = (lw.iter().map(|l| (1e-6 + l).ln()).sum::<f64>() / 4.0).exp();
        let scaled: Vec<f64> = lw.iter().map(|l| l / l_wa).collect();
        let l_max = scaled.iter().cloned().fold(0.0, f64::max);
        let b = 0.85f64;
        for (i, p) in out.pixels().iter().enumerate() {
            let l = scaled[i];
            let ld = (1.0 / (l_max + 1.0).log10()) * (l + 1.0).ln()
                / (2.0 + 8.0 * (l / l_max).powf(b.ln() / 0.5f64.ln())).ln();
            assert_close(luminance(&out, *p), ld, "L_d");
        }
        assert_close(luminance(&out, out.pixels()[3]), 1.0, "brightest → 1");
        assert_monotone(ToneOperator::Drago03, &ToneParams::default(), None);
    }

    #[test]
    fn fast_path_matches_f64_to_a_fraction_of_a_16_bit_code() {
        let img = sweep_image(40_000);
        let result = ToneOperator::Drago03
            .apply(&img, &ToneParams::default())
            .unwrap();
        // Eq. 4 in f64 on the operator's own statistics (log-average, maximum).
        let value = |k: &str| result.report.values[k];
        let (l_wa, l_max) = (value("log_average"), value("max_scaled_luminance"));
        let e = 0.85f64.ln() / 0.5f64.ln();
        let want: Vec<[f64; 3]> = img
            .pixels()
            .iter()
            .map(|p| {
                let l = luminance(&img, *p);
                let lw = l / l_wa;
                let ld = (lw + 1.0).ln()
                    / ((l_max + 1.0).log10() * (2.0 + 8.0 * (lw / l_max).powf(e)).ln());
                p.map(|c| c as f64 * ld / l)
            })
            .collect();
        let err = max_code_error_16(result.image.pixels(), &want);
        eprintln!("drago03: max error {err} 16-bit codes");
        // Measured 0.006 codes (the curve tabulated from f64, ~1e-7 relative, and f32
        // sums; the f32 closed form with fast log2/exp2 measured 0.05): a 16-bit PNG
        // changes at most where a value lies within that distance of a half-code tie.
        assert!(err < 0.015, "{err} 16-bit codes");
    }

    /// Both forms of the curve through every ISA's pass: the table (whose slice lookup
    /// runs each ISA's kernel) and, made where the machine has AVX-512, the octave
    /// polynomials.
    #[test]
    fn vector_path_gives_the_scalar_bits() {
        use super::super::kernels::tests::same_bits_as_scalar;
        let f = |l: f64| (1.0 + l).ln() / (l * (2.0 + l.powf(0.23)).ln());
        same_bits_as_scalar(&bit_test_image(), 1.0, |simd| {
            super::Table(CurveTable::new(1e-3, 1e3, f), simd)
        });
        if let Some(avx512) = prism_cpu::each_isa().into_iter().find(|s| s.avx512()) {
            let octaves = || super::Octaves(OctaveCurve::new(avx512, 1e-3, 1e3, f).unwrap());
            same_bits_as_scalar(&bit_test_image(), 1.0, |_| octaves());
        }
    }
}
