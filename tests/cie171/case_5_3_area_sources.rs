//! CIE 171 §5.3, area light sources: a uniform Lambertian rectangle (1.2 m × 0.6 m,
//! 5000 cd/m², emitting downwards 2.5 m above the floor); illuminance on the floor and on a
//! vertical plane from Lambert's polygon formula (exact for any polygon, clipped to the
//! receiver's hemisphere).

use glam::DVec3;

use crate::common::{check_table, js, measure, polygon_illuminance, Row};

#[test]
fn cie171_5_3_rectangular_lambertian_source() {
    let (w, h, y, l) = (1.2, 0.6, 2.5, 5000.0);
    let poly = [
        DVec3::new(-w / 2.0, y, -h / 2.0),
        DVec3::new(w / 2.0, y, -h / 2.0),
        DVec3::new(w / 2.0, y, h / 2.0),
        DVec3::new(-w / 2.0, y, h / 2.0),
    ];
    let mut points: Vec<(DVec3, DVec3, String)> = Vec::new();
    for x in [0.0, 0.5, 1.0, 2.0, 3.0] {
        for z in [0.0, 1.0] {
            points.push((DVec3::new(x, 0.0, z), DVec3::Y, format!("floor ({x}, {z})")));
        }
    }
    for yy in [0.5, 1.5, 2.2] {
        points.push((
            DVec3::new(1.5, yy, 0.0),
            DVec3::NEG_X,
            format!("vertical x=1.5 y={yy}"),
        ));
    }
    // Straddling the source's plane: half of the source is behind the receiver.
    points.push((
        DVec3::new(0.3, 2.0, 0.0),
        DVec3::NEG_X,
        "vertical under the source".into(),
    ));
    let ps: Vec<String> = points.iter().map(|(p, _, _)| js(*p)).collect();
    let ns: Vec<String> = points.iter().map(|(_, n, _)| js(*n)).collect();
    // A rectangle's normal is +Z locally; rotating by +90° about X turns it to −Y.
    let json = format!(
        r#"{{"shapes": [{{"type": "rectangle", "name": "panel", "size_m": [{w}, {h}],
                        "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                                      {{"translate": [0, {y}, 0]}}]}}],
            "lights": [{{"type": "area", "shape": "panel", "luminance_cd_m2": {l}}}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normals": [{}],
                          "relative_error": 0.004}}]}}"#,
        ps.join(", "),
        ns.join(", ")
    );
    let r = measure(&json);
    let rows: Vec<Row> = points
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| Row {
            label: label.clone(),
            reference_lx: polygon_illuminance(*p, *n, &poly, l),
            ours: *ours,
        })
        .collect();
    check_table("5.3 rectangular Lambertian area source", &rows);
}
