//! ACES filmic: the RRT + sRGB ODT of the Academy Color Encoding System approximated by
//! Stephen Hill's fit (BakingLab `ACES.hlsl`, 2016), chosen over Narkowicz's 2015
//! single-curve fit because it keeps the RRT's gamut handling and saturation:
//! c_in = M_in · rgb (sRGB → AP1 with the RRT saturation),
//! f(v) = (v (v + 0.0245786) − 0.000090537) / (v (0.983729 v + 0.4329510) + 0.238081),
//! rgb_out = clamp(M_out · f(c_in), 0, 1) (ODT saturation → sRGB).
//! Input in other colour spaces is converted to linear sRGB first and back afterwards.

use glam::{Mat3, Vec3};
use prism_spectrum::rgb_space::RgbColorSpace;

use super::pixels::{map_pixels, PixelMap};
use super::{Context, OperatorInfo, Output};

pub(crate) static INFO: OperatorInfo = OperatorInfo {
    name: "aces",
    reference: "ACES RRT + sRGB ODT, Hill 2016 fit (BakingLab ACES.hlsl); Academy S-2014-004",
    absolute: false,
    params: &[],
};

/// Hill's ACESInputMat, rows as printed.
const INPUT_ROWS: [[f32; 3]; 3] = [
    [0.59719, 0.35458, 0.04823],
    [0.07600, 0.90834, 0.01566],
    [0.02840, 0.13383, 0.83777],
];
/// Hill's ACESOutputMat, rows as printed.
const OUTPUT_ROWS: [[f32; 3]; 3] = [
    [1.60475, -0.53108, -0.07367],
    [-0.10208, 1.10813, -0.00605],
    [-0.00327, -0.07276, 1.07602],
];

pub(crate) fn from_rows(r: [[f32; 3]; 3]) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(r[0][0], r[1][0], r[2][0]),
        Vec3::new(r[0][1], r[1][1], r[2][1]),
        Vec3::new(r[0][2], r[1][2], r[2][2]),
    )
}

/// Hill's RRTAndODTFit.
#[allow(clippy::excessive_precision)] // the published digits, kept verbatim
#[inline(always)]
pub fn rrt_odt_fit(v: f32) -> f32 {
    (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081)
}

/// Linear RGB in `space` ↔ linear sRGB matrices.
pub(crate) fn srgb_matrices(space: &RgbColorSpace) -> (Mat3, Mat3) {
    let srgb = RgbColorSpace::srgb();
    let to = (srgb.xyz_to_rgb * space.rgb_to_xyz).as_mat3();
    let from = (space.xyz_to_rgb * srgb.rgb_to_xyz).as_mat3();
    (to, from)
}

/// M_in, the fit per channel, M_out, clamp, back to the image's space.
struct Map {
    input: Mat3,
    output: Mat3,
    from_srgb: Mat3,
}

impl PixelMap for Map {
    #[inline(always)]
    fn map(&self, _start: usize, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        // Locals, not fields, in the loop: the planes could alias `self` as far as the
        // compiler knows, which would keep the loop scalar.
        let (input, output, from_srgb) = (self.input, self.output, self.from_srgb);
        for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
            let v = input * Vec3::new(*r, *g, *b);
            let f = Vec3::new(rrt_odt_fit(v.x), rrt_odt_fit(v.y), rrt_odt_fit(v.z));
            let srgb = (output * f).clamp(Vec3::ZERO, Vec3::ONE);
            let c = from_srgb * srgb;
            (*r, *g, *b) = (c.x, c.y, c.z);
        }
    }
}

pub(crate) fn apply(ctx: &Context) -> Output {
    let (to_srgb, from_srgb) = srgb_matrices(&ctx.image.color_space);
    let map = Map {
        input: from_rows(INPUT_ROWS) * to_srgb,
        output: from_rows(OUTPUT_ROWS),
        from_srgb,
    };
    Output {
        mapped: map_pixels(ctx, ctx.exposure, &map),
        values: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ToneOperator, ToneParams};
    use super::*;

    #[test]
    fn greys_follow_the_fit_curve() {
        // Both of Hill's matrices have unit row sums, so a grey g maps to the grey f(g).
        for r in INPUT_ROWS.iter().chain(OUTPUT_ROWS.iter()) {
            assert!((r.iter().sum::<f32>() - 1.0).abs() < 1e-4);
        }
        let img = small_image();
        let out = ToneOperator::Aces
            .apply(&img, &ToneParams::default())
            .unwrap()
            .image;
        for i in [0, 2] {
            let g = img.pixels()[i][0];
            let want = rrt_odt_fit(g).clamp(0.0, 1.0) as f64;
            for c in 0..3 {
                // Row sums are 1 to 1e-4 of the printed digits.
                assert!((out.pixels()[i][c] as f64 - want).abs() < 2e-4 * g as f64 + 1e-5);
            }
        }
        // Hand evaluation: f(0.18) = 0.036734 / 0.347885 = 0.10559; f(∞) = 1 / 0.983729.
        assert!((rrt_odt_fit(0.18) - 0.10559).abs() < 1e-4);
        assert!((rrt_odt_fit(1e7) - 1.0 / 0.983729).abs() < 1e-5);
        assert_monotone(ToneOperator::Aces, &ToneParams::default(), None);
    }
}
