//! Participating media: what a path meets between surfaces. This slice has the phase
//! functions that a medium vertex scatters with (`phase`), the reader of Mitsuba's `.vol`
//! density grids (`vol_file`) and a grid's trilinear density with its majorant cells and
//! their DDA (`density_grid`); the media themselves (homogeneous, grid) and their
//! transmittance follow with the media work. Scenes that declare media are refused until
//! then (`scene_build`), never rendered as vacuum.

#![deny(clippy::wildcard_enum_match_arm)]

pub mod density_grid;
pub mod phase;
pub mod vol_file;

pub use density_grid::{DensityGrid, MajorantIter, MajorantSegment, MAJORANT_RES};
pub use phase::{PhaseFunction, PhaseSample};
pub use vol_file::{VolError, VolGrid};
