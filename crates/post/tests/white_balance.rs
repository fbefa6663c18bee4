//! White balance: a grey card rendered under CIE illuminant A becomes neutral relative to
//! D65 (|a*|, |b*| < 0.5), for every applicable method and adaptation transform.

use glam::DVec3;
use prism_post::colour::white_balance::{cct_white_xyz, daylight_locus_xy};
use prism_post::colour::{
    apply_white_balance, apply_with_source_white, estimate_source_white_xyz,
    illumination_white_xyz, PostColourError, WhiteBalance,
};
use prism_spectrum::colorimetry::{reflectance_to_xyz, xyz_to_lab, xyz_to_xy};
use prism_spectrum::data::{colorchecker_patch, illuminant};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::{AdaptationMethod, DenseSpectrum, Observer};

const GREY_CARD_REFLECTANCE: f64 = 0.18;
const NEUTRALITY_TOLERANCE_AB: f64 = 0.5;

/// Linear sRGB of a reflectance under CIE A by 1 nm spectral integration (CIE 15:2018
/// eqs. 7.1–7.3, Y of the perfect diffuser = 1), with no chromatic adaptation.
fn srgb_under_a(reflectance: &DenseSpectrum) -> [f32; 3] {
    let a = illuminant("A").unwrap().to_dense();
    let xyz = reflectance_to_xyz(reflectance, &a, Observer::Cie1931) / 100.0;
    let rgb = RgbColorSpace::srgb().xyz_to_rgb * xyz;
    [rgb.x as f32, rgb.y as f32, rgb.z as f32]
}

fn flat(reflectance: f64) -> [f32; 3] {
    srgb_under_a(&DenseSpectrum::constant(reflectance))
}

/// CIELAB of a linear sRGB pixel relative to the sRGB (D65) white.
fn lab_d65(p: [f32; 3]) -> DVec3 {
    let srgb = RgbColorSpace::srgb();
    let xyz = srgb.rgb_to_xyz * DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    xyz_to_lab(xyz, srgb.white_xyz())
}

/// Neutral patches under A; the grey card is at index 1.
fn neutral_scene() -> Vec<[f32; 3]> {
    [0.03, GREY_CARD_REFLECTANCE, 0.35, 0.6, 0.9]
        .iter()
        .flat_map(|&r| std::iter::repeat_n(flat(r), 20))
        .collect()
}

const ADAPTATIONS: [AdaptationMethod; 4] = [
    AdaptationMethod::Bradford,
    AdaptationMethod::Cat16,
    AdaptationMethod::Cat02,
    AdaptationMethod::VonKries,
];

#[test]
fn grey_card_under_a_becomes_neutral_for_every_method() {
    let before = lab_d65(flat(GREY_CARD_REFLECTANCE));
    assert!(
        before.y.hypot(before.z) > 20.0,
        "A is strongly yellow: {before}"
    );
    let methods = [
        WhiteBalance::GreyWorld,
        WhiteBalance::WhitePatchMax,
        WhiteBalance::WhitePatchPercentile(99.0),
        WhiteBalance::Illuminant("A".into()),
        WhiteBalance::Cct(2856.0),
    ];
    let srgb = RgbColorSpace::srgb();
    for method in &methods {
        for adaptation in ADAPTATIONS {
            let mut pixels = neutral_scene();
            let report = apply_white_balance(&mut pixels, &srgb, method, adaptation).unwrap();
            let lab = lab_d65(pixels[20]);
            assert!(
                lab.y.abs() < NEUTRALITY_TOLERANCE_AB && lab.z.abs() < NEUTRALITY_TOLERANCE_AB,
                "{method} / {adaptation}: grey card Lab {lab}"
            );
            // Only chromaticity is adapted: the grey card keeps its lightness.
            assert!(
                (lab.x - before.x).abs() < 1.0,
                "{method}: L* {} → {}",
                before.x,
                lab.x
            );
            let cct = report.source_cct.unwrap().cct_k;
            assert!((cct - 2856.0).abs() < 15.0, "{method}: scene CCT {cct}");
        }
    }
}

