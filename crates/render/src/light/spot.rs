//! A spot light: a point source whose intensity falls off with the angle θ from its axis
//! (pbrt-v4 §12.2.2 `SpotLight`).
//!
//! I(θ) = I₀(λ) · smoothstep(cos θ; cos θ_cone, cos θ_start), with
//! smoothstep(x; a, b) = t²(3 − 2t), t = clamp((x − a)/(b − a), 0, 1), and a hard edge
//! (I₀ inside the cone, 0 outside) when θ_start = θ_cone. Full intensity inside the
//! falloff start θ_start, none beyond the cone half-angle θ_cone; the smoothstep is taken
//! in cos θ, not in θ.
//!
//! Flux: Φ = ∫ I dω = 2π I₀ [(1 − cos θ_start) + (cos θ_start − cos θ_cone)/2], exact
//! because ∫₀¹ t²(3 − 2t) dt = ½ (pbrt-v4 `SpotLight::Phi`).
//!
//! Emitted rays: directions with density I(ω)/Φ (pbrt-v4 §12.2.2 `SpotLight::SampleLe`):
//! the inner cone (uniform) or the falloff ring (cos θ by the smoothstep density, φ
//! uniform), chosen in proportion to their shares of Φ, so pdf_dir = falloff(cos θ) / Ω_f
//! with Ω_f = Φ / I₀ and I/pdf_dir = I₀ Ω_f for every direction.

use std::f64::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::Frame;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::point::{integrate_nm, point_emission, point_emitter_sample};
use super::scene_sphere::SceneSphere;
use super::warp::{sample_smoothstep, sample_uniform_cone};
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};

#[derive(Clone, Debug, PartialEq)]
pub struct SpotLight {
    /// Position, metres (world).
    pub position_m: Vec3A,
    /// Unit beam axis (world), the direction the light shines in.
    pub axis: Vec3A,
    /// On-axis radiant intensity I₀(λ), W·sr⁻¹·nm⁻¹ (absolute).
    pub intensity: Spectrum,
    /// cos of the cone half-angle: no light beyond it.
    pub cos_cone: f32,
    /// cos of the falloff start angle (≥ `cos_cone`): full intensity inside it.
    pub cos_falloff_start: f32,
}

/// smoothstep(x; a, b) = t²(3 − 2t), t = clamp((x − a)/(b − a), 0, 1); a step at a = b
/// (pbrt-v4 `SmoothStep`).
#[inline]
pub fn smoothstep(x: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl SpotLight {
    /// From angles in radians: `cone_angle_rad` ∈ (0, π/2], `falloff_start_rad` ∈
    /// [0, cone_angle_rad].
    pub fn new(
        position_m: Vec3A,
        axis: Vec3A,
        cone_angle_rad: f64,
        falloff_start_rad: f64,
        intensity: Spectrum,
    ) -> Self {
        let start = falloff_start_rad.clamp(0.0, cone_angle_rad);
        Self {
            position_m,
            axis: axis.normalize_or(Vec3A::NEG_Y),
            intensity,
            cos_cone: cone_angle_rad.cos() as f32,
            cos_falloff_start: start.cos() as f32,
        }
    }

    /// The falloff factor I(θ)/I₀ for cos θ.
    #[inline]
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        smoothstep(cos_theta, self.cos_cone, self.cos_falloff_start)
    }

    /// Solid-angle integral of the falloff, ∫ I(ω)/I₀ dω in sr: Φ = I₀ × this.
    pub fn falloff_solid_angle_sr(&self) -> f64 {
        solid_angle_of_falloff(f64::from(self.cos_cone), f64::from(self.cos_falloff_start))
    }

    /// A direction in the spot's frame (+Z the axis) with density ∝ falloff(cos θ): the
    /// inner cone with probability (1 − cos θ_start) / (Ω_f / 2π), else the ring.
    #[inline]
    fn sample_falloff_local(&self, u: Vec2) -> Vec3A {
        let inner = 1.0 - self.cos_falloff_start;
        let ring = 0.5 * (self.cos_falloff_start - self.cos_cone);
        let p_inner = inner / (inner + ring);
        if u.x < p_inner {
            let ux = (u.x / p_inner).min(1.0f32.next_down());
            return sample_uniform_cone(Vec2::new(ux, u.y), inner);
        }
        let ux = ((u.x - p_inner) / (1.0 - p_inner)).clamp(0.0, 1.0);
        let t = sample_smoothstep(ux);
        let cos_theta = self.cos_cone + t * (self.cos_falloff_start - self.cos_cone);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * std::f32::consts::PI * u.y).sin_cos();
        Vec3A::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
    }

    /// pdf_dir of `sample_le` along the unit `direction`: falloff(cos θ) / Ω_f.
    #[inline]
    fn direction_pdf(&self, direction: Vec3A) -> f32 {
        let solid_angle = self.falloff_solid_angle_sr() as f32;
        if solid_angle > 0.0 {
            self.falloff(direction.dot(self.axis)) / solid_angle
        } else {
            0.0
        }
    }
}

