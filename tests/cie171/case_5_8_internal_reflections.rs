//! CIE 171 §5.8, the internally reflected component: in a sphere with diffuse walls of
//! reflectance ρ the reflected illuminance is the same at every wall point,
//! ρΦ / (A (1 − ρ)), whatever the source's distribution (every wall element sees every
//! other with the form factor dA/(4πR²)). Here a luminaire with a strongly directional
//! IES distribution I(γ) = (Φ/π) cos γ (downwards only) and ρ = 0.7, so most of the light
//! at the upper wall is reflected; the table lists total illuminance (direct + reflected)
//! and the reflected part is printed separately.

use glam::DVec3;

use crate::common::{check_table, js, measure_in, Row};

#[test]
fn cie171_5_8_reflected_component_in_a_sphere_with_a_directional_luminaire() {
    let (radius, rho, flux) = (2.0, 0.7, 3000.0);
    let i0 = flux / std::f64::consts::PI;
    let dir = tempfile::tempdir().unwrap();
    // Relative table (the strength comes from power_lm): cos γ every degree.
    let mut ies = String::from(
        "IESNA:LM-63-2002\n[TEST] CIE 171 5.8\n[MANUFAC] prism tests\nTILT=NONE\n1 -1 1 91 1 1 2 0 0 0\n1 1 10\n",
    );
    ies += &(0..=90)
        .map(|g| g.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    ies += "\n0\n";
    ies += &(0..=90)
        .map(|g| format!("{:.8}", 100.0 * (g as f64).to_radians().cos()))
        .collect::<Vec<_>>()
        .join(" ");
    ies += "\n";
    std::fs::write(dir.path().join("down.ies"), ies).unwrap();
    let source = DVec3::new(0.0, 1.0, 0.0);
    let mut pts = Vec::new();
    for &(t, p) in [
        (0.2f64, 0.0f64),
        (0.9, 1.0),
        (1.4, 2.0),
        (1.7, 3.0),
        (2.3, 4.5),
        (2.8, 5.5),
        (3.0, 2.0),
    ]
    .iter()
    {
        let d = DVec3::new(t.sin() * p.cos(), t.cos(), t.sin() * p.sin());
        pts.push((d * (radius - 1e-4), -d, format!("wall θ = {t} rad")));
    }
    let ps: Vec<String> = pts.iter().map(|(p, _, _)| js(*p)).collect();
    let ns: Vec<String> = pts.iter().map(|(_, n, _)| js(*n)).collect();
    let json = format!(
        r#"{{"materials": {{"wall": {{"type": "lambert", "reflectance": {rho}}},
                           "inside": {{"type": "two_sided", "material": "wall"}}}},
            "integrator": {{"type": "path", "max_depth": 80, "rr_depth": 8}},
            "shapes": [{{"type": "sphere", "radius_m": {radius}, "material": "inside"}}],
            "lights": [{{"type": "luminaire", "file": "down.ies", "position_m": {}, "power_lm": {flux}}}],
            "sensors": [{{"type": "points", "positions_m": [{}], "normals": [{}], "relative_error": 0.006}}]}}"#,
        js(source),
        ps.join(", "),
        ns.join(", ")
    );
    let r = measure_in(dir.path(), &json);
    let area = 4.0 * std::f64::consts::PI * radius * radius;
    let reflected = rho * flux / (area * (1.0 - rho));
    let rows: Vec<Row> = pts
        .iter()
        .zip(&r[0])
        .map(|((p, n, label), ours)| {
            let to = *p - source;
            let w = to.normalize();
            let cos_gamma = w.dot(DVec3::NEG_Y).max(0.0);
            let direct = i0 * cos_gamma * (-w).dot(*n).max(0.0) / to.length_squared();
            println!(
                "{label}: reflected reference {reflected:.4} lx, ours {:.4} lx",
                ours.illuminance_lx - direct
            );
            Row {
                label: label.clone(),
                reference_lx: direct + reflected,
                ours: *ours,
            }
        })
        .collect();
    check_table("5.8 internally reflected component, sphere ρ = 0.7", &rows);
}
