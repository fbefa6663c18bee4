//! ν_l of each kind of light, the light's part of the shading bandwidth that the sample
//! planner predicts (Bagher et al. 2013, eqs. 4, 5, 9; `probe.rs` hands it to
//! prism-bandwidth). Cycles per metre (spatial) and per radian (angular), stated choices:
//! - point, spot, goniometric: a Dirac in position, ν_l = [∞, 0] (their angular
//!   distributions are smooth); an ideal directional light: a Dirac in direction, [0, ∞];
//! - area light of area A: a box of width √A in space, ν_s = 1/√A, ν_a = 0 (Lambertian);
//!   the whole light's value, what a probe without maps uses and what a curved mesh or an
//!   ellipsoid keeps; the predictor's probe answers per point of the emitter from eq. 7
//!   (`area_bandwidth.rs`);
//! - sun of angular diameter 2α: ν_a = 1/(2α); uniform sky: 0;
//! - environment map W texels wide: its Nyquist rate, ν_a = W / 4π (W/2 cycles per 2π), as a
//!   whole; per direction the predictor uses eq. 7's map (`environment_bandwidth.rs`);
//! - daylight sky: the indicatrix exp(d χ) (|d| ≤ 3) varies over about 1/3 rad, ≈ 1.5
//!   cycles/rad.

use prism_bandwidth::Bandwidth;

use super::{AreaLight, DirectionalLight, EnvironmentLight};

fn bandwidth(spatial: f32, angular: f32) -> Bandwidth {
    Bandwidth {
        spatial_cycles_per_m: spatial,
        angular_cycles_per_rad: angular,
    }
}

/// Point, spot and goniometric lights: a Dirac in position (Bagher Fig. 4: ν_l = [∞, 0]).
pub(super) fn point_like() -> Bandwidth {
    Bandwidth::POINT_LIGHT
}

pub(super) fn directional(d: &DirectionalLight) -> Bandwidth {
    if d.one_minus_cos_half_angle > 0.0 {
        let half = (1.0 - d.one_minus_cos_half_angle).clamp(-1.0, 1.0).acos();
        bandwidth(0.0, 1.0 / (2.0 * half))
    } else {
        bandwidth(0.0, f32::INFINITY)
    }
}

pub(super) fn area(a: &AreaLight) -> Bandwidth {
    bandwidth((1.0 / a.shape.area_m2().sqrt()) as f32, 0.0)
}

pub(super) fn environment(e: &EnvironmentLight) -> Bandwidth {
    bandwidth(0.0, e.resolution().0 as f32 / (4.0 * std::f32::consts::PI))
}

pub(super) fn uniform_sky() -> Bandwidth {
    bandwidth(0.0, 0.0)
}

pub(super) fn daylight_sky() -> Bandwidth {
    bandwidth(0.0, 1.5)
}
