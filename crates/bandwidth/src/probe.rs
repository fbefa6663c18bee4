//! The shading probe: how the predictor asks render, at a G-buffer hit, for the quantities
//! of Bagher et al. 2013's eqs. 4, 5 and 9 without depending on render (render implements
//! the trait; docs/architecture.md).
//!
//! For each of n_b sampled incident directions ω_i at the hit x (Bagher uses n_b = 16):
//!
//! - eq. 4: ν^i = T_{d′} R T_d ν_l^i needs the light's bandwidth ν_l^i along ω_i
//!   ([`LightSample::light_bandwidth`]), the distance d from the light to x
//!   ([`LightSample::distance_m`]), the reflection operator R of eq. 3 (curvature, θ_i, θ_x,
//!   and the material's ρ and t: [`LightSample::cos_theta_i`], [`LightSample::material_bandwidth`],
//!   the rest from the [`GBufferHit`]) and the camera distance d′ (`GBufferHit::depth_m`);
//! - eq. 5: ν = Σ λ_i ν^i / Σ λ_i with λ_i = L_i(ω_i) ρ(ω_i, ω_o) cos θ_i
//!   ([`LightSample::weight_y`]);
//! - eq. 9: V(L_p) ≤ 4π²/N_p Σ (ν_a^i + ν_ρa^i) χ_i² with χ_i = L_i ρ ([`LightSample::chi_y`]).
//!
//! Radiance and BSDF values are **luminance-like scalars**: the Y of the spectral quantity in
//! Prism's output normalisation, Y = ∫ q(λ) ȳ(λ) dλ / ∫ ȳ dλ (a flat spectrum of 1 has
//! Y = 1; multiply a radiance Y by `prism:cd_m2_per_unit` = 683.002 · ∫ȳ dλ for cd/m²). A
//! BSDF's Y is its reflectance-weighted ȳ average (a white Lambertian has Y = 1/π sr⁻¹).
//! The predictor only needs relative magnitudes (eq. 5 is a ratio; eq. 9 sets N_p up to a
//! constant), and a scalar keeps the probe cheap; a probe may estimate these Y values from
//! the hero wavelengths.

use glam::{UVec2, Vec3A};

use crate::bandwidth::{Bandwidth, MaterialBandwidth};
use crate::gbuffer::GBufferHit;
use crate::visibility::Visibility;

/// One sampled incident direction at a G-buffer hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// ω_i: unit world-space direction from the hit towards the light.
    pub direction: Vec3A,
    /// L_i(ω_i): Y of the incident radiance from the light along ω_i (W·m⁻²·sr⁻¹ per unit
    /// of the output normalisation), ignoring occlusion (Bagher's eq. 1 ignores
    /// visibility). For a delta light (`pdf_per_sr` = 0) it is instead the Y of the
    /// irradiance at normal incidence it delivers, E⊥ = I/d² (W·m⁻² per unit).
    pub radiance_y: f32,
    /// p(ω_i): the solid-angle density ω_i was drawn with, sr⁻¹; 0 for a delta light
    /// (point, spot, directional), which has a single direction.
    pub pdf_per_sr: f32,
    /// ρ(ω_i, ω_o) |cos θ_i|: Y of the BSDF times the cosine at the shading normal, for ω_o
    /// the G-buffer's view direction, sr⁻¹.
    pub bsdf_cos_per_sr: f32,
    /// |cos θ_i| = |n · ω_i| at the shading normal (θ_i of P_i in eq. 3).
    pub cos_theta_i: f32,
    /// d of eq. 4: distance from the hit to the sampled point on the light, metres;
    /// +∞ for distant lights (environment, directional).
    pub distance_m: f32,
    /// ν_l^i: bandwidth of the light field leaving the light along ω_i (eq. 4's input):
    /// spatial for area lights, angular for distant ones.
    pub light_bandwidth: Bandwidth,
    /// ν_l of the light as a whole, which sets the penumbra of its shadows (`visibility`):
    /// an area light's 1/√A, since a penumbra spans the whole emitter and not the detail
    /// at the sampled point (`light_bandwidth` holds eq. 7's ν_s there, which is high on
    /// the outline); for other lights the same as `light_bandwidth`.
    pub emitter_bandwidth: Bandwidth,
    /// Which light the sample is of (the probe's numbering), so that disagreeing shadow
    /// rays are a penumbra only when they are of one light.
    pub light_index: u32,
    /// ρ and t of the material at the hit for (ω_i, ω_o) (eq. 3's B_{t,ρ}, eq. 9's ν_ρa).
    pub material_bandwidth: MaterialBandwidth,
    /// The colour noise of this sample's weight that luminance bandwidth misses: the
    /// variance of its hero-wavelength XYZ estimate over the sample's wavelength lanes
    /// (X, Y and Z variances summed), in the weight's units squared. 0 for a probe that
    /// does not measure it, or a flat spectrum.
    pub lane_variance: f32,
    /// What the sample's shadow ray met (`Unknown` where the probe does not trace it).
    pub visibility: Visibility,
    /// The sample's part of the render estimator's direct-light value for the camera sample
    /// it stands for (Y, occlusion ignored): L_i ρ cos θ_i over its own strategy's density,
    /// times the estimator's MIS weight; for a delta light L_i ρ cos θ_i over the light's
    /// selection probability. The estimator takes one light and one BSDF sample per hit,
    /// so two probe samples (`draw`) make one camera sample's value.
    pub estimator_y: f32,
    /// Which of the estimator's draws (camera samples) the sample belongs to, below the
    /// count `ShadingProbe::sample_lights` returns.
    pub draw: u32,
}

