//! Participating media: what a path meets between surfaces. The media themselves
//! (`media`: a homogeneous or grid `Medium` with its `MediumOptics`), their phase functions
//! (`phase`, `tabulated_phase`), the reader of Mitsuba's `.vol` density grids (`vol_file`)
//! and a grid's trilinear density with its majorant cells and their DDA (`density_grid`).
//! Transport through them is `integrator::medium_transport`.

#![deny(clippy::wildcard_enum_match_arm)]

pub mod density_grid;
pub mod grid;
pub mod homogeneous;
pub mod media;
pub mod phase;
pub mod tabulated_phase;
pub mod vol_file;

pub use density_grid::{DensityGrid, MajorantIter, MajorantSegment, MAJORANT_RES};
pub use grid::GridMedium;
pub use homogeneous::HomogeneousMedium;
pub use media::{DensityStretch, Fluorophore, Medium, MediumOptics, OpticsAtLanes, Stretches};
pub use phase::{PhaseFunction, PhaseSample};
pub use tabulated_phase::TabulatedPhase;
pub use vol_file::{VolError, VolGrid};
