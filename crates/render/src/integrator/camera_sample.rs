//! The start of every camera sample: its stream, film point and filter weight, and lens
//! point (`dimensions`: film 2, lens 2; the wavelength dimension is the estimator's).

use glam::{UVec2, Vec2};

use super::dimensions::LENS_DIMENSIONS;
use super::estimator::TileWork;
use crate::film::FilmTile;
use crate::sampler::SampleStream;

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
        }
    }
}
