//! A grid medium (pbrt-v4 `GridMedium`): σa and σs scaled by a density grid looked up
//! trilinearly; its 16³ majorant cells, walked by the 3-D DDA of `density_grid`, bound the
//! density on each stretch of a ray, so delta tracking samples against a tight majorant.

use super::{DensityGrid, MediumOptics};

/// σ(p) = density(p) × σ.
#[derive(Clone, Debug)]
pub struct GridMedium {
    pub optics: MediumOptics,
    pub density: DensityGrid,
}
