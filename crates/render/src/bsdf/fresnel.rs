//! Fresnel reflectance of smooth interfaces (unpolarised light) and the reflection and
//! refraction of directions about a normal.
//!
//! - `fresnel_dielectric`: real relative index η = η_t/η_i (Born & Wolf, *Principles of
//!   Optics*, 7th ed., §1.5.2 eqs. 20–21; pbrt-v4 §9.3.5 eq. 9.5 `FrDielectric`).
//! - `fresnel_complex`: a conductor's complex index η̃ = η + ik (Born & Wolf §14.2; the same
//!   amplitude ratios with complex η̃ and cos θₜ; pbrt-v4 §9.3.6 `FrComplex`).
//! - `reflect`, `refract`: mirror reflection and Snell's law in vector form (pbrt-v4
//!   §9.3.2, eq. 9.4).

use glam::Vec3A;
use prism_spectrum::SampledSpectrum;

/// Unpolarised Fresnel reflectance of a dielectric interface.
///
/// `cos_theta_i` is the cosine between the incident direction and the normal on the side
/// of the incident medium when positive; a negative value means the light arrives from
/// the other side, where the relative index is 1/η. `eta` = η_t/η_i (the medium below the
/// normal over the one above). Total internal reflection returns 1.
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_theta_i < 0.0 {
        (-cos_theta_i, 1.0 / eta)
    } else {
        (cos_theta_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    // Snell: sin θₜ = sin θᵢ / η.
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    // Born & Wolf §1.5.2 eqs. 21a, 21b (amplitude ratios rₚ, rₛ), written with η = n₂/n₁.
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// A complex number, just what the conductor Fresnel equations need.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex {
    re: f32,
    im: f32,
}

impl Complex {
    const fn new(re: f32, im: f32) -> Self {
        Self { re, im }
    }

    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }

    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }

    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }

    fn scale(self, s: f32) -> Self {
        Self::new(self.re * s, self.im * s)
    }

    fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }

    fn div(self, o: Self) -> Self {
        let d = o.norm();
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }

    /// Principal square root (non-negative real part): √z = (√((|z|+x)/2), sign(y)·√((|z|−x)/2)).
    fn sqrt(self) -> Self {
        let r = self.re.hypot(self.im);
        if r == 0.0 {
            return Self::new(0.0, 0.0);
        }
        let t = (0.5 * (r + self.re.abs())).sqrt();
        if self.re >= 0.0 {
            Self::new(t, 0.5 * self.im / t)
        } else {
            Self::new(0.5 * self.im.abs() / t, t.copysign(self.im))
        }
    }
}

/// Unpolarised Fresnel reflectance at an interface from a dielectric of index 1 into a
/// medium of complex relative index η + ik (k ≥ 0 absorbs). `cos_theta_i` ∈ [0, 1]
/// (clamped). With k = 0 this equals `fresnel_dielectric(cos_theta_i, eta)`.
#[inline]
pub fn fresnel_complex(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_theta_i.clamp(0.0, 1.0);
    if cos_i == 0.0 {
        return 1.0; // Grazing incidence (the ratios below are 0/0 for η̃ = 1).
    }
    let eta_c = Complex::new(eta, k);
    // Snell with complex η̃: sin²θₜ = sin²θᵢ/η̃², cos θₜ = √(1 − sin²θₜ) (principal branch,
    // Born & Wolf §14.2 eq. 5 ff.).
    let sin2_i = Complex::new((1.0 - cos_i * cos_i).max(0.0), 0.0);
    let sin2_t = sin2_i.div(eta_c.mul(eta_c));
    let cos_t = Complex::new(1.0, 0.0).sub(sin2_t).sqrt();
    let ci = Complex::new(cos_i, 0.0);
    let r_parallel = eta_c
        .scale(cos_i)
        .sub(cos_t)
        .div(eta_c.scale(cos_i).add(cos_t));
    let r_perpendicular = ci.sub(eta_c.mul(cos_t)).div(ci.add(eta_c.mul(cos_t)));
    0.5 * (r_parallel.norm() + r_perpendicular.norm())
}

/// `fresnel_complex` at each of the four wavelengths, in the equivalent real-arithmetic
/// form of the same equations (no branches, so the four lanes vectorise): with
/// a² + b² = √((η² − k² − sin²θ)² + 4η²k²) and a = √((a² + b² + η² − k² − sin²θ)/2),
/// Rₛ = (a² + b² + cos²θ − 2a cos θ)/(a² + b² + cos²θ + 2a cos θ) and
/// Rₚ = Rₛ (cos²θ (a² + b²) + sin⁴θ − 2a cos θ sin²θ)/(cos²θ (a² + b²) + sin⁴θ + 2a cos θ sin²θ)
/// (Born & Wolf §14.2 eqs. 21–22 with η₁ = 1; pbrt-v3 §8.2.1 `FrConductor`), R = (Rₛ + Rₚ)/2.
#[inline]
pub fn fresnel_complex_spectrum(
    cos_theta_i: f32,
    eta: SampledSpectrum,
    k: SampledSpectrum,
) -> SampledSpectrum {
    let cos = cos_theta_i.clamp(0.0, 1.0);
    let cos2 = cos * cos;
    let sin2 = 1.0 - cos2;
    SampledSpectrum::from_fn(|l| {
        let (eta2, k2) = (eta[l] * eta[l], k[l] * k[l]);
        let t0 = eta2 - k2 - sin2;
        let a2_plus_b2 = (t0 * t0 + 4.0 * eta2 * k2).sqrt();
        let t1 = a2_plus_b2 + cos2;
        let a = (0.5 * (a2_plus_b2 + t0)).max(0.0).sqrt();
        let t2 = 2.0 * cos * a;
        let rs = (t1 - t2) / (t1 + t2);
        let t3 = cos2 * a2_plus_b2 + sin2 * sin2;
        let t4 = t2 * sin2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        // t1 + t2 = 0 only for η = 1, k = 0 at grazing incidence, where R → 1.
        let r = 0.5 * (rp + rs);
        if r.is_nan() {
            1.0
        } else {
            r
        }
    })
}

