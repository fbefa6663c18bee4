//! The interpolated table against its nodes and an analytic flux; a ring of sensors around
//! a luminaire against the file's candela table; the flux the sensors measure over a sphere
//! against the file's.

use super::*;
use crate::scene_build::RenderScene;
use crate::sensor::measure_sensors;

/// An asymmetric Type C luminaire (bilateral, C 0–180 by 30°, γ 0–180 by 15°): a wide
/// downward lobe stronger towards C = 0 and a weak uplight.
fn asymmetric_ies() -> String {
    let gammas: Vec<f64> = (0..=12).map(|j| j as f64 * 15.0).collect();
    let cs: Vec<f64> = (0..=6).map(|i| i as f64 * 30.0).collect();
    let mut s = String::from(
        "IESNA:LM-63-2002\n[TEST] prism-ring\n[MANUFAC] Prism\nTILT=NONE\n1 -1 1 13 7 1 2 0.1 0.3 0\n1 1 40\n",
    );
    s += &gammas
        .iter()
        .map(|g| g.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    s += "\n";
    s += &cs
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    s += "\n";
    for c in &cs {
        let row: Vec<String> = gammas
            .iter()
            .map(|g| {
                let gr = g.to_radians();
                let down = if *g <= 90.0 {
                    1000.0 * gr.cos().powf(1.5) * (1.0 + 0.5 * c.to_radians().cos())
                } else {
                    0.0
                };
                let up = if *g > 90.0 { 80.0 * (-gr.cos()) } else { 0.0 };
                format!("{:.3}", down + up)
            })
            .collect();
        s += &row.join(" ");
        s += "\n";
    }
    s
}

fn table_of(text: &str) -> IntensityTable {
    let d = prism_scene::photometric::parse_ies(text, std::path::Path::new("t.ies")).unwrap();
    IntensityTable::from_distribution(&d)
}

#[test]
fn interpolation_hits_the_nodes_is_periodic_and_never_negative() {
    let text = asymmetric_ies();
    let d = prism_scene::photometric::parse_ies(&text, std::path::Path::new("t.ies")).unwrap();
    let t = IntensityTable::from_distribution(&d);
    for (i, c) in d.horizontal_deg.iter().enumerate() {
        for (j, g) in d.vertical_deg.iter().enumerate() {
            let v = t.eval_angles(c.to_radians(), g.to_radians());
            assert!(
                (v - d.candela_at(i, j)).abs() < 1e-9 * (1.0 + v),
                "C {c} γ {g}: {v}"
            );
        }
    }
    // Continuous across C = 0 / 360.
    let g = 0.7;
    let a = t.eval_angles(-1e-7, g);
    let b = t.eval_angles(1e-7, g);
    assert!((a - b).abs() < 1e-4 * a, "{a} {b}");
    // Never negative, bounded by the neighbouring nodes' extremes (monotone cubic).
    for k in 0..2000 {
        let c = k as f64 * 0.0031;
        let g = (k as f64 * 0.0917) % PI;
        let v = t.eval_angles(c, g);
        assert!((0.0..=1500.0 + 1e-9).contains(&v), "{v}");
    }
}

#[test]
fn flux_of_a_cosine_distribution_is_pi_i0() {
    // Rotationally symmetric I = I0 cos γ over γ 0–90 by 2.5°: Φ = π I0.
    let n = 37;
    let mut s = format!("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 {n} 1 1 2 0 0 0\n1 1 10\n");
    for j in 0..n {
        s += &format!("{} ", j as f64 * 2.5);
    }
    s += "\n0\n";
    for j in 0..n {
        s += &format!("{} ", 500.0 * (j as f64 * 2.5).to_radians().cos());
    }
    let phi = table_of(&s).flux();
    assert!((phi - PI * 500.0).abs() < 2e-4 * PI * 500.0, "{phi}");
}

#[test]
fn type_b_and_a_axes_put_the_peak_where_the_definition_says() {
    // A single bright node at H = 30°, V = 20°.
    let text = |kind: u32| {
        let mut s = format!(
            "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 5 5 {kind} 2 0 0 0\n1 1 10\n-40 -20 0 20 40\n-60 -30 0 30 60\n"
        );
        for h in 0..5 {
            for v in 0..5 {
                s += if h == 3 && v == 3 { "900 " } else { "0 " };
            }
            s += "\n";
        }
        s
    };
    let (h, v) = (30f64.to_radians(), 20f64.to_radians());
    let tb = table_of(&text(2));
    // Type B: d = cos V (cos H a + sin H l) + sin V w.
    let (dl, dw, da) = (v.cos() * h.sin(), v.sin(), v.cos() * h.cos());
    assert!((tb.eval_local(dl, dw, da) - 900.0).abs() < 1e-6);
    // Mirrored across the aim–width plane (H = −30°): dark.
    assert_eq!(tb.eval_local(-dl, dw, da), 0.0);
    let ta = table_of(&text(3));
    // Type A: d = cos V (cos H a + sin H w) + sin V l.
    assert!((ta.eval_local(dw, dl, da) - 900.0).abs() < 1e-6);
    // Outside the H range (behind the floodlight): dark.
    assert_eq!(tb.eval_local(0.0, 0.0, -1.0), 0.0);
}

fn luminaire_scene(dir: &std::path::Path, light_extra: &str, sensors: &str) -> RenderScene {
    std::fs::write(dir.join("lum.ies"), asymmetric_ies()).unwrap();
    let json = format!(
        r#"{{"lights": [{{"type": "luminaire", "file": "lum.ies", "position_m": [0, 3, 0],
              "aim": [0, -1, 0], "c0_direction": [1, 0, 0] {light_extra}}}],
            "sensors": {sensors}}}"#
    );
    let d = prism_scene::parse_scene_str(&json, dir.join("scene.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    RenderScene::build(&d, None).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_ring_of_sensors_reproduces_the_candela_table() {
    let dir = tempfile::tempdir().unwrap();
    let file =
        prism_scene::photometric::parse_ies(&asymmetric_ies(), std::path::Path::new("x.ies"))
            .unwrap();
    // Sensors 4 m from the luminaire at every (C, γ) node of the file with 0 < γ < 180,
    // facing it: E = I / r². C = 0 is +X, C = 90° is c0 × aim = +X × −Y = −Z.
    let r = 4.0;
    let (mut pos, mut nrm, mut expect) = (Vec::new(), Vec::new(), Vec::new());
    for (i, c) in file
        .horizontal_deg
        .iter()
        .enumerate()
        .take(file.horizontal_deg.len() - 1)
    {
        for (j, g) in file.vertical_deg.iter().enumerate() {
            if *g <= 0.0 || *g >= 180.0 {
                continue;
            }
            let (c, g) = (c.to_radians(), g.to_radians());
            let d = DVec3::new(g.sin() * c.cos(), -g.cos(), -g.sin() * c.sin());
            let p = DVec3::new(0.0, 3.0, 0.0) + d * r;
            pos.push(format!("[{}, {}, {}]", p.x, p.y, p.z));
            nrm.push(format!("[{}, {}, {}]", -d.x, -d.y, -d.z));
            expect.push(file.candela_at(i, j));
        }
    }
    let sensors = format!(
        r#"[{{"type": "points", "positions_m": [{}], "normals": [{}], "samples": 256}}]"#,
        pos.join(","),
        nrm.join(",")
    );
    let scene = luminaire_scene(dir.path(), "", &sensors);
    let (readings, _) = measure_sensors(&scene, &scene_sensors(dir.path(), &sensors), 3, &|_| {});
    for (p, i) in readings[0].points.iter().zip(&expect) {
        let measured_cd = p.illuminance_lx * r * r;
        let se = p.std_error_lx * r * r;
        assert!(
            (measured_cd - i).abs() <= 4.5 * se + 1e-6 * i,
            "at {:?}: {measured_cd} ± {se} cd vs table {i}",
            p.position_m
        );
    }
}

fn scene_sensors(dir: &std::path::Path, sensors: &str) -> Vec<prism_scene::Sensor> {
    let json = format!(r#"{{"sensors": {sensors}}}"#);
    prism_scene::parse_scene_str(&json, dir.join("s.json"))
        .unwrap()
        .sensors
}

#[test]
fn sensors_over_a_sphere_measure_the_files_flux_and_power_lm_sets_it() {
    let dir = tempfile::tempdir().unwrap();
    // Uniformly random directions (fixed-seed LCG), sensors 2 m away facing the luminaire:
    // Φ = 4π r² E[E] over the sphere; the standard error includes the spread of E over
    // directions.
    let n = 3000;
    let mut state = 0x1234_5678_9abc_def0u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let r = 2.0;
    let (mut pos, mut nrm) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let z = 1.0 - 2.0 * next();
        let phi = 2.0 * PI * next();
        let s = (1.0 - z * z).sqrt();
        let d = DVec3::new(s * phi.cos(), z, s * phi.sin());
        let p = DVec3::new(0.0, 3.0, 0.0) + d * r;
        pos.push(format!("[{}, {}, {}]", p.x, p.y, p.z));
        nrm.push(format!("[{}, {}, {}]", -d.x, -d.y, -d.z));
    }
    let sensors = format!(
        r#"[{{"type": "points", "positions_m": [{}], "normals": [{}], "samples": 8}}]"#,
        pos.join(","),
        nrm.join(",")
    );
    for (extra, expected) in [("", None), (r#", "power_lm": 2500"#, Some(2500.0))] {
        let scene = luminaire_scene(dir.path(), extra, &sensors);
        let crate::light::Light::Goniometric(g) = scene.lights.light(0) else {
            panic!("not a luminaire")
        };
        let table_flux = g.flux_lm;
        if let Some(e) = expected {
            assert!((table_flux - e).abs() < 1e-9 * e);
        } else {
            // The file's own flux by the trapezoid rule over its grid: on a 15° grid its
            // O(h²) error is ≈ 1.6 % for this cos^1.5 lobe, so agree within 2.5 %.
            let file = prism_scene::photometric::parse_ies(
                &asymmetric_ies(),
                std::path::Path::new("x.ies"),
            )
            .unwrap();
            let mut trap = 0.0;
            let (hs, vs) = (&file.horizontal_deg, &file.vertical_deg);
            for i in 0..hs.len() - 1 {
                let dc = (hs[i + 1] - hs[i]).to_radians();
                for j in 0..vs.len() - 1 {
                    let (g0, g1) = (vs[j].to_radians(), vs[j + 1].to_radians());
                    let band = g0.cos() - g1.cos();
                    let avg = (file.candela_at(i, j)
                        + file.candela_at(i + 1, j)
                        + file.candela_at(i, j + 1)
                        + file.candela_at(i + 1, j + 1))
                        / 4.0;
                    trap += avg * band * dc;
                }
            }
            assert!(
                (table_flux - trap).abs() < 0.025 * trap,
                "{table_flux} vs {trap}"
            );
        }
        let (readings, _) =
            measure_sensors(&scene, &scene_sensors(dir.path(), &sensors), 5, &|_| {});
        let mut stats = crate::sensor::RunningStats::default();
        for p in &readings[0].points {
            stats.push(4.0 * PI * r * r * p.illuminance_lx);
        }
        let se = stats.std_error();
        assert!(
            (stats.mean - table_flux).abs() <= 4.5 * se,
            "measured {} ± {se} lm vs {table_flux} lm",
            stats.mean
        );
        assert!(se < 0.03 * table_flux);
    }
}
