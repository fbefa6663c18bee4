//! Prism's global operators against colour-hdri where both implement the same definition
//! (fixture: tests/fixtures/tonemap_colour_hdri.json, written by
//! tools/export_tonemap_fixtures.py with colour-hdri 0.2.5 / colour-science 0.4.7; each
//! case records its exact call).
//!
//! Matching exactly (same formula, same luminance):
//! - `tonemapping_operator_gamma(gamma=1, EV)` = `linear` with `--exposure EV`;
//! - `tonemapping_operator_logarithmic(q, k)` = `logarithmic` (q, k);
//! - `tonemapping_operator_exponential(q, k)` = `exponential` (q, k), except for the
//!   log-average's offset: colour-hdri adds ε = 2.2e-16, Prism δ = 1e-6 (Reinhard 2002);
//! - `tonemapping_operator_Schlick1994(p)` = `schlick94` with `--param p=…`.
//!
//! Not compared, and why:
//! - `Tumblin1999`: colour-hdri computes γ_wd with a natural log, 1.855 + 0.4 ln(L_da),
//!   where Tumblin et al. 1999 (and Prism) use log10; it also takes relative luminance,
//!   Prism's `tumblin-rushmeier` absolute cd/m²;
//! - `Reinhard2004` (Reinhard & Devlin 2005 photoreceptor model), `filmic` (Hable),
//!   `simple` (per-channel x/(1+x)), `normalisation`, `logarithmic_mapping`,
//!   `exponentiation_mapping`: no Prism operator with these definitions (Prism's
//!   `reinhard02` is the 2002 photographic operator, on luminance).

use prism_image::Image;
use prism_post::{ToneOperator, ToneParams};
use prism_spectrum::rgb_space::RgbColorSpace;
use serde_json::Value;

fn fixture() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/fixtures/tonemap_colour_hdri.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("fixture present")).unwrap()
}

fn pixels(v: &Value) -> Vec<[f32; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let c: Vec<f64> = serde_json::from_value(p.clone()).unwrap();
            [c[0] as f32, c[1] as f32, c[2] as f32]
        })
        .collect()
}

fn case<'a>(f: &'a Value, function: &str, key: &str, value: f64) -> &'a Value {
    f["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["function"] == function && c["kwargs"][key].as_f64() == Some(value))
        .unwrap_or_else(|| panic!("{function} {key}={value} in the fixture"))
}

/// f32 evaluation with the fast log/exp (≤ 1e-5 relative, as the operators' own formula
/// tests) plus the luminance weights' difference (checked ≤ 1e-6 below).
const F32_RELATIVE: f64 = 1e-5;

fn assert_matches(got: &Image, want: &[[f32; 3]], extra: f64, what: &str) {
    for (i, (g, w)) in got.pixels().iter().zip(want).enumerate() {
        for c in 0..3 {
            let (g, w) = (g[c] as f64, w[c] as f64);
            assert!(
                (g - w).abs() <= (F32_RELATIVE + extra) * w.abs() + 1e-7,
                "{what}: pixel {i} channel {c}: {g} vs colour-hdri {w}"
            );
        }
    }
}

#[test]
fn matching_global_operators_agree_with_colour_hdri() {
    let f = fixture();
    assert_eq!(f["provenance"]["colour_hdri"], "0.2.5");
    let input = pixels(&f["input"]);
    let img = Image::new(4, 3, input.clone(), RgbColorSpace::srgb()).unwrap();
    let weights: Vec<f64> = serde_json::from_value(f["luminance_weights"].clone()).unwrap();
    for (ours, theirs) in img.luminance_weights().iter().zip(&weights) {
        assert!((*ours as f64 - theirs).abs() <= 1e-6, "{ours} vs {theirs}");
    }
    let with = |pairs: &[(&str, f64)]| ToneParams {
        values: pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        ..Default::default()
    };

    // gamma = 1, EV = −2 ↔ linear at −2 EV: a power-of-two scale, exact in f32.
    let want = pixels(&case(&f, "tonemapping_operator_gamma", "gamma", 1.0)["output"]);
    let params = ToneParams {
        exposure_ev: -2.0,
        ..Default::default()
    };
    let got = ToneOperator::Linear.apply(&img, &params).unwrap().image;
    assert_eq!(got.pixels(), &want[..]);

    for (q, k) in [(1.0, 1.0), (4.0, 2.0)] {
        let c = case(&f, "tonemapping_operator_logarithmic", "q", q);
        assert_eq!(c["kwargs"]["k"].as_f64(), Some(k));
        let got = ToneOperator::Logarithmic
            .apply(&img, &with(&[("q", q), ("k", k)]))
            .unwrap()
            .image;
        assert_matches(
            &got,
            &pixels(&c["output"]),
            0.0,
            c["call"].as_str().unwrap(),
        );
    }

    // The log-average offsets differ (δ = 1e-6 vs 2.2e-16): ln L_avg moves by
    // mean(ln(1 + δ/L)) ≤ δ / L_min = 1e-6 / 0.125 = 8e-6, and L_d by at most as much
    // relatively (x e^{−x} / (1 − e^{−x}) ≤ 1).
    let l_min = 0.125;
    for (q, k) in [(1.0, 1.0), (2.0, 3.0)] {
        let c = case(&f, "tonemapping_operator_exponential", "q", q);
        let got = ToneOperator::Exponential
            .apply(&img, &with(&[("q", q), ("k", k)]))
            .unwrap()
            .image;
        assert_matches(
            &got,
            &pixels(&c["output"]),
            1e-6 / l_min,
            c["call"].as_str().unwrap(),
        );
    }

    for p in [1.0, 20.0] {
        let c = case(&f, "tonemapping_operator_Schlick1994", "p", p);
        let got = ToneOperator::Schlick94
            .apply(&img, &with(&[("p", p)]))
            .unwrap()
            .image;
        assert_matches(
            &got,
            &pixels(&c["output"]),
            0.0,
            c["call"].as_str().unwrap(),
        );
    }
}
