//! Render's implementation of prism-bandwidth's `ShadingProbe` (Bagher et al. 2013,
//! eqs. 4, 5, 9): at a G-buffer hit, sampled light directions with the incident radiance,
//! BSDF·cos, distance and the light's and material's bandwidths, so the predictor never
//! depends on render.
//!
//! Values are luminance-like Y in the output normalisation (prism-bandwidth's probe docs),
//! estimated from one set of hero wavelengths per sample. Occlusion is ignored, as in
//! Bagher's eq. 1.
//!
//! Bandwidths (cycles per metre / per radian), stated choices:
//! - point, spot, ideal directional light: a Dirac in angle, ν_a = ∞, ν_s = 0;
//! - area light of area A: a box of width √A in space, ν_s = 1/√A, ν_a = 0 (Lambertian);
//! - sun of angular diameter α: ν_a = 1/α; uniform sky: 0;
//! - environment map W texels wide: its Nyquist rate, ν_a = W / 4π (W/2 cycles per 2π);
//! - Lambert: ρ = 0; microfacet lobe of roughness α (radians of slope spread): a lobe of
//!   angular standard deviation ≈ α has spectrum width 1/(2πα); Dirac lobes: ∞.

use glam::{UVec2, Vec2, Vec3A};
use prism_bandwidth::{Bandwidth, GBufferHit, LightSample, MaterialBandwidth, ShadingProbe};
use prism_geometry::{Differentials, Frame, SurfaceInteraction};
use prism_spectrum::colorimetry::sampled_radiance_to_xyz;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use crate::bsdf::{Bsdf, Bxdf, TransportMode};
use crate::light::{Light, LightSampleContext};
use crate::sampler::{PixelSampler, SamplerKind};
use crate::scene_build::RenderScene;

/// A `ShadingProbe` over a built scene.
pub struct RenderProbe<'a> {
    pub scene: &'a RenderScene,
    pub seed: u64,
}

/// ν_l of a light (see the module docs; the choices live in `light/bandwidth.rs`).
pub fn light_bandwidth(light: &Light) -> Bandwidth {
    light.bandwidth()
}

/// ρ of a BSDF (see the module docs): each lobe's `Bxdf::angular_bandwidth_cycles_per_rad`.
pub fn material_bandwidth(bsdf: &Bsdf) -> MaterialBandwidth {
    MaterialBandwidth {
        angular_cycles_per_rad: bsdf.lobe.angular_bandwidth_cycles_per_rad(),
        texture_cycles_per_m: 0.0,
    }
}

/// Y of a spectral quantity at `wavelengths` (hero-wavelength estimate).
fn luminance_y(s: SampledSpectrum, wavelengths: &SampledWavelengths) -> f32 {
    sampled_radiance_to_xyz(s, wavelengths).y as f32
}

/// The ȳ-weighted mean of a BSDF value over the lanes (a white Lambertian gives 1/π).
fn reflectance_y(f: SampledSpectrum, wavelengths: &SampledWavelengths) -> f32 {
    let ones = luminance_y(SampledSpectrum::splat(1.0), wavelengths);
    if ones > 0.0 {
        luminance_y(f, wavelengths) / ones
    } else {
        0.0
    }
}

fn hit_interaction(hit: &GBufferHit) -> SurfaceInteraction {
    let n = hit.normal();
    let frame = Frame::from_z(n);
    SurfaceInteraction {
        p: hit.position_m(),
        t: hit.depth_m(),
        n_geometric: n,
        n_shading: n,
        uv: Vec2::ZERO,
        dpdu: frame.x,
        dpdv: frame.y,
        dndu: Vec3A::ZERO,
        dndv: Vec3A::ZERO,
        curvature: hit.curvature(),
        differentials: Differentials::default(),
        primitive_id: 0,
        material_id: hit.material_id(),
        object_id: 0,
        instance_id: 0,
    }
}

