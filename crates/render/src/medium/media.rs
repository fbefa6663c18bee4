//! The media a scene holds: what a path meets between surfaces (pbrt-v4 §11.4 `Medium`).
//! Every medium scales one set of optical properties (`MediumOptics`) by a density: 1
//! everywhere (homogeneous) or a grid's. Transport asks a medium for two things: the
//! majorant stretches of a ray (density bound × σ_maj) and the density at a point.

use glam::Vec3A;
use prism_geometry::Ray;
use prism_spectrum::{ReradiationMatrix, SampledSpectrum, SampledWavelengths, Spectrum};

use super::{GridMedium, HomogeneousMedium, MajorantIter, PhaseFunction};

/// What a medium is made of, per unit density.
#[derive(Clone, Debug, PartialEq)]
pub struct MediumOptics {
    /// Absorption coefficient σa, m⁻¹.
    pub sigma_a: Spectrum,
    /// Scattering coefficient σs, m⁻¹.
    pub sigma_s: Spectrum,
    /// Emitted radiance Le; the source term is σa·Le (pbrt-v4 `MediumProperties::Le`).
    pub emission: Option<Spectrum>,
    pub phase: PhaseFunction,
    /// A dissolved fluorophore (`None`: the medium does not fluoresce).
    pub fluorescence: Option<Fluorophore>,
}

/// A fluorophore in a medium: its absorption σf adds to σa, and what it absorbs at λi is
/// re-emitted isotropically at λo with the medium's re-radiation matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Fluorophore {
    /// σf, m⁻¹ (per unit density).
    pub sigma_f: Spectrum,
    /// M(λi, λo), m⁻¹·nm⁻¹ (per unit density): the source term at λo is
    /// ∫ M(λi, λo) ∫ L(λi, ω) dω/4π dλi.
    pub matrix: ReradiationMatrix,
}

/// `MediumOptics` at a path's four wavelengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpticsAtLanes {
    pub sigma_a: SampledSpectrum,
    pub sigma_s: SampledSpectrum,
    /// σt = σa + σs.
    pub sigma_t: SampledSpectrum,
    /// Le (0 where the medium does not emit).
    pub emission: SampledSpectrum,
    /// c(λ) = ∫ M(λi, λ) dλi, the fluorophore's re-emission coefficient at each lane's
    /// wavelength (0 without a fluorophore).
    pub sigma_fl: SampledSpectrum,
    /// The majorant per unit density: σt, or `fluorescent_majorant`'s.
    pub sigma_maj: SampledSpectrum,
}

impl OpticsAtLanes {
    /// Where a fluorophore may re-emit (some lane's c > 0) on a segment that may still
    /// scatter: one majorant for every lane, max σt + max c, so the hero collides wherever
    /// any lane re-emits and keeps null collisions for the lanes that pass
    /// (integrator::medium_transport). Elsewhere σt stays the majorant, so a segment that
    /// cannot re-emit never walks null collisions (an unbounded one would not end).
    #[inline]
    pub fn fluorescent_majorant(mut self, may_scatter: bool) -> Self {
        let c_max = self.sigma_fl.max_component();
        if may_scatter && c_max > 0.0 {
            self.sigma_maj = SampledSpectrum::splat(self.sigma_t.max_component() + c_max);
        }
        self
    }
}

impl MediumOptics {
    /// The coefficients at `wavelengths`.
    #[inline]
    pub fn at(&self, wavelengths: &SampledWavelengths) -> OpticsAtLanes {
        let mut sigma_a = self.sigma_a.eval(wavelengths);
        let sigma_s = self.sigma_s.eval(wavelengths);
        let mut sigma_fl = SampledSpectrum::splat(0.0);
        if let Some(f) = &self.fluorescence {
            sigma_a += f.sigma_f.eval(wavelengths);
            let lambda = wavelengths.lambda();
            for (lane, &nm) in lambda.iter().enumerate() {
                sigma_fl[lane] = f.matrix.column_integral(nm);
            }
        }
        let sigma_t = sigma_a + sigma_s;
        OpticsAtLanes {
            sigma_a,
            sigma_s,
            sigma_t,
            emission: self
                .emission
                .as_ref()
                .map_or(SampledSpectrum::splat(0.0), |e| e.eval(wavelengths)),
            sigma_fl,
            sigma_maj: sigma_t,
        }
    }
}

/// A participating medium.
#[derive(Clone, Debug)]
pub enum Medium {
    Homogeneous(HomogeneousMedium),
    Grid(GridMedium),
}

/// One stretch of a ray with its density majorant: density ≤ `density_bound` on
/// [t_min, t_max] (ray parameter; the ray's direction is unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DensityStretch {
    pub t_min: f32,
    pub t_max: f32,
    pub density_bound: f32,
}

/// The stretches of a ray through a medium, in order.
pub enum Stretches<'a> {
    /// One stretch of density 1 (or none once taken).
    Homogeneous(Option<DensityStretch>),
    Grid(MajorantIter<'a>),
}

impl Iterator for Stretches<'_> {
    type Item = DensityStretch;

    #[inline]
    fn next(&mut self) -> Option<DensityStretch> {
        match self {
            Stretches::Homogeneous(s) => s.take(),
            Stretches::Grid(it) => it.next().map(|s| DensityStretch {
                t_min: s.t_min,
                t_max: s.t_max,
                density_bound: s.majorant,
            }),
        }
    }
}

impl Medium {
    #[inline]
    pub fn optics(&self) -> &MediumOptics {
        match self {
            Medium::Homogeneous(m) => &m.optics,
            Medium::Grid(m) => &m.optics,
        }
    }

    /// The density at `p_m` (1 in a homogeneous medium).
    #[inline]
    pub fn density(&self, p_m: Vec3A) -> f32 {
        match self {
            Medium::Homogeneous(_) => 1.0,
            Medium::Grid(m) => m.density.density(p_m),
        }
    }

    /// The stretches of `ray` (unit direction) over [ray.t_min, ray.t_max]. A grid yields
    /// nothing outside its box: the density is 0 there.
    #[inline]
    pub fn stretches(&self, ray: &Ray) -> Stretches<'_> {
        match self {
            Medium::Homogeneous(_) => {
                Stretches::Homogeneous((ray.t_max > ray.t_min).then_some(DensityStretch {
                    t_min: ray.t_min,
                    t_max: ray.t_max,
                    density_bound: 1.0,
                }))
            }
            Medium::Grid(m) => Stretches::Grid(m.density.majorant_segments(ray)),
        }
    }

    /// "homogeneous" or "grid", for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Medium::Homogeneous(_) => "homogeneous",
            Medium::Grid(_) => "grid",
        }
    }
}