impl LightSource for SpotLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        point_emitter_sample(ctx, self.position_m, |out| {
            let falloff = self.falloff(out.dot(self.axis));
            (falloff > 0.0).then(|| self.intensity.eval(wavelengths) * falloff)
        })
    }

    #[inline]
    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        0.0
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    #[inline]
    fn infinite_radiance(&self, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    fn sample_le(
        &self,
        _scene: &SceneSphere,
        _u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let local = self.sample_falloff_local(u_dir);
        let w = Frame::from_z(self.axis).from_local(local).normalize();
        // The density of the direction as returned (the same function as `pdf_le`).
        let falloff = self.falloff(w.dot(self.axis));
        let pdf_dir = self.direction_pdf(w);
        if !(pdf_dir > 0.0 && pdf_dir < f32::INFINITY) {
            return None;
        }
        Some(point_emission(
            self.position_m,
            w,
            self.intensity.eval(wavelengths) * falloff,
            pdf_dir,
        ))
    }

    fn pdf_le(&self, _: &SceneSphere, _origin: Vec3A, _n: Vec3A, direction: Vec3A) -> (f32, f32) {
        (1.0, self.direction_pdf(direction))
    }

    /// Φ = I₀ · 2π [(1 − cos θ_start) + (cos θ_start − cos θ_cone)/2] integrated over λ, W.
    fn power_w(&self, _scene_radius_m: f32) -> f64 {
        integrate_nm(&self.intensity) * self.falloff_solid_angle_sr()
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::point_like()
    }

    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    #[inline]
    fn is_infinite(&self) -> bool {
        false
    }
}

/// 2π [(1 − c_start) + (c_start − c_cone)/2]: the solid angle of full intensity plus half
/// the falloff ring (∫ smoothstep d cos θ over the ring is half its width).
pub fn solid_angle_of_falloff(cos_cone: f64, cos_falloff_start: f64) -> f64 {
    2.0 * PI * ((1.0 - cos_falloff_start) + 0.5 * (cos_falloff_start - cos_cone))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_support::{build_scene, photometric_sum};

    fn spot(cone_deg: f64, start_deg: f64) -> SpotLight {
        SpotLight::new(
            Vec3A::ZERO,
            Vec3A::NEG_Y,
            cone_deg.to_radians(),
            start_deg.to_radians(),
            Spectrum::constant(1.0),
        )
    }

    #[test]
    fn falloff_is_one_inside_the_start_zero_outside_the_cone_and_smooth_between() {
        let s = spot(30.0, 20.0);
        assert_eq!(s.falloff(15f32.to_radians().cos()), 1.0);
        assert_eq!(s.falloff(31f32.to_radians().cos()), 0.0);
        let (a, b) = (30f32.to_radians().cos(), 20f32.to_radians().cos());
        let mid = 0.5 * (a + b);
        assert!((s.falloff(mid) - 0.5).abs() < 1e-5);
        // Hard edge.
        let h = spot(30.0, 30.0);
        assert_eq!(h.falloff(29.9f32.to_radians().cos()), 1.0);
        assert_eq!(h.falloff(30.1f32.to_radians().cos()), 0.0);
    }

    #[test]
    fn flux_formula_is_the_integral_of_the_falloff() {
        // ∫ falloff dω = 2π ∫ falloff(cos θ) d cos θ, midpoint rule in cos θ.
        for (cone, start) in [(30.0, 25.0), (60.0, 0.0), (90.0, 45.0), (10.0, 10.0)] {
            let s = spot(cone, start);
            let n = 200_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                sum += f64::from(s.falloff(c as f32));
            }
            let numeric = 2.0 * PI * sum * 2.0 / n as f64;
            let exact = s.falloff_solid_angle_sr();
            // The midpoint rule misplaces a hard edge by up to one step, 2/n in cos θ.
            let tolerance = 2.0 * PI * 2.0 / n as f64 + 1e-6 * exact;
            assert!(
                (numeric - exact).abs() < tolerance,
                "{cone}/{start}: {numeric} vs {exact}"
            );
        }
    }

    #[test]
    fn a_point_outside_the_cone_gets_nothing_and_inside_the_inverse_square_law() {
        let s = spot(30.0, 20.0);
        let wl = SampledWavelengths::sample_uniform(0.3);
        let below = LightSampleContext {
            p: Vec3A::new(0.0, -2.0, 0.0),
            n: Vec3A::Y,
        };
        let ls = s.sample_li(&below, Vec2::ZERO, &wl).unwrap();
        assert!(ls.delta && ls.pdf == 1.0);
        assert!((ls.radiance.to_array()[0] - 0.25).abs() < 1e-6);
        let beside = LightSampleContext {
            p: Vec3A::new(2.0, -0.5, 0.0),
            n: Vec3A::Y,
        };
        assert!(s.sample_li(&beside, Vec2::ZERO, &wl).is_none());
    }

    #[test]
    fn spot_light_flux_and_intensity_are_exact() {
        // Φ lm → on-axis I₀ = Φ / (2π[(1 − cos θ_start) + (cos θ_start − cos θ_cone)/2]).
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"lights": [
            {"type": "spot", "position_m": [0, 3, 0], "target_m": [0, 0, 0], "cone_angle_deg": 25,
             "falloff_start_deg": 15, "power_lm": 1200, "spectrum": {"blackbody_k": 3200}},
            {"type": "spot", "position_m": [0, 3, 0], "direction": [0, -1, 0], "intensity_cd": 800}]}"#;
        let (_, lights) = build_scene(dir.path(), json).unwrap();
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::Y,
        };
        let on_axis_cd = |k: u32| {
            9.0 * photometric_sum(|wl| {
                lights
                    .light(k)
                    .sample_li(&ctx, Vec2::ZERO, wl)
                    .unwrap()
                    .radiance
            })
        };
        let (c, s) = (25f64.to_radians().cos(), 15f64.to_radians().cos());
        let exact = 1200.0 / (2.0 * PI * ((1.0 - s) + (s - c) / 2.0));
        let i0 = on_axis_cd(0);
        assert!((i0 - exact).abs() < 1e-4 * exact, "{i0} vs {exact}");
        assert!((on_axis_cd(1) - 800.0).abs() < 1e-4 * 800.0);
    }
}
