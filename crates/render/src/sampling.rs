//! Sample warps used by the cameras.

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
