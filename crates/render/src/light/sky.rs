//! A uniform sky: the same radiance L(λ) from every direction of the sphere (pbrt-v4
//! §12.5.1 `UniformInfiniteLight`). An unoccluded horizontal surface receives E = π L.
//!
//! Sampling: at a surface point (n ≠ 0) a cosine-weighted direction about n or about −n,
//! each with probability ½ — density |cos θ| / 2π — so both sides of the surface are
//! covered (transmission, and normals that face away from the incoming path) and the
//! estimator L·f·|cos θ|/pdf = 2π L f has no cosine variance. In a medium (n = 0) a
//! uniform direction on the sphere, density 1/4π.
//!
//! Emitted rays: a uniform direction on the sphere (pdf_dir 1/4π), from the scene disk
//! facing it (pbrt-v4 §12.5.1 `UniformInfiniteLight::SampleLe`); the estimator's mean is
//! `power_w` exactly.

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::Frame;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::point::integrate_nm;
use super::scene_sphere::SceneSphere;
use super::warp::sample_uniform_sphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};
use crate::sampling::sample_cosine_hemisphere;

#[derive(Clone, Debug, PartialEq)]
pub struct UniformSky {
    /// L(λ), W·m⁻²·sr⁻¹·nm⁻¹.
    pub radiance: Spectrum,
    pub scene: SceneSphere,
}

/// The unit normal of `ctx`, or `None` in a medium (zero normal).
#[inline]
fn surface_normal(ctx: &LightSampleContext) -> Option<Vec3A> {
    ctx.n.try_normalize()
}

impl LightSource for UniformSky {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, pdf) = match surface_normal(ctx) {
            Some(n) => {
                // u.x picks the side, then is stretched back to [0, 1).
                let (side, ux) = if u.x < 0.5 {
                    (n, 2.0 * u.x)
                } else {
                    (-n, 2.0 * u.x - 1.0)
                };
                let local = sample_cosine_hemisphere(Vec2::new(ux.min(1.0), u.y));
                let wi = Frame::from_z(side).from_local(local).normalize();
                (wi, wi.dot(n).abs() / (2.0 * PI))
            }
            None => (sample_uniform_sphere(u), 1.0 / (4.0 * PI)),
        };
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            radiance: self.radiance.eval(wavelengths),
            pdf,
            p_light: self.scene.point_beyond(ctx.p, wi),
            distance_m: f32::INFINITY,
            delta: false,
            n_light: Vec3A::ZERO,
        })
    }

    #[inline]
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        match surface_normal(ctx) {
            Some(n) => wi.dot(n).abs() / (2.0 * PI),
            None => 1.0 / (4.0 * PI),
        }
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    #[inline]
    fn infinite_radiance(
        &self,
        _direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.radiance.eval(wavelengths)
    }

    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let wi = sample_uniform_sphere(u_dir);
        scene.emission(wi, u_pos, self.radiance.eval(wavelengths), 1.0 / (4.0 * PI))
    }

    fn pdf_le(
        &self,
        scene: &SceneSphere,
        _origin: Vec3A,
        _n: Vec3A,
        _direction: Vec3A,
    ) -> (f32, f32) {
        (scene.disk_pdf(), 1.0 / (4.0 * PI))
    }

    /// Φ = 4π · π r² ∫ L dλ: the flux the sky sends into a sphere of the scene's radius
    /// (pbrt-v4 `UniformInfiniteLight::Phi`), W.
    fn power_w(&self, scene_radius_m: f32) -> f64 {
        let r = f64::from(scene_radius_m);
        4.0 * std::f64::consts::PI * std::f64::consts::PI * r * r * integrate_nm(&self.radiance)
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::uniform_sky()
    }

    #[inline]
    fn is_delta(&self) -> bool {
        false
    }

    #[inline]
    fn is_infinite(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_support::{
        build_scene, chi2_config, mean_and_standard_error, photometric_sum,
    };
    use prism_testkit::chi2::chi2_test_adaptive;

    #[test]
    fn chi2_sky() {
        let sky = UniformSky {
            radiance: Spectrum::constant(1.0),
            scene: SceneSphere::default(),
        };
        let wl = SampledWavelengths::sample_uniform(0.4);
        let normals = [
            Vec3A::ZERO,
            Vec3A::Y,
            Vec3A::new(0.3, -0.5, 0.8).normalize(),
        ];
        let config = chi2_config(normals.len(), 61);
        for n in normals {
            let ctx = LightSampleContext { p: Vec3A::ONE, n };
            let r = chi2_test_adaptive(
                &config,
                |_, u| sky.sample_li(&ctx, u, &wl).map(|s| s.wi),
                |w| f64::from(sky.pdf_li(&ctx, w, None)),
            );
            assert!(r.passed, "n = {n}: {}", r.message);
            assert!(
                (r.pdf_integral - 1.0).abs() < 1e-3,
                "n = {n}: {}",
                r.message
            );
        }
    }

    #[test]
    fn sky_illuminance_on_horizontal_surface_is_pi_l() {
        let dir = tempfile::tempdir().unwrap();
        let json = r#"{"lights": [{"type": "sky", "luminance_cd_m2": 3000, "spectrum": {"blackbody_k": 6500}}]}"#;
        let (_, lights) = build_scene(dir.path(), json).unwrap();
        let light = lights.light(0);
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::Y,
        };
        // L·cos/pdf is 2πL above the horizon and 0 below, each half the time: mean πL,
        // standard error πL/√N.
        let (e, se) = mean_and_standard_error(4000, 9, |u| {
            let mut cos_over_pdf = 0.0;
            let l = photometric_sum(|wl| {
                let s = light.sample_li(&ctx, u, wl).unwrap();
                cos_over_pdf = f64::from(s.wi.dot(ctx.n).max(0.0)) / f64::from(s.pdf);
                s.radiance
            });
            l * cos_over_pdf
        });
        let exact = std::f64::consts::PI * 3000.0;
        assert!((e - exact).abs() < 4.0 * se, "{e} ± {se} vs {exact}");
        assert!(se > 0.0 && se < 0.05 * exact);
        assert_eq!(lights.infinite_lights(), &[0]);
    }
}
