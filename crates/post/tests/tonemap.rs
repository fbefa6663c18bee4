//! Properties every tone operator shares: finite, non-negative output whatever the input,
//! problems counted in the report, parameters checked with clear errors.

use prism_image::Image;
use prism_post::{ToneOperator, ToneParams};
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

/// `apply_in_place` (what `prism tonemap` runs, so that input and output are never held
/// together) gives `apply`'s image and report bit for bit, for every operator, on a
/// 300×200 image larger than one mapping chunk with troubled pixels among smooth ones.
#[test]
fn every_operator_maps_in_place_to_the_same_bits() {
    let (w, h) = (300usize, 200usize);
    let troubled = troubled_image();
    let pixels: Vec<[f32; 3]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            if i % 997 < 8 {
                return troubled.pixels()[i % 997];
            }
            let l = 10f32.powf(-2.0 + 5.0 * x / w as f32) * (1.0 + 0.5 * (y * 0.3).sin());
            [l, 0.7 * l * (1.0 + 0.2 * (x * 0.1).cos()), 0.4 * l]
        })
        .collect();
    let mut img = Image::new(w, h, pixels, RgbColorSpace::rec2020()).unwrap();
    img.cd_m2_per_unit = Some(10.0);
    for op in ToneOperator::ALL {
        let params = ToneParams::default();
        let borrowed = op.apply(&img, &params).unwrap();
        let in_place = op.apply_in_place(img.clone(), &params).unwrap();
        let bits =
            |i: &Image| -> Vec<u32> { i.pixels().iter().flatten().map(|c| c.to_bits()).collect() };
        assert!(
            bits(&borrowed.image) == bits(&in_place.image),
            "{}",
            op.name()
        );
        assert_eq!(borrowed.report, in_place.report, "{}", op.name());
        assert_eq!(
            borrowed.image.metadata,
            in_place.image.metadata,
            "{}",
            op.name()
        );
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

#[test]
fn tonemap_file_writes_png_and_exr_and_compare_files_reads_them_back() {
    use prism_image::io;
    use prism_post::{compare_files, tonemap_file, TonemapOptions};
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("prism-post-pipeline");
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("in.exr");
    let pixels = (0..64 * 48)
        .map(|i| {
            let v = 10f32.powf(-2.0 + 4.0 * (i % 64) as f32 / 63.0);
            [v, 0.8 * v, 0.6 * v]
        })
        .collect();
    io::write_image(
        &input,
        &Image::new(64, 48, pixels, RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    let options = TonemapOptions {
        operator: ToneOperator::Reinhard02.into(),
        ..Default::default()
    };
    let exr_out = dir.join("out.exr");
    let png_out = dir.join("out.png");
    let report = tonemap_file(&input, &exr_out, &options).unwrap();
    assert_eq!((report.width, report.height), (64, 48));
    assert!(serde_json::to_string(&report)
        .unwrap()
        .contains("\"operator\":\"reinhard02\""));
    tonemap_file(&input, &png_out, &options).unwrap();
    let exr = io::read_image(&exr_out).unwrap();
    assert!(exr
        .pixels()
        .iter()
        .flatten()
        .all(|c| (0.0..=1.0).contains(c)));
    // The 16-bit PNG holds the same display values to within one code step (decoded).
    let c = compare_files(&png_out, &exr_out).unwrap();
    assert!(c.rmse < 1e-4, "{c:?}");
    let json = serde_json::to_value(&c).unwrap();
    for key in [
        "mse",
        "rmse",
        "relmse",
        "psnr_db",
        "ssim",
        "delta_e2000_mean",
        "delta_e2000_p95",
    ] {
        assert!(json.get(key).is_some(), "{key}");
    }
    assert!(json["per_channel"]["mse"].is_array());
    // Mismatched sizes name both files.
    let small = dir.join("small.exr");
    io::write_image(
        &small,
        &Image::filled(2, 2, [1.0; 3], RgbColorSpace::srgb()).unwrap(),
    )
    .unwrap();
    let err = compare_files(&small, &exr_out).unwrap_err().to_string();
    assert!(
        err.contains("small.exr") && err.contains("out.exr"),
        "{err}"
    );
}

#[test]
fn tonemap_file_runs_exposure_white_balance_operator_gamut_and_the_contact_sheet() {
    use prism_image::io;
    use prism_post::colour::{GamutMethod, GamutTarget, WhiteBalance};
    use prism_post::{tonemap_file, OperatorChoice, TonemapOptions};
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("prism-post-sheet");
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("in.exr");
    let (w, h) = (96, 54);
    let pixels = (0..w * h)
        .map(|i| {
            let v = 10f32.powf(-2.0 + 4.0 * (i % w) as f32 / (w - 1) as f32);
            [v, 0.8 * v, 0.3 * v]
        })
        .collect();
    let mut img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
    img.pixels_mut()[0] = [f32::NAN, 1.0, 1.0];
    io::write_image(&input, &img).unwrap();

    // Linear operator, exposure −3 EV: EXR holds clip(2^−3 · x) (same space, clip).
    let exr_out = dir.join("linear.exr");
    let options = TonemapOptions {
        operator: OperatorChoice::parse("linear").unwrap(),
        exposure_ev: -3.0,
        ..Default::default()
    };
    let report = tonemap_file(&input, &exr_out, &options).unwrap();
    let out = io::read_image(&exr_out).unwrap();
    for (o, i) in out.pixels().iter().zip(img.pixels()).skip(1) {
        for c in 0..3 {
            assert!((o[c] - (i[c] / 8.0).clamp(0.0, 1.0)).abs() <= 1e-6 * i[c].max(1.0));
        }
    }
    assert_eq!(report.non_finite_pixels, 1);
    assert!(report.gamut_fraction_outside > 0.1 && report.gamut_fraction_outside < 0.9);

    // Grey world, P3 target, local gamut mapping, the contact sheet of every operator.
    let sheet_out = dir.join("sheet.png");
    let options = TonemapOptions {
        operator: OperatorChoice::parse("ALL").unwrap(),
        wb: WhiteBalance::parse("grey-world").unwrap(),
        gamut: GamutMethod::parse("local-lch").unwrap(),
        target: GamutTarget::parse("p3").unwrap(),
        luminance_scale_cd_m2: Some(100.0),
        ..Default::default()
    };
    let report = tonemap_file(&input, &sheet_out, &options).unwrap();
    assert_eq!(report.tone.len(), ToneOperator::ALL.len());
    assert!(report.failures.is_empty());
    assert!(report.white_balance_source_xy.is_some());
    let json = serde_json::to_string(&report).unwrap();
    for key in [
        "\"operator\":\"all\"",
        "\"target\":\"p3\"",
        "timings",
        "tone_ms",
    ] {
        assert!(json.contains(key), "{key} in {json}");
    }
    let sheet = io::read_image(&sheet_out).unwrap();
    assert_eq!(
        (sheet.width(), sheet.height()),
        (report.width, report.height)
    );
    assert!(sheet.width() > 4 * w);
    // Unknown names fail with the list of valid ones.
    let err = OperatorChoice::parse("reinhard03").unwrap_err().to_string();
    assert!(
        err.contains("reinhard02-local") && err.contains("durand02"),
        "{err}"
    );
}