#[test]
fn white_patch_finds_the_white_card_among_colour_patches() {
    // 24 ColorChecker patches (2 pixels each), the grey card, and a white card (4 pixels):
    // grey world is biased by the colours, white patch is not.
    let mut pixels: Vec<[f32; 3]> = (0..24)
        .flat_map(|i| std::iter::repeat_n(srgb_under_a(&colorchecker_patch(i).to_dense()), 2))
        .collect();
    pixels.push(flat(GREY_CARD_REFLECTANCE));
    let grey_index = pixels.len() - 1;
    // A white card brighter than the chart's own (non-flat) white patch.
    pixels.extend(std::iter::repeat_n(flat(0.98), 4));
    let srgb = RgbColorSpace::srgb();
    for method in [
        WhiteBalance::WhitePatchMax,
        WhiteBalance::WhitePatchPercentile(95.0),
    ] {
        let mut p = pixels.clone();
        let report =
            apply_white_balance(&mut p, &srgb, &method, AdaptationMethod::Bradford).unwrap();
        let lab = lab_d65(p[grey_index]);
        assert!(
            lab.y.abs() < NEUTRALITY_TOLERANCE_AB && lab.z.abs() < NEUTRALITY_TOLERANCE_AB,
            "{method}: {lab}"
        );
        assert_eq!(report.pixels_used, 4, "{method}: only the white card");
    }
}

#[test]
fn none_leaves_pixels_bit_for_bit() {
    let mut pixels = neutral_scene();
    pixels.push([f32::NAN, -1.0, 7.5]);
    let before = pixels.clone();
    let report = apply_white_balance(
        &mut pixels,
        &RgbColorSpace::srgb(),
        &WhiteBalance::None,
        AdaptationMethod::Bradford,
    )
    .unwrap();
    assert!(pixels
        .iter()
        .zip(&before)
        .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)));
    assert_eq!(report.pixels_used, 0);
}

#[test]
fn estimates_ignore_non_finite_pixels_and_fail_cleanly_on_black_or_empty() {
    let srgb = RgbColorSpace::srgb();
    let mut pixels = neutral_scene();
    pixels.push([f32::INFINITY, 0.0, 0.0]);
    pixels.push([f32::NAN, 1.0, 1.0]);
    let report = apply_white_balance(
        &mut pixels,
        &srgb,
        &WhiteBalance::GreyWorld,
        AdaptationMethod::Cat16,
    )
    .unwrap();
    assert_eq!(report.pixels_used, 100);
    for method in [
        WhiteBalance::GreyWorld,
        WhiteBalance::WhitePatchMax,
        WhiteBalance::WhitePatchPercentile(50.0),
    ] {
        for image in [vec![], vec![[0.0f32; 3]; 10], vec![[f32::NAN; 3]; 3]] {
            let mut p = image.clone();
            let err = apply_white_balance(&mut p, &srgb, &method, AdaptationMethod::Bradford)
                .unwrap_err();
            assert!(matches!(err, PostColourError::NoSceneWhite { .. }), "{err}");
            assert_eq!(p.len(), image.len());
        }
    }
}

#[test]
fn parses_every_documented_form() {
    let cases: [(&str, WhiteBalance); 14] = [
        ("none", WhiteBalance::None),
        ("grey-world", WhiteBalance::GreyWorld),
        ("Gray-World", WhiteBalance::GreyWorld),
        ("white-patch", WhiteBalance::WhitePatchMax),
        ("white-patch:99", WhiteBalance::WhitePatchPercentile(99.0)),
        (
            "white-patch:99.5%",
            WhiteBalance::WhitePatchPercentile(99.5),
        ),
        ("illuminant:A", WhiteBalance::Illuminant("A".into())),
        ("illuminant:fl2", WhiteBalance::Illuminant("F2".into())),
        ("d50", WhiteBalance::Illuminant("D50".into())),
        ("LED-B3", WhiteBalance::Illuminant("LED-B3".into())),
        ("cct:3200", WhiteBalance::Cct(3200.0)),
        ("cct: 6504K", WhiteBalance::Cct(6504.0)),
        ("scene", WhiteBalance::Scene),
        ("Scene", WhiteBalance::Scene),
    ];
    for (text, expected) in cases {
        let parsed = WhiteBalance::parse(text).unwrap();
        assert_eq!(parsed, expected, "{text}");
        assert_eq!(WhiteBalance::parse(&parsed.name()).unwrap(), parsed);
    }
}

