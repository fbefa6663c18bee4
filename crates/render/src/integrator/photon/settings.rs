//! The photon integrators' parameters (`PhotonMapper`) and what they resolve to for one
//! scene (`PhotonPlan`): every parameter the scene leaves out gets a default here, so
//! `prism converge --method photon|photon_progressive` runs on a scene written for
//! `path`. The storage is estimated before anything is allocated and refused above the
//! memory limit.

use super::photon_map::TREE_BYTES_PER_PHOTON;
use super::sppm::SppmStatistics;
use crate::scene_build::{RenderScene, SceneBuildError};

/// How the gather radius is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusRule {
    /// `photon`: one radius (`None`: the default radius).
    Fixed(Option<f32>),
    /// `photon`: each photon's radius is the distance to its k-th nearest neighbour.
    Nearest(u32),
    /// `photon_progressive` from the initial radius (`None`: the default radius): in media
    /// r²ᵢ₊₁ = r²ᵢ(i + α)/(i + 1) (Knaus & Zwicker 2011, eq. 20 with the 2-D kernel); on
    /// surfaces per pixel, with α the fraction of photons kept (`sppm`).
    Progressive { initial_m: Option<f32>, alpha: f32 },
}

/// Parameters of `photon` and `photon_progressive`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonMapper {
    /// Most scattering events of a whole light path (camera and photon parts together).
    pub max_depth: u32,
    /// Russian roulette of camera paths after this many scattering events.
    pub rr_depth: u32,
    /// Photons shot per pass (`None`: one per pixel, as pbrt-v4's SPPM).
    pub photons_per_pass: Option<u32>,
    pub radius: RadiusRule,
    /// Most bytes a pass's photons may take (`None`: 75 % of the machine's memory, where
    /// /proc/meminfo says how much that is; else no limit).
    pub memory_limit_bytes: Option<u64>,
}

/// A photon integrator's settings for one scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonPlan {
    pub photons_per_pass: u32,
    /// The radius of pass 0 (every pass's, unless progressive), metres.
    pub radius_m: f32,
    /// Progressive: α.
    pub alpha: Option<f32>,
    /// k-NN radius: k.
    pub nearest: Option<u32>,
    /// Upper bound of the photon integrator's own memory, bytes: one pass's photon
    /// storage plus, when progressive, the per-pixel statistics (`statistics_bytes`).
    pub estimate_bytes: u64,
    /// Of `estimate_bytes`: photon_progressive's per-pixel radius and count, kept for the
    /// whole render (0 otherwise).
    pub statistics_bytes: u64,
    /// The limit it was checked against, bytes (`None`: none known).
    pub limit_bytes: Option<u64>,
}

/// Photons a light path stores at most: one per real medium scattering up to
/// `max_depth`, or one caustic photon.
fn stored_per_path(max_depth: u32, has_media: bool) -> u64 {
    if has_media {
        u64::from(max_depth.max(1))
    } else {
        1
    }
}

/// 75 % of MemTotal from /proc/meminfo, bytes; `None` where it cannot be read.
pub fn default_memory_limit_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024 / 4 * 3)
}

impl PhotonMapper {
    /// `photon_progressive` (else `photon`).
    pub fn is_progressive(&self) -> bool {
        match self.radius {
            RadiusRule::Progressive { .. } => true,
            RadiusRule::Fixed(_) | RadiusRule::Nearest(_) => false,
        }
    }

