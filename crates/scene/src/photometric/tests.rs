//! Realistic files of every revision and symmetry, and malformed ones with their messages.

use super::*;

fn ies(text: &str) -> Result<IntensityDistribution, String> {
    parse_ies(text, Path::new("lamp.ies")).map_err(|e| e.to_string())
}

fn ldt(text: &str) -> Result<IntensityDistribution, String> {
    parse_ldt(text, Path::new("lamp.ldt")).map_err(|e| e.to_string())
}

/// A 2002 downlight, quadrant symmetric (C 0–90), ballast factor 0.95.
const DOWNLIGHT_2002: &str = "IESNA:LM-63-2002
[TEST] 12345
[TESTLAB] Prism photometric lab
[ISSUEDATE] 2026-11-22
[MANUFAC] Example Lighting
[LUMCAT] DL-200
[LUMINAIRE] Recessed downlight, clear reflector
[LAMP] LED module 3000 K
TILT=NONE
1 2000 1.0 5 3 1 2 0.2 0.2 0.0
0.95 1.0 24
0 22.5 45 67.5 90
0 45 90
800 700 450 120 0
800 690 430 110 0
800 680 400 100 0
";

#[test]
fn ies_2002_quadrant_symmetric_expands_to_360_degrees_with_factors() {
    let d = ies(DOWNLIGHT_2002).unwrap();
    assert_eq!(d.format, PhotometricFormat::Ies2002);
    assert_eq!(d.photometry, PhotometryType::C);
    assert_eq!(
        d.horizontal_deg,
        vec![0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0, 360.0]
    );
    assert_eq!(d.vertical_deg, vec![0.0, 22.5, 45.0, 67.5, 90.0]);
    // Ballast factor 0.95 × candela multiplier 1.
    assert!((d.candela_at(0, 0) - 760.0).abs() < 1e-9);
    // Mirror images: C 135 = C 45, C 180 = C 0, C 270 = C 90.
    for v in 0..5 {
        assert_eq!(d.candela_at(3, v), d.candela_at(1, v));
        assert_eq!(d.candela_at(4, v), d.candela_at(0, v));
        assert_eq!(d.candela_at(6, v), d.candela_at(2, v));
        assert_eq!(d.candela_at(8, v), d.candela_at(0, v));
    }
    assert_eq!(d.lamp_flux_lm, Some(2000.0));
    assert_eq!(d.opening_m, [0.2, 0.2, 0.0]);
    assert!(d
        .keywords
        .iter()
        .any(|(k, v)| k == "MANUFAC" && v == "Example Lighting"));
}

#[test]
fn ies_1986_1991_1995_and_2019_headers_and_symmetries() {
    // 1986: no header line, free text, rotationally symmetric, feet.
    let d = ies("Example Lighting catalog 12\nA19 bulb\nTILT=NONE\n1 -1 2.0 3 1 1 1 -0.5 0 0.3\n1 1 60\n0 90 180\n0\n100 110 90\n").unwrap();
    assert_eq!(d.format, PhotometricFormat::Ies1986);
    assert_eq!(d.horizontal_deg, vec![0.0]);
    assert_eq!(d.candela, vec![200.0, 220.0, 180.0]);
    assert_eq!(d.lamp_flux_lm, None, "lumens −1: absolute photometry");
    assert!(
        (d.opening_m[0] + 0.5 * 0.3048).abs() < 1e-12,
        "round: negative width kept"
    );
    // 1991: bilateral C 0–180, values split by commas over lines.
    let d = ies("IESNA91\n[TEST] 1\nTILT=NONE\n1,1000,1,2,3,1,2,0.1,0.3,0\n1,1,30\n0,90\n0,90,180\n10,20\n30,40\n50,60\n").unwrap();
    assert_eq!(d.format, PhotometricFormat::Ies1991);
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    assert_eq!(d.candela_at(3, 1), 40.0, "C 270 mirrors C 90");
    // 1995: full 0–360, the ballast-lamp factor multiplies.
    let d = ies("IESNA:LM-63-1995\n[TEST] x\nTILT=NONE\n1 1000 1 2 5 1 2 0 0 0\n1 0.5 10\n0 90\n0 90 180 270 360\n2 1 4 1 6 1 8 1 2 1\n").unwrap();
    assert_eq!(d.format, PhotometricFormat::Ies1995);
    assert_eq!(d.candela_at(1, 0), 2.0, "4 × 0.5");
    // 2019: C 90–270 (symmetric about the C90–C270 plane); file-generation type does not
    // multiply; required keywords.
    let d = ies("IES:LM-63-2019\n[TEST] T1\n[TESTLAB] L\n[ISSUEDATE] 2026\n[MANUFAC] M\nTILT=NONE\n1 -1 1 2 3 1 2 0.6 0.6 0\n1 1.10000 30\n0 90\n90 180 270\n10 1\n20 2\n30 3\n").unwrap();
    assert_eq!(d.format, PhotometricFormat::Ies2019);
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    // I(C) = I(180° − C): C 0 = C 180, C 360 = C 0.
    assert_eq!(d.candela_at(0, 0), 20.0);
    assert_eq!(d.candela_at(1, 0), 10.0);
    assert_eq!(d.candela_at(3, 0), 30.0);
    assert_eq!(d.candela_at(4, 0), 20.0);
    let e = ies("IES:LM-63-2019\n[TEST] T1\nTILT=NONE\n1 -1 1 1 1 1 2 0 0 0\n1 1 1\n0\n0\n5\n")
        .unwrap_err();
    assert!(
        e.contains("lamp.ies:3: an LM-63-2019 file needs the keyword [TESTLAB]"),
        "{e}"
    );
}