impl ShadingProbe for RenderProbe<'_> {
    fn sample_lights(
        &self,
        pixel: UVec2,
        hit: &GBufferHit,
        count: u32,
        out: &mut Vec<LightSample>,
    ) {
        out.clear();
        let lights = &self.scene.lights;
        if lights.is_empty() {
            return;
        }
        let si = hit_interaction(hit);
        let material = self.scene.material(hit.material_id());
        let frame = Frame::from_zx(si.n_shading, si.dpdu);
        let wo_local = frame.to_local(hit.view_direction());
        let ctx = LightSampleContext {
            p: si.p,
            n: si.n_geometric,
        };
        let sampler = PixelSampler::with_kind(SamplerKind::Independent, self.seed);
        for k in 0..count {
            let mut stream = sampler.stream(pixel, k);
            let wavelengths = SampledWavelengths::sample_visible(stream.get_1d());
            let bsdf = material.bsdf(&si, &wavelengths);
            let Some((l, pmf)) = lights.sample(stream.get_1d()) else {
                continue;
            };
            let light = lights.light(l);
            let Some(ls) = light.sample_li(&ctx, stream.get_2d(), &wavelengths) else {
                continue;
            };
            let wi_local = frame.to_local(ls.wi);
            let cos = wi_local.z.abs();
            let f = bsdf.eval(wo_local, wi_local, TransportMode::Radiance) * cos;
            out.push(LightSample {
                direction: ls.wi,
                radiance_y: luminance_y(ls.radiance, &wavelengths),
                pdf_per_sr: if ls.delta { 0.0 } else { pmf * ls.pdf },
                bsdf_cos_per_sr: reflectance_y(f, &wavelengths),
                cos_theta_i: cos,
                distance_m: ls.distance_m,
                light_bandwidth: light_bandwidth(light),
                material_bandwidth: material_bandwidth(&bsdf),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_geometry::Curvature;
    use prism_scene::parse_scene_str;

    #[test]
    fn probe_at_a_lambertian_hit_under_a_point_light_gives_i_over_d2_and_one_over_pi() {
        let json = r#"{"materials": {"white": {"type": "lambert", "reflectance": 1.0}},
            "shapes": [{"type": "sphere", "material": "white"}],
            "lights": [{"type": "point", "position_m": [0, 3, 0], "spectrum": 1.0, "scale": 2.0}]}"#;
        let scene = RenderScene::build(&parse_scene_str(json, "t.json").unwrap(), None).unwrap();
        let probe = RenderProbe {
            scene: &scene,
            seed: 1,
        };
        let hit = GBufferHit::new(
            Vec3A::new(0.0, 1.0, 0.0),
            2.0,
            Vec3A::Y,
            Curvature::default(),
            Vec3A::Y,
            0,
        )
        .unwrap();
        let mut out = Vec::new();
        probe.sample_lights(UVec2::new(3, 4), &hit, 64, &mut out);
        assert_eq!(out.len(), 64);
        let values: Vec<f64> = out.iter().map(|s| f64::from(s.radiance_y)).collect();
        let mean_radiance = values.iter().sum::<f64>() / 64.0;
        let sd = (values
            .iter()
            .map(|v| (v - mean_radiance).powi(2))
            .sum::<f64>()
            / 63.0)
            .sqrt();
        // I/d² = 2/4 at the hit; Y of a flat spectrum is exact in expectation: 5 standard
        // errors of the hero-wavelength estimate.
        assert!(
            (mean_radiance - 0.5).abs() < 5.0 * sd / 8.0,
            "{mean_radiance} (sd {sd})"
        );
        for s in &out {
            assert!(s.is_delta());
            assert!((s.bsdf_cos_per_sr - 1.0 / std::f32::consts::PI).abs() < 1e-4);
            assert!((s.distance_m - 2.0).abs() < 1e-5);
            assert_eq!(s.material_bandwidth.angular_cycles_per_rad, 0.0);
            assert!(s.light_bandwidth.angular_cycles_per_rad.is_infinite());
        }
        // Deterministic per pixel.
        let mut again = Vec::new();
        probe.sample_lights(UVec2::new(3, 4), &hit, 64, &mut again);
        assert_eq!(out, again);
    }
}
