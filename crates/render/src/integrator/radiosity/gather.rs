//! The solved scene a final gather reads: the radiosity solution and the map from hits to
//! its patches.

use glam::Vec3A;
use prism_geometry::SurfaceInteraction;
use prism_radiosity::Radiosity;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::patches::{band_of, PatchMap};
use crate::integrator::SolutionGather;

pub struct SolvedScene {
    pub solution: Radiosity,
    pub map: PatchMap,
}

impl SolutionGather for SolvedScene {
    /// (B − B_e)/π of the leaf element under the hit, at the band of each lane; resolved
    /// when the element is seen from at least its own size (√area). On a tiled carrier the
    /// hit is on the tile's faces, which cover 1 − τ(ωo) of the carrier as seen from ωo
    /// (rays through the holes see what is behind): their radiance is the carrier's
    /// reflected radiance divided by that share.
    fn reflected_radiance(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
        seen_from_m: Option<f32>,
    ) -> Option<SampledSpectrum> {
        let Some(patch) = self.map.patch_of(si.instance_id, si.primitive_id, wo) else {
            return Some(SampledSpectrum::splat(0.0));
        };
        let leaf = self.solution.leaf_at(patch, si.p);
        if seen_from_m.is_some_and(|d| d * d < leaf.area_m2) {
            return None;
        }
        let e = self.solution.emission(patch);
        // At most a 20-fold gain: beyond that the faces are slivers the carrier's average
        // does not describe.
        let faces_share = self.map.carrier[si.instance_id as usize].map_or(1.0, |c| {
            (1.0 - self.map.carriers.transparency_towards(c as usize, wo)).max(0.05)
        });
        Some(SampledSpectrum::from_fn(|lane| {
            let k = band_of(wavelengths.wavelength_nm(lane));
            (leaf.radiosity[k] - e[k]).max(0.0) * std::f32::consts::FRAC_1_PI / faces_share
        }))
    }
}