/// `wo` mirrored about `n` (both pointing away from the surface): 2(wo·n)n − wo.
#[inline]
pub fn reflect(wo: Vec3A, n: Vec3A) -> Vec3A {
    2.0 * wo.dot(n) * n - wo
}

/// `wi` refracted through an interface with normal `n` and relative index `eta` = η below
/// `n` / η above (Snell's law in vector form, pbrt-v4 eq. 9.4). `wi` points away from the
/// surface; when it lies below `n` the interface is seen from the other side (η → 1/η).
/// Returns the transmitted direction (pointing away from the surface, on the other side)
/// and the relative index η' = η_transmitted/η_incident along it, or `None` on total
/// internal reflection.
#[inline]
pub fn refract(wi: Vec3A, n: Vec3A, eta: f32) -> Option<(Vec3A, f32)> {
    let mut cos_i = wi.dot(n);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wt = -wi / eta + (cos_i / eta - cos_t) * n;
    Some((wt, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_fresnel_known_values() {
        // Normal incidence: ((η−1)/(η+1))²; η = 1.5 → 0.04.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        // Brewster's angle tan θ_B = η: the p component vanishes, R = rₛ²/2.
        let theta_b = 1.5f32.atan();
        let (c, s) = (theta_b.cos(), theta_b.sin());
        let cos_t = (1.0 - (s / 1.5).powi(2)).sqrt();
        let rs = (c - 1.5 * cos_t) / (c + 1.5 * cos_t);
        assert!((fresnel_dielectric(c, 1.5) - 0.5 * rs * rs).abs() < 1e-6);
        // Grazing: 1. From inside beyond the critical angle: 1 (total internal reflection).
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(-0.5, 1.5), 1.0);
        // Same interface seen from both sides at corresponding angles (Stokes relations):
        // R(θᵢ, η) = R(θₜ, 1/η).
        let ci = 0.8f32;
        let (wt, _) = refract(Vec3A::new((1.0 - ci * ci).sqrt(), 0.0, ci), Vec3A::Z, 1.5).unwrap();
        assert!((fresnel_dielectric(ci, 1.5) - fresnel_dielectric(wt.z, 1.5)).abs() < 1e-6);
    }

    #[test]
    fn conductor_fresnel_with_k_zero_is_the_dielectric_fresnel() {
        for eta in [0.2f32, 0.7, 1.0, 1.33, 1.5, 2.4, 4.0] {
            for i in 0..=20 {
                let c = i as f32 / 20.0;
                let (a, b) = (fresnel_complex(c, eta, 0.0), fresnel_dielectric(c, eta));
                assert!((a - b).abs() < 2e-5, "η = {eta}, cos = {c}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn real_and_complex_forms_of_the_conductor_fresnel_agree() {
        for (eta, k) in [
            (0.27f32, 2.78f32),
            (1.38, 1.85),
            (0.05, 10.0),
            (1.5, 0.0),
            (0.7, 0.0),
        ] {
            for i in 0..=40 {
                let c = i as f32 / 40.0;
                let a = fresnel_complex(c, eta, k);
                let b = fresnel_complex_spectrum(
                    c,
                    SampledSpectrum::splat(eta),
                    SampledSpectrum::splat(k),
                )[0];
                assert!(
                    (a - b).abs() < 2e-5,
                    "η = {eta}, k = {k}, cos = {c}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn conductor_fresnel_normal_incidence_and_bounds() {
        // R(0) = ((η−1)² + k²)/((η+1)² + k²) (Born & Wolf §14.2 eq. 25).
        let (eta, k) = (0.27f32, 2.78f32);
        let r0 = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        assert!((fresnel_complex(1.0, eta, k) - r0).abs() < 1e-5);
        for i in 0..=50 {
            let r = fresnel_complex(i as f32 / 50.0, eta, k);
            assert!((0.0..=1.0 + 1e-6).contains(&r), "{r}");
        }
        assert!((fresnel_complex(0.0, eta, k) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn refraction_obeys_snell_and_reverses() {
        let wi = Vec3A::new(0.6, 0.0, 0.8);
        let (wt, etap) = refract(wi, Vec3A::Z, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        assert!((wt.length() - 1.0).abs() < 1e-6 && wt.z < 0.0);
        // sin θₜ = sin θᵢ / η, in the plane of incidence on the other side.
        assert!((wt.x + 0.6 / 1.5).abs() < 1e-6);
        let (back, etap_back) = refract(wt, Vec3A::Z, 1.5).unwrap();
        assert!((back - wi).length() < 1e-5 && (etap_back - 1.0 / 1.5).abs() < 1e-6);
        // Total internal reflection from inside beyond the critical angle.
        assert!(refract(Vec3A::new(0.8, 0.0, -0.6), Vec3A::Z, 1.5).is_none());
        let r = reflect(wi, Vec3A::Z);
        assert!((r - Vec3A::new(-0.6, 0.0, 0.8)).length() < 1e-6);
    }
}
