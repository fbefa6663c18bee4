//! The daylight sky emitter: radiance from every direction above the horizon given by a sky
//! model (CIE general sky, Perez, Preetham), a Lambertian ground below it, importance-sampled
//! through a table over the sphere.
//!
//! **Radiance.** Above the horizon (cos θ = ω·up > 0) the model's luminance L_v(ω) in cd/m²
//! (evaluated exactly, not from the table) times a spectrum of unit luminance: the stated
//! D-series spectrum of the sky's CCT for the CIE and Perez skies, or for the Preetham sky the
//! CIE daylight spectrum of the element's own chromaticity (x, y):
//! L(λ) = L_v (S0 + M1 S1 + M2 S2)(λ) / (K_m ∫ (S0 + M1 S1 + M2 S2) V dλ). Below the horizon
//! the ground, a uniform Lambertian reflector of albedo ρ lit by the unobstructed sky and
//! sun: L_g(λ) = ρ (E_sky,h(λ) + E_sun,h(λ)) / π (0 for ρ = 0, the default).
//!
//! **Sampling.** A 2-D piecewise-constant distribution (`PiecewiseConstant2D`) over
//! (u, v) = (φ / 2π, (1 − cos θ) / 2) — an equal-area map of the whole sphere, θ from +Y,
//! φ from −Z towards +X — whose cell values are the mean luminance at 3 × 3 points of the
//! cell; a direction is uniform in solid angle within the chosen cell. Density:
//! pdf(ω) = pdf(u, v) / 4π. The radiance itself never comes from the table, so the table's
//! resolution only changes the variance.
//!
//! **Emitted rays.** The same direction sampling, then an origin on the scene disk facing
//! it (pbrt-v4 §12.5). The mean of the power estimator is π r² ∫∫ L dλ dω, which
//! `power_w` approximates by the table's luminance times ∫ S dλ of the stated sky
//! spectrum (exact but for the quadrature where every direction has that spectrum: CIE
//! and Perez skies over a black ground).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::super::environment::azimuth_fraction;
use super::super::piecewise_constant::PiecewiseConstant2D;
use super::super::scene_sphere::SceneSphere;
use super::super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};
use super::SkyShape;

/// Table resolution: columns in φ, rows in cos θ (over the whole sphere).
const TABLE_NU: usize = 256;
const TABLE_NV: usize = 256;

