//! The shading probe seam with the closed-form mock: a point light over a Lambertian plane.
//! Its samples reproduce the inverse-square law and Lambert's cosine law exactly, eq. 5's
//! weighted mean of equal bandwidths is that bandwidth, and the probe works through
//! `&dyn ShadingProbe` over a whole G-buffer.

use glam::{UVec2, Vec3A};
use prism_bandwidth::{
    Bandwidth, GBuffer, GBufferHit, LightSample, MaterialBandwidth, MockProbe, SamplePlan,
    ShadingProbe,
};
use prism_geometry::Curvature;

/// A G-buffer of a plane y = 0 seen from above: pixel (i, j) hits (i, 0, j), normal +Y.
fn plane_gbuffer(resolution: UVec2) -> GBuffer {
    let camera = Vec3A::new(0.0, 5.0, 0.0);
    let mut g = GBuffer::new(resolution).unwrap();
    for j in 0..resolution.y {
        for i in 0..resolution.x {
            let p = Vec3A::new(i as f32, 0.0, j as f32);
            let to_camera = camera - p;
            let hit = GBufferHit::new(
                p,
                to_camera.length(),
                Vec3A::Y,
                Curvature::default(),
                to_camera.normalize(),
                0,
            )
            .unwrap();
            g.set(UVec2::new(i, j), Some(hit)).unwrap();
        }
    }
    g
}

fn probe() -> MockProbe {
    MockProbe {
        light_position_m: Vec3A::new(0.0, 2.0, 0.0),
        intensity_y: 8.0,
        albedo: 0.5,
        light_bandwidth: Bandwidth::area_light(3.0).unwrap(),
        material_bandwidth: MaterialBandwidth::new(0.0, 0.0).unwrap(),
    }
}

#[test]
fn mock_samples_follow_the_inverse_square_and_cosine_laws() {
    let g = plane_gbuffer(UVec2::new(3, 1));
    let p: &dyn ShadingProbe = &probe();
    let mut out = vec![];
    // Under the light: d = 2 m, E⊥ = 8/4 = 2, cos = 1, BSDF·cos = 0.5/π.
    p.sample_lights(UVec2::ZERO, g.hit(UVec2::ZERO).unwrap(), 4, &mut out);
    assert_eq!(out.len(), 4);
    let s = out[0];
    assert!(s.is_delta() && s.distance_m == 2.0 && s.cos_theta_i == 1.0);
    assert_eq!(s.radiance_y, 2.0);
    let reflected = 2.0 * 0.5 / std::f32::consts::PI;
    assert!((s.weight_y() - reflected).abs() < 1e-6);
    assert!((s.chi_y() - reflected).abs() < 1e-6);
    // 2 m to the side: d = √8, cos θ = 2/√8, E = I cos/d² = 8 · 0.7071 / 8.
    p.sample_lights(
        UVec2::new(2, 0),
        g.hit(UVec2::new(2, 0)).unwrap(),
        1,
        &mut out,
    );
    assert_eq!(out.len(), 1, "out is cleared first");
    let s = out[0];
    let cos = 2.0 / 8f32.sqrt();
    assert!((s.cos_theta_i - cos).abs() < 1e-6);
    assert!((s.weight_y() - 8.0 / 8.0 * cos * 0.5 / std::f32::consts::PI).abs() < 1e-6);
    assert!((s.direction.length() - 1.0).abs() < 1e-6);
    // A light below the tangent plane gives nothing.
    let below = MockProbe {
        light_position_m: Vec3A::new(0.0, -1.0, 0.0),
        ..probe()
    };
    below.sample_lights(UVec2::ZERO, g.hit(UVec2::ZERO).unwrap(), 4, &mut out);
    assert!(out.is_empty());
}

/// Bagher eq. 5: ν = Σ wᵢ νⁱ / Σ wᵢ (here with the light's bandwidth standing in for νⁱ).
fn weighted_mean_bandwidth(samples: &[LightSample]) -> Option<Bandwidth> {
    let total: f32 = samples.iter().map(LightSample::weight_y).sum();
    (total > 0.0).then(|| Bandwidth {
        spatial_cycles_per_m: samples
            .iter()
            .map(|s| s.weight_y() * s.light_bandwidth.spatial_cycles_per_m)
            .sum::<f32>()
            / total,
        angular_cycles_per_rad: samples
            .iter()
            .map(|s| s.weight_y() * s.light_bandwidth.angular_cycles_per_rad)
            .sum::<f32>()
            / total,
    })
}

#[test]
fn a_predictor_loop_over_the_gbuffer_and_plan_runs_through_the_trait() {
    let resolution = UVec2::new(4, 3);
    let g = plane_gbuffer(resolution);
    let plan = SamplePlan::uniform(resolution, 8).unwrap();
    plan.check_resolution(g.resolution()).unwrap();
    let probe: Box<dyn ShadingProbe> = Box::new(probe());
    let mut samples = Vec::new();
    let mut probed = 0;
    for (pixel, hit) in g.iter_hits() {
        probe.sample_lights(pixel, hit, plan.light_samples(pixel) * 16, &mut samples);
        assert_eq!(samples.len(), 16);
        // Equal bandwidths on every path: eq. 5 gives exactly that bandwidth.
        let nu = weighted_mean_bandwidth(&samples).unwrap();
        assert!((nu.spatial_cycles_per_m - 3.0).abs() < 1e-5);
        assert_eq!(nu.angular_cycles_per_rad, 0.0);
        probed += 1;
    }
    assert_eq!(probed, 12);
}
