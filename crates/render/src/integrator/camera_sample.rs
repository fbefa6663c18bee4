//! The start of every camera sample: its stream, film point and filter weight, and lens
//! point (`dimensions`: film 2, lens 2; the wavelength dimension is the estimator's).

use glam::{UVec2, Vec2};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, WavelengthDensity};

use super::dimensions::LENS_DIMENSIONS;
use super::estimator::TileWork;
use super::path::FirstHit;
use super::LaneWavelengths;
use super::RenderStats;
use crate::film::{FilmTile, SurfaceAov};
use crate::sampler::SampleStream;
use crate::scene_build::RenderScene;
use prism_spectrum::XyzWeights;

/// A camera sample before its first ray.
#[derive(Clone, Copy, Debug)]
pub struct CameraSample {
    /// Continuous film point, px.
    pub film_point: Vec2,
    /// The filter's weight f/p of the point's offset (`FilterSampler`).
    pub filter_weight: f32,
    /// Lens variate ∈ [0, 1)² (zero for cameras that do not read it).
    pub lens: Vec2,
    /// The stream, after the film and lens dimensions.
    pub stream: SampleStream,
    /// The density its wavelengths are drawn from (`FilmTile::wavelength_density`); read
    /// through [`Self::draw_wavelengths`].
    wavelength_density: WavelengthDensity,
}

impl CameraSample {
    /// Sample `sample_index` of `pixel`.
    #[inline(always)]
    pub fn start(tile: &FilmTile, work: &TileWork, pixel: UVec2, sample_index: u32) -> Self {
        let mut stream = work.sampler.stream(pixel, sample_index);
        let (film_point, filter_weight) = tile.sample_film_point(pixel, stream.get_2d());
        // The lens dimensions are reserved for every camera, computed for the thin lens
        // only (the others ignore them).
        let lens_dimension = stream.reserve(LENS_DIMENSIONS);
        let lens = if work.uses_lens {
            stream.get_2d_at(lens_dimension)
        } else {
            Vec2::ZERO
        };
        Self {
            film_point,
            filter_weight,
            lens,
            stream,
            wavelength_density: tile.wavelength_density(),
        }
    }
}

impl CameraSample {
    /// The sample's wavelengths: the hero from the stream's next dimension (the wavelength
    /// dimension, right after the lens), drawn from the film's density, and its three
    /// rotations.
    #[inline(always)]
    pub fn draw_wavelengths(&mut self) -> LaneWavelengths {
        LaneWavelengths::new(self.wavelength_density.sample(self.stream.get_1d()))
    }

    /// Adds this sample of `pixel` to `tile`: its `estimate` (radiance at `sensor`, and
    /// the first hit for the AOVs; `None` when the film point had no camera ray, a zero),
    /// counted in `stats` (a traced ray, a non-finite estimate, a sample).
    #[allow(clippy::too_many_arguments)]
    pub fn add_to_tile(
        &self,
        tile: &mut FilmTile,
        scene: &RenderScene,
        pixel: UVec2,
        sensor: &SampledWavelengths,
        xyz_weights: &XyzWeights,
        estimate: Option<(SampledSpectrum, Option<FirstHit>)>,
        stats: &mut RenderStats,
    ) {
        let (radiance, aov) = match estimate {
            None => (SampledSpectrum::splat(0.0), None),
            Some((radiance, first_hit)) => {
                stats.rays_traced += 1;
                let aov = first_hit.map(|si| SurfaceAov {
                    depth_m: si.t,
                    normal: si.n_shading,
                    albedo_rgb: scene.albedo(si.material_id),
                });
                (radiance, aov)
            }
        };
        if radiance.has_non_finite() {
            stats.non_finite_samples += 1;
        }
        tile.add_sample_with(
            pixel,
            self.film_point,
            radiance,
            sensor,
            xyz_weights,
            self.filter_weight,
            aov.as_ref(),
        );
        stats.samples += 1;
    }
}