/// The spectral part of the sky radiance.
#[derive(Clone, Debug, PartialEq)]
pub enum SkyColour {
    /// One spectrum of unit luminance (1 cd/m²) for every direction.
    Fixed(Spectrum),
    /// CIE daylight of each direction's chromaticity (Preetham): S0, S1, S2 and their
    /// photometric values.
    Daylight {
        basis: Box<[Spectrum; 3]>,
        basis_luminance: [f32; 3],
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct DaylightSkyLight {
    pub shape: SkyShape,
    /// cd/m² per unit of `shape.relative_luminance`.
    pub luminance_scale: f64,
    /// Unit direction towards the sun (world).
    pub sun_dir: Vec3A,
    pub colour: SkyColour,
    /// Radiance of the ground below the horizon (W·m⁻²·sr⁻¹·nm⁻¹); `None` for a black ground.
    pub ground: Option<Spectrum>,
    /// Luminance of the ground, cd/m².
    pub ground_luminance_cd_m2: f64,
    /// Illuminance of the sky alone on an unobstructed horizontal plane, lx (quadrature).
    pub horizontal_illuminance_lx: f64,
    distribution: PiecewiseConstant2D,
    scene: SceneSphere,
    /// Σ cells L_v ΔΩ (cd/m² · sr) and ∫ S dλ of a unit-luminance spectrum (power estimate).
    luminance_solid_angle: f64,
    radiant_per_luminance_nm: f64,
}

/// Direction of (u, v) in the equal-area sphere map.
#[inline]
pub fn sphere_direction(uv: Vec2) -> Vec3A {
    let cos_t = (1.0 - 2.0 * uv.y).clamp(-1.0, 1.0);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (sin_p, cos_p) = (2.0 * PI * uv.x).sin_cos();
    Vec3A::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

/// (u, v) of a unit direction.
#[inline]
pub fn sphere_uv(d: Vec3A) -> Vec2 {
    Vec2::new(azimuth_fraction(d), ((1.0 - d.y) * 0.5).clamp(0.0, 1.0))
}

impl DaylightSkyLight {
    /// Builds the sampling table. `luminance_scale` turns the shape's relative luminance into
    /// cd/m²; `ground` and its luminance come from the caller (they need the sun).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        shape: SkyShape,
        luminance_scale: f64,
        sun_dir: Vec3A,
        colour: SkyColour,
        ground: Option<Spectrum>,
        ground_luminance_cd_m2: f64,
        horizontal_illuminance_lx: f64,
        radiant_per_luminance_nm: f64,
        scene: SceneSphere,
    ) -> Self {
        let mut light = Self {
            shape,
            luminance_scale,
            sun_dir: sun_dir.normalize(),
            colour,
            ground,
            ground_luminance_cd_m2,
            horizontal_illuminance_lx,
            distribution: PiecewiseConstant2D::new(&[1.0], 1, 1),
            scene,
            luminance_solid_angle: 0.0,
            radiant_per_luminance_nm,
        };
        let sub = 3;
        let mut values = vec![0.0f32; TABLE_NU * TABLE_NV];
        let mut total = 0.0f64;
        for y in 0..TABLE_NV {
            for x in 0..TABLE_NU {
                let mut sum = 0.0f64;
                for j in 0..sub {
                    for i in 0..sub {
                        let uv = Vec2::new(
                            (x as f32 + (i as f32 + 0.5) / sub as f32) / TABLE_NU as f32,
                            (y as f32 + (j as f32 + 0.5) / sub as f32) / TABLE_NV as f32,
                        );
                        sum += light.luminance_cd_m2(sphere_direction(uv));
                    }
                }
                let mean = sum / (sub * sub) as f64;
                values[y * TABLE_NU + x] = mean as f32;
                total += mean;
            }
        }
        // Never a zero cell where the sky is not black: a floor of 10⁻⁴ of the mean keeps
        // the estimator unbiased wherever the sampled points of a cell missed its light.
        let floor = (1e-4 * total / values.len() as f64) as f32;
        for (k, v) in values.iter_mut().enumerate() {
            let below = k / TABLE_NU >= TABLE_NV / 2;
            if !(below && light.ground.is_none()) {
                *v = v.max(floor);
            }
        }
        light.luminance_solid_angle = total * 4.0 * std::f64::consts::PI / values.len() as f64;
        light.distribution = PiecewiseConstant2D::new(&values, TABLE_NU, TABLE_NV);
        light
    }

    /// Luminance in cd/m² seen along the unit direction `d` (world, pointing at the sky).
    #[inline]
    pub fn luminance_cd_m2(&self, d: Vec3A) -> f64 {
        let cos_z = f64::from(d.y);
        if cos_z <= 0.0 {
            return self.ground_luminance_cd_m2;
        }
        self.luminance_scale
            * self
                .shape
                .relative_luminance(cos_z, f64::from(d.dot(self.sun_dir)))
    }

    /// Spectral radiance along `d`.
    #[inline]
    pub fn radiance(&self, d: Vec3A, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        if d.y <= 0.0 {
            return match &self.ground {
                Some(g) => g.eval(wavelengths),
                None => SampledSpectrum::splat(0.0),
            };
        }
        let lv = self.luminance_cd_m2(d) as f32;
        match &self.colour {
            SkyColour::Fixed(unit) => unit.eval(wavelengths) * lv,
            SkyColour::Daylight {
                basis,
                basis_luminance,
            } => {
                let (x, y) = self
                    .shape
                    .chromaticity(f64::from(d.y), f64::from(d.dot(self.sun_dir)));
                let (m1, m2) = prism_spectrum::daylight::daylight_m1_m2(x, y);
                let (m1, m2) = (m1 as f32, m2 as f32);
                let norm = basis_luminance[0] + m1 * basis_luminance[1] + m2 * basis_luminance[2];
                if norm.is_nan() || norm <= 0.0 {
                    return SampledSpectrum::splat(0.0);
                }
                let s = basis[0].eval(wavelengths)
                    + basis[1].eval(wavelengths) * m1
                    + basis[2].eval(wavelengths) * m2;
                (s * (lv / norm)).clamp_zero()
            }
        }
    }

    /// Density of `sample_li` per steradian at the unit direction `wi`.
    #[inline]
    pub fn direction_pdf(&self, wi: Vec3A) -> f32 {
        self.distribution.pdf(sphere_uv(wi)) * (1.0 / (4.0 * PI))
    }

    /// A direction from the table and its density (that of the cell the direction maps
    /// back to: identical but for rounding on a cell boundary, so that sampling and
    /// `direction_pdf` always agree).
    #[inline]
    fn sample_direction(&self, u: Vec2) -> Option<(Vec3A, f32)> {
        let (uv, pdf_uv, _) = self.distribution.sample(u);
        if !(pdf_uv > 0.0 && pdf_uv.is_finite()) {
            return None;
        }
        let wi = sphere_direction(uv);
        let pdf = self.direction_pdf(wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some((wi, pdf))
    }
}

impl LightSource for DaylightSkyLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, pdf) = self.sample_direction(u)?;
        Some(LightSample {
            wi,
            radiance: self.radiance(wi, wavelengths),
            pdf,
            p_light: self.scene.point_beyond(ctx.p, wi),
            distance_m: f32::INFINITY,
            delta: false,
            n_light: Vec3A::ZERO,
        })
    }

    #[inline]
    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        self.direction_pdf(wi)
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    #[inline]
    fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.radiance(direction, wavelengths)
    }

    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (wi, pdf) = self.sample_direction(u_dir)?;
        scene.emission(wi, u_pos, self.radiance(wi, wavelengths), pdf)
    }

    fn pdf_le(
        &self,
        scene: &SceneSphere,
        _origin: Vec3A,
        _n: Vec3A,
        direction: Vec3A,
    ) -> (f32, f32) {
        (scene.disk_pdf(), self.direction_pdf(-direction))
    }

    /// Φ ≈ π r² Σ L_v ΔΩ · ∫ S dλ per cd/m², W (only to choose lights).
    fn power_w(&self, scene_radius_m: f32) -> f64 {
        let r = f64::from(scene_radius_m);
        std::f64::consts::PI * r * r * self.luminance_solid_angle * self.radiant_per_luminance_nm
    }

    fn bandwidth(&self) -> Bandwidth {
        super::super::bandwidth::daylight_sky()
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
