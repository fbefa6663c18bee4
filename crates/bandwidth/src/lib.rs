//! prism-bandwidth: the seam between the renderer and the frequency/bandwidth predictor of
//! Bagher, Soler, Subr, Belcour & Holzschuch 2013, "Interactive Rendering of Acquired
//! Materials on Dynamic Geometry Using Frequency Analysis" (IEEE TVCG 19(5)).
//!
//! The data flow (docs/architecture.md): render fills a [`GBuffer`] from the primary hits; the
//! predictor reads it, asks render's [`ShadingProbe`] for sampled light directions with
//! their radiance, BSDF value, distance and bandwidths (Bagher eqs. 4, 5, 9), and returns a
//! [`SamplePlan`]; render executes the plan. This crate depends only on geometry types
//! (prism-geometry's `Curvature`) and glam, never on render.
//!
//! What exists now: the types ([`GBuffer`], [`GBufferHit`], [`SamplePlan`] with
//! [`SamplePlan::uniform`] as the default plan, [`Bandwidth`], [`MaterialBandwidth`],
//! [`LightSample`], [`ShadingProbe`]) and a closed-form [`MockProbe`] for tests; the local
//! bandwidth of a 2-D signal by a Haar pyramid ([`local_bandwidth`], [`LocalBandwidth`],
//! eq. 7 with a measured deviation in the level choice); the transport operators of Fig. 4
//! with eq. 3's reflection and eq. 4's one-bounce bandwidth ([`operators`], [`Bounce`]). The rest of the predictor (per-pixel bandwidth and variance,
//! the bandwidth pyramid, variance → samples) comes next; see docs/bandwidth.md.
//!
//! Units: metres, radians, frequencies in cycles per metre and cycles per radian
//! (`bandwidth` module), radiance and BSDF values as Y in Prism's output normalisation
//! (`probe` module).

pub mod bandwidth;
pub mod error;
pub mod gbuffer;
pub mod local_bandwidth;
pub mod mock_probe;
pub mod operators;
pub mod probe;
pub mod sample_plan;
#[cfg(test)]
mod test_rng;

pub use bandwidth::{Bandwidth, MaterialBandwidth};
pub use error::BandwidthError;
pub use gbuffer::{GBuffer, GBufferHit};
pub use local_bandwidth::{Boundary, LocalBandwidth};
pub use mock_probe::MockProbe;
pub use operators::Bounce;
pub use probe::{LightSample, ShadingProbe};
pub use sample_plan::{SamplePlan, DEFAULT_LIGHT_SAMPLES};
