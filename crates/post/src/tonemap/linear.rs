//! Linear exposure: L_d = 2^EV · L_w per channel (no compression; values above 1 are left
//! to the clipping / gamut stage).

use super::pixels::{map_pixels, PixelMap};
use super::{Context, OperatorInfo, Output};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "linear",
    reference: "Linear exposure scaling, L_d = 2^EV · L_w (no reference needed)",
    absolute: false,
    params: &[],
};

/// The identity (the exposure is the sanitising scale).
struct Identity;

impl PixelMap for Identity {
    #[inline(always)]
    fn map(&self, _start: usize, _r: &mut [f32], _g: &mut [f32], _b: &mut [f32]) {}
}

pub(crate) fn apply(ctx: &Context) -> Output {
    Output {
        mapped: map_pixels(ctx, ctx.exposure, &Identity),
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