#[test]
fn ies_tilt_include_and_type_b_and_a() {
    let d = ies("IESNA:LM-63-2002\n[TEST] 1\nTILT=INCLUDE\n1\n7\n0 15 30 45 60 75 90\n1.0 .95 .94 .90 .88 .87 .94\n2 4000 1 3 3 2 2 0.5 0.3 0.1\n1 1 100\n-90 0 90\n0 45 90\n0 500 0\n0 1000 0\n0 400 0\n").unwrap();
    let t = d.tilt.as_ref().unwrap();
    assert_eq!(t.lamp_to_luminaire_geometry, 1);
    assert_eq!(t.angles_deg.len(), 7);
    assert_eq!(t.factors[1], 0.95);
    assert_eq!(d.photometry, PhotometryType::B);
    // H 0–90 mirrored to −90…90.
    assert_eq!(d.horizontal_deg, vec![-90.0, -45.0, 0.0, 45.0, 90.0]);
    assert_eq!(d.candela_at(2, 1), 500.0);
    assert_eq!(d.candela_at(3, 1), 1000.0);
    assert_eq!(d.candela_at(0, 1), d.candela_at(4, 1));
    assert_eq!(d.lamp_flux_lm, Some(8000.0));
    let d = ies("IESNA:LM-63-2002\n[TEST] 1\nTILT=NONE\n1 1000 1 2 3 3 2 0 0 0\n1 1 10\n-45 45\n-30 0 30\n1 2\n3 4\n5 6\n").unwrap();
    assert_eq!(d.photometry, PhotometryType::A);
    assert_eq!(d.horizontal_deg, vec![-30.0, 0.0, 30.0]);
}

#[test]
fn malformed_ies_files_say_where_and_what() {
    let cases: &[(&str, &str)] = &[
        ("", "lamp.ies: the file is empty"),
        (
            "IESNA:LM-63-2002\n[TEST] 1\n1 2 3\n",
            "lamp.ies:3: expected a `[KEYWORD] value` line or `TILT=…`, found `1 2 3`",
        ),
        (
            "IESNA:LM-63-2002\n[TEST] 1\n",
            "no `TILT=` line",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 45\n",
            "lamp.ies:5: the file ends early: expected vertical angle 3 of 3",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 45 40\n0\n1 2 3\n",
            "lamp.ies:5: vertical angles must increase, but angle 3 (40°) follows 45°",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n1 2 3\n",
            "lamp.ies:7: unexpected `3` after the 1 × 2 candela values",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 1 4 2 0 0 0\n1 1 10\n0 90\n0\n1 2\n",
            "lamp.ies:3: expected the photometric type 1 (C), 2 (B) or 3 (A), found 4",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 2 1 2 0 0 0\n1 1 10\n0 90\n0 120\n1 2\n1 2\n",
            "lamp.ies:6: the C-planes must run 0–0 (rotational symmetry), 0–90, 0–180, 90–270 or 0–360°, found 0–120°",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n1 -2\n",
            "lamp.ies:7: candela values must be ≥ 0, found -2",
        ),
        (
            "IESNA:LM-63-2002\nTILT=NONE\n1 1000 x 2 1 1 2 0 0 0\n",
            "lamp.ies:3: expected the candela multiplier (a number), found `x`",
        ),
        (
            "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n2\n0 90\n-0.5 1\n",
            "lamp.ies:6: tilt factors must be ≥ 0, found -0.5",
        ),
        (
            "IESNA:LM-63-2002\nTILT=lamp.tlt\n",
            "lamp.ies:2: cannot read the tilt file lamp.tlt",
        ),
        (
            "IESNA:LM-63-2021\nTILT=NONE\n",
            "lamp.ies:1: unknown LM-63 revision `IESNA:LM-63-2021`",
        ),
    ];
    for (text, expected) in cases {
        let e = ies(text).unwrap_err();
        assert!(e.contains(expected), "{text}\n→ {e}\nexpected: {expected}");
    }
}

