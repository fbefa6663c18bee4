//! Scene pixel filter → runtime `Filter`. The scene gives a Gaussian by σ (px); the filter
//! takes the falloff α = 1/(2σ²) (pbrt-v4 §8.8.2).

use prism_scene::PixelFilter;

use crate::film::filter::{BlackmanHarrisFilter, BoxFilter, GaussianFilter, MitchellFilter};
use crate::{Filter, InvalidParameter};

pub fn build_filter(filter: &PixelFilter) -> Result<Filter, InvalidParameter> {
    Ok(match *filter {
        PixelFilter::Box { radius_px } => Filter::Box(BoxFilter::new(radius_px as f32)?),
        PixelFilter::Gaussian {
            radius_px,
            sigma_px,
        } => Filter::Gaussian(GaussianFilter::new(
            radius_px as f32,
            (1.0 / (2.0 * sigma_px * sigma_px)) as f32,
        )?),
        PixelFilter::BlackmanHarris { radius_px } => {
            Filter::BlackmanHarris(BlackmanHarrisFilter::new(radius_px as f32)?)
        }
        PixelFilter::Mitchell { radius_px, b, c } => {
            Filter::Mitchell(MitchellFilter::new(radius_px as f32, b as f32, c as f32)?)
        }
    })
}