#[test]
fn rejects_bad_values_with_the_valid_forms_and_a_suggestion() {
    let message = |s: &str| WhiteBalance::parse(s).unwrap_err().to_string();
    let m = message("grey-wrld");
    assert!(
        m.contains("`grey-world`") && m.contains("white-patch:<percentile"),
        "{m}"
    );
    assert!(message("illuminant:D66").contains("`D65`"));
    assert!(message("whte-patch:99").contains("`white-patch`"));
    assert!(message("D66").contains("`D65`"));
    for bad in [
        "white-patch:0",
        "white-patch:101",
        "white-patch:x",
        "cct:500",
        "cct:30000",
        "cct:nan",
        "cct:",
        "",
    ] {
        assert!(WhiteBalance::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn cct_whites_follow_planckian_then_daylight_locus() {
    // colour-science 0.4.7 `colour.temperature.CCT_to_xy_CIE_D(5000.0)` and (10000.0).
    let d5000 = daylight_locus_xy(5000.0).unwrap();
    assert!((d5000.x - 0.345_741).abs() < 1e-6 && (d5000.y - 0.358_666_15).abs() < 1e-6);
    let d10000 = daylight_locus_xy(10_000.0).unwrap();
    assert!((d10000.x - 0.278_799_6).abs() < 1e-6 && (d10000.y - 0.291_967_2).abs() < 1e-6);
    // cct:6504 ≈ D65 (0.3127, 0.3290); cct:2856 ≈ A (0.44757, 0.40745), CIE 15:2018 Table 1.
    let d65 = xyz_to_xy(cct_white_xyz(6504.0).unwrap()).unwrap();
    assert!(
        (d65.x - 0.3127).abs() < 2e-4 && (d65.y - 0.3290).abs() < 2e-4,
        "{d65}"
    );
    let a = xyz_to_xy(cct_white_xyz(2856.0).unwrap()).unwrap();
    assert!(
        (a.x - 0.44757).abs() < 3e-4 && (a.y - 0.40745).abs() < 3e-4,
        "{a}"
    );
    assert!(cct_white_xyz(999.0).is_none() && cct_white_xyz(25_001.0).is_none());
    assert!(cct_white_xyz(f64::NAN).is_none());
}

#[test]
fn scene_white_from_an_illumination_layer_of_a_makes_the_grey_card_neutral() {
    // The illumination layer holds the XYZ of a white diffuser under A at each pixel, at
    // varying levels (a falloff) and with some misses (0); the pixels are neutral patches
    // under A.
    let a = illuminant("A").unwrap().to_dense();
    let white = reflectance_to_xyz(&DenseSpectrum::constant(1.0), &a, Observer::Cie1931) / 100.0;
    let layer: Vec<[f32; 3]> = (0..100)
        .map(|i| {
            if i % 10 == 0 {
                [0.0; 3]
            } else {
                (white * (0.2 + 0.01 * i as f64)).as_vec3().to_array()
            }
        })
        .collect();
    let scene = illumination_white_xyz(&layer).unwrap();
    assert_eq!(scene.pixels_used, 90);
    let xy = xyz_to_xy(scene.xyz).unwrap();
    // CIE 15:2018 Table 1: A is (0.44757, 0.40745).
    assert!(
        (xy.x - 0.44757).abs() < 5e-5 && (xy.y - 0.40745).abs() < 5e-5,
        "{xy}"
    );
    let srgb = RgbColorSpace::srgb();
    for adaptation in ADAPTATIONS {
        let mut pixels = neutral_scene();
        let report =
            apply_with_source_white(&mut pixels, &srgb, &WhiteBalance::Scene, scene, adaptation);
        assert_eq!(report.method, "scene");
        let lab = lab_d65(pixels[20]);
        assert!(
            lab.y.abs() < NEUTRALITY_TOLERANCE_AB && lab.z.abs() < NEUTRALITY_TOLERANCE_AB,
            "{adaptation}: grey card Lab {lab}"
        );
    }
    // The pixel-based entry points cannot see layers and say so.
    let e = estimate_source_white_xyz(&neutral_scene(), &srgb, &WhiteBalance::Scene)
        .unwrap_err()
        .to_string();
    assert!(e.contains("illumination layer"), "{e}");
}
