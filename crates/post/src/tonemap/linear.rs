//! Linear exposure: L_d = 2^EV · L_w per channel (no compression; values above 1 are left
//! to the clipping / gamut stage).

use super::pixels::map_pixels;
use super::{Context, OperatorInfo, Output};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "linear",
    reference: "Linear exposure scaling, L_d = 2^EV · L_w (no reference needed)",
    absolute: false,
    params: &[],
};

pub(crate) fn apply(ctx: &Context) -> Output {
    Output {
        mapped: map_pixels(ctx, ctx.exposure, |c| c),
        values: vec![("scale", ctx.exposure as f64)],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};

    #[test]
    fn scales_by_two_to_the_exposure() {
        let img = small_image();
        let params = ToneParams {
            exposure_ev: -2.0,
            ..Default::default()
        };
        let out = ToneOperator::Linear.apply(&img, &params).unwrap().image;
        for (a, b) in img.pixels().iter().zip(out.pixels()) {
            for c in 0..3 {
                assert_eq!(b[c], a[c] * 0.25);
            }
        }
        assert_monotone(ToneOperator::Linear, &ToneParams::default(), None);
    }
}
