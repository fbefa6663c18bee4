//! End-to-end checks of `prism color` against colour-science (tests/fixtures/color_cli.json,
//! made by tools/export_color_cli_fixture.py) and of its error messages.

use std::path::{Path, PathBuf};

use serde_json::Value;

mod support;
use support::prism;

fn fixture(name: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs `prism` with `args`, which must succeed, and parses its JSON output.
fn json_of(args: &[&str]) -> Value {
    let out = prism(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn assert_close(what: &str, ours: &[f64], expected: &[f64], tol: impl Fn(f64) -> f64) {
    assert_eq!(ours.len(), expected.len(), "{what}");
    for (o, e) in ours.iter().zip(expected) {
        assert!(
            (o - e).abs() <= tol(*e),
            "{what}: ours {ours:?}, fixture {expected:?}"
        );
    }
}

#[test]
fn color_json_matches_colour_science() {
    let fixture = fixture("color_cli.json");
    let cases = fixture["cases"].as_array().unwrap();
    assert!(cases.len() >= 10);
    for case in cases {
        let mut args: Vec<&str> = vec!["color", "--json"];
        args.extend(
            case["args"]
                .as_array()
                .unwrap()
                .iter()
                .map(|a| a.as_str().unwrap()),
        );
        let ours = json_of(&args);
        let want = &case["expected"];
        let what = |key: &str| format!("{args:?} {key}");
        // Issue contract: XYZ to 1e-6 relative; CCT to 0.5 K.
        assert_close(
            &what("XYZ"),
            &floats(&ours["XYZ"]),
            &floats(&want["XYZ"]),
            |e| 1e-6 * e.abs(),
        );
        assert_close(
            &what("xy"),
            &floats(&ours["xy"]),
            &floats(&want["xy"]),
            |_| 1e-8,
        );
        assert_close(
            &what("CCT_K"),
            &[ours["CCT_K"].as_f64().unwrap()],
            &[want["CCT_K"].as_f64().unwrap()],
            |_| 0.5,
        );
        assert_close(
            &what("Duv"),
            &[ours["Duv"].as_f64().unwrap()],
            &[want["Duv"].as_f64().unwrap()],
            |_| 1e-5,
        );
        if want["Lab"].is_null() {
            assert!(ours["Lab"].is_null(), "{}", what("Lab"));
        } else {
            assert_close(
                &what("Lab"),
                &floats(&ours["Lab"]),
                &floats(&want["Lab"]),
                |_| 1e-6,
            );
        }
        // sRGB values of emission are absolute (hundreds of cd/m²): relative tolerance.
        let rgb_tol = |e: f64| 1e-7 * e.abs().max(1.0);
        assert_close(
            &what("linear_sRGB"),
            &floats(&ours["linear_sRGB"]),
            &floats(&want["linear_sRGB"]),
            rgb_tol,
        );
        assert_close(
            &what("sRGB"),
            &floats(&ours["sRGB"]),
            &floats(&want["sRGB"]),
            rgb_tol,
        );
    }
}

#[test]
fn color_without_json_prints_a_table() {
    let out = prism(&[
        "color",
        "--spectrum",
        "colorchecker:dark skin",
        "--illuminant",
        "D65",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for label in ["XYZ (Y=100)", "xy", "CCT", "L*a*b*", "sRGB"] {
        assert!(text.contains(label), "{text}");
    }
}

/// A file in its own temporary folder, removed with it.
struct TempFile {
    _dir: tempfile::TempDir,
    path: PathBuf,
}

impl TempFile {
    fn new(name: &str, text: &str) -> Self {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        Self { _dir: dir, path }
    }
    fn arg(&self) -> &str {
        self.path.to_str().unwrap()
    }
}

#[test]
fn large_values_stay_in_columns_and_ccts_out_of_range_are_flagged() {
    // A 10⁶ K blackbody: huge XYZ, a CCT far beyond Ohno 2013's table.
    let out = prism(&["color", "--spectrum", "blackbody:1000000"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for line in text
        .lines()
        .filter(|l| l.starts_with("XYZ") || l.starts_with("linear"))
    {
        let fields: Vec<&str> = line[13..].split_whitespace().collect();
        assert_eq!(fields.len(), 3, "numbers ran together: {line}");
        for f in fields {
            assert!(f.parse::<f64>().is_ok(), "{f} in {line}");
        }
    }
    assert!(text.contains("outside the method's valid range"), "{text}");
    let v = json_of(&["color", "--spectrum", "blackbody:500", "--json"]);
    assert_eq!(v["CCT_in_valid_range"], false, "{v}");
    let v = json_of(&["color", "--spectrum", "blackbody:6500", "--json"]);
    assert_eq!(v["CCT_in_valid_range"], true, "{v}");
    // A reflectance without an illuminant is treated as radiance, with a warning.
    let out = prism(&["color", "--spectrum", "colorchecker:dark skin"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("is a reflectance but no --illuminant"),
        "{err}"
    );
}

fn expect_error(args: &[&str], needles: &[&str]) {
    let out = prism(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: `{needle}` not in: {err}");
    }
}

#[test]
fn bad_input_names_the_file_the_line_and_what_was_expected() {
    expect_error(
        &["color", "--spectrum", "no/such/file.csv"],
        &["no/such/file.csv", "no such file"],
    );
    let malformed = TempFile::new("malformed.csv", "400,0.5\n410;0.6\n");
    expect_error(
        &["color", "--spectrum", malformed.arg()],
        &[&format!("{}:2:", malformed.arg()), "expected"],
    );
    let decreasing = TempFile::new("decreasing.csv", "# test\n500,1\n490,1\n");
    expect_error(
        &["color", "--spectrum", decreasing.arg()],
        &[&format!("{}:3:", decreasing.arg()), "increase strictly"],
    );
    let nan = TempFile::new("nan.csv", "400,1\n410,nan\n");
    expect_error(
        &["color", "--spectrum", nan.arg()],
        &[&format!("{}:2:", nan.arg()), "finite"],
    );
    let negative = TempFile::new("negative.csv", "wavelength_nm,value\n400,1\n410,-0.5\n");
    expect_error(
        &["color", "--spectrum", negative.arg()],
        &[&format!("{}:3:", negative.arg()), "non-negative"],
    );
    // A negative reflectance is data, not an error (colour-science accepts it too): it is
    // integrated as given, so every tristimulus value lies below that of the same file
    // with 0 in its place (x̄, ȳ, z̄ > 0 at 400–410 nm) …
    let xyz_of = |file: &TempFile| -> Vec<f64> {
        let out = prism(&[
            "color",
            "--spectrum",
            file.arg(),
            "--illuminant",
            "D65",
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}: {}",
            file.arg(),
            String::from_utf8_lossy(&out.stderr)
        );
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        floats(&v["XYZ"])
    };
    let clipped = TempFile::new("clipped.csv", "wavelength_nm,value\n400,1\n410,0\n");
    let (with_negative, with_zero) = (xyz_of(&negative), xyz_of(&clipped));
    assert_eq!(with_negative.len(), 3);
    assert!(
        with_negative
            .iter()
            .zip(&with_zero)
            .all(|(n, z)| n.is_finite() && n < z),
        "XYZ with −0.5 {with_negative:?}, with 0 {with_zero:?}"
    );
    // … but a negative illuminant is.
    expect_error(
        &[
            "color",
            "--spectrum",
            "colorchecker:red",
            "--illuminant",
            negative.arg(),
        ],
        &[&format!("{}:3:", negative.arg()), "non-negative"],
    );
}

#[test]
fn unknown_names_suggest_the_closest_known_ones() {
    expect_error(
        &["color", "--spectrum", "D66"],
        &["D66", "did you mean", "`D65`"],
    );
    expect_error(
        &[
            "color",
            "--spectrum",
            "colorchecker:dark skn",
            "--illuminant",
            "D65",
        ],
        &["dark skn", "`dark skin`"],
    );
    expect_error(
        &[
            "color",
            "--spectrum",
            "colorchecker:red",
            "--illuminant",
            "LED-B9",
        ],
        &["LED-B9", "did you mean"],
    );
    expect_error(
        &["color", "--spectrum", "D65", "--observer", "cie1965"],
        &["cie1965", "cie1964"],
    );
    expect_error(
        &["color", "--spectrum", "cie1931-2deg"],
        &["spectra/cie1931-2deg.csv", "3 columns"],
    );
}

#[test]
fn names_and_aliases_resolve_to_the_same_spectrum() {
    let a = prism(&["color", "--spectrum", "F2", "--json"]);
    let b = prism(&["color", "--spectrum", "fl2", "--json"]);
    assert!(a.status.success() && b.status.success());
    let a: Value = serde_json::from_slice(&a.stdout).unwrap();
    let b: Value = serde_json::from_slice(&b.stdout).unwrap();
    let xyz = floats(&a["XYZ"]);
    assert!(
        xyz.len() == 3 && xyz.iter().all(|c| c.is_finite() && *c > 0.0),
        "{xyz:?}"
    );
    assert_eq!(a["XYZ"], b["XYZ"]);
}

#[test]
fn blackbody_spectra_have_their_own_temperature_as_cct() {
    for temperature_k in [1500.0, 2856.0, 6500.0, 20000.0] {
        let spec = format!("blackbody:{temperature_k}");
        let v = json_of(&["color", "--spectrum", &spec, "--json"]);
        let cct = v["CCT_K"].as_f64().unwrap();
        assert!((cct - temperature_k).abs() < 0.5, "{spec}: CCT {cct}");
        assert!(v["Duv"].as_f64().unwrap().abs() < 1e-5);
    }
    expect_error(
        &["color", "--spectrum", "blackbody:hot"],
        &["blackbody:<temperature in K>"],
    );
}

/// Issue 21 test 7: a synthetic optically brightened white against band sums done
/// independently (tools/export_bispectral_fixture.py, standard-library Python on spectra/).
#[test]
fn bispectral_matches_the_independent_band_sums() {
    let fixture = fixture("bispectral_cli.json");
    let bfc = fixture["bfc"].as_str().unwrap();
    let mut args = vec!["color", "--json", "--bispectral", bfc];
    args.extend(
        fixture["args"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap()),
    );
    let ours = json_of(&args);
    assert_eq!(ours["negatives"]["policy"], "clamp");
    assert_eq!(ours["negatives"]["count"], 0);
    let relative = |e: f64| 1e-6 * e.abs();
    let want_all = fixture["illuminants"].as_array().unwrap();
    let ours_all = ours["illuminants"].as_array().unwrap();
    assert_eq!(ours_all.len(), want_all.len());
    for (o, w) in ours_all.iter().zip(want_all) {
        let name = w["illuminant"].as_str().unwrap();
        assert_eq!(o["illuminant"], w["illuminant"]);
        let what = |key: &str| format!("{name} {key}");
        assert_close(
            &what("white"),
            &floats(&o["white_XYZ"]),
            &floats(&w["white_XYZ"]),
            relative,
        );
        for part in ["reflected", "total"] {
            assert_close(
                &what(&format!("{part} XYZ")),
                &floats(&o[part]["XYZ"]),
                &floats(&w[part]["XYZ"]),
                relative,
            );
            assert_close(
                &what(&format!("{part} xy")),
                &floats(&o[part]["xy"]),
                &floats(&w[part]["xy"]),
                |_| 1e-8,
            );
            assert_close(
                &what(&format!("{part} Lab")),
                &floats(&o[part]["Lab"]),
                &floats(&w[part]["Lab"]),
                |_| 1e-6,
            );
        }
        let bands =
            |v: &Value| -> Vec<f64> { v.as_array().unwrap().iter().flat_map(floats).collect() };
        assert_close(
            &what("beta_t"),
            &bands(&o["beta_t"]),
            &bands(&w["beta_t"]),
            |e| 1e-6 * e.abs().max(1e-3),
        );
        for key in ["beta_t_peak", "beta_l_peak"] {
            assert_close(&what(key), &floats(&o[key]), &floats(&w[key]), |e| {
                1e-6 * e.abs()
            });
        }
    }
    // The accepted check: βT changes with the illuminant (the UV-rich D65 excites more).
    let peak = |i: usize| floats(&ours_all[i]["beta_t_peak"])[1];
    assert!(
        peak(0) > peak(1) + 0.1,
        "βT peaks {} vs {}",
        peak(0),
        peak(1)
    );
    let (o, w) = (&ours["whiteness"], &fixture["whiteness"]);
    for key in ["W", "T_W"] {
        assert_close(
            key,
            &[o[key].as_f64().unwrap()],
            &[w[key].as_f64().unwrap()],
            |_| 1e-6,
        );
    }
    assert_eq!(o["valid"], w["valid"]);
    assert_eq!(o["valid"], true);
}

#[test]
fn bispectral_text_prints_both_illuminants_the_policy_and_whiteness() {
    let fixture = fixture("bispectral_cli.json");
    let bfc = fixture["bfc"].as_str().unwrap();
    let out = prism(&["color", "--bispectral", bfc, "--compare-illuminant", "A"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for label in [
        "negatives    clamp (no negative entries)",
        "illuminant D65",
        "illuminant A",
        "reflected (R alone)",
        "total (R + fluorescence)",
        "βT peak D65",
        "βT peak A",
        "βL peak",
        "whiteness",
        "T_W",
    ] {
        assert!(text.contains(label), "`{label}` not in:\n{text}");
    }
}

/// A 3 × 3 file (400–420 nm) with one negative off-diagonal entry on line 7, column 10.
const SMALL_BFC_WITH_NEGATIVE: &str = "VEC_01\t9\nBFC-450 Matrix File\n400 420 10 3 400 10\nr:c: 400 410 420\n400\t0.9\t0\t0\n410\t0.01\t0.9\t0\n420\t0.02\t-0.003\t0.9\nEOD\n";

#[test]
fn bispectral_bad_input_and_negatives() {
    let fixture_bfc = "tests/fixtures/bispectral-synthetic.bfc";
    expect_error(
        &["color", "--bispectral", fixture_bfc, "--spectrum", "D65"],
        &["--spectrum", "cannot be used with"],
    );
    expect_error(&["color"], &["--spectrum", "--bispectral"]);
    expect_error(
        &["color", "--spectrum", "D65", "--compare-illuminant", "A"],
        &["--bispectral only"],
    );
    expect_error(
        &["color", "--spectrum", "D65", "--negatives", "keep"],
        &["--bispectral only"],
    );
    let malformed = TempFile::new(
        "malformed.bfc",
        &SMALL_BFC_WITH_NEGATIVE.replace("0.01\t0.9", "0.01\tx9"),
    );
    expect_error(
        &["color", "--bispectral", malformed.arg()],
        &[&format!("{}:6:10:", malformed.arg()), "expected a number"],
    );
    let negative = TempFile::new("negative.bfc", SMALL_BFC_WITH_NEGATIVE);
    expect_error(
        &[
            "color",
            "--bispectral",
            negative.arg(),
            "--negatives",
            "error",
        ],
        &[&format!("{}:7:10:", negative.arg()), "negative", "-0.003"],
    );
    // clamp (the default) reports the count and the worst entry, in text and JSON.
    let out = prism(&["color", "--bispectral", negative.arg()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("clamp (1 of 9 entries are negative, the most negative -0.003 at excitation 410 nm, emission 420 nm (line 7, column 10): set to 0)"),
        "{text}"
    );
    let ours = json_of(&[
        "color",
        "--bispectral",
        negative.arg(),
        "--negatives",
        "keep",
        "--json",
    ]);
    let negatives = &ours["negatives"];
    assert_eq!(negatives["policy"], "keep");
    assert_eq!(negatives["count"], 1);
    assert_eq!(negatives["worst"]["emission_nm"], 420.0);
    assert_eq!(negatives["worst"]["excitation_nm"], 410.0);
}
