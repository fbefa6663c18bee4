//! Sample warps: the cameras', the lights' (a linear and a bilinear density on the unit
//! square, for environment-map cells and the cosine warp of solid-angle rectangle samples).

use glam::Vec2;
use std::f32::consts::FRAC_PI_4;

/// Concentric mapping of the unit square onto the unit disk (Shirley & Chiu 1997, "A
/// low distortion map between disk and square"; pbrt-v4 §A.5.1 `SampleUniformDiskConcentric`).
/// Uniform in area; adjacent strata stay adjacent and compact.
#[inline]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let offset = 2.0 * u - Vec2::ONE;
    if offset.x == 0.0 && offset.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if offset.x.abs() > offset.y.abs() {
        (offset.x, FRAC_PI_4 * (offset.y / offset.x))
    } else {
        (
            offset.y,
            2.0 * FRAC_PI_4 - FRAC_PI_4 * (offset.x / offset.y),
        )
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the hemisphere about +Z (Malley's method: a uniform disk
/// point lifted onto the hemisphere; pbrt-v4 §A.5.3 `SampleCosineHemisphere`). Density
/// cos θ / π per steradian.
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> glam::Vec3A {
    let d = sample_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    glam::Vec3A::new(d.x, d.y, z)
}

/// A direction about +Z with density (n + 1)/(2π) cosⁿθ per steradian, the normalised
/// Phong lobe (Lafortune & Willems 1994 §4; pbrt-v3 §14.1): cos θ = u₁^{1/(n+1)}, φ = 2πu₂.
#[inline]
pub fn sample_power_cosine(u: Vec2, exponent: f32) -> glam::Vec3A {
    let cos_t = u.x.powf(1.0 / (exponent + 1.0));
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (sin_p, cos_p) = (2.0 * std::f32::consts::PI * u.y).sin_cos();
    glam::Vec3A::new(sin_t * cos_p, sin_t * sin_p, cos_t)
}

/// Density of [`sample_power_cosine`] at a direction with this cos θ (0 below the horizon).
#[inline]
pub fn power_cosine_pdf(cos_theta: f32, exponent: f32) -> f32 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    (exponent + 1.0) * 0.5 * std::f32::consts::FRAC_1_PI * cos_theta.powf(exponent)
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// x ∈ [0, 1) with density ∝ (1 − x)·a + x·b (a, b ≥ 0), by inverting its cdf, written so
/// that it stays exact as a → b.
#[inline]
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return u;
    }
    let x = u * (a + b) / (a + (a * a + u * (b * b - a * a)).max(0.0).sqrt());
    x.clamp(0.0, ONE_MINUS_EPSILON)
}

/// A point of [0, 1)² with density `bilinear_pdf(·, w)` for `u` uniform, w the corner weights
/// at (0, 0), (1, 0), (0, 1), (1, 1): y from its marginal, then x from its conditional, each
/// linear (pbrt-v4 `SampleBilinear`).
#[inline]
pub fn sample_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, w[0] + y * (w[2] - w[0]), w[1] + y * (w[3] - w[1]));
    Vec2::new(x, y)
}

/// Density on [0, 1]² of the bilinear interpolation of the corner weights `w` (order as
/// `sample_bilinear`), normalised; 1 where every weight is 0 (pbrt-v4 `BilinearPDF`).
#[inline]
pub fn bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum <= 0.0 {
        return 1.0;
    }
    let (x, y) = (p.x, p.y);
    4.0 * ((1.0 - x) * (1.0 - y) * w[0]
        + x * (1.0 - y) * w[1]
        + (1.0 - x) * y * w[2]
        + x * y * w[3])
        / sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_hemisphere_is_unit_upward_and_has_mean_cos_two_thirds() {
        // E[cos θ] under p = cos θ/π is ∫cos²θ/π dω = 2/3.
        let n = 256;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                let d = sample_cosine_hemisphere(u);
                assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
                sum += f64::from(d.z);
            }
        }
        let mean = sum / f64::from(n * n);
        assert!((mean - 2.0 / 3.0).abs() < 1e-3, "{mean}");
    }

    #[test]
    fn concentric_disk_stays_in_disk_and_reaches_its_edge() {
        let n = 64;
        let mut max_r = 0.0f32;
        for i in 0..=n {
            for j in 0..=n {
                let p = sample_uniform_disk_concentric(Vec2::new(i as f32, j as f32) / n as f32);
                assert!(p.length() <= 1.0 + 1e-6);
                max_r = max_r.max(p.length());
            }
        }
        assert!((max_r - 1.0).abs() < 1e-6);
    }

    #[test]
    fn concentric_disk_is_uniform_in_area() {
        // The fraction of a regular grid of the square landing within radius ρ is ρ².
        let n = 400;
        let mut inside = 0;
        for i in 0..n {
            for j in 0..n {
                let u = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                if sample_uniform_disk_concentric(u).length() < 0.5 {
                    inside += 1;
                }
            }
        }
        let frac = inside as f32 / (n * n) as f32;
        assert!((frac - 0.25).abs() < 0.005, "{frac}");
    }
}
