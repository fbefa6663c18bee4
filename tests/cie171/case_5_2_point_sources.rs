//! CIE 171 §5.2, point light sources: the illuminance from a point source is
//! E = I(ω) cos θ / d² (inverse-square and cosine laws). An isotropic 1000 cd source and a
//! luminaire read from an IES file with I(γ) = I₀ cos γ (downward hemisphere, 1° table),
//! 3 m above a horizontal plane; receivers on the plane (horizontal) and on a vertical
//! plane, in the dark (no surfaces, so no reflected light).

use glam::DVec3;

use crate::common::{check_table, js, measure_in, Row};

fn grid() -> Vec<(DVec3, DVec3, String)> {
    let mut v = Vec::new();
    for x in [0.0, 1.0, 2.0, 4.0] {
        for z in [0.0, 1.5, 3.0] {
            v.push((DVec3::new(x, 0.0, z), DVec3::Y, format!("floor ({x}, {z})")));
        }
    }
    for y in [0.5, 1.5, 2.5] {
        v.push((
            DVec3::new(2.0, y, 0.5),
            DVec3::NEG_X,
            format!("wall x=2 y={y}"),
        ));
    }
    v
}

fn sensors(points: &[(DVec3, DVec3, String)]) -> String {
    let p: Vec<String> = points.iter().map(|(p, _, _)| js(*p)).collect();
    let n: Vec<String> = points.iter().map(|(_, n, _)| js(*n)).collect();
    format!(
        r#"[{{"type": "points", "positions_m": [{}], "normals": [{}], "relative_error": 0.004}}]"#,
        p.join(", "),
        n.join(", ")
    )
}

#[test]
fn cie171_5_2_isotropic_point_source() {
    let source = DVec3::new(0.0, 3.0, 0.0);
    let points = grid();
    let json = format!(
        r#"{{"lights": [{{"type": "point", "position_m": {}, "intensity_cd": 1000}}],
            "sensors": {}}}"#,
        js(source),
        sensors(&points)
    );
    let dir = tempfile::tempdir().unwrap();
    let r = measure_in(dir.path(), &json);
    let rows: Vec<Row> = points
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| {
            let to = source - *p;
            let d2 = to.length_squared();
            Row {
                label: label.clone(),
                reference_lx: 1000.0 * (to.normalize().dot(*n)).max(0.0) / d2,
                ours: *ours,
            }
        })
        .collect();
    check_table("5.2 point source, isotropic 1000 cd", &rows);
}

#[test]
fn cie171_5_2_luminaire_with_a_cosine_distribution() {
    // I(γ) = 800 cos γ for γ ≤ 90°, nothing upwards, tabulated every degree.
    let i0 = 800.0;
    let mut ies = String::from(
        "IESNA:LM-63-2002\n[TEST] CIE 171 5.2\n[MANUFAC] prism tests\nTILT=NONE\n1 -1 1 91 1 1 2 0 0 0\n1 1 10\n",
    );
    ies += &(0..=90)
        .map(|g| g.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    ies += "\n0\n";
    ies += &(0..=90)
        .map(|g| format!("{:.6}", i0 * (g as f64).to_radians().cos()))
        .collect::<Vec<_>>()
        .join(" ");
    ies += "\n";
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cosine.ies"), ies).unwrap();
    let source = DVec3::new(0.0, 3.0, 0.0);
    let points = grid();
    let json = format!(
        r#"{{"lights": [{{"type": "luminaire", "file": "cosine.ies", "position_m": {}}}],
            "sensors": {}}}"#,
        js(source),
        sensors(&points)
    );
    let r = measure_in(dir.path(), &json);
    let rows: Vec<Row> = points
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| {
            let to = source - *p;
            let d2 = to.length_squared();
            let cos_gamma = (-to.normalize()).dot(DVec3::NEG_Y).max(0.0);
            Row {
                label: label.clone(),
                reference_lx: i0 * cos_gamma * (to.normalize().dot(*n)).max(0.0) / d2,
                ours: *ours,
            }
        })
        .collect();
    check_table("5.2 point source, IES I(γ) = 800 cos γ cd", &rows);
}
