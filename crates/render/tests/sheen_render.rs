//! The `sheen` material end to end: a scene's `{"type": "sheen", …}` renders, in a white
//! furnace (a `sky` of radiance 1), as its directional albedo ∫ f cos θᵢ dωᵢ, which this
//! test integrates itself from `Sheen::eval` (midpoint rule; neither `sample` nor `albedo`
//! is involved). A large plane seen by an orthographic camera gives every pixel the same
//! exit angle, so the pixels' mean is compared with one number per angle. Also: the
//! roughness outside [0.1, 1] is refused at its JSON path.

use glam::Vec3A;
use prism_render::bsdf::{Bxdf, Sheen, TransportMode};
use prism_render::{render, RenderScene, RenderSettings};
use prism_scene::parse_scene_str;
use prism_spectrum::SampledSpectrum;

const REFLECTANCE: f64 = 0.8;

/// The scene: a sheen plane (normal +y) seen at `theta_deg` from its normal, from 10 m away
/// (so that the whole film is above the plane at grazing views).
fn furnace_scene(roughness: f64, theta_deg: f64) -> String {
    let (s, c) = theta_deg.to_radians().sin_cos();
    let (s, c) = (10.0 * s, 10.0 * c);
    format!(
        r#"{{
  "camera": {{"type": "orthographic", "width_m": 2,
              "transform": {{"look_at": {{"eye": [0, {c}, {s}], "target": [0, 0, 0], "up": [0, 0, -1]}}}}}},
  "film": {{"resolution": [16, 16], "filter": {{"type": "box", "radius_px": 0.5}}}},
  "integrator": {{"type": "path", "max_depth": 4, "sampler": "independent"}},
  "materials": {{"velvet": {{"type": "sheen", "reflectance": {REFLECTANCE}, "roughness": {roughness}}}}},
  "shapes": [{{"type": "rectangle", "size_m": [40, 40],
               "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}, "material": "velvet"}}],
  "lights": [{{"type": "sky", "spectrum": 1.0, "scale": 1.0}}]
}}"#
    )
}

/// ∫ f(ωₒ, ωᵢ) cos θᵢ dωᵢ over the upper hemisphere by the midpoint rule in (cos θᵢ, φᵢ),
/// f64 sums (f cos θᵢ stays bounded at grazing ωᵢ: D G / (4 cos θₒ)).
fn albedo_by_quadrature(lobe: &Sheen, wo: Vec3A) -> f64 {
    let (n_mu, n_phi) = (400, 800);
    let (d_mu, d_phi) = (1.0 / n_mu as f64, std::f64::consts::TAU / n_phi as f64);
    let mut sum = 0.0f64;
    for i in 0..n_mu {
        let mu = (i as f64 + 0.5) * d_mu;
        let sin = (1.0 - mu * mu).sqrt();
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * d_phi;
            let wi = Vec3A::new(
                (sin * phi.cos()) as f32,
                (sin * phi.sin()) as f32,
                mu as f32,
            );
            sum += f64::from(lobe.eval(wo, wi, TransportMode::Radiance)[0]) * mu;
        }
    }
    sum * d_mu * d_phi
}

#[test]
fn a_sheen_plane_in_a_white_furnace_renders_as_its_albedo() {
    let mut report = Vec::new();
    for roughness in [0.3, 1.0] {
        for theta_deg in [0.0, 70.0] {
            let json = furnace_scene(roughness, theta_deg);
            let description = parse_scene_str(&json, "sheen.json").expect("scene parses");
            let scene = RenderScene::build(&description, None).expect("scene builds");
            let settings = RenderSettings {
                spp: 64,
                seed: 5,
                ..RenderSettings::default()
            };
            let (image, _) = render(&scene, &settings, &|_| {});
            let n = image.y.len() as f64;
            let mean = image.y.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
            let sd = (image
                .y
                .iter()
                .map(|&v| (f64::from(v) - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0))
                .sqrt();
            let se = sd / n.sqrt();

            let lobe = Sheen {
                reflectance: SampledSpectrum::splat(REFLECTANCE as f32),
                roughness: roughness as f32,
            };
            let t = (theta_deg as f32).to_radians();
            let wo = Vec3A::new(0.0, t.sin(), t.cos());
            let expected = albedo_by_quadrature(&lobe, wo);
            report.push(format!(
                "r {roughness} θₒ {theta_deg}°: rendered {mean:.4} ± {se:.4}, ∫ f cos {expected:.4}"
            ));
            // 5 standard errors of the pixels' mean, plus the quadrature's error.
            assert!(
                (mean - expected).abs() <= 5.0 * se + 1e-3,
                "r {roughness} θₒ {theta_deg}°: rendered {mean} ± {se}, expected {expected}"
            );
            // A sheen reflects some light at every angle: a test of a black image cannot pass.
            assert!(expected > 0.02, "albedo {expected}");
        }
    }
    eprintln!("{}", report.join("\n"));
}

#[test]
fn sheen_roughness_outside_its_range_is_refused_at_its_place() {
    for (roughness, what) in [("0.05", "0.05"), ("1.5", "1.5")] {
        let json = furnace_scene(0.5, 0.0).replace(
            r#""roughness": 0.5"#,
            &format!(r#""roughness": {roughness}"#),
        );
        let err = parse_scene_str(&json, "sheen.json")
            .expect_err("roughness out of range")
            .to_string();
        assert!(
            err.contains("materials.velvet.roughness") && err.contains(what),
            "{err}"
        );
    }
    let json = furnace_scene(0.5, 0.0).replace(r#", "roughness": 0.5"#, "");
    let err = parse_scene_str(&json, "sheen.json")
        .expect_err("roughness is required")
        .to_string();
    assert!(err.contains("roughness"), "{err}");
}
