//! prism-radiosity: a view-independent, spectral hierarchical radiosity solution with
//! clustering (Hanrahan, Salzman & Aupperle 1991; Smits, Arvo & Greenberg 1994), the
//! foundation of the radiosity method for textured periodic surfaces of Mostefaoui,
//! Dischler & Ghazanfarpour ("Rendering Inhomogeneous Surfaces with Radiosity").
//!
//! Units: metres; radiosity and emission in the caller's units (W m⁻² nm⁻¹ per band in the
//! renderer), form factors dimensionless. The renderer supplies planar one-sided patches
//! with per-band reflectance and emission and a [`Visibility`] oracle (its ray tracer); the
//! solution answers the radiosity at any point of a patch ([`Radiosity::radiosity_at`]).

pub mod bins;
mod cluster_view;
pub mod directional;
pub mod element;
pub mod final_gather;
pub mod form_factor;
mod hierarchy;
mod solution_file;
pub mod solver;
pub mod tile_cells;

pub use element::ElementShape;
pub use final_gather::ReceiverGather;
pub use solver::{
    r2, DirectIrradiance, InputPatch, IterationStats, LeafAt, LeafElement, NoDirectLight,
    Radiosity, RadiosityError, RadiositySettings, Unoccluded, Visibility,
};
