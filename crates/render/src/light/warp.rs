//! Sample warps of the emitters: uniform directions in a cone and on the sphere, uniform
//! points in a triangle, and the smoothstep density of a spot light's falloff ring. Each
//! states its density, so the emitters' pdfs follow in closed form.

use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

/// A direction uniform in solid angle inside the cone of half-angle θ_max about +Z, given
/// 1 − cos θ_max (passed directly so that tiny cones such as the sun's, 1 − cos 0.265° ≈
/// 1.07·10⁻⁵, keep their precision in f32). Density 1 / (2π (1 − cos θ_max)) per steradian
/// (pbrt-v4 §A.5.4 `SampleUniformCone`: 1 − cos θ = u₀ (1 − cos θ_max), φ = 2π u₁).
#[inline]
pub fn sample_uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3A {
    let one_minus_cos = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    // sin²θ = (1 − cos θ)(1 + cos θ), exact for small angles.
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
    Vec3A::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// A direction uniform on the unit sphere (Archimedes: z uniform in [−1, 1]); density
/// 1/(4π) (pbrt-v4 §A.5.2 `SampleUniformSphere`).
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3A {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
    Vec3A::new(r * cos_phi, r * sin_phi, z)
}

/// Barycentrics (b₀, b₁, b₂) of a point uniform in area in a triangle (Heitz 2019, "A
/// Low-Distortion Map Between Triangle and Square"; pbrt-v4 §A.5.4 `SampleUniformTriangle`).
#[inline]
pub fn sample_uniform_triangle(u: Vec2) -> [f32; 3] {
    let (b0, b1) = if u.x < u.y {
        let b0 = u.x / 2.0;
        (b0, u.y - b0)
    } else {
        let b1 = u.y / 2.0;
        (u.x - b1, b1)
    };
    [b0, b1, 1.0 - b0 - b1]
}

/// t ∈ [0, 1] with density 2 smoothstep(t) = 2t²(3 − 2t) (pbrt-v4 `SampleSmoothStep`,
/// Appendix A): the inverse of the CDF F(t) = 2t³ − t⁴ by Newton's method, safeguarded by
/// bisection, in f64.
pub fn sample_smoothstep(u: f32) -> f32 {
    let u = f64::from(u).clamp(0.0, 1.0);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // F ≈ 2t³ near 0: a start within a few per cent everywhere but near 1.
    let mut t = (0.5 * u).cbrt().min(1.0);
    for _ in 0..40 {
        let f = t * t * t * (2.0 - t) - u;
        if f.abs() < 1e-12 {
            break;
        }
        if f < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let df = t * t * (6.0 - 4.0 * t);
        let next = t - f / df;
        t = if df > 0.0 && next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    t as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_testkit::chi2::{chi2_test, chi2_test_adaptive, Chi2Config};

    fn config() -> Chi2Config {
        Chi2Config {
            sample_count: 200_000,
            ..Chi2Config::default()
        }
    }

    #[test]
    fn cone_and_sphere_warps_pass_chi2_against_their_densities() {
        let omc = 1.0 - 50f32.to_radians().cos();
        let r = chi2_test_adaptive(
            &config(),
            |_, u| Some(sample_uniform_cone(u, omc)),
            |w| {
                if f64::from(w.z) >= 1.0 - f64::from(omc) {
                    1.0 / (2.0 * std::f64::consts::PI * f64::from(omc))
                } else {
                    0.0
                }
            },
        );
        assert!(r.passed, "cone: {}", r.message);
        let r = chi2_test(
            &config(),
            |_, u| Some(sample_uniform_sphere(u)),
            |_| 0.25 / std::f64::consts::PI,
        );
        assert!(r.passed, "sphere: {}", r.message);
        assert!((r.pdf_integral - 1.0).abs() < 1e-3, "{}", r.message);
    }

    #[test]
    fn a_tiny_cone_stays_inside_its_half_angle() {
        let half_angle = 0.265f32.to_radians();
        let omc = (2.0 * (0.5 * f64::from(half_angle)).sin().powi(2)) as f32;
        for i in 0..=64 {
            for j in 0..=8 {
                let w = sample_uniform_cone(Vec2::new(i as f32 / 64.0, j as f32 / 8.0), omc);
                assert!((w.length() - 1.0).abs() < 1e-6);
                let sin_theta = Vec2::new(w.x, w.y).length();
                assert!(sin_theta <= half_angle.sin() * (1.0 + 1e-5) && w.z > 0.0);
            }
        }
    }

    #[test]
    fn smoothstep_sampling_inverts_its_cdf() {
        for i in 0..=1000 {
            let u = i as f32 / 1000.0;
            let t = f64::from(sample_smoothstep(u));
            assert!((0.0..=1.0).contains(&t));
            let cdf = 2.0 * t.powi(3) - t.powi(4);
            assert!((cdf - f64::from(u)).abs() < 1e-6, "u {u}: t {t}, F {cdf}");
        }
    }

    #[test]
    fn triangle_barycentrics_are_uniform_in_area() {
        // The fraction of a regular grid of the square landing in the sub-triangle
        // b₀ > ½ (a quarter of the area) is ¼.
        let n = 400;
        let mut inside = 0;
        for i in 0..n {
            for j in 0..n {
                let u = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                let b = sample_uniform_triangle(u);
                assert!(b.iter().all(|&x| (-1e-6..=1.0 + 1e-6).contains(&x)));
                if b[0] > 0.5 {
                    inside += 1;
                }
            }
        }
        let frac = inside as f64 / f64::from(n * n);
        assert!((frac - 0.25).abs() < 0.005, "{frac}");
    }
}
