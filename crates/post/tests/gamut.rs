//! Gamut mapping: every output inside the target cube, local methods leave in-gamut pixels
//! bit-for-bit and keep hue, the global method preserves the ordering of chroma, ACES RGC
//! follows the published formula, and the outside fraction is reported correctly.

use glam::DVec3;
use prism_image::rgb_matrix::rgb_to_rgb_matrix;
use prism_post::colour::aces_rgc::{aces_rgc_acescg, AcesRgcParameters};
use prism_post::colour::cielab_lch::{hue_difference_deg, lab_to_lch_deg, CielabConverter};
use prism_post::colour::gamut::is_inside_unit_cube;
use prism_post::colour::oklab::OklabConverter;
use prism_post::colour::{map_gamut, GamutMethod, GamutTarget};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::AdaptationMethod;

const ALL_METHODS: [GamutMethod; 5] = [
    GamutMethod::Clip,
    GamutMethod::LocalLch,
    GamutMethod::LocalOklab,
    GamutMethod::GlobalChroma,
    GamutMethod::AcesRgc,
];
const ALL_TARGETS: [GamutTarget; 3] = [
    GamutTarget::Srgb,
    GamutTarget::DisplayP3,
    GamutTarget::Rec2020,
];

/// Deterministic xorshift64* in [0, 1).
struct Rng(u64);
impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
}

/// Random linear RGB, most in [0, 1], some beyond (negative, > 1 and HDR).
fn random_pixels(n: usize, seed: u64, lo: f32, hi: f32) -> Vec<[f32; 3]> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| [rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi)])
        .collect()
}

