//! Directional transfer through a tiled surface: a floor of white louvres (slats at 45°)
//! splits a closed room, a lamp above them; everything below is lit through the slats.
//! `radiosity` carries the louvres' light in their pyramid's direction bins (Γ reflected
//! and transmitted, τ̄ through the gaps) and must read what `path` reads below them.

mod support;
use support::{sensor_lux, Dir};

/// One slat per 5 cm period: 35 mm wide across x, tilted 45° about the period's y.
const LOUVRE_OBJ: &[u8] = b"mtllib louvre.mtl\n\
v 0.005 0 -0.0175\nv 0.040 0 0.0175\nv 0.040 0.05 0.0175\nv 0.005 0.05 -0.0175\n\
usemtl slat\nf 1 2 3\nf 1 3 4\n";

fn louvre_room(dir: &Dir, integrator: &str) -> prism_render::RenderScene {
    std::fs::create_dir_all(dir.0.join("tiles")).unwrap();
    dir.write("tiles/louvre.obj", LOUVRE_OBJ);
    dir.write("tiles/louvre.mtl", b"newmtl slat\nKd 0.8 0.8 0.8\n");
    let face = |name: &str, transform: &str| {
        format!(
            r#"{{"type": "rectangle", "name": "{name}", "size_m": [2, 2], "material": "plaster", "transform": {transform}}}"#
        )
    };
    let faces = [
        face(
            "floor",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [0, -1, 0]}]"#,
        ),
        face(
            "ceiling",
            r#"[{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [0, 1, 0]}]"#,
        ),
        face("back", r#"[{"translate": [0, 0, -1]}]"#),
        face(
            "front",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 180}}, {"translate": [0, 0, 1]}]"#,
        ),
        face(
            "left",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}, {"translate": [-1, 0, 0]}]"#,
        ),
        face(
            "right",
            r#"[{"rotate": {"axis": [0, 1, 0], "angle_deg": -90}}, {"translate": [1, 0, 0]}]"#,
        ),
    ]
    .join(",\n    ");
    let json = format!(
        r#"{{
  "camera": {{"type": "pinhole", "fov_deg": 60, "transform": {{"look_at": {{"eye": [0, 0, 0.9], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
  "film": {{"resolution": [8, 8], "spp": 1}},
  "integrator": {integrator},
  "tiles": {{"louvre": {{"mesh": "tiles/louvre.obj", "period_m": [0.05, 0.05], "materials": {{"slat": "slat"}}}}}},
  "materials": {{
    "slat face": {{"type": "lambert", "reflectance": 0.8}},
    "slat": {{"type": "two_sided", "material": "slat face"}},
    "louvres": {{"type": "tiled", "tile": "louvre"}},
    "plaster": {{"type": "lambert", "reflectance": 0.6}}
  }},
  "shapes": [
    {faces},
    {{"type": "rectangle", "name": "louvres", "size_m": [2, 2], "material": "louvres",
      "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}, {{"translate": [0, 0.2, 0]}}]}}
  ],
  "lights": [{{"type": "point", "position_m": [-0.6, 0.8, 0.2], "power_lm": 3000}}],
  "sensors": [
    {{"type": "points", "name": "floor", "samples": 32768,
      "positions_m": [[0, -0.999, 0], [0.6, -0.999, 0.3], [-0.6, -0.999, -0.5], [0.7, -0.999, -0.7]],
      "normal": [0, 1, 0]}},
    {{"type": "points", "name": "back wall below", "samples": 32768,
      "positions_m": [[0, -0.5, -0.999], [0.4, -0.3, -0.999]], "normal": [0, 0, 1]}},
    {{"type": "points", "name": "ceiling", "samples": 32768, "positions_m": [[0.5, 0.999, 0.5]],
      "normal": [0, -1, 0]}}
  ]
}}"#
    );
    dir.scene(&json)
}

/// Every point within 6 % + 4 s.e. of `path`. Measured (2026-12-06, path's s.e. 0.7 …
/// 1.5 %): the floor −0.0 … +4.2 %, the wall below +3.1 and +6.4 % (the bins' resolution:
/// 45° sectors and rings of ¼ cos θ, against slats that open and close within one grazing
/// bin), the ceiling −1.4 %. Holding the louvres as a diffuse equivalent without scattered
/// transmission read −19 … −55 % below them against a 131 072-sample `path`; τ at each
/// bin's centre instead of its mean over the bin, +15 and +21 % on the wall.
#[test]
fn radiosity_carries_light_through_louvres_by_their_direction_bins() {
    let dir = Dir::new("tiled-louvres", "room");
    let path = louvre_room(
        &dir,
        r#"{"type": "path", "max_depth": 64, "rr_depth": 5, "sampler": "independent"}"#,
    );
    let expected = sensor_lux(&path, &dir, 3);
    let radiosity = louvre_room(&dir, r#"{"type": "radiosity", "error_bound_rel": 0.001}"#);
    let got = sensor_lux(&radiosity, &dir, 3);
    let mut failures = 0;
    for (i, (&(e, e_se), &(g, g_se))) in expected.iter().zip(&got).enumerate() {
        let se = (e_se * e_se + g_se * g_se).sqrt();
        eprintln!(
            "point {i}: radiosity {g:.2} lx, path {e:.2} lx ({:+.2} %), s.e. {se:.2}",
            100.0 * (g / e - 1.0)
        );
        failures += usize::from((g - e).abs() > 0.06 * e + 4.0 * se);
    }
    assert_eq!(failures, 0);
}
