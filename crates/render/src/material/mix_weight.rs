//! The weight of a `mix` material. A plain value for now; a small type of its own so a
//! texture lookup can join it as another variant without touching the mix.

use prism_geometry::SurfaceInteraction;

/// Weight of the second material of a mix, in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub enum MixWeight {
    Constant(f32),
}

impl MixWeight {
    /// The weight at a hit.
    #[inline]
    pub fn eval(&self, _hit: &SurfaceInteraction) -> f32 {
        match self {
            MixWeight::Constant(w) => *w,
        }
    }
}
