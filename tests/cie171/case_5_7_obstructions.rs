//! CIE 171 §5.7, internal obstructions: a 2 m × 2 m Lambertian ceiling source
//! (3000 cd/m², 3 m up) half hidden from the floor by a black opaque screen at 1.5 m whose
//! edge runs along z above x = 0. From a floor point (x_p, 0) a source point at x is hidden
//! when the line to it crosses the screen, x < x* = x_p + (0 − x_p)·3/1.5 = −x_p, so the
//! visible source is the rectangle cut at x*, and E follows from Lambert's polygon formula
//! (0 in full shadow, the whole source in full view).

use glam::DVec3;

use crate::common::{check_table, clip, js, measure, polygon_illuminance, Row};

#[test]
fn cie171_5_7_screen_between_source_and_floor() {
    let (l, ys, yo) = (3000.0, 3.0, 1.5);
    let poly = [
        DVec3::new(-1.0, ys, -1.0),
        DVec3::new(1.0, ys, -1.0),
        DVec3::new(1.0, ys, 1.0),
        DVec3::new(-1.0, ys, 1.0),
    ];
    let xs = [-1.5, -1.0, -0.6, -0.3, 0.0, 0.3, 0.6, 1.0, 1.5];
    let ps: Vec<String> = xs.iter().map(|x| js(DVec3::new(*x, 0.0, 0.2))).collect();
    let black = r#"{"type": "lambert", "reflectance": 0}"#;
    let json = format!(
        r#"{{"materials": {{"black": {black}}},
            "shapes": [
              {{"type": "rectangle", "name": "panel", "size_m": [2, 2], "material": "black",
                "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, {ys}, 0]}}]}},
              {{"type": "rectangle", "size_m": [20, 40], "material": "black",
                "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [-10, {yo}, 0]}}]}}],
            "lights": [{{"type": "area", "shape": "panel", "luminance_cd_m2": {l}}}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normal": [0, 1, 0], "relative_error": 0.005,
                          "absolute_error_lx": 0.5}}]}}"#,
        ps.join(", ")
    );
    let r = measure(&json);
    let rows: Vec<Row> = xs
        .iter()
        .zip(&r[0])
        .map(|(x, ours)| {
            let p = DVec3::new(*x, 0.0, 0.2);
            let x_star = x + (0.0 - x) * (ys - p.y) / (yo - p.y);
            let visible = clip(&poly, DVec3::new(x_star, 0.0, 0.0), DVec3::X);
            let reference = if visible.len() < 3 {
                0.0
            } else {
                polygon_illuminance(p, DVec3::Y, &visible, l)
            };
            Row {
                label: format!("floor x={x}"),
                reference_lx: reference,
                ours: *ours,
            }
        })
        .collect();
    check_table(
        "5.7 obstruction: screen half hiding a ceiling source",
        &rows,
    );
}
