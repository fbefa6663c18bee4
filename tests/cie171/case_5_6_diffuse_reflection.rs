//! CIE 171 §5.6, diffuse reflection: a 2 m × 2 m Lambertian panel (ρ = 0.5), lit evenly
//! from below by parallel light of 1000 lx, has luminance L = ρE/π on its lower face;
//! receivers below it (facing up or tilted, never towards the light) get only the
//! reflected light, E = L × (Lambert's polygon formula).

use glam::DVec3;

use crate::common::{check_table, js, measure, polygon_illuminance, Row};

#[test]
fn cie171_5_6_diffuse_reflection_from_a_lit_panel() {
    let (rho, e0, y) = (0.5, 1000.0, 2.0);
    let l = rho * e0 / std::f64::consts::PI;
    let poly = [
        DVec3::new(-1.0, y, -1.0),
        DVec3::new(1.0, y, -1.0),
        DVec3::new(1.0, y, 1.0),
        DVec3::new(-1.0, y, 1.0),
    ];
    let mut pts = Vec::new();
    for x in [0.0, 0.5, 1.0, 1.5, 2.5] {
        pts.push((DVec3::new(x, 0.0, 0.3), DVec3::Y, format!("floor x={x}")));
    }
    for (k, n) in [
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.5),
        DVec3::new(0.0, 0.3, 1.0),
    ]
    .iter()
    .enumerate()
    {
        pts.push((
            DVec3::new(0.8, 0.5, 0.0),
            n.normalize(),
            format!("tilted {k}"),
        ));
    }
    let ps: Vec<String> = pts.iter().map(|(p, _, _)| js(*p)).collect();
    let ns: Vec<String> = pts.iter().map(|(_, n, _)| js(*n)).collect();
    // The rectangle's normal (+Z) turned to −Y by +90° about X: its lit face looks down.
    let json = format!(
        r#"{{"materials": {{"panel": {{"type": "lambert", "reflectance": {rho}}}}},
            "shapes": [{{"type": "rectangle", "size_m": [2, 2], "material": "panel",
                        "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                                      {{"translate": [0, {y}, 0]}}]}}],
            "lights": [{{"type": "directional", "direction": [0, 1, 0], "illuminance_lx": {e0}}}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normals": [{}], "relative_error": 0.005}}]}}"#,
        ps.join(", "),
        ns.join(", ")
    );
    let r = measure(&json);
    let rows: Vec<Row> = pts
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| Row {
            label: label.clone(),
            reference_lx: polygon_illuminance(*p, *n, &poly, l),
            ours: *ours,
        })
        .collect();
    check_table("5.6 diffuse reflection, panel ρ = 0.5 under 1000 lx", &rows);
}