fn to_d(p: [f32; 3]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// `pixels` converted to `target` exactly as map_gamut converts them (f64 matrix, f32 out).
fn converted(pixels: &[[f32; 3]], source: &RgbColorSpace, target: &RgbColorSpace) -> Vec<[f32; 3]> {
    let m = rgb_to_rgb_matrix(source, target, AdaptationMethod::Bradford);
    pixels
        .iter()
        .map(|&p| {
            let v = m * to_d(p);
            [v.x as f32, v.y as f32, v.z as f32]
        })
        .collect()
}

#[test]
fn every_output_is_inside_every_target_for_every_method() {
    let mut pixels = random_pixels(20_000, 7, -0.4, 1.6);
    pixels.extend([
        [f32::NAN, 0.5, 0.5],
        [f32::INFINITY, -f32::INFINITY, 0.2],
        [40.0, 20.0, 10.0],
        [-3.0, -2.0, -1.0],
        [0.0; 3],
        [1.0; 3],
    ]);
    for source in [
        RgbColorSpace::rec2020(),
        RgbColorSpace::acescg(),
        RgbColorSpace::srgb(),
    ] {
        for target in ALL_TARGETS {
            for method in ALL_METHODS {
                let mut p = pixels.clone();
                let report = map_gamut(&mut p, &source, target, method);
                assert_eq!(report.pixel_count, pixels.len());
                assert!(report.pixels_outside > 0);
                for (i, q) in p.iter().enumerate() {
                    assert!(
                        q.iter().all(|c| (-1e-6..=1.0 + 1e-6).contains(c)),
                        "{} → {target} {method}: pixel {i} {q:?}",
                        source.name
                    );
                }
            }
        }
    }
}

#[test]
fn fraction_outside_is_counted_exactly() {
    let srgb = RgbColorSpace::srgb();
    let pixels = vec![
        [0.2, 0.3, 0.4],      // inside
        [0.0, 1.0, 0.5],      // inside (on the boundary)
        [1.0001, 0.5, 0.5],   // outside
        [0.5, -1e-6, 0.5],    // outside
        [f32::NAN, 0.5, 0.5], // outside
        [0.9, 0.9, 0.9],      // inside
        [2.0, 2.0, 2.0],      // outside (brighter than white)
        [0.1, 0.1, 0.1],      // inside
    ];
    for method in ALL_METHODS {
        let mut p = pixels.clone();
        let report = map_gamut(&mut p, &srgb, GamutTarget::Srgb, method);
        assert_eq!(report.pixels_outside, 4, "{method}");
        assert_eq!(report.fraction_outside, 0.5, "{method}");
    }
    let mut empty: Vec<[f32; 3]> = vec![];
    let report = map_gamut(
        &mut empty,
        &srgb,
        GamutTarget::Srgb,
        GamutMethod::GlobalChroma,
    );
    assert_eq!((report.pixels_outside, report.fraction_outside), (0, 0.0));
    // Rec.2020 green is outside sRGB; its white is not.
    let mut p = vec![[0.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
    let report = map_gamut(
        &mut p,
        &RgbColorSpace::rec2020(),
        GamutTarget::Srgb,
        GamutMethod::Clip,
    );
    assert_eq!(report.pixels_outside, 1);
}

#[test]
fn clip_clips_each_channel_and_leaves_inside_pixels() {
    let srgb = RgbColorSpace::srgb();
    let mut p = vec![
        [1.5, -0.25, 0.5],
        [0.25, 0.5, 0.75],
        [f32::NAN, f32::INFINITY, -f32::INFINITY],
    ];
    map_gamut(&mut p, &srgb, GamutTarget::Srgb, GamutMethod::Clip);
    assert_eq!(p, vec![[1.0, 0.0, 0.5], [0.25, 0.5, 0.75], [0.0, 1.0, 0.0]]);
}

/// Local methods: in-gamut pixels bit-for-bit, outside pixels keep lightness and hue
/// (LCh for local-lch, Oklab for local-oklab).
#[test]
fn local_methods_leave_inside_pixels_and_keep_lightness_and_hue() {
    let srgb = RgbColorSpace::srgb();
    // Rec.2020 colours in [0, 1]: all have lightness within [0, 100], many are outside sRGB.
    let source = RgbColorSpace::rec2020();
    let pixels = random_pixels(20_000, 11, 0.0, 1.0);
    let in_srgb = converted(&pixels, &source, &srgb);
    let lab = CielabConverter::new(&srgb);
    let oklab = OklabConverter::new(&srgb);
    for method in [GamutMethod::LocalLch, GamutMethod::LocalOklab] {
        let mut p = pixels.clone();
        let report = map_gamut(&mut p, &source, GamutTarget::Srgb, method);
        assert!(report.fraction_outside > 0.2, "{report:?}");
        let mut checked = 0;
        for (before, after) in in_srgb.iter().zip(&p) {
            if is_inside_unit_cube(*before) {
                assert_eq!(
                    before.map(f32::to_bits),
                    after.map(f32::to_bits),
                    "{method}"
                );
                continue;
            }
            let (b, a) = match method {
                GamutMethod::LocalLch => {
                    (lab.rgb_to_lab(to_d(*before)), lab.rgb_to_lab(to_d(*after)))
                }
                _ => (
                    oklab.rgb_to_oklab(to_d(*before)),
                    oklab.rgb_to_oklab(to_d(*after)),
                ),
            };
            let (b, a) = (lab_to_lch_deg(b), lab_to_lch_deg(a));
            let l_scale = if method == GamutMethod::LocalLch {
                100.0
            } else {
                1.0
            };
            assert!(
                (a.x - b.x).abs() < 1e-3 * l_scale,
                "{method}: L {} → {}",
                b.x,
                a.x
            );
            assert!(a.y <= b.y + 1e-6 * l_scale, "{method}: chroma grew");
            // Hue is meaningless for (near-)neutral results.
            if a.y > 0.01 * l_scale {
                let dh = hue_difference_deg(a.z, b.z);
                assert!(dh < 1.0, "{method}: hue {} → {} ({dh}°)", b.z, a.z);
                checked += 1;
            }
        }
        assert!(checked > 1000, "{method}: {checked}");
    }
}

#[test]
fn local_lch_moves_to_the_boundary_not_inside_it() {
    // Rec.2020 pure green in sRGB: the result must touch the cube (a channel at 0 or 1).
    let mut p = vec![[0.0, 0.6, 0.0]];
    map_gamut(
        &mut p,
        &RgbColorSpace::rec2020(),
        GamutTarget::Srgb,
        GamutMethod::LocalLch,
    );
    let touches = p[0].iter().any(|&c| !(1e-3..=1.0 - 1e-3).contains(&c));
    assert!(touches, "{:?}", p[0]);
}

#[test]
fn out_of_range_lightness_is_clipped_first() {
    let srgb = RgbColorSpace::srgb();
    let mut p = vec![[3.0, 2.0, 2.0], [-0.5, -0.1, -0.2]];
    for method in [GamutMethod::LocalLch, GamutMethod::LocalOklab] {
        let mut q = p.clone();
        map_gamut(&mut q, &srgb, GamutTarget::Srgb, method);
        for c in q[0] {
            assert!((c - 1.0).abs() < 1e-4, "{method}: {:?}", q[0]);
        }
        for c in q[1] {
            assert!(c.abs() < 1e-4, "{method}: {:?}", q[1]);
        }
    }
    map_gamut(&mut p, &srgb, GamutTarget::Srgb, GamutMethod::GlobalChroma);
    assert!(p[0].iter().all(|&c| (c - 1.0).abs() < 1e-4));
}

/// Global: one chroma factor; the ordering of chroma (and chroma ratios) is preserved and
/// hue and lightness are kept, on random sets.
#[test]
fn global_preserves_chroma_ordering_on_random_sets() {
    let srgb = RgbColorSpace::srgb();
    let lab = CielabConverter::new(&srgb);
    for (seed, source) in [
        (3, RgbColorSpace::rec2020()),
        (5, RgbColorSpace::display_p3()),
        (9, RgbColorSpace::acescg()),
    ] {
        let pixels = random_pixels(5000, seed, 0.02, 0.95);
        let before: Vec<DVec3> = converted(&pixels, &source, &srgb)
            .iter()
            .map(|&p| lab_to_lch_deg(lab.rgb_to_lab(to_d(p))))
            .collect();
        let mut p = pixels.clone();
        let report = map_gamut(
            &mut p,
            &source,
            GamutTarget::Srgb,
            GamutMethod::GlobalChroma,
        );
        let k = report.chroma_scale;
        assert!(
            report.pixels_outside > 0 && k < 1.0 && k > 0.0,
            "{report:?}"
        );
        let after: Vec<DVec3> = p
            .iter()
            .map(|&q| lab_to_lch_deg(lab.rgb_to_lab(to_d(q))))
            .collect();
        let mut order: Vec<usize> = (0..p.len()).collect();
        order.sort_by(|&i, &j| before[i].y.total_cmp(&before[j].y));
        for w in order.windows(2) {
            let (i, j) = (w[0], w[1]);
            assert!(
                after[i].y <= after[j].y + 1e-3,
                "{}: chroma order broken: {} < {} but {} > {}",
                source.name,
                before[i].y,
                before[j].y,
                after[i].y,
                after[j].y
            );
        }
        for (b, a) in before.iter().zip(&after) {
            assert!(
                (a.y - k * b.y).abs() < 2e-3,
                "C {} → {} (k = {k})",
                b.y,
                a.y
            );
            assert!((a.x - b.x).abs() < 2e-3, "L {} → {}", b.x, a.x);
            if a.y > 1.0 {
                assert!(hue_difference_deg(a.z, b.z) < 1.0);
            }
        }
    }
}

#[test]
fn global_leaves_an_in_gamut_image_untouched() {
    let pixels = random_pixels(5000, 13, 0.0, 1.0);
    let mut p = pixels.clone();
    let report = map_gamut(
        &mut p,
        &RgbColorSpace::srgb(),
        GamutTarget::Srgb,
        GamutMethod::GlobalChroma,
    );
    assert_eq!((report.pixels_outside, report.chroma_scale), (0, 1.0));
    assert_eq!(p, pixels);
}

/// map_gamut's ACES RGC equals the published formula in ACEScg, converted to the target
/// and clipped; the formula itself is checked against hand-computed values in aces_rgc.rs.
#[test]
fn aces_rgc_matches_the_published_formula() {
    let acescg = RgbColorSpace::acescg();
    let srgb = RgbColorSpace::srgb();
    let pixels = vec![
        [0.5, 1.0, -0.2],
        [-0.1, 0.2, 0.4],
        [0.18, 0.18, 0.18],
        [0.9, 0.05, 0.02],
    ];
    let mut p = pixels.clone();
    map_gamut(&mut p, &acescg, GamutTarget::Srgb, GamutMethod::AcesRgc);
    let to_srgb = rgb_to_rgb_matrix(&acescg, &srgb, AdaptationMethod::Bradford);
    for (input, output) in pixels.iter().zip(&p) {
        let expected = to_srgb * aces_rgc_acescg(to_d(*input), &AcesRgcParameters::REFERENCE);
        let expected = expected.clamp(DVec3::ZERO, DVec3::ONE);
        assert!(
            to_d(*output).abs_diff_eq(expected, 1e-6),
            "{input:?}: {output:?} vs {expected}"
        );
    }
    // A neutral stays neutral (ACES white → D65 white by Bradford).
    assert!((p[2][0] - p[2][1]).abs() < 1e-6 && (p[2][1] - p[2][2]).abs() < 1e-6);
}

#[test]
fn targets_and_methods_parse_with_suggestions() {
    assert_eq!(GamutTarget::parse("P3").unwrap(), GamutTarget::DisplayP3);
    assert_eq!(GamutTarget::parse("rec2020").unwrap(), GamutTarget::Rec2020);
    assert_eq!(GamutTarget::parse("srgb").unwrap(), GamutTarget::Srgb);
    assert!(GamutTarget::parse("rec2021")
        .unwrap_err()
        .to_string()
        .contains("`rec2020`"));
    for m in ALL_METHODS {
        assert_eq!(GamutMethod::parse(m.name()).unwrap(), m);
    }
    assert_eq!(
        GamutMethod::parse("global-chroma").unwrap(),
        GamutMethod::GlobalChroma
    );
    let e = GamutMethod::parse("local-okla").unwrap_err().to_string();
    assert!(e.contains("`local-oklab`") && e.contains("aces-rgc"), "{e}");
    for t in ALL_TARGETS {
        assert_eq!(GamutTarget::parse(t.name()).unwrap(), t);
    }
}
