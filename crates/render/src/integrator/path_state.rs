//! What a path carries from vertex to vertex (pbrt-v4 §13.4 `PathIntegrator::Li`'s loop
//! state): throughput per lane, the MIS state of the last scattering event, depth, the
//! radiance-scale of refractions, the sample-dimension cursor and the lane wavelengths.
//! Every estimator that walks paths (the path tracer, sensors, BDPT's random walks) keeps
//! one, so the bookkeeping after a scattering event is written once.

use glam::Vec3A;
use prism_spectrum::SampledSpectrum;

use super::dimensions::VertexDimensions;
use super::lane_wavelengths::LaneWavelengths;
use super::scatter_vertex::ScatterSample;
use crate::light::LightSampleContext;
use crate::sampler::SampleStream;

/// Most null events (opacity-mask pass-throughs, straight transmission through thin
/// glazing) one path may take: they are not scattering events, so `max_depth` does not
/// bound them.
pub const MAX_NULL_EVENTS: u32 = 256;

/// Where a non-camera path starts: the point that sampled the first direction (with its
/// geometric normal, for the lights' pdfs) and the solid-angle pdf of that direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathOrigin {
    pub ctx: LightSampleContext,
    /// Solid-angle pdf with which the first direction was sampled (> 0).
    pub direction_pdf: f32,
}

/// The state of one path.
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    /// Throughput β per lane: the path's contribution factor so far, divided by its pdf.
    pub beta: SampledSpectrum,
    /// Scattering events so far.
    pub depth: u32,
    /// The ray was produced by a Dirac lobe or is the camera ray: emission it meets is
    /// counted in full (no light-sampling strategy could have produced it).
    pub specular_bounce: bool,
    /// The vertex that sampled the current ray (light pdfs are measured from it).
    pub prev_ctx: LightSampleContext,
    /// Solid-angle pdf of the current ray's direction at `prev_ctx`.
    pub prev_pdf: f32,
    /// Product of η² over refractions: roulette compares radiance, not the 1/η²-scaled
    /// throughput (pbrt-v4 §13.4.4 `etaScale`).
    pub eta_scale: f32,
    /// Null events so far (`MAX_NULL_EVENTS`).
    pub null_events: u32,
    /// The sample-dimension cursor: each vertex takes its block from here.
    pub stream: SampleStream,
    pub wavelengths: LaneWavelengths,
}

impl PathState {
    /// A path leaving `origin_p` along its first ray: a camera path (`origin` `None`: the
    /// first emission met counts in full) or one sampled at a non-specular point whose
    /// light samples the caller takes (emission is then MIS-weighted).
    #[inline(always)]
    pub fn new(
        origin_p: Vec3A,
        origin: Option<PathOrigin>,
        stream: SampleStream,
        wavelengths: LaneWavelengths,
    ) -> Self {
        Self {
            beta: SampledSpectrum::splat(1.0),
            depth: 0,
            specular_bounce: origin.is_none(),
            prev_ctx: origin.map_or(
                LightSampleContext {
                    p: origin_p,
                    n: Vec3A::ZERO,
                },
                |o| o.ctx,
            ),
            prev_pdf: origin.map_or(0.0f32, |o| o.direction_pdf),
            eta_scale: 1.0,
            null_events: 0,
            stream,
            wavelengths,
        }
    }

    /// The next vertex's block of sample dimensions.
    #[inline(always)]
    pub fn next_vertex_dimensions(&mut self) -> VertexDimensions {
        VertexDimensions::reserve(&mut self.stream)
    }

    /// Counts a null event; false once the path has taken too many.
    #[inline(always)]
    pub fn null_event(&mut self) -> bool {
        self.null_events += 1;
        self.null_events <= MAX_NULL_EVENTS
    }

    /// The MIS state after scattering at `ctx` by `sample`.
    #[inline(always)]
    pub fn scattered(&mut self, ctx: LightSampleContext, sample: &ScatterSample) {
        self.specular_bounce = sample.specular;
        self.prev_pdf = sample.pdf;
        if sample.transmission {
            self.eta_scale *= sample.eta * sample.eta;
        }
        self.prev_ctx = ctx;
    }

    /// Russian roulette (Arvo & Kirk 1990) on the radiance-scaled throughput with variate
    /// `u`, once `depth` ≥ `rr_depth`: true when the path ends; otherwise β is divided by
    /// the survival probability.
    #[inline(always)]
    pub fn roulette(&mut self, rr_depth: u32, u: impl FnOnce() -> f32) -> bool {
        if self.depth < rr_depth {
            return false;
        }
        // |β|: re-radiation with a signed matrix (`negatives: keep`) makes lanes negative.
        let q = (1.0 - (self.beta * self.eta_scale).map(f32::abs).max_component()).max(0.0);
        if u() < q {
            return true;
        }
        self.beta *= 1.0 / (1.0 - q);
        false
    }
}
