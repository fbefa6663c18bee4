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
    /// (B − B_e)/π of the leaf element under the hit, at the band of each lane.
    fn reflected_radiance(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let Some(patch) = self.map.patch_of(si.instance_id, si.primitive_id, wo) else {
            return SampledSpectrum::splat(0.0);
        };
        let b = self.solution.radiosity_at(patch, si.p);
        let e = self.solution.emission(patch);
        SampledSpectrum::from_fn(|lane| {
            let k = band_of(wavelengths.wavelength_nm(lane));
            (b[k] - e[k]).max(0.0) * std::f32::consts::FRAC_1_PI
        })
    }

    /// Resolved when the leaf element is seen from at least its own size (√area).
    fn resolves(&self, si: &SurfaceInteraction, wo: Vec3A, distance_m: f32) -> bool {
        let Some(patch) = self.map.patch_of(si.instance_id, si.primitive_id, wo) else {
            return true;
        };
        let area = self.solution.leaf_area_at(patch, si.p);
        distance_m * distance_m >= area
    }
}
