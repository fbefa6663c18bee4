//! CIE 171 §5.4, luminous flux conservation: in a closed room whose surfaces all reflect
//! diffusely with reflectance ρ, the flux Φ of the source reaches the surfaces
//! Φ (1 + ρ + ρ² + …) = Φ / (1 − ρ) times, so the area-average illuminance of all
//! surfaces is Φ / (A (1 − ρ)) whatever the room's shape and the source's position.
//! In a sphere it is exact point by point: every wall element sees every other with the
//! form factor dA/(4πR²), so the reflected part is uniform, ρΦ/(A(1 − ρ)), and
//! E(p) = I cos θ / d² + ρΦ / (A (1 − ρ)).

use glam::DVec3;

use crate::common::{check_table, js, measure, Row};

#[test]
fn cie171_5_4_closed_cube_average_illuminance() {
    let (side, rho, flux) = (3.0, 0.5, 1000.0);
    let source = DVec3::new(0.4, 0.9, -0.3);
    let h = side / 2.0;
    let n = 16;
    // Six grids on the inner faces, normals inwards.
    let faces = [
        (
            DVec3::new(-h, -h, -h),
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.0, 0.0, side),
            DVec3::Y,
        ),
        (
            DVec3::new(-h, h, -h),
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.0, 0.0, side),
            DVec3::NEG_Y,
        ),
        (
            DVec3::new(-h, -h, -h),
            DVec3::new(0.0, side, 0.0),
            DVec3::new(0.0, 0.0, side),
            DVec3::X,
        ),
        (
            DVec3::new(h, -h, -h),
            DVec3::new(0.0, side, 0.0),
            DVec3::new(0.0, 0.0, side),
            DVec3::NEG_X,
        ),
        (
            DVec3::new(-h, -h, -h),
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.0, side, 0.0),
            DVec3::Z,
        ),
        (
            DVec3::new(-h, -h, h),
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.0, side, 0.0),
            DVec3::NEG_Z,
        ),
    ];
    let grids: Vec<String> = faces
        .iter()
        .map(|(o, u, v, nrm)| {
            format!(
                r#"{{"type": "grid", "origin_m": {}, "u_m": {}, "v_m": {}, "normal": {},
                     "resolution": [{n}, {n}], "relative_error": 0.04}}"#,
                js(*o),
                js(*u),
                js(*v),
                js(*nrm)
            )
        })
        .collect();
    let json = format!(
        r#"{{"materials": {{"wall": {{"type": "lambert", "reflectance": {rho}}},
                           "inside": {{"type": "two_sided", "material": "wall"}}}},
            "integrator": {{"type": "path", "max_depth": 60, "rr_depth": 8}},
            "shapes": [{{"type": "cuboid", "size_m": [{side}, {side}, {side}], "material": "inside"}}],
            "lights": [{{"type": "point", "position_m": {}, "power_lm": {flux}}}],
            "sensors": [{}]}}"#,
        js(source),
        grids.join(", ")
    );
    let r = measure(&json);
    // Equal faces, equal cells: the area average is the plain mean.
    let all: Vec<_> = r.iter().flatten().copied().collect();
    let mean = all.iter().map(|p| p.illuminance_lx).sum::<f64>() / all.len() as f64;
    let se = (all.iter().map(|p| p.std_error_lx.powi(2)).sum::<f64>()).sqrt() / all.len() as f64;
    let area = 6.0 * side * side;
    let reference = flux / (area * (1.0 - rho));
    let mut avg = all[0];
    avg.illuminance_lx = mean;
    avg.std_error_lx = se;
    // Per-face means, for the table (no per-face closed form in a cube).
    for (k, face) in r.iter().enumerate() {
        let m = face.iter().map(|p| p.illuminance_lx).sum::<f64>() / face.len() as f64;
        println!("face {k}: mean {m:.4} lx over {} points", face.len());
    }
    check_table(
        "5.4 flux conservation, closed cube ρ = 0.5 (area average of 6 × 16 × 16 points)",
        &[Row {
            label: "all surfaces, average".into(),
            reference_lx: reference,
            ours: avg,
        }],
    );
}

#[test]
fn cie171_5_4_closed_sphere_point_by_point() {
    let (radius, rho, flux) = (1.5, 0.5, 1000.0);
    let source = DVec3::new(0.3, 0.5, -0.2);
    let intensity = flux / (4.0 * std::f64::consts::PI);
    // Points on the wall (0.1 mm inside, normals inwards).
    let mut pts = Vec::new();
    for (k, &(t, p)) in [
        (0.3f64, 0.0f64),
        (1.0, 1.0),
        (1.6, 2.0),
        (2.2, 3.0),
        (2.9, 4.5),
        (1.2, 5.5),
        (0.05, 2.0),
        (3.1, 1.0),
    ]
    .iter()
    .enumerate()
    {
        let d = DVec3::new(t.sin() * p.cos(), t.cos(), t.sin() * p.sin());
        pts.push((d * (radius - 1e-4), -d, format!("wall point {k}")));
    }
    let ps: Vec<String> = pts.iter().map(|(p, _, _)| js(*p)).collect();
    let ns: Vec<String> = pts.iter().map(|(_, n, _)| js(*n)).collect();
    let json = format!(
        r#"{{"materials": {{"wall": {{"type": "lambert", "reflectance": {rho}}},
                           "inside": {{"type": "two_sided", "material": "wall"}}}},
            "integrator": {{"type": "path", "max_depth": 60, "rr_depth": 8}},
            "shapes": [{{"type": "sphere", "radius_m": {radius}, "material": "inside"}}],
            "lights": [{{"type": "point", "position_m": {}, "power_lm": {flux}}}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normals": [{}], "relative_error": 0.006}}]}}"#,
        js(source),
        ps.join(", "),
        ns.join(", ")
    );
    let r = measure(&json);
    let area = 4.0 * std::f64::consts::PI * radius * radius;
    let reflected = rho * flux / (area * (1.0 - rho));
    let rows: Vec<Row> = pts
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| {
            let to = source - *p;
            Row {
                label: label.clone(),
                reference_lx: intensity * to.normalize().dot(*n).max(0.0) / to.length_squared()
                    + reflected,
                ours: *ours,
            }
        })
        .collect();
    check_table("5.4 flux conservation, closed sphere ρ = 0.5", &rows);
}
