//! An isotropic point light: intensity I(λ) in W·sr⁻¹·nm⁻¹ in every direction; the
//! irradiance at distance d on a surface facing it is I/d² (inverse-square law). Emitted
//! rays leave it uniformly over the sphere, pdf_dir = 1/4π (pbrt-v4 §12.2.1
//! `PointLight::SampleLe`).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::Ray;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::scene_sphere::SceneSphere;
use super::warp::sample_uniform_sphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};

#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    /// Position, metres (world).
    pub position_m: Vec3A,
    /// Radiant intensity I(λ), W·sr⁻¹·nm⁻¹ (absolute: photometric strengths are applied).
    pub intensity: Spectrum,
}

impl LightSource for PointLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        point_emitter_sample(ctx, self.position_m, |_| {
            Some(self.intensity.eval(wavelengths))
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

    #[inline]
    fn sample_le(
        &self,
        _scene: &SceneSphere,
        _u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        Some(point_emission(
            self.position_m,
            sample_uniform_sphere(u_dir),
            self.intensity.eval(wavelengths),
            1.0 / (4.0 * PI),
        ))
    }

    #[inline]
    fn pdf_le(&self, _: &SceneSphere, _origin: Vec3A, _n: Vec3A, _direction: Vec3A) -> (f32, f32) {
        (1.0, 1.0 / (4.0 * PI))
    }

    /// Φ = 4π ∫ I(λ) dλ, W.
    fn power_w(&self, _scene_radius_m: f32) -> f64 {
        4.0 * std::f64::consts::PI * integrate_nm(&self.intensity)
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

/// The emitted ray of a point emitter (point, spot, goniometric): from `position_m` along
/// the unit `direction`, with the intensity I(ω) as radiance and pdf_pos = 1 (a Dirac).
#[inline]
pub(crate) fn point_emission(
    position_m: Vec3A,
    direction: Vec3A,
    intensity: SampledSpectrum,
    pdf_dir: f32,
) -> LightLeSample {
    LightLeSample {
        ray: Ray::infinite(position_m, direction),
        n: Vec3A::ZERO,
        radiance: intensity,
        pdf_pos: 1.0,
        pdf_dir,
    }
}

/// The light sample of a point emitter at `position_m` seen from `ctx`: `intensity(ω)`
/// gives I(λ) in W·sr⁻¹·nm⁻¹ along the emitted direction ω (unit, from the light to the
/// receiver), or `None` where it is zero; the radiance is I/d² (inverse-square law) with
/// a Dirac pdf of 1. `None` at zero or non-finite distance.
#[inline]
pub(crate) fn point_emitter_sample(
    ctx: &LightSampleContext,
    position_m: Vec3A,
    intensity: impl FnOnce(Vec3A) -> Option<SampledSpectrum>,
) -> Option<LightSample> {
    let to = position_m - ctx.p;
    let d2 = to.length_squared();
    if d2 <= 0.0 || !d2.is_finite() {
        return None;
    }
    let d = d2.sqrt();
    let wi = to / d;
    Some(LightSample {
        wi,
        radiance: intensity(-wi)? * (1.0 / d2),
        pdf: 1.0,
        p_light: position_m,
        distance_m: d,
        delta: true,
        n_light: Vec3A::ZERO,
    })
}

/// ∫ S(λ) dλ over 360–830 nm at 1 nm (trapezoid), for light powers.
pub(crate) fn integrate_nm(s: &Spectrum) -> f64 {
    let mut sum = 0.0;
    for wl in 360..=830 {
        let w = if wl == 360 || wl == 830 { 0.5 } else { 1.0 };
        sum += w * s.eval_nm(f64::from(wl));
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_support::{build_error, build_scene, photometric_sum};
    use crate::light::Light;

    fn intensity_cd(light: &Light) -> f64 {
        let Light::Point(p) = light else { panic!() };
        photometric_sum(|wl| p.intensity.eval(wl))
    }

    #[test]
    fn point_light_of_1000_lm_has_1000_over_4pi_cd() {
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"lights": [{"type": "point", "power_lm": 1000, "spectrum": {"blackbody_k": 2700}},
            {"type": "point", "intensity_cd": 250, "spectrum": "F11"}]}"#;
        let (_, lights) = build_scene(dir.path(), json).unwrap();
        let i = intensity_cd(lights.light(0));
        let exact = 1000.0 / (4.0 * std::f64::consts::PI);
        assert!((i - exact).abs() < 1e-5 * exact, "{i} vs {exact}");
        assert!((intensity_cd(lights.light(1)) - 250.0).abs() < 1e-5 * 250.0);
    }

    #[test]
    fn point_light_illuminance_is_intensity_over_distance_squared() {
        let dir = tempfile::tempdir().unwrap();
        let json =
            r#"{"lights": [{"type": "point", "position_m": [1, 2, 3], "intensity_cd": 500}]}"#;
        let (_, lights) = build_scene(dir.path(), json).unwrap();
        for d in [0.5f32, 2.0, 7.0] {
            let to = Vec3A::new(2.0, -1.0, 2.0).normalize();
            let ctx = LightSampleContext {
                p: Vec3A::new(1.0, 2.0, 3.0) - to * d,
                n: to,
            };
            // Facing the light: E = I/d² (cos = 1, pdf = 1).
            let e = photometric_sum(|wl| {
                let s = lights.light(0).sample_li(&ctx, Vec2::ZERO, wl).unwrap();
                assert!(s.delta && (s.distance_m - d).abs() < 1e-5 * d);
                s.radiance * s.wi.dot(ctx.n)
            });
            let exact = 500.0 / f64::from(d * d);
            assert!((e - exact).abs() < 1e-5 * exact, "d {d}: {e} vs {exact}");
        }
    }

    #[test]
    fn photometric_strengths_a_kind_does_not_take_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"lights": [{"type": "point", "intensity_cd": 5}]}"#;
        let mut scene = prism_scene::parse_scene_str(json, dir.path().join("scene.json")).unwrap();
        scene.lights[0].strength = prism_scene::Strength::IlluminanceLx(3.0);
        let geometry = crate::scene_build::build_geometry(&scene).unwrap();
        let e = crate::light::LightSet::build(&scene, &geometry)
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("scene.json: lights[0].illuminance_lx: a point light does not take `illuminance_lx` (see docs/scene-format.md, lights)"), "{e}");
        scene.lights[0].strength = prism_scene::Strength::Scale(f64::NAN);
        let e = crate::light::LightSet::build(&scene, &geometry)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("lights[0].scale: expected a finite value ≥ 0, found NaN"),
            "{e}"
        );
        let e = build_error(
            dir.path(),
            r#"{"lights": [{"type": "point", "intensity_cd": 5, "spectrum": 0}]}"#,
        );
        assert!(
            e.contains("lights[0].intensity_cd: the emission spectrum has no luminous content"),
            "{e}"
        );
    }
}
