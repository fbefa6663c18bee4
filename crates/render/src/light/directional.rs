//! Directional light (the sun): light from infinitely far away, given by the irradiance
//! E⊥(λ) it produces on a surface facing it (W·m⁻²·nm⁻¹).
//!
//! - Angular diameter 0: ideal parallel light, a Dirac in direction (pbrt-v4 §12.4
//!   `DistantLight`). `sample_li` returns the one direction with `radiance` = E⊥ and pdf 1;
//!   no ray can hit it.
//! - Angular diameter 2α > 0: a disk of directions of uniform radiance L around the
//!   direction towards the source — the cone of half-angle α. The irradiance on a surface
//!   facing the centre of the disk is E⊥ = ∫_cone L cos θ dω = L · π sin²α, so
//!   L = E⊥ / (π sin²α) = E⊥ / (Ω · mean cos θ) with Ω = 2π(1 − cos α) and
//!   mean cos θ = (1 + cos α)/2 over the cone. That surface then receives exactly E⊥ for
//!   every α (the strength does not change with the size). The light is then "infinite"
//!   (escaping rays inside the cone see L) and not delta; it is sampled uniformly in
//!   solid angle over the cone, pdf 1/Ω.
//!
//! Emitted rays start uniformly on the scene disk facing the light (pdf_pos 1/(π r²)),
//! along the one direction (pdf_dir 1, radiance E⊥) or, with a disk, along a direction
//! uniform in the cone (pdf_dir 1/Ω, radiance L). Power: π r² ∫ E⊥ dλ (pbrt-v4
//! `DistantLight::Phi`), the flux through the disk facing the source's centre. With a disk
//! the mean of `sample_le`'s estimator is π r² Ω ∫ L dλ = π r² ∫ E⊥ dλ · 2/(1 + cos α),
//! the flux through the disks facing each direction of the cone: 1 + 5·10⁻⁶ times
//! `power_w` for the sun, 1.0076 times for a 20° disk.

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_geometry::Frame;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::point::integrate_nm;
use super::scene_sphere::SceneSphere;
use super::warp::sample_uniform_cone;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};

#[derive(Clone, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction from the scene towards the source (minus the direction of travel).
    pub to_light: Vec3A,
    /// E⊥(λ), W·m⁻²·nm⁻¹, on a surface facing the source.
    pub irradiance: Spectrum,
    /// L(λ) = E⊥ / (π sin²α) inside the cone (unused when the light is ideal).
    pub radiance: Spectrum,
    /// 1 − cos α of the half-angle α (0: ideal parallel light).
    pub one_minus_cos_half_angle: f32,
    /// sin²α.
    pub sin2_half_angle: f32,
    frame: Frame,
    scene: SceneSphere,
}

impl DirectionalLight {
    /// `direction`: the direction the light travels (any length > 0);
    /// `angular_diameter_rad` ∈ [0, π]: 2α.
    pub fn new(
        direction: Vec3A,
        angular_diameter_rad: f64,
        irradiance: Spectrum,
        scene: SceneSphere,
    ) -> Self {
        let to_light = (-direction).normalize_or(Vec3A::Y);
        let alpha = (0.5 * angular_diameter_rad).clamp(0.0, 0.5 * std::f64::consts::PI);
        // 1 − cos α = 2 sin²(α/2): no cancellation for the sun's 0.265°.
        let omc = 2.0 * (0.5 * alpha).sin().powi(2);
        let sin2 = alpha.sin().powi(2);
        let radiance = if sin2 > 0.0 {
            irradiance
                .clone()
                .scaled((1.0 / (std::f64::consts::PI * sin2)) as f32)
        } else {
            Spectrum::constant(0.0)
        };
        Self {
            to_light,
            irradiance,
            radiance,
            one_minus_cos_half_angle: omc as f32,
            sin2_half_angle: sin2 as f32,
            frame: Frame::from_z(to_light),
            scene,
        }
    }

    /// Solid angle of the source, Ω = 2π(1 − cos α), sr.
    #[inline]
    fn solid_angle_sr(&self) -> f32 {
        2.0 * PI * self.one_minus_cos_half_angle
    }

    /// Whether the unit direction `w` points into the source's cone. sin²θ comes from the
    /// cross product, which stays accurate for tiny cones where 1 − cos θ would not.
    #[inline]
    fn in_cone(&self, w: Vec3A) -> bool {
        let cos = w.dot(self.to_light);
        if self.sin2_half_angle >= 1.0 {
            return cos >= 0.0;
        }
        cos > 0.0 && w.cross(self.to_light).length_squared() <= self.sin2_half_angle
    }

    /// 1/Ω inside the cone, 0 outside and for ideal parallel light.
    #[inline]
    pub fn direction_pdf(&self, wi: Vec3A) -> f32 {
        if !self.is_delta() && self.in_cone(wi) {
            1.0 / self.solid_angle_sr()
        } else {
            0.0
        }
    }
}

