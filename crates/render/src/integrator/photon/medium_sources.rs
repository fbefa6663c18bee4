//! Where a pass's photons start: the lights, and media that emit. A medium with `emission`
//! radiates σa·d(p)·Le per unit length and solid angle (the source term of the radiative
//! transfer equation, pbrt-v4 §11.1), a flux Φ(λ) = 4π ∫_V d(p)·σa(λ)·Le(λ) dV. A photon
//! from it starts at a point drawn uniformly in a box B that holds the medium's region
//! (the bounds of the shapes that bound it, cut to a grid's box), in a uniform direction,
//! with flux β = d(p)·σa·Le·|B|·4π/(pmf·N) where the point lies in the medium and 0 where
//! it does not (the probe ray of `medium_at_start` says which).
//!
//! Sources are chosen in proportion to power: the lights as one group by their summed
//! `power_w` (then one light by `LightSet::sample`), each medium by an estimate of its Φ
//! over 360–830 nm from a fixed set of points. Any positive choice probability leaves the
//! estimate unbiased; the powers only spend photons well.

use glam::{Vec2, Vec3A};
use prism_geometry::Ray;
use prism_spectrum::Spectrum;

use super::medium_flight::medium_at_start;
use crate::integrator::medium_transport::MediumRng;
use crate::light::warp::sample_uniform_sphere;
use crate::medium::Medium;
use crate::scene_build::media::MediaScene;
use crate::scene_build::{RenderScene, SceneBuildError};

/// Points per medium for its power estimate.
const POWER_POINTS: u32 = 4096;

/// One emissive medium as a photon source.
#[derive(Clone, Debug, PartialEq)]
pub struct MediumSource {
    pub medium: u32,
    /// The box photons start in, metres.
    pub box_min_m: Vec3A,
    pub box_max_m: Vec3A,
    /// |B|, m³.
    pub volume_m3: f32,
    /// Estimated Φ over 360–830 nm, W.
    pub power_w: f64,
}

/// Where a photon starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// The lights, chosen with this probability; the light itself is then drawn by
    /// `LightSet::sample` with the given uniform number.
    Lights { group_pmf: f32, u_light: f32 },
    /// `media[index]`, chosen with probability `pmf`.
    Medium { index: usize, pmf: f32 },
}

/// The photon sources of a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhotonSources {
    pub media: Vec<MediumSource>,
    /// Probability of the light group, then of each medium (sums to 1).
    lights_pmf: f32,
    media_pmf: Vec<f32>,
}

impl PhotonSources {
    /// The lights and every emissive medium of `scene`; an error for an emissive medium
    /// whose region has no bound (the world's, or one no shape holds inside it).
    pub fn build(scene: &RenderScene) -> Result<Self, SceneBuildError> {
        let Some(media) = &scene.media else {
            return Ok(Self::lights_only());
        };
        let mut sources = Vec::new();
        for (m, medium) in media.media.iter().enumerate() {
            let Some(emission) = &medium.optics().emission else {
                continue;
            };
            let m = m as u32;
            let (box_min_m, box_max_m) = region_box(scene, media, m)?;
            let extent = (box_max_m - box_min_m).max(Vec3A::ZERO);
            let volume_m3 = extent.x * extent.y * extent.z;
            if volume_m3 <= 0.0 {
                continue;
            }
            let spectral_w = product_integral_nm(&medium.optics().sigma_a, emission);
            let density_volume = density_volume_m3(scene, media, m, box_min_m, extent);
            // A region the fixed points all missed still gets photons, at its upper bound.
            let density_volume = if density_volume > 0.0 {
                density_volume
            } else {
                f64::from(volume_m3) * f64::from(max_density(medium))
            };
            let power_w = 4.0 * std::f64::consts::PI * density_volume * spectral_w;
            if power_w > 0.0 && power_w.is_finite() {
                sources.push(MediumSource {
                    medium: m,
                    box_min_m,
                    box_max_m,
                    volume_m3,
                    power_w,
                });
            }
        }
        if sources.is_empty() {
            return Ok(Self::lights_only());
        }
        let radius_m = scene.lights.scene_sphere().radius_m;
        let lights_w: f64 = scene
            .lights
            .lights()
            .iter()
            .map(|l| l.power_w(radius_m).max(0.0))
            .sum();
        let total = lights_w + sources.iter().map(|s| s.power_w).sum::<f64>();
        Ok(Self {
            lights_pmf: (lights_w / total) as f32,
            media_pmf: sources.iter().map(|s| (s.power_w / total) as f32).collect(),
            media: sources,
        })
    }

    fn lights_only() -> Self {
        Self {
            media: Vec::new(),
            lights_pmf: 1.0,
            media_pmf: Vec::new(),
        }
    }

    /// Whether anything shoots photons.
    pub fn is_empty(&self, scene: &RenderScene) -> bool {
        self.media.is_empty() && scene.lights.is_empty()
    }