    /// The method's name in scene files.
    pub fn name(&self) -> &'static str {
        if self.is_progressive() {
            "photon_progressive"
        } else {
            "photon"
        }
    }

    /// The default gather radius: four pixel footprints at the distance from the camera
    /// to the centre of the scene's bounds (so a pass's density estimate blurs a few
    /// pixels, Hachisuka & Jensen 2009 §4), at most 2 % of the bounding sphere's radius
    /// and at least 10⁻⁴ of it.
    pub fn default_radius_m(scene: &RenderScene) -> f32 {
        let sphere = scene.lights.scene_sphere();
        let radius = sphere.radius_m.max(1e-6);
        let footprint =
            crate::texture::CameraFootprint::from_camera(&scene.camera, scene.resolution)
                .map(|f| {
                    let d = (sphere.center_m - f.origin).length();
                    f.position_spread_m + d * f.direction_spread
                })
                .unwrap_or(0.0);
        let r = 4.0 * footprint;
        if r.is_finite() && r > 0.0 {
            r.clamp(1e-4 * radius, 0.02 * radius)
        } else {
            0.02 * radius
        }
    }

    /// Every default filled in for `scene`, and the storage checked against the limit.
    pub fn plan(&self, scene: &RenderScene) -> Result<PhotonPlan, SceneBuildError> {
        let pixels = u64::from(scene.resolution.x) * u64::from(scene.resolution.y);
        let photons_per_pass = self
            .photons_per_pass
            .unwrap_or(pixels.clamp(1, u64::from(u32::MAX)) as u32);
        let (radius, alpha, nearest) = match self.radius {
            RadiusRule::Fixed(r) => (r, None, None),
            RadiusRule::Nearest(k) => (None, None, Some(k)),
            RadiusRule::Progressive { initial_m, alpha } => (initial_m, Some(alpha), None),
        };
        let radius_m = radius.unwrap_or_else(|| Self::default_radius_m(scene));
        let stored =
            u64::from(photons_per_pass) * stored_per_path(self.max_depth, scene.media.is_some());
        let photon_bytes = stored * TREE_BYTES_PER_PHOTON as u64;
        let statistics_bytes = if alpha.is_some() {
            pixels * SppmStatistics::BYTES_PER_PIXEL
        } else {
            0
        };
        let estimate_bytes = photon_bytes + statistics_bytes;
        let limit_bytes = self.memory_limit_bytes.or_else(default_memory_limit_bytes);
        if let Some(limit) = limit_bytes {
            if estimate_bytes > limit {
                return Err(SceneBuildError::new(
                    &scene.file,
                    "integrator",
                    format!(
                        "`{}` with {photons_per_pass} photons per pass may store {stored} \
                         photons ({photon_bytes} bytes){}, about {} MiB ({estimate_bytes} \
                         bytes) in all, above the memory limit of {} MiB ({limit} bytes): \
                         lower `photons_per_pass`{}",
                        self.name(),
                        if statistics_bytes > 0 {
                            format!(" and keep {statistics_bytes} bytes of per-pixel statistics")
                        } else {
                            String::new()
                        },
                        estimate_bytes.div_ceil(1 << 20),
                        limit / (1 << 20),
                        if statistics_bytes > 0 {
                            " or the resolution"
                        } else {
                            ""
                        },
                    ),
                ));
            }
        }
        Ok(PhotonPlan {
            photons_per_pass,
            radius_m,
            alpha,
            nearest,
            estimate_bytes,
            statistics_bytes,
            limit_bytes,
        })
    }
}

impl PhotonPlan {
    /// The gather radius of pass `iteration` (0-based) in media (on surfaces too unless
    /// progressive): Knaus & Zwicker 2011's r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1) when progressive,
    /// else the fixed radius.
    pub fn radius_at(&self, iteration: u32) -> f32 {
        self.radius_from(iteration, None).1.sqrt() as f32
    }

    /// (iteration, r²) of pass `iteration`, continuing from `known` — an earlier pass's
    /// (iteration, r²) — when given: passes mostly come in order, so each step is O(1).
    pub fn radius_from(&self, iteration: u32, known: Option<(u32, f64)>) -> (u32, f64) {
        let r2_0 = f64::from(self.radius_m).powi(2);
        let Some(alpha) = self.alpha else {
            return (iteration, r2_0);
        };
        let alpha = f64::from(alpha);
        let (mut i, mut r2) = match known {
            Some((k, r2)) if k <= iteration => (k, r2),
            _ => (0, r2_0),
        };
        while i < iteration {
            r2 *= (f64::from(i) + alpha) / (f64::from(i) + 1.0);
            i += 1;
        }
        (iteration, r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_progressive_radius_follows_knaus_zwicker() {
        let plan = PhotonPlan {
            photons_per_pass: 1,
            radius_m: 0.1,
            alpha: Some(2.0 / 3.0),
            nearest: None,
            estimate_bytes: 0,
            statistics_bytes: 0,
            limit_bytes: None,
        };
        assert_eq!(plan.radius_at(0), 0.1);
        let r1 = plan.radius_at(1);
        assert!((r1 * r1 - 0.01 * 2.0 / 3.0).abs() < 1e-8);
        let r2 = plan.radius_at(2);
        assert!((r2 * r2 - r1 * r1 * (1.0 + 2.0 / 3.0) / 2.0).abs() < 1e-8);
        // r² ~ i^(α−1): the radius keeps shrinking.
        assert!(plan.radius_at(1000) < 0.1 * 1000f32.powf(-1.0 / 6.0) * 1.5);
        // Continuing from an earlier pass gives the same radius.
        let (_, r2) = plan.radius_from(1000, Some(plan.radius_from(400, None)));
        assert!((r2.sqrt() as f32 - plan.radius_at(1000)).abs() < 1e-7);
    }
}