impl LightSource for DirectionalLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        if self.is_delta() {
            return Some(LightSample {
                wi: self.to_light,
                radiance: self.irradiance.eval(wavelengths),
                pdf: 1.0,
                p_light: self.scene.point_beyond(ctx.p, self.to_light),
                distance_m: f32::INFINITY,
                delta: true,
                n_light: Vec3A::ZERO,
            });
        }
        let local = sample_uniform_cone(u, self.one_minus_cos_half_angle);
        let wi = self.frame.from_local(local).normalize();
        Some(LightSample {
            wi,
            radiance: self.radiance.eval(wavelengths),
            pdf: 1.0 / self.solid_angle_sr(),
            p_light: self.scene.point_beyond(ctx.p, wi),
            distance_m: f32::INFINITY,
            delta: false,
            n_light: Vec3A::ZERO,
        })
    }

    /// 1/Ω inside the cone, 0 outside and for ideal parallel light.
    #[inline]
    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        self.direction_pdf(wi)
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    /// L inside the cone (for rays leaving the scene), 0 elsewhere and when ideal.
    #[inline]
    fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        if !self.is_delta() && self.in_cone(direction) {
            self.radiance.eval(wavelengths)
        } else {
            SampledSpectrum::splat(0.0)
        }
    }

    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        if self.is_delta() {
            return scene.emission(self.to_light, u_pos, self.irradiance.eval(wavelengths), 1.0);
        }
        let local = sample_uniform_cone(u_dir, self.one_minus_cos_half_angle);
        let wi = self.frame.from_local(local).normalize();
        // 0 (no sample) where rounding put the direction outside the cone, as `pdf_le`.
        let pdf_dir = self.direction_pdf(wi);
        scene.emission(wi, u_pos, self.radiance.eval(wavelengths), pdf_dir)
    }

    fn pdf_le(
        &self,
        scene: &SceneSphere,
        _origin: Vec3A,
        _n: Vec3A,
        direction: Vec3A,
    ) -> (f32, f32) {
        let pdf_dir = if self.is_delta() {
            1.0
        } else {
            self.direction_pdf(-direction)
        };
        (scene.disk_pdf(), pdf_dir)
    }

    /// The flux through a disk of the scene's radius facing the light: Φ = π r² ∫ E⊥ dλ
    /// (pbrt-v4 `DistantLight::Phi`), W.
    fn power_w(&self, scene_radius_m: f32) -> f64 {
        let r = f64::from(scene_radius_m);
        std::f64::consts::PI * r * r * integrate_nm(&self.irradiance)
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::directional(self)
    }

    /// Ideal parallel light (angular diameter 0).
    #[inline]
    fn is_delta(&self) -> bool {
        self.one_minus_cos_half_angle <= 0.0
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
    use crate::light::Light;
    use prism_testkit::chi2::chi2_test_adaptive;

    #[test]
    fn chi2_sun() {
        let diameters_deg = [0.53, 30.0, 90.0, 180.0];
        let config = chi2_config(diameters_deg.len(), 51);
        let ctx = LightSampleContext {
            p: Vec3A::new(0.3, 0.1, -0.2),
            n: Vec3A::ZERO,
        };
        let wl = SampledWavelengths::sample_uniform(0.4);
        for d in diameters_deg {
            let sun = DirectionalLight::new(
                Vec3A::new(0.3, -1.0, 0.2),
                f64::to_radians(d),
                Spectrum::constant(1.0),
                SceneSphere::default(),
            );
            let r = chi2_test_adaptive(
                &config,
                |_, u| sun.sample_li(&ctx, u, &wl).map(|s| s.wi),
                |w| f64::from(sun.direction_pdf(w)),
            );
            assert!(r.passed, "{d}°: {}", r.message);
            assert!((r.pdf_integral - 1.0).abs() < 1e-3, "{d}°: {}", r.message);
            // Every sample lies in the cone, where the radiance is.
            for i in 0..1000 {
                let u = Vec2::new(i as f32 / 1000.0, (i as f32 * 0.618).fract());
                let s = sun.sample_li(&ctx, u, &wl).unwrap();
                assert!(!s.delta && s.distance_m == f32::INFINITY);
                assert!(sun.in_cone(s.wi), "{d}°: {:?}", s.wi);
                assert!(!sun.infinite_radiance(s.wi, &wl).is_black());
                assert_eq!(sun.direction_pdf(s.wi), s.pdf);
            }
        }
    }

    /// Illuminance in lx on a surface facing the light, from `sample_li` with V(λ).
    fn illuminance_lx(light: &Light, n: usize) -> (f64, f64) {
        let Light::Directional(sun) = light else {
            panic!()
        };
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: sun.to_light,
        };
        mean_and_standard_error(n, 5, |u| {
            let mut cos_over_pdf = 0.0;
            let e = photometric_sum(|wl| {
                let s = light.sample_li(&ctx, u, wl).unwrap();
                cos_over_pdf = f64::from(s.wi.dot(ctx.n).max(0.0)) / f64::from(s.pdf);
                s.radiance
            });
            e * cos_over_pdf
        })
    }

    #[test]
    fn directional_light_gives_its_illuminance() {
        let dir = tempfile::tempdir().unwrap();
        for diameter in [0.0, 0.53, 20.0] {
            let json = format!(
                r#"{{"lights": [{{"type": "directional", "direction": [0.3, -1, 0.2],
                    "angular_diameter_deg": {diameter}, "illuminance_lx": 100000, "spectrum": "D65"}}]}}"#
            );
            let (_, lights) = build_scene(dir.path(), &json).unwrap();
            let (e, se) = illuminance_lx(lights.light(0), 2000);
            assert!(
                (e - 1e5).abs() < 4.0 * se + 1e-5 * 1e5,
                "{diameter}°: {e} ± {se}"
            );
            assert_eq!(lights.light(0).is_delta(), diameter == 0.0);
            assert_eq!(lights.infinite_lights().len(), usize::from(diameter > 0.0));
        }
    }
}