    /// The source of uniform number `u`. Without emissive media it is the lights with `u`
    /// itself, so such scenes draw the photons they drew before media could emit.
    pub fn choose(&self, u: f32) -> Source {
        if self.media.is_empty() {
            return Source::Lights {
                group_pmf: 1.0,
                u_light: u,
            };
        }
        if u < self.lights_pmf {
            return Source::Lights {
                group_pmf: self.lights_pmf,
                u_light: (u / self.lights_pmf).min(1.0 - f32::EPSILON / 2.0),
            };
        }
        let mut cumulative = self.lights_pmf;
        for (index, &pmf) in self.media_pmf.iter().enumerate() {
            cumulative += pmf;
            if u < cumulative {
                return Source::Medium { index, pmf };
            }
        }
        // Rounding left u above the last sum: the last medium.
        let index = self.media_pmf.len() - 1;
        Source::Medium {
            index,
            pmf: self.media_pmf[index],
        }
    }

    /// A start point in medium source `index`'s box for uniform numbers `u`.
    pub fn point_in_box(&self, index: usize, u: [f32; 3]) -> Vec3A {
        let s = &self.media[index];
        s.box_min_m + (s.box_max_m - s.box_min_m) * Vec3A::from_array(u)
    }
}

/// `--explain`'s words for where photons start when media emit: "; photons from the lights
/// 40 %, medium 'glow' 60 %" (by power); nothing without emissive media.
pub fn source_shares(scene: &RenderScene) -> String {
    let Ok(sources) = PhotonSources::build(scene) else {
        return String::new();
    };
    let Some(media) = &scene.media else {
        return String::new();
    };
    if sources.media.is_empty() {
        return String::new();
    }
    let percent = |pmf: f32| match 100.0 * pmf {
        p if p > 0.0 && p < 0.5 => "< 1 %".to_string(),
        p if p < 100.0 && p > 99.5 => "> 99 %".to_string(),
        p => format!("{p:.0} %"),
    };
    let mut parts = vec![format!("the lights {}", percent(sources.lights_pmf))];
    for (s, &pmf) in sources.media.iter().zip(&sources.media_pmf) {
        parts.push(format!(
            "medium '{}' {}",
            media.names[s.medium as usize],
            percent(pmf)
        ));
    }
    format!("; photons from {} (by power)", parts.join(", "))
}

/// ∫ a(λ)·b(λ) dλ over 360–830 nm at 1 nm (as `Light::power_w`'s integral).
fn product_integral_nm(a: &Spectrum, b: &Spectrum) -> f64 {
    (360..=830)
        .map(|nm| {
            let w = if nm == 360 || nm == 830 { 0.5 } else { 1.0 };
            let nm = f64::from(nm);
            w * a.eval_nm(nm) * b.eval_nm(nm)
        })
        .sum()
}

fn max_density(medium: &Medium) -> f32 {
    match medium {
        Medium::Homogeneous(_) => 1.0,
        Medium::Grid(g) => g.density.max_density(),
    }
}

/// A box that holds medium `m`'s region: the union of the bounds of every shape that
/// names it on a side, cut to a grid's box. The region must be inside some shape: the
/// world's medium and a medium only ever outside shapes fill unbounded space.
fn region_box(
    scene: &RenderScene,
    media: &MediaScene,
    m: u32,
) -> Result<(Vec3A, Vec3A), SceneBuildError> {
    let name = &media.names[m as usize];
    let unbounded = |why: &str| {
        SceneBuildError::new(
            &scene.file,
            format!("media.{name}"),
            format!(
                "medium '{name}' emits light (`emission`) and {why}: the photon integrators \
                 shoot photons from a bounded region only (use path, or put the medium inside \
                 a closed shape with `interior_medium`)"
            ),
        )
    };
    if media.world == Some(m) {
        return Err(unbounded("fills the world (`world_medium`)"));
    }
    let mut inside_some_shape = false;
    let mut lo = Vec3A::splat(f32::INFINITY);
    let mut hi = Vec3A::splat(f32::NEG_INFINITY);
    for instance in 0..media.boundaries.len() as u32 {
        let Some(b) = media.boundary(instance) else {
            continue;
        };
        if b.interior == Some(m) {
            inside_some_shape = true;
        }
        if b.interior == Some(m) || b.exterior == Some(m) {
            if let Some((a, z)) = scene.geometry.instance_world_bounds(instance) {
                lo = lo.min(a);
                hi = hi.max(z);
            }
        }
    }
    if !inside_some_shape {
        return Err(unbounded("is the interior of no shape"));
    }
    if let Medium::Grid(g) = media.medium(m) {
        let (a, z) = g.density.bounds_m();
        lo = lo.max(a);
        hi = hi.min(z);
    }
    Ok((lo, hi))
}

/// ∫ d(p) dV over medium `m`'s part of the box, m³, by `POWER_POINTS` fixed points, each
/// placed in the medium or not by a probe ray in a fixed pseudo-random direction.
fn density_volume_m3(
    scene: &RenderScene,
    media: &MediaScene,
    m: u32,
    box_min_m: Vec3A,
    extent_m: Vec3A,
) -> f64 {
    let medium = media.medium(m);
    let mut rng = MediumRng::new(0x5eed_0000_0000_0001_u64 ^ u64::from(m));
    let mut sum = 0.0f64;
    for _ in 0..POWER_POINTS {
        let p = box_min_m + extent_m * Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform());
        let d = sample_uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        if medium_at_start(scene, media, &Ray::infinite(p, d)) == Some(m) {
            sum += f64::from(medium.density(p));
        }
    }
    sum / f64::from(POWER_POINTS) * f64::from(extent_m.x * extent_m.y * extent_m.z)
}
