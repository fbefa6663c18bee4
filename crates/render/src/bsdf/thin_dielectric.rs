//! A thin dielectric sheet (window pane, soap film without interference): Mitsuba's
//! `thindielectric` (W. Jakob, Mitsuba 0.6 documentation §8.2; Mitsuba 3
//! `thindielectric.cpp`). Light meets two parallel interfaces; summing the bounces between
//! them (Fresnel R at each, T = 1 − R, no absorption) gives
//!
//!   R' = R + T² R / (1 − R²) = 2R/(1 + R),   T' = 1 − R' = (1 − R)/(1 + R),
//!
//! with R = F(θ, η) the single-interface Fresnel reflectance. Both lobes are Dirac: the
//! mirror direction, and the unrefracted straight-through direction −ωₒ (the two
//! refractions cancel). Seen from either side (symmetric); no radiance scaling (the ray
//! ends in the medium it started in). Each lane has its own R' (η may vary with λ without
//! bending the ray, so no wavelength is dropped); the lobe is chosen with the lane mean of
//! R'.

use glam::{Vec2, Vec3A};
use prism_spectrum::SampledSpectrum;

use super::fresnel::fresnel_dielectric;
use super::{BsdfSample, Bxdf, TransportMode};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// Index of refraction of the sheet relative to the surrounding medium, per lane.
    pub eta: SampledSpectrum,
}

impl ThinDielectric {
    /// R' per lane for a direction with this |cos θ|.
    #[inline]
    pub fn reflectance(&self, cos_theta: f32) -> SampledSpectrum {
        self.eta.map(|eta| {
            let r = fresnel_dielectric(cos_theta.abs(), eta);
            // Mitsuba `thindielectric`: R' = R + T²R/(1 − R²) (1 at total reflection).
            if r < 1.0 {
                r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r)
            } else {
                1.0
            }
        })
    }
}

impl Bxdf for ThinDielectric {
    #[inline]
    fn eval(&self, _wo: Vec3A, _wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        SampledSpectrum::zero()
    }

    #[inline]
    fn pdf(&self, _wo: Vec3A, _wi: Vec3A, _mode: TransportMode) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, _u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        let cos = wo.z.abs();
        if cos == 0.0 {
            return None;
        }
        let r = self.reflectance(cos);
        let pr = r.average().clamp(0.0, 1.0);
        if u_lobe < pr {
            Some(BsdfSample {
                wi: Vec3A::new(-wo.x, -wo.y, wo.z),
                f: r / cos,
                pdf: pr,
                specular: true,
                transmission: false,
                eta: 1.0,
            })
        } else {
            let t = SampledSpectrum::splat(1.0) - r;
            Some(BsdfSample {
                wi: -wo,
                f: t / cos,
                pdf: 1.0 - pr,
                specular: true,
                transmission: true,
                eta: 1.0,
            })
        }
    }

    /// Closed form: R' + T' = 1 per lane (no absorption in the sheet), 0 exactly at grazing
    /// where `sample` fails.
    fn albedo(&self, wo: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z == 0.0 {
            return SampledSpectrum::zero();
        }
        SampledSpectrum::splat(1.0)
    }

    /// Both lobes are Dirac.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        f32::INFINITY
    }

    #[inline]
    fn is_specular(&self) -> bool {
        true
    }

    #[inline]
    fn has_specular(&self) -> bool {
        true
    }

    /// Transmits straight through.
    #[inline]
    fn is_reflection_only(&self) -> bool {
        false
    }

    #[inline]
    fn is_isotropic(&self) -> bool {
        true
    }
}
