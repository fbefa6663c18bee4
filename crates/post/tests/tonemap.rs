//! Properties every tone operator shares: finite, non-negative output whatever the input,
//! problems counted in the report, parameters checked with clear errors.

use prism_post::{Image, ToneOperator, ToneParams};
use prism_spectrum::rgb_space::RgbColorSpace;

fn troubled_image() -> Image {
    let mut img = Image::new(
        4,
        2,
        vec![
            [f32::NAN, 1.0, 1.0],
            [f32::INFINITY, 0.0, 0.0],
            [1.0, f32::NEG_INFINITY, 2.0],
            [-1.0, 0.5, 0.5],
            [0.2, -0.1, 3.0],
            [0.0, 0.0, 0.0],
            [5.0, 5.0, 5.0],
            [1e4, 2e4, 3e3],
        ],
        RgbColorSpace::rec2020(),
    )
    .unwrap();
    img.cd_m2_per_unit = Some(10.0);
    img
}

#[test]
fn every_operator_outputs_finite_non_negative_values_and_counts_bad_input() {
    let img = troubled_image();
    for op in ToneOperator::ALL {
        for exposure_ev in [0.0, -5.0, 5.0] {
            let params = ToneParams {
                exposure_ev,
                ..Default::default()
            };
            let result = op.apply(&img, &params).unwrap();
            for p in result.image.pixels() {
                for c in p {
                    // AgX/ACES convert back from sRGB to Rec.2020 with a matrix; sRGB's
                    // gamut lies inside Rec.2020 so results stay ≥ 0 up to f32 rounding.
                    assert!(c.is_finite() && *c >= -1e-6, "{}: {p:?}", op.name());
                }
            }
            assert_eq!(result.report.non_finite_pixels, 3, "{}", op.name());
            assert_eq!(result.report.negative_pixels, 2, "{}", op.name());
            assert_eq!(
                result.image.pixels()[0],
                [0.0; 3],
                "{}: NaN → black",
                op.name()
            );
            assert_eq!(result.report.operator, op.name());
        }
    }
}

#[test]
fn black_and_single_pixel_images_are_handled() {
    for rgb in [[0.0f32; 3], [1.0; 3]] {
        let mut img = Image::filled(1, 1, rgb, RgbColorSpace::srgb()).unwrap();
        img.cd_m2_per_unit = Some(100.0);
        for op in ToneOperator::ALL {
            let out = op.apply(&img, &ToneParams::default()).unwrap();
            assert!(
                out.image.pixels()[0].iter().all(|c| c.is_finite()),
                "{}",
                op.name()
            );
        }
    }
}

#[test]
fn names_and_parameters_are_checked_with_helpful_errors() {
    for op in ToneOperator::ALL {
        assert_eq!(ToneOperator::from_name(op.name()).unwrap(), op);
        assert!(!op.info().reference.is_empty());
    }
    let err = ToneOperator::from_name("reinhard2")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("reinhard02") && err.contains("tumblin-rushmeier"),
        "{err}"
    );

    let img = troubled_image();
    let mut params = ToneParams::default();
    params.values.insert("keey".into(), 0.3);
    let err = ToneOperator::Reinhard02
        .apply(&img, &params)
        .unwrap_err()
        .to_string();
    assert!(err.contains("keey") && err.contains("key"), "{err}");
    params.values.clear();
    params.values.insert("key".into(), -1.0);
    let err = ToneOperator::Reinhard02
        .apply(&img, &params)
        .unwrap_err()
        .to_string();
    assert!(err.contains("key = -1"), "{err}");
    let params = ToneParams {
        exposure_ev: f64::NAN,
        ..Default::default()
    };
    assert!(ToneOperator::Linear.apply(&img, &params).is_err());
}

#[test]
fn absolute_operators_need_a_scale_and_accept_either_source() {
    let mut img = troubled_image();
    img.cd_m2_per_unit = None;
    for op in ToneOperator::ALL {
        let result = op.apply(&img, &ToneParams::default());
        assert_eq!(result.is_err(), op.info().absolute, "{}", op.name());
        let params = ToneParams {
            luminance_scale_cd_m2: Some(10.0),
            ..Default::default()
        };
        let with_param = op.apply(&img, &params).unwrap().image;
        img.cd_m2_per_unit = Some(10.0);
        let with_header = op.apply(&img, &ToneParams::default()).unwrap().image;
        img.cd_m2_per_unit = None;
        assert_eq!(with_param.pixels(), with_header.pixels(), "{}", op.name());
    }
}
