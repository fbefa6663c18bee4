//! What the photon integrators do in media. Camera segments and shadow rays estimate
//! transmittance only: one grey majorant per stretch, σ̄ = max over the lanes of σt × the
//! stretch's density bound, so every lane's ratio-tracking weight 1 − σt(λ)/σ̄ is ≥ 0
//! (Kutz et al. 2017, "Spectral and decomposition tracking", §4: the maximum majorant).
//!
//! - `photon_flight`: a photon's free flight by delta tracking at the hero's majorant with
//!   spectral MIS (as `path`, below).
//! - `Transmittance`: T(0, t) along a camera segment for every t at once — closed form in a
//!   homogeneous medium, else ratio tracking's running product (Novák et al. 2014: the
//!   product up to t is an unbiased estimate of T(0, t) for every t).
//! - `shadow_transmittance`: T of a shadow ray to a light sample through the media and
//!   `interface` surfaces on its way (ratio tracking), masks' holes and thin panes.

use glam::Vec3A;
use prism_geometry::Ray;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use crate::integrator::medium_transport::{sample_t_maj, MediumRng};
use crate::integrator::PathCounters;
use crate::medium::{Medium, OpticsAtLanes};
use crate::scene_build::media::MediaScene;
use crate::scene_build::RenderScene;

/// How a photon's flight through a medium segment ended.
pub enum Flight {
    /// It reached the segment's end.
    Passed,
    Absorbed,
    /// Real scattering at this point.
    Scattered(Vec3A),
}

/// Delta tracking of a photon along `ray` (unit direction, over [t_min, t_max]) at the
/// hero lane's majorant, as `path` samples its distances (pbrt-v4 `SampleT_maj`): the hero
/// decides absorption, scattering or a null collision; β takes every lane's
/// f/p_hero and `r_u` every lane's p_lane/p_hero (pbrt-v4's rescaled probabilities), so
/// the flux a photon stores is β/⟨r_u⟩, the balance heuristic over the four wavelengths
/// (weighting each lane by its own coefficient over the hero's made its flux a product of
/// ratios that explodes over many scatterings in a chromatic medium).
pub fn photon_flight(
    medium: &Medium,
    optics: &OpticsAtLanes,
    ray: &Ray,
    beta: &mut SampledSpectrum,
    r_u: &mut SampledSpectrum,
    rng: &mut MediumRng,
) -> Flight {
    let mut end = Flight::Passed;
    let u = rng.uniform();
    let (mut b, mut r) = (*beta, *r_u);
    let t_maj = sample_t_maj(medium, optics, ray, u, rng, |c, rng| {
        let u_mode = rng.uniform();
        let p_absorb = c.sigma_a[0] / c.sigma_maj[0];
        let p_scatter = c.sigma_s[0] / c.sigma_maj[0];
        if u_mode < p_absorb {
            end = Flight::Absorbed;
            return false;
        }
        if u_mode < p_absorb + p_scatter {
            let pdf = c.t_maj[0] * c.sigma_s[0];
            b *= c.t_maj * c.sigma_s / pdf;
            r *= c.t_maj * c.sigma_s / pdf;
            end = Flight::Scattered(c.p);
            return false;
        }
        let sigma_n = (c.sigma_maj - c.sigma_a - c.sigma_s).clamp_zero();
        let pdf = c.t_maj[0] * sigma_n[0];
        if pdf <= 0.0 {
            end = Flight::Absorbed;
            return false;
        }
        b *= c.t_maj * sigma_n / pdf;
        r *= c.t_maj * sigma_n / pdf;
        if b.is_black() {
            end = Flight::Absorbed;
            return false;
        }
        true
    });
    if let Flight::Passed = end {
        let scale = t_maj / t_maj[0];
        b *= scale;
        r *= scale;
    }
    *beta = b;
    *r_u = r;
    end
}

/// T(0, t) along one camera segment.
pub enum Transmittance<'a> {
    /// e^(−σt·(t − t0)).
    Homogeneous { sigma_t: SampledSpectrum, t0: f32 },
    /// Ratio tracking's collisions: (t, running product after it), in order.
    Steps(&'a [(f32, SampledSpectrum)]),
}

impl Transmittance<'_> {
    /// T from the segment's start to parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> SampledSpectrum {
        match self {
            Transmittance::Homogeneous { sigma_t, t0 } => (*sigma_t * -(t - t0).max(0.0)).exp(),
            Transmittance::Steps(steps) => {
                let n = steps.partition_point(|(s, _)| *s <= t);
                if n == 0 {
                    SampledSpectrum::splat(1.0)
                } else {
                    steps[n - 1].1
                }
            }
        }
    }
}

/// What a camera segment through a medium carries.
pub struct Segment<'a> {
    /// T from the segment's start to any point on it.
    pub transmittance: Transmittance<'a>,
    /// T at the segment's end.
    pub end: SampledSpectrum,
    /// The radiance the medium emits towards the segment's start, ∫ T(t) σa(t) Le dt (0
    /// where it does not emit).
    pub emitted: SampledSpectrum,
}

