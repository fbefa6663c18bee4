//! A tiny [`ShadingProbe`] with a closed-form answer, for tests of the predictor before
//! render implements the real one: one isotropic point light above Lambertian surfaces.
//!
//! At a hit x with normal n, for the light at P with intensity I (the Y of its radiant
//! intensity, W·sr⁻¹ in the output normalisation): ω_i = (P − x)/d, d = ‖P − x‖, the irradiance at normal incidence
//! E⊥ = I/d² (inverse-square law), and the Lambertian BSDF·cos = (albedo/π) · (n·ω_i). A
//! point light is a delta light (pdf 0), so every one of the `count` samples is the same
//! direction; none when the light is below the hit's tangent plane.

use glam::{UVec2, Vec3A};

use crate::bandwidth::{Bandwidth, MaterialBandwidth};
use crate::gbuffer::GBufferHit;
use crate::probe::{LightSample, ShadingProbe};
use crate::visibility::Visibility;

/// A point light over Lambertian surfaces (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MockProbe {
    /// P, world space, metres.
    pub light_position_m: Vec3A,
    /// I: Y of the radiant intensity, W·sr⁻¹ in the output normalisation.
    pub intensity_y: f32,
    /// Lambertian albedo of every surface, in [0, 1].
    pub albedo: f32,
    /// ν_l reported for every sample.
    pub light_bandwidth: Bandwidth,
    /// ρ and t reported for every sample.
    pub material_bandwidth: MaterialBandwidth,
}

impl ShadingProbe for MockProbe {
    fn sample_lights(
        &self,
        _pixel: UVec2,
        hit: &GBufferHit,
        count: u32,
        out: &mut Vec<LightSample>,
    ) -> u32 {
        out.clear();
        let to_light = self.light_position_m - hit.position_m();
        let distance_m = to_light.length();
        // The hit at the light itself (d = 0) or non-finite input: no direction.
        if distance_m.is_nan() || distance_m <= 0.0 || distance_m.is_infinite() {
            return count;
        }
        let direction = to_light / distance_m;
        let cos_theta_i = hit.normal().dot(direction);
        if cos_theta_i <= 0.0 {
            return count;
        }
        let radiance_y = self.intensity_y / (distance_m * distance_m);
        let bsdf_cos_per_sr = self.albedo * std::f32::consts::FRAC_1_PI * cos_theta_i;
        let sample = LightSample {
            direction,
            radiance_y,
            pdf_per_sr: 0.0,
            bsdf_cos_per_sr,
            cos_theta_i,
            distance_m,
            light_bandwidth: self.light_bandwidth,
            emitter_bandwidth: self.light_bandwidth,
            light_index: 0,
            material_bandwidth: self.material_bandwidth,
            lane_variance: 0.0,
            visibility: Visibility::Unknown,
            // One light, one direction: every draw is the whole estimate.
            estimator_y: radiance_y * bsdf_cos_per_sr,
            draw: 0,
        };
        out.extend((0..count).map(|draw| LightSample { draw, ..sample }));
        count
    }
}
