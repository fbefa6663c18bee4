//! Ambient occlusion against closed forms.
//!
//! Open plane: nothing above a floor occludes it, so every occlusion ray escapes and the
//! visible fraction is exactly 1 (Y = 1.0 bit for bit, since Y of a flat spectrum of 1 is
//! exactly 1 and the film's weighted mean of equal values is that value).
//!
//! Floor beside a wall. Put the wall in the plane x = 0, from the floor y = 0 up to height
//! h and infinitely long along z; the shaded point is on the floor at distance x from it,
//! with normal +y. With unbounded occlusion distance, AO is 1 − F where F is the
//! cosine-weighted fraction of the hemisphere whose rays hit the wall:
//!
//!   F = (1/π) ∫_{ω hits wall} cos θ dω.
//!
//! (1/π)·cos θ dω is the view factor of a differential area to the directions dω; for an
//! infinitely long wall it reduces to the 2D view factor in the cross-section (x, y) plane
//! (Hottel's crossed strings; Modest, "Radiative Heat Transfer", 3rd ed., §4.4, eq. 4.35:
//! F = (sin φ₂ − sin φ₁)/2 with φ the in-plane angle from the normal). The wall spans
//! in-plane directions from the foot (−x, 0), φ₁ = −90°, to the top (−x, h),
//! sin φ₂ = −x/√(x² + h²) measured towards the wall, so
//!
//!   F = ½ (1 − x / √(x² + h²)),   AO = ½ (1 + x / √(x² + h²)).
//!
//! For an infinitely high wall F = ½ for every x > 0: the wall occludes exactly the half
//! hemisphere with d·x̂ < 0, and (x, y, z) → (−x, y, z) maps that half onto the other half
//! with the same cos θ. The test confirms the closed form by brute-force quadrature over
//! the hemisphere for the wall actually in the scene (finite length), then renders.

use glam::UVec2;
use prism_render::{render, RenderScene, RenderSettings};
use prism_scene::parse_scene_str;

fn rendered_visibility(scene_json: &str, spp: u32) -> Vec<f32> {
    let description = parse_scene_str(scene_json, "test.json").expect("test scene parses");
    let scene = RenderScene::build(&description, None).expect("test scene builds");
    let settings = RenderSettings {
        spp,
        seed: 7,
        tile_size_px: 16,
        ..RenderSettings::default()
    };
    let (image, stats) = render(&scene, &settings, &|_| {});
    assert_eq!(stats.non_finite_samples, 0);
    image.y
}

#[test]
fn ambient_occlusion_of_an_open_plane_is_exactly_one() {
    let scene = r#"{
      "camera": {"type": "orthographic", "width_m": 4,
                 "transform": {"look_at": {"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 0, -1]}}},
      "film": {"resolution": [24, 24], "filter": "gaussian"},
      "integrator": {"type": "ambient_occlusion", "samples": 4},
      "shapes": [{"type": "rectangle", "size_m": [10, 10],
                  "transform": {"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}}]
    }"#;
    for y in rendered_visibility(scene, 8) {
        assert_eq!(y, 1.0);
    }
}

/// Cosine-weighted fraction of the hemisphere above (x, 0, 0) (normal +y) whose rays hit
/// the rectangle x = 0, 0 ≤ y ≤ h, |z| ≤ length/2, by midpoint quadrature in (θ, φ).
fn occluded_fraction_quadrature(x: f64, h: f64, length: f64) -> f64 {
    let (n_theta, n_phi) = (1500usize, 3000usize);
    let (d_theta, d_phi) = (
        std::f64::consts::FRAC_PI_2 / n_theta as f64,
        2.0 * std::f64::consts::PI / n_phi as f64,
    );
    let mut sum = 0.0;
    for i in 0..n_theta {
        let theta = (i as f64 + 0.5) * d_theta;
        let (s, c) = theta.sin_cos();
        let mut hits = 0usize;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * d_phi;
            let d = [s * phi.cos(), c, s * phi.sin()];
            if d[0] < 0.0 {
                let t = x / -d[0];
                if t * d[1] <= h && (t * d[2]).abs() <= 0.5 * length {
                    hits += 1;
                }
            }
        }
        sum += hits as f64 * c * s * d_theta * d_phi;
    }
    sum / std::f64::consts::PI
}

fn wall_scene(x: f64, h: f64, length: f64) -> String {
    format!(
        r#"{{
      "camera": {{"type": "orthographic", "width_m": 0.0001,
                 "transform": {{"look_at": {{"eye": [{x}, 0.5, 0], "target": [{x}, 0, 0], "up": [0, 0, -1]}}}}}},
      "film": {{"resolution": [1, 1], "filter": "box"}},
      "integrator": {{"type": "ambient_occlusion", "samples": 1}},
      "shapes": [
        {{"type": "rectangle", "size_m": [{floor}, {floor}],
          "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
        {{"type": "rectangle", "size_m": [{length}, {h}],
          "transform": [{{"rotate": {{"axis": [0, 1, 0], "angle_deg": 90}}}}, {{"translate": [0, {half_h}, 0]}}]}}
      ]
    }}"#,
        floor = 4.0 * length,
        half_h = 0.5 * h
    )
}

#[test]
fn ambient_occlusion_beside_a_wall_matches_the_view_factor() {
    let length = 2000.0;
    let spp = 16_384;
    for (x, h) in [(0.25f64, 1.0f64), (1.0, 1.0), (0.5, 0.3), (0.5, 1000.0)] {
        let closed_form_occluded = 0.5 * (1.0 - x / (x * x + h * h).sqrt());
        let quadrature = occluded_fraction_quadrature(x, h, length);
        assert!(
            (quadrature - closed_form_occluded).abs() < 2e-3,
            "x {x} h {h}: quadrature {quadrature} vs closed form {closed_form_occluded}"
        );
        let expected = 1.0 - quadrature;
        let ao = f64::from(rendered_visibility(&wall_scene(x, h, length), spp)[0]);
        // Each sample is a Bernoulli(AO) variable: standard error √(AO(1 − AO)/N).
        let standard_error = (expected * (1.0 - expected) / f64::from(spp)).sqrt();
        assert!(
            (ao - expected).abs() < 4.0 * standard_error,
            "x {x} h {h}: AO {ao}, expected {expected} ± {standard_error}"
        );
    }
    // Infinitely high wall: exactly half the cosine-weighted hemisphere is occluded.
    let q = occluded_fraction_quadrature(0.5, 1e9, 1e12);
    assert!((q - 0.5).abs() < 1e-3, "{q}");
}

#[test]
fn max_distance_ignores_far_occluders() {
    // A 1 m high wall 0.5 m away: with max distance 0.01 m no occlusion ray reaches it.
    let scene = wall_scene(0.5, 1.0, 2000.0).replace(
        r#""samples": 1}"#,
        r#""samples": 1, "max_distance_m": 0.01}"#,
    );
    assert!(scene.contains("max_distance_m"));
    assert_eq!(rendered_visibility(&scene, 256)[0], 1.0);
}

#[test]
fn resolution_override_is_used() {
    let description = parse_scene_str(&wall_scene(0.5, 1.0, 10.0), "test.json").unwrap();
    let scene = RenderScene::build(&description, Some(UVec2::new(3, 2))).unwrap();
    assert_eq!(scene.resolution, UVec2::new(3, 2));
}