/// The transmittance of `ray` (unit direction) over [t_min, t_max] through `medium`, and
/// what the medium emits along it. `steps` is the buffer a grid's ratio tracking fills.
///
/// Emission: in a homogeneous medium the closed form σa·Le·(1 − e^(−σt·L))/σt; in a grid,
/// each ratio-tracking collision t_i (a Poisson process of rate σ̄) adds
/// T̂(t_i⁻)·σa·d(t_i)·Le/σ̄ — by Campbell's theorem the sum's mean is ∫ T σa d Le dt, since the
/// running product before t_i estimates T(t_i) without bias (Novák et al. 2014).
pub fn segment_transmittance<'a>(
    medium: &Medium,
    optics: &OpticsAtLanes,
    ray: &Ray,
    steps: &'a mut Vec<(f32, SampledSpectrum)>,
    rng: &mut MediumRng,
) -> Segment<'a> {
    let emits = !optics.emission.is_black();
    match medium {
        Medium::Homogeneous(_) => {
            let length = ray.t_max - ray.t_min;
            let end = if length.is_finite() {
                (optics.sigma_t * -length).exp()
            } else if optics.sigma_t.max_component() > 0.0 {
                optics.sigma_t.map(|s| if s > 0.0 { 0.0 } else { 1.0 })
            } else {
                SampledSpectrum::splat(1.0)
            };
            let mut emitted = SampledSpectrum::splat(0.0);
            if emits {
                for lane in 0..4 {
                    let sigma_t = optics.sigma_t[lane];
                    // σt = 0 means σa = 0 (σt = σa + σs): nothing is emitted.
                    if sigma_t > 0.0 {
                        emitted[lane] =
                            optics.sigma_a[lane] * optics.emission[lane] * (1.0 - end[lane])
                                / sigma_t;
                    }
                }
            }
            Segment {
                transmittance: Transmittance::Homogeneous {
                    sigma_t: optics.sigma_t,
                    t0: ray.t_min,
                },
                end,
                emitted,
            }
        }
        Medium::Grid(_) => {
            steps.clear();
            let mut tr = SampledSpectrum::splat(1.0);
            let mut emitted = SampledSpectrum::splat(0.0);
            let sigma_t_max = optics.sigma_t.max_component();
            'stretches: for stretch in medium.stretches(ray) {
                let sigma_bar = sigma_t_max * stretch.density_bound;
                if sigma_bar <= 0.0 {
                    continue;
                }
                let mut t = stretch.t_min;
                loop {
                    t -= (1.0 - rng.uniform()).ln() / sigma_bar;
                    if t >= stretch.t_max {
                        break;
                    }
                    let density = medium.density(ray.origin + ray.direction * t);
                    if emits {
                        emitted += tr * optics.sigma_a * optics.emission * (density / sigma_bar);
                    }
                    let sigma_n =
                        (SampledSpectrum::splat(sigma_bar) - optics.sigma_t * density).clamp_zero();
                    tr *= sigma_n * (1.0 / sigma_bar);
                    steps.push((t, tr));
                    if tr.is_black() {
                        break 'stretches;
                    }
                }
            }
            Segment {
                transmittance: Transmittance::Steps(steps),
                end: tr,
                emitted,
            }
        }
    }
}

/// Transmittance from `p` (leaving in `medium`) to the light sample `ls`; 0 where an
/// opaque surface blocks it.
#[allow(clippy::too_many_arguments)]
pub fn shadow_transmittance(
    scene: &RenderScene,
    media: &MediaScene,
    mut p: Vec3A,
    ls: &crate::light::LightSample,
    mut medium: Option<u32>,
    wavelengths: &SampledWavelengths,
    rng: &mut MediumRng,
    counters: &mut PathCounters,
) -> SampledSpectrum {
    let zero = SampledSpectrum::splat(0.0);
    let mut tr = SampledSpectrum::splat(1.0);
    let mut steps = Vec::new();
    for _ in 0..256 {
        let shadow = if ls.distance_m.is_finite() {
            Ray::spawn_to(p, ls.p_light)
        } else {
            Ray::spawn(p, ls.wi)
        };
        let hit = scene.geometry.intersect(&shadow);
        let mut next = None;
        if let Some(h) = &hit {
            let si = scene.geometry.shading_interaction(&shadow, h);
            let material = scene.material(si.material_id);
            let mut through = if media.is_interface(si.material_id) {
                SampledSpectrum::splat(1.0)
            } else {
                let opacity = material.opacity_at(&si);
                let mut through = SampledSpectrum::splat(1.0 - opacity);
                if let Some(pane) = material.thin_glazing(wavelengths) {
                    let cos = ls.wi.dot(si.n_shading).abs();
                    through += pane.transmittance(cos) * opacity;
                }
                through
            };
            if through.is_black() {
                return zero;
            }
            through = through.clamp_zero();
            next = Some((si.p, si.n_geometric, h.instance_id, h.t, through));
        }
        if let Some(m) = medium {
            let length = shadow.direction.length();
            let t_end = next.as_ref().map_or(shadow.t_max, |n| n.3);
            let segment = Ray::new(
                shadow.origin,
                shadow.direction / length,
                shadow.t_min * length,
                t_end * length,
            );
            let med = media.medium(m);
            let optics = med.optics().at(wavelengths);
            tr *= segment_transmittance(med, &optics, &segment, &mut steps, rng).end;
        }
        if tr.is_black() {
            return zero;
        }
        let Some((p_hit, n, instance, _, through)) = next else {
            return tr;
        };
        tr *= through;
        medium = media.after_surface(medium, instance, ls.wi, n);
        p = p_hit;
        counters.rays += 1;
    }
    zero
}

/// The medium a ray from `origin` starts in: the side of the first medium boundary it
/// meets that it arrives from, the world's medium if it meets none.
pub fn medium_at_start(scene: &RenderScene, media: &MediaScene, ray: &Ray) -> Option<u32> {
    let mut probe = *ray;
    for _ in 0..64 {
        let Some(hit) = scene.geometry.intersect(&probe) else {
            return media.world;
        };
        if let Some(b) = media.boundary(hit.instance_id) {
            let si = scene.geometry.shading_interaction(&probe, &hit);
            return b.medium_towards(-probe.direction, si.n_geometric);
        }
        let si = scene.geometry.shading_interaction(&probe, &hit);
        probe = Ray::spawn_off_surface(si.p, si.n_geometric, probe.direction);
    }
    media.world
}
