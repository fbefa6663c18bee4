//! A homogeneous medium: the same coefficients everywhere, so the majorant is σt itself
//! and delta tracking never meets a null collision.

use super::MediumOptics;

/// Constant σa, σs (and emission, phase) over all of space the medium fills.
#[derive(Clone, Debug, PartialEq)]
pub struct HomogeneousMedium {
    pub optics: MediumOptics,
}
