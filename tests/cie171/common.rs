//! Shared pieces of the CIE 171 cases: run a scene's sensors, Lambert's polygon formula
//! for the illuminance from a uniform Lambertian polygon, and the pass table.

use glam::DVec3;
use prism_render::sensor::{measure_sensors, PointReading};
use prism_render::RenderScene;

/// Measures the sensors of scene `json` (seed 1); one list of readings per sensor entry.
pub fn measure(json: &str) -> Vec<Vec<PointReading>> {
    let dir = tempfile::tempdir().unwrap();
    measure_in(dir.path(), json)
}

/// As `measure`, with assets in `dir`.
pub fn measure_in(dir: &std::path::Path, json: &str) -> Vec<Vec<PointReading>> {
    let description = prism_scene::parse_scene_str(json, dir.join("scene.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    let scene = RenderScene::build(&description, None).unwrap_or_else(|e| panic!("{e}"));
    let (readings, _) = measure_sensors(&scene, &description.sensors, 1, &|_| {});
    readings.into_iter().map(|r| r.points).collect()
}

/// `[x, y, z]` for scene JSON.
pub fn js(v: DVec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// Clips a polygon to the half-space (x − p)·n ≥ 0 (Sutherland–Hodgman).
pub fn clip(poly: &[DVec3], p: DVec3, n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = ((a - p).dot(n), (b - p).dot(n));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Illuminance (lx) at `p` on a surface facing `n` from a uniform Lambertian polygon of
/// luminance `l` (cd/m²) seen from its emitting side: Lambert's formula (Lambert 1760;
/// Arvo 1995, eq. 9) E = L Σᵢ ½ Θᵢ n·Γᵢ, Θᵢ the angle the edge i subtends at p and Γᵢ the
/// unit normal of the plane through p and the edge, after clipping the polygon to the
/// hemisphere above the receiver.
pub fn polygon_illuminance(p: DVec3, n: DVec3, poly: &[DVec3], l: f64) -> f64 {
    let clipped = clip(poly, p + n * 1e-12, n);
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let a = (clipped[i] - p).normalize();
        let b = (clipped[(i + 1) % clipped.len()] - p).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        let g = a.cross(b);
        if g.length() > 0.0 {
            sum += 0.5 * theta * n.dot(g.normalize());
        }
    }
    l * sum.abs()
}

/// One row of a case's table.
pub struct Row {
    pub label: String,
    pub reference_lx: f64,
    pub ours: PointReading,
}

/// Prints the table and asserts the CIE 171 criterion: every point within 5 % (points
/// whose reference is 0 — full shadow — must read below 0.5 % of the mean reference
/// instead) and the average within 2 %.
pub fn check_table(case: &str, rows: &[Row]) {
    println!("\nCIE 171 {case}");
    println!(
        "{:<28} {:>14} {:>14} {:>10} {:>9}",
        "point", "reference lx", "ours lx", "± s.e.", "error %"
    );
    let n = rows.len() as f64;
    let mean_ref = rows.iter().map(|r| r.reference_lx).sum::<f64>() / n;
    let mean_ours = rows.iter().map(|r| r.ours.illuminance_lx).sum::<f64>() / n;
    let mut failures = Vec::new();
    for r in rows {
        let ours = r.ours.illuminance_lx;
        let (err, ok) = if r.reference_lx > 0.0 {
            let e = ours / r.reference_lx - 1.0;
            (e * 100.0, e.abs() <= 0.05)
        } else {
            (f64::NAN, ours <= 0.005 * mean_ref)
        };
        println!(
            "{:<28} {:>14.4} {:>14.4} {:>10.4} {:>9.3}{}",
            r.label,
            r.reference_lx,
            ours,
            r.ours.std_error_lx,
            err,
            if ok { "" } else { "  FAIL" }
        );
        if !ok {
            failures.push(r.label.clone());
        }
    }
    let avg_err = mean_ours / mean_ref - 1.0;
    println!(
        "{:<28} {:>14.4} {:>14.4} {:>10} {:>9.3}",
        "average",
        mean_ref,
        mean_ours,
        "",
        avg_err * 100.0
    );
    assert!(
        failures.is_empty(),
        "{case}: points beyond 5 %: {failures:?}"
    );
    assert!(
        avg_err.abs() <= 0.02,
        "{case}: average error {:.3} % beyond 2 %",
        avg_err * 100.0
    );
}
