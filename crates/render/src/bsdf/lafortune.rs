//! Generalized cosine lobes (E. P. F. Lafortune, S.-C. Foo, K. E. Torrance and D. P.
//! Greenberg, "Non-linear approximation of reflectance functions", SIGGRAPH 1997, eq. 4
//! with the anisotropic C_x ≠ C_y of §4):
//!
//! f(ωₒ, ωᵢ) = ρ_d/π + Σⱼ ρⱼ [C_x,j ωₒ,x ωᵢ,x + C_y,j ωₒ,y ωᵢ,y + C_z,j ωₒ,z ωᵢ,z]₊^{nⱼ},
//!
//! each bracket clamped at 0. C_x = C_y = −1, C_z = 1 is a Phong lobe about the mirror
//! direction; −C_x > C_z moves the lobe towards grazing (off-specular peaks); C_x > 0 makes
//! it retro-reflective. The model is a fit: its lobes carry no normalisation, so energy
//! conservation is the fit's business (the paper's own fits stay below 1), not a property
//! of the model. Symmetric in ωₒ, ωᵢ (reciprocal).
//!
//! Sampling: the bracket is (C∘ωₒ)·ωᵢ = |s| cos β with s = (C_x ωₒ,x, C_y ωₒ,y, C_z ωₒ,z),
//! so lobe j is a cosine power about ŝⱼ and is sampled with density (n + 1)/(2π) cosⁿβ
//! (as the paper's §5 suggests). A lobe is picked with probability ∝ its weight
//! ρ̄ⱼ |sⱼ|ⁿ 2π/(n + 1) (its integral over the sphere), the diffuse one ∝ ρ̄_d; the pdf is
//! the mixture. Samples below the horizon fail. One-sided.

use glam::{Vec2, Vec3A};
use prism_geometry::Frame;
use prism_spectrum::SampledSpectrum;

use super::{bandwidth_from_exponent, estimate_albedo, BsdfSample, Bxdf, TransportMode};
use crate::sampling::{power_cosine_pdf, sample_cosine_hemisphere, sample_power_cosine};

/// Most lobes a material may have (the paper fits up to three).
pub const LAFORTUNE_MAX_LOBES: usize = 3;

/// One generalized cosine lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LafortuneLobe {
    pub cx: f32,
    pub cy: f32,
    pub cz: f32,
    /// Exponent n ≥ 0.
    pub exponent: f32,
    /// Spectral scale ρⱼ(λ) ≥ 0 of the lobe.
    pub albedo: SampledSpectrum,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lafortune {
    pub diffuse: SampledSpectrum,
    pub lobes: [LafortuneLobe; LAFORTUNE_MAX_LOBES],
    /// Lobes in use (the first `count` of `lobes`).
    pub count: usize,
}

impl LafortuneLobe {
    /// An unused slot.
    pub const NONE: LafortuneLobe = LafortuneLobe {
        cx: 0.0,
        cy: 0.0,
        cz: 0.0,
        exponent: 0.0,
        albedo: SampledSpectrum::new([0.0; 4]),
    };

    #[inline]
    fn axis(&self, wo: Vec3A) -> Vec3A {
        Vec3A::new(self.cx * wo.x, self.cy * wo.y, self.cz * wo.z)
    }
}

impl Lafortune {
    /// Unnormalised selection weights: diffuse first, then each lobe.
    #[inline]
    fn weights(&self, wo: Vec3A) -> [f32; LAFORTUNE_MAX_LOBES + 1] {
        let mut w = [0.0; LAFORTUNE_MAX_LOBES + 1];
        w[0] = self.diffuse.average().max(0.0);
        for (j, lobe) in self.lobes[..self.count].iter().enumerate() {
            let s = lobe.axis(wo).length();
            w[j + 1] = if s > 0.0 {
                lobe.albedo.average().max(0.0) * s.powf(lobe.exponent) * 2.0 * std::f32::consts::PI
                    / (lobe.exponent + 1.0)
            } else {
                0.0
            };
        }
        if w.iter().sum::<f32>() <= 0.0 {
            w[0] = 1.0;
        }
        w
    }
}

impl Bxdf for Lafortune {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::splat(0.0);
        }
        let mut f = self.diffuse * std::f32::consts::FRAC_1_PI;
        for lobe in &self.lobes[..self.count] {
            let dot = lobe.axis(wo).dot(wi);
            if dot > 0.0 {
                f += lobe.albedo * dot.powf(lobe.exponent);
            }
        }
        f
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let w = self.weights(wo);
        let total: f32 = w.iter().sum();
        let mut pdf = w[0] * wi.z * std::f32::consts::FRAC_1_PI;
        for (j, lobe) in self.lobes[..self.count].iter().enumerate() {
            if w[j + 1] > 0.0 {
                let axis = lobe.axis(wo).normalize_or_zero();
                pdf += w[j + 1] * power_cosine_pdf(axis.dot(wi).min(1.0), lobe.exponent);
            }
        }
        pdf / total
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let w = self.weights(wo);
        let total: f32 = w.iter().sum();
        let mut target = u_lobe * total;
        let mut chosen = 0;
        for (j, &wj) in w[..=self.count].iter().enumerate() {
            chosen = j;
            if target < wj {
                break;
            }
            target -= wj;
        }
        // Skip trailing zero-weight lobes a rounding `target` could land on.
        while w[chosen] <= 0.0 && chosen > 0 {
            chosen -= 1;
        }
        let wi = if chosen == 0 {
            sample_cosine_hemisphere(u)
        } else {
            let lobe = &self.lobes[chosen - 1];
            let frame = Frame::from_z(lobe.axis(wo).normalize());
            frame.from_local(sample_power_cosine(u, lobe.exponent))
        };
        BsdfSample::reflection(wi, self.pdf(wo, wi, mode), || self.eval(wo, wi, mode))
    }

    /// No closed form (the clamped lobes are cut by the horizon): `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        estimate_albedo(self, wo, mode)
    }

    /// The sharpest lobe in use (non-zero albedo) through its cosine power; 0 with none.
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        self.lobes[..self.count]
            .iter()
            .filter(|j| j.albedo.max_component() > 0.0)
            .map(|j| bandwidth_from_exponent(j.exponent))
            .fold(0.0, f32::max)
    }

    #[inline]
    fn is_specular(&self) -> bool {
        false
    }

    #[inline]
    fn has_specular(&self) -> bool {
        false
    }

    #[inline]
    fn is_reflection_only(&self) -> bool {
        true
    }

    /// Isotropic when every lobe weighs x and y alike (C_x = C_y).
    fn is_isotropic(&self) -> bool {
        self.lobes[..self.count].iter().all(|j| j.cx == j.cy)
    }
}
