//! FLIP against NVIDIA's reference implementation (fixture: tests/fixtures/flip_reference.json,
//! written by tools/export_flip_fixture.py with flip-evaluator 1.7, which names the calls).
//! The image pairs are built here from the script's formula. Checks: LDR and HDR means
//! within 1 % relative, HDR's automatic exposure range equal, and both per-pixel maps
//! within 2 % (relative, or 1e-3 absolute near 0) on at least 99 % of pixels.

use prism_post::metrics::flip::{hdr_flip, ldr_flip, ExposureRange, FlipMap, DEFAULT_PPD};
use serde_json::Value;

const W: usize = 64;
const H: usize = 48;

fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^ (x >> 16)
}

fn noise(i: usize, seed: u32) -> f64 {
    let h = hash32((i as u32).wrapping_mul(0x9E37_79B9).wrapping_add(seed));
    f64::from(h >> 8) / f64::from(1u32 << 23) - 1.0
}

type Plane = Vec<[f64; 3]>;

fn scene(highlight: f64) -> Plane {
    let mut img = vec![[0.0; 3]; W * H];
    for y in 0..H {
        for x in 0..W {
            let (u, v) = (x as f64 / W as f64, y as f64 / H as f64);
            let mut c = [
                0.05 + 0.9 * u,
                0.05 + 0.9 * v,
                0.3 + 0.25 * (2.0 * std::f64::consts::PI * (u + v)).sin(),
            ];
            let mut gain = (4.0 * u - 1.0).exp2();
            if ((x / 8) + (y / 8)) % 2 == 0 {
                gain *= 0.3;
            }
            let (dx, dy) = (x as i64 - 48, y as i64 - 12);
            if dx * dx + dy * dy <= 16 {
                c = [highlight, 0.9 * highlight, 0.8 * highlight];
                gain = 1.0;
            }
            img[y * W + x] = c.map(|ch| ch * gain);
        }
    }
    img
}

fn noisy(img: &Plane, amount: f64, seed: u32) -> Plane {
    img.iter()
        .enumerate()
        .map(|(p, px)| [0, 1, 2].map(|c| px[c] * (1.0 + amount * noise(p * 3 + c, seed))))
        .collect()
}

fn map(img: &Plane, f: impl Fn(usize, [f64; 3]) -> [f64; 3]) -> Plane {
    img.iter().enumerate().map(|(i, p)| f(i, *p)).collect()
}

/// (name, test, reference) in the script's order.
fn pairs() -> Vec<(&'static str, Plane, Plane)> {
    let base = scene(50.0);
    let bright = scene(1000.0);
    let shifted = map(&base, |i, _| {
        let (x, y) = (i % W, i / W);
        base[y * W + (x + W - 1) % W]
    });
    vec![
        ("noise-5%", noisy(&base, 0.05, 1), base.clone()),
        ("noise-20%", noisy(&base, 0.2, 2), base.clone()),
        ("noise-60%", noisy(&base, 0.6, 3), base.clone()),
        (
            "tonemapped",
            map(&base, |_, p| p.map(|v| (0.5 * v).clamp(0.0, 1.0))),
            map(&base, |_, p| p.map(|v| v / (1.0 + v))),
        ),
        ("highlight", noisy(&scene(800.0), 0.1, 5), bright),
        ("shift-1px", shifted, base.clone()),
        (
            "colour-cast",
            map(&base, |_, p| [p[0] * 1.1, p[1], p[2] * 0.85]),
            base.clone(),
        ),
    ]
}

fn f32s(img: &Plane) -> Vec<[f32; 3]> {
    img.iter().map(|p| p.map(|v| v as f32)).collect()
}

/// The share of pixels where `ours` is within 2 % of the reference (or 1e-3 of it).
fn share_within(ours: &FlipMap, theirs: &[Value]) -> f64 {
    let close = ours
        .values
        .iter()
        .zip(theirs)
        .filter(|(a, b)| {
            let b = b.as_f64().unwrap();
            (f64::from(**a) - b).abs() <= (0.02 * b).max(1e-3)
        })
        .count();
    close as f64 / ours.values.len() as f64
}

#[test]
fn flip_matches_the_reference_implementation() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/fixtures/flip_reference.json"
    ))
    .unwrap();
    let fixture: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(fixture["tool"], "flip-evaluator 1.7");
    assert_eq!(fixture["width"], W);
    let expected = fixture["pairs"].as_array().unwrap();
    let ours = pairs();
    assert_eq!(expected.len(), ours.len());
    assert!(ours.len() >= 6);
    for (e, (name, test, reference)) in expected.iter().zip(&ours) {
        assert_eq!(e["name"], *name);
        // The reference's default viewing condition, as it reports it (f32).
        assert!((e["ppd"].as_f64().unwrap() - DEFAULT_PPD).abs() < 1e-5);
        let (t, r) = (f32s(test), f32s(reference));
        let ldr = ldr_flip(&t, &r, W, H, DEFAULT_PPD).unwrap();
        let hdr = hdr_flip(&t, &r, W, H, DEFAULT_PPD).unwrap();
        let rel = |ours: f64, key: &str| {
            let theirs = e[key].as_f64().unwrap();
            (ours - theirs).abs() / theirs
        };
        let (ldr_rel, hdr_rel) = (rel(ldr.mean(), "ldr_mean"), rel(hdr.map.mean(), "hdr_mean"));
        let ldr_share = share_within(&ldr, e["ldr_map"].as_array().unwrap());
        let hdr_share = share_within(&hdr.map, e["hdr_map"].as_array().unwrap());
        eprintln!(
            "{name:12} LDR {:.5} (rel {ldr_rel:.2e}, {:.2}% px within 2%)  HDR {:.5} (rel {hdr_rel:.2e}, {:.2}% px)",
            ldr.mean(),
            100.0 * ldr_share,
            hdr.map.mean(),
            100.0 * hdr_share
        );
        let ExposureRange {
            start_stops,
            stop_stops,
            count,
        } = hdr.exposures;
        assert!((start_stops - e["hdr_start_exposure"].as_f64().unwrap()).abs() < 1e-4);
        assert!((stop_stops - e["hdr_stop_exposure"].as_f64().unwrap()).abs() < 1e-4);
        assert_eq!(count as u64, e["hdr_num_exposures"].as_u64().unwrap());
        assert!(ldr_rel < 0.01, "{name}: LDR mean off by {ldr_rel}");
        assert!(hdr_rel < 0.01, "{name}: HDR mean off by {hdr_rel}");
        assert!(ldr_share >= 0.99, "{name}: LDR map {ldr_share}");
        assert!(hdr_share >= 0.99, "{name}: HDR map {hdr_share}");
    }
}
