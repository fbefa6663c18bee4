//! The photon integrators, `photon` and `photon_progressive` (issue 20): photons shot
//! from the lights into a caustic map on surfaces (Jensen 1996) and a volume map in media
//! gathered along camera rays by the beam radiance estimate (Jarosz et al. 2008); the
//! rest of the light by `path`'s estimators. `photon` keeps one radius (fixed or
//! k-nearest-neighbour, biased); `photon_progressive` shrinks it pass by pass, consistent:
//! per pixel on surfaces (stochastic progressive photon mapping, Hachisuka & Jensen 2009)
//! and for the whole pass in media (Knaus & Zwicker 2011). One concept per file:
//!
//! - `settings`: the parameters, their defaults for a scene, the memory estimate;
//! - `sppm`: the per-pixel radius and photon count of the progressive surface gather;
//! - `photon_map`: the stored photon and the tree over the photons' spheres;
//! - `medium_flight`: photon flights, camera-segment and shadow-ray transmittance in media;
//! - `shoot`: one pass's photon tracing, in parallel;
//! - `replay`: the statistics of passes rendered elsewhere, without their image;
//! - `camera`: camera paths with the caustic gather and the beam estimate;
//! - `estimator`: the `Estimator` (one photon pass per sample index).

mod camera;
mod estimator;
mod medium_flight;
mod medium_sources;
mod photon_map;
mod replay;
mod settings;
mod shoot;
mod sppm;

pub use estimator::{refusal, PhotonEstimator};
pub use medium_sources::source_shares;
pub use photon_map::{Photon, PhotonTree};
pub use settings::{default_memory_limit_bytes, PhotonMapper, PhotonPlan, RadiusRule};
pub use sppm::{PixelStatistics, SppmStatistics};