impl LightSample {
    /// λ_i / p(ω_i) of eq. 5 — L_i ρ cos θ_i divided by the direction's density (1 for a
    /// delta light) — the Monte Carlo weight of this sample in eq. 5's sums, so that with
    /// importance-sampled directions Σ wᵢ ν^i / Σ wᵢ estimates the integrand-weighted mean
    /// bandwidth. Zero for a negative or NaN density.
    pub fn weight_y(&self) -> f32 {
        let value = self.radiance_y * self.bsdf_cos_per_sr;
        if self.pdf_per_sr > 0.0 {
            value / self.pdf_per_sr
        } else if self.is_delta() {
            value
        } else {
            0.0
        }
    }

    /// [`estimator_y`](Self::estimator_y) with the shadow ray's outcome (0 where blocked).
    pub fn visible_estimator_y(&self) -> f32 {
        if self.is_blocked() {
            0.0
        } else {
            self.estimator_y
        }
    }

    /// [`weight_y`](Self::weight_y) with the shadow ray's outcome: 0 where it was blocked
    /// (an untraced sample counts as visible).
    pub fn visible_weight_y(&self) -> f32 {
        if self.is_blocked() {
            0.0
        } else {
            self.weight_y()
        }
    }

    /// True where the sample's shadow ray was traced and blocked.
    pub fn is_blocked(&self) -> bool {
        match self.visibility {
            Visibility::Blocked { .. } => true,
            Visibility::Visible | Visibility::Unknown => false,
        }
    }

    /// χ_i = L_i ρ of eq. 9 (no cosine): `radiance_y · bsdf_cos_per_sr / cos_theta_i`,
    /// 0 at grazing incidence.
    pub fn chi_y(&self) -> f32 {
        if self.cos_theta_i > 0.0 {
            self.radiance_y * self.bsdf_cos_per_sr / self.cos_theta_i
        } else {
            0.0
        }
    }

    /// True for a sample of a delta light (a single direction; `pdf_per_sr` = 0 and
    /// `radiance_y` is an irradiance).
    pub fn is_delta(&self) -> bool {
        self.pdf_per_sr == 0.0
    }
}

/// One indirect estimate of the probe (`ShadingProbe::sample_indirect`): its luminance and
/// the colour noise of its hero wavelengths.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IndirectEstimate {
    /// Y of the estimate (0 where it found no light).
    pub radiance_y: f32,
    /// The variance of its hero-wavelength XYZ estimate over the lanes (X, Y, Z summed), as
    /// `LightSample::lane_variance`: dispersion through glass, spiky spectra.
    pub lane_variance: f32,
}

/// What render implements so the predictor can probe the shading at G-buffer hits.
///
/// `Sync` because the predictor probes pixels in parallel.
pub trait ShadingProbe: Sync {
    /// Clears `out` and fills it with up to `count` light samples at `hit`, the G-buffer
    /// entry of `pixel` (fewer, possibly none, when no light can reach the hit's
    /// hemisphere). Deterministic: the samples depend only on (pixel, count) and the
    /// probe's own seed — seed them per pixel as the renderer's `PixelSampler` does, never
    /// per thread — so a predicted plan is the same for any thread count. Returns how many
    /// of the render estimator's draws (camera samples) the samples stand for: their
    /// `draw` indices are below it, and a draw with no sample is a zero value.
    fn sample_lights(
        &self,
        pixel: UVec2,
        hit: &GBufferHit,
        count: u32,
        out: &mut Vec<LightSample>,
    ) -> u32;

    /// Beyond the paper: clears `out` and fills it with `count` one-bounce indirect
    /// estimates at `hit` (a BSDF-sampled direction, the first non-Dirac surface it meets,
    /// one light sample there with its shadow ray; 0 where the direction meets nothing or
    /// an emitter, whose light `sample_lights` counts), so that L̂_p and V̂_p see the light
    /// the paper's direct-only probe misses. Deterministic like `sample_lights`. The
    /// default (a probe without geometry) has none.
    fn sample_indirect(
        &self,
        _pixel: UVec2,
        _hit: &GBufferHit,
        _count: u32,
        out: &mut Vec<IndirectEstimate>,
    ) {
        out.clear();
    }
}