/// An EULUMDAT file with symmetry `isym`, `mc` planes every `360/mc`°, γ 0…180 by 45°.
fn ldt_text(isym: u32, mc: usize, stored: usize, values: impl Fn(usize, usize) -> f64) -> String {
    let ng = 5;
    let mut s = String::new();
    let mut push = |x: String| {
        s.push_str(&x);
        s.push_str("\r\n");
    };
    push("Example Lighting".into());
    push("1".into());
    push(isym.to_string());
    push(mc.to_string());
    push(format!("{}", 360.0 / mc as f64));
    push(ng.to_string());
    push("45".into());
    for t in [
        "R-001",
        "Panel 600",
        "P600",
        "panel.ldt",
        "2026-11-22 prism",
    ] {
        push(t.into());
    }
    for x in ["600", "600", "50", "580", "580", "0", "0", "0", "0"] {
        push(x.into());
    }
    push("100".into()); // DFF
    push("85,5".into()); // LOR, decimal comma
    push("1".into()); // conversion factor
    push("0".into()); // tilt
    push("1".into()); // sets
    push("1".into());
    push("LED".into());
    push("4000".into());
    push("4000".into());
    push("80".into());
    push("36".into());
    for k in 0..10 {
        push(format!("0.{}", 5 + k / 3));
    }
    for i in 0..mc {
        push(format!("{}", i as f64 * 360.0 / mc as f64));
    }
    for j in 0..ng {
        push(format!("{}", j as f64 * 45.0));
    }
    for i in 0..stored {
        for j in 0..ng {
            push(format!("{}", values(i, j)));
        }
    }
    s
}

#[test]
fn eulumdat_symmetries_expand_and_scale_by_lamp_flux() {
    // Isym 1: one plane; cd/klm × 4000 lm / 1000.
    let d = ldt(&ldt_text(1, 1, 1, |_, j| {
        [300.0, 250.0, 100.0, 0.0, 0.0][j]
    }))
    .unwrap();
    assert_eq!(d.format, PhotometricFormat::Eulumdat);
    assert_eq!(d.horizontal_deg, vec![0.0]);
    assert_eq!(d.candela, vec![1200.0, 1000.0, 400.0, 0.0, 0.0]);
    assert_eq!(d.lamp_flux_lm, Some(4000.0));
    assert!((d.opening_m[1] - 0.58).abs() < 1e-12);
    // Isym 0: 4 planes 0, 90, 180, 270 stored, closed at 360.
    let d = ldt(&ldt_text(0, 4, 4, |i, j| (10 * i + j) as f64)).unwrap();
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    assert_eq!(d.candela_at(4, 2), d.candela_at(0, 2));
    // Isym 2: C 0…180 stored (3 planes of 4), mirrored.
    let d = ldt(&ldt_text(2, 4, 3, |i, j| (10 * i + j) as f64)).unwrap();
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    assert_eq!(d.candela_at(3, 1), d.candela_at(1, 1));
    // Isym 3: C 90…270 stored.
    let d = ldt(&ldt_text(3, 4, 3, |i, j| (10 * i + j) as f64)).unwrap();
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    // C 0 mirrors C 180 (stored index 1), C 90 is stored index 0.
    assert_eq!(d.candela_at(0, 1), 4.0 * 11.0);
    assert_eq!(d.candela_at(1, 1), 4.0 * 1.0);
    // Isym 4: C 0…90 stored (2 planes of 4).
    let d = ldt(&ldt_text(4, 4, 2, |i, j| (10 * i + j) as f64)).unwrap();
    assert_eq!(d.horizontal_deg, vec![0.0, 90.0, 180.0, 270.0, 360.0]);
    assert_eq!(d.candela_at(2, 3), d.candela_at(0, 3));
}

#[test]
fn malformed_eulumdat_files_say_where_and_what() {
    let good = ldt_text(2, 4, 3, |i, j| (10 * i + j) as f64);
    // Truncated: drop the last 4 lines.
    let lines: Vec<&str> = good.lines().collect();
    let truncated = lines[..lines.len() - 4].join("\n");
    let e = ldt(&truncated).unwrap_err();
    assert!(
        e.contains("the file ends early") && e.contains("the intensity at C = 180°"),
        "{e}"
    );
    // Wrong counts: one intensity too many.
    let e = ldt(&format!("{good}7\n")).unwrap_err();
    assert!(e.contains("Mc, Ng or Isym do not match the data"), "{e}");
    // Non-monotonic γ: swap two γ angles (lines 43–47 hold γ after 4 C-planes from 39).
    let mut l2: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    let g0 = 42 + 4; // 0-based index of the first γ line
    l2.swap(g0 + 1, g0 + 2);
    let e = ldt(&l2.join("\n")).unwrap_err();
    assert!(
        e.contains(&format!("lamp.ldt:{}: γ angles must increase", g0 + 3)),
        "{e}"
    );
    // Bad symmetry indicator.
    let mut l3 = l2.clone();
    l3[2] = "7".into();
    let e = ldt(&l3.join("\n")).unwrap_err();
    assert!(e.contains("lamp.ldt:3: expected the symmetry indicator Isym (0–4) (a whole number in 0…4), found 7"), "{e}");
    let e = ldt("").unwrap_err();
    assert!(e.contains("the file is empty"));
}
