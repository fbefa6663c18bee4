//! The sample-dimension layout: which dimension of a camera sample's stream means what, in
//! one place for every estimator and both path tracers (scalar and packet).
//!
//! A low-discrepancy sampler stratifies each dimension over a pixel's samples, so a
//! dimension must mean the same thing in every path: every vertex reserves its
//! `VertexDimensions::COUNT` dimensions in a fixed order whether it uses them or not
//! (`SampleStream::reserve`), and computes only those it reads.
//!
//! A camera sample: filter offset 2, lens 2, wavelength 1 (`CAMERA_SAMPLE_DIMENSIONS`), then
//! one `VertexDimensions` block per scattering vertex. Extra light samples of a
//! `SamplePlan` with more than one per hit draw 3 more each, after the vertex's block.
//! Light paths (`light`, `bdpt`) continue the same stream after the camera side: a
//! `LightStartDimensions` block for the emission, then vertex blocks.

use crate::sampler::SampleStream;

/// Dimensions 0–1: the film point's offset within the pixel (drawn from the filter).
pub const FILM_DIMENSIONS: u32 = 2;
/// Dimensions 2–3: the point on the lens (read by the thin lens only; reserved by all).
pub const LENS_DIMENSIONS: u32 = 2;
/// Dimension 4: the hero wavelength.
pub const WAVELENGTH_DIMENSIONS: u32 = 1;
/// The dimensions a camera sample uses before its first vertex.
pub const CAMERA_SAMPLE_DIMENSIONS: u32 = FILM_DIMENSIONS + LENS_DIMENSIONS + WAVELENGTH_DIMENSIONS;
/// The first dimension of each of those draws: film point, lens point, wavelength.
pub const FILM_DIMENSION: u32 = 0;
pub const LENS_DIMENSION: u32 = FILM_DIMENSION + FILM_DIMENSIONS;
pub const WAVELENGTH_DIMENSION: u32 = LENS_DIMENSION + LENS_DIMENSIONS;

/// The block of dimensions one path vertex reserves. Offsets within the block:
/// opacity mask 0, light choice 1, light position 2–3, BSDF lobe 4, BSDF direction 5–6,
/// Russian roulette 7. A light-path vertex uses the light-position pair for the lens point
/// of its connection to the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VertexDimensions {
    first: u32,
}

impl VertexDimensions {
    /// Dimensions per vertex.
    pub const COUNT: u32 = 8;
    pub const MASK: u32 = 0;
    pub const LIGHT_CHOICE: u32 = 1;
    pub const LIGHT: u32 = 2;
    pub const LOBE: u32 = 4;
    pub const BSDF: u32 = 5;
    pub const ROULETTE: u32 = 7;

    /// Reserves the next vertex's block of `stream`.
    #[inline(always)]
    pub fn reserve(stream: &mut SampleStream) -> Self {
        Self {
            first: stream.reserve(Self::COUNT),
        }
    }

    /// The block that starts at `first` (for code that keeps the cursor itself).
    #[inline(always)]
    pub fn starting_at(first: u32) -> Self {
        Self { first }
    }

    #[inline(always)]
    pub fn first(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    pub fn mask(&self) -> u32 {
        self.first + Self::MASK
    }
    #[inline(always)]
    pub fn light_choice(&self) -> u32 {
        self.first + Self::LIGHT_CHOICE
    }
    /// The 2-D light-position variate (and, on light paths, the camera connection's lens
    /// point).
    #[inline(always)]
    pub fn light(&self) -> u32 {
        self.first + Self::LIGHT
    }
    #[inline(always)]
    pub fn lobe(&self) -> u32 {
        self.first + Self::LOBE
    }
    /// The 2-D BSDF (or phase function) direction variate.
    #[inline(always)]
    pub fn bsdf(&self) -> u32 {
        self.first + Self::BSDF
    }
    #[inline(always)]
    pub fn roulette(&self) -> u32 {
        self.first + Self::ROULETTE
    }
}

/// Two more dimensions per vertex in scenes with re-radiation (`RenderScene::
/// has_reradiation`), right after the vertex's block: the lanes' choice between reflection
/// and re-radiation, and the excitation wavelength (integrator/fluorescent_vertex.rs).
/// Other scenes do not reserve them, so their dimensions (and images) are unchanged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReradiationDimensions {
    first: u32,
}

impl ReradiationDimensions {
    pub const COUNT: u32 = 2;

    /// Reserves the pair at the stream's cursor.
    #[inline(always)]
    pub fn reserve(stream: &mut SampleStream) -> Self {
        Self {
            first: stream.reserve(Self::COUNT),
        }
    }
    #[inline(always)]
    pub fn choice(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    pub fn excitation(&self) -> u32 {
        self.first + 1
    }
}

/// The block a path segment through a medium reserves before its vertex's block, in
/// scenes with media only (so media-free scenes keep their layout, and their images):
/// the first free-flight distance 0, and 1 whose 64-bit hash (`SampleStream::seed_at`)
/// seeds the generator of the segment's further collisions and of the following vertex's
/// shadow rays (ratio tracking): their count is unbounded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MediumDimensions {
    first: u32,
}

impl MediumDimensions {
    pub const COUNT: u32 = 2;

    #[inline(always)]
    pub fn reserve(stream: &mut SampleStream) -> Self {
        Self {
            first: stream.reserve(Self::COUNT),
        }
    }
    #[inline(always)]
    pub fn distance(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    pub fn generator(&self) -> u32 {
        self.first + 1
    }
}

/// The block that starts a light path: light choice 1, position on the light 2, direction
/// of emission 2, and the lens point (2) of light tracing's connection of the light's own
/// point to the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightStartDimensions {
    first: u32,
}

impl LightStartDimensions {
    pub const COUNT: u32 = 7;

    /// Reserves the block at the stream's cursor.
    #[inline(always)]
    pub fn reserve(stream: &mut SampleStream) -> Self {
        Self {
            first: stream.reserve(Self::COUNT),
        }
    }
    #[inline(always)]
    pub fn first(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    pub fn light_choice(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    pub fn lens(&self) -> u32 {
        self.first + 5
    }
    #[inline(always)]
    pub fn position(&self) -> u32 {
        self.first + 1
    }
    #[inline(always)]
    pub fn direction(&self) -> u32 {
        self.first + 3
    }
}

/// Where a BDPT light subpath's dimensions start: after the camera sample and one vertex
/// block per possible camera vertex (`max_depth` + 1), so that neither subpath's
/// dimensions depend on the other's length.
#[inline]
pub fn bdpt_light_subpath_first_dimension(max_depth: u32) -> u32 {
    CAMERA_SAMPLE_DIMENSIONS
        .saturating_add(VertexDimensions::COUNT.saturating_mul(max_depth.saturating_add(1)))
}
