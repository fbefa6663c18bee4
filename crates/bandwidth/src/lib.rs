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
//! bandwidth of a 2-D signal by a Haar pyramid ([`local_bandwidth`], eq. 7 with a measured
//! deviation in the level choice); the transport operators of Fig. 4 ([`operators`], eqs. 3
//! and 4); the per-pixel prediction ([`pixel_prediction`], eqs. 5, 6, 9); the bandwidth
//! buffer ([`bandwidth_buffer`], eq. 11 and its pyramid); the allocation of camera samples
//! ([`allocation`]) and the adaptive-sampling baseline ([`adaptive_error`]). The renderer
//! side (G-buffer pass, probe bandwidths, executing the plan) is docs/bandwidth.md's last
//! section.
//!
//! Units: metres, radians, frequencies in cycles per metre and cycles per radian
//! (`bandwidth` module), radiance and BSDF values as Y in Prism's output normalisation
//! (`probe` module).

pub mod adaptive_error;
pub mod allocation;
pub mod bandwidth;
pub mod bandwidth_buffer;
pub mod defocus_mixing;
pub mod error;
pub mod gbuffer;
pub mod geometric_edges;
pub mod hierarchical_shading;
pub mod local_bandwidth;
pub mod mock_probe;
pub mod operators;
pub mod pixel_neighbours;
pub mod pixel_prediction;
pub mod probe;
pub mod sample_plan;
pub mod sparse_probing;
mod stochastic_rounding;
#[cfg(test)]
mod test_rng;
pub mod variance_model;
pub mod variance_pooling;
pub mod visibility;

pub use adaptive_error::{adaptive_error, adaptive_pass_counts};
pub use allocation::{allocate, Allocated, Allocation, AllocationInputs, AllocationSettings};
pub use bandwidth::{Bandwidth, MaterialBandwidth};
pub use bandwidth_buffer::{shading_level, BandwidthBuffer, BandwidthLevel};
pub use defocus_mixing::{mix_over_circles_of_confusion, DefocusPlanes};
pub use error::BandwidthError;
pub use gbuffer::{GBuffer, GBufferHit};
pub use geometric_edges::{geometric_edges, MeanLuminance, SeenSurface};
pub use hierarchical_shading::{HierarchyInputs, SurfacePoint, Upsampling};
pub use local_bandwidth::{Boundary, LocalBandwidth};
pub use mock_probe::MockProbe;
pub use operators::Bounce;
pub use pixel_neighbours::four_neighbours;
pub use pixel_prediction::{predict_pixel, PixelFootprint, PixelPrediction, VarianceBandwidth};
pub use probe::{IndirectEstimate, LightSample, ShadingProbe};
pub use sample_plan::{SamplePlan, DEFAULT_LIGHT_SAMPLES};
pub use sparse_probing::{
    nearest_probed, on_probe_lattice, probed_pixels, samples_per_probed_pixel, ProbeStride,
    AUTO_MAX_STRIDE_PX, DEFAULT_PROBE_STRIDE,
};
pub use variance_model::{model_variance, ModelledVariance};
pub use variance_pooling::{
    pool_scaled, pool_variance, PixelClass, PoolRadius, DEFAULT_POOL_RADIUS,
};
pub use visibility::{Visibility, VisibilitySummary};
