//! Textures: image textures (MIP-mapped, nearest/bilinear/trilinear), the box-filtered
//! checkerboard and Perlin noise (fBm, turbulence), evaluated at a hit with its ray
//! differentials; their use as spectra (RGB → spectrum, Jakob & Hanika 2019: bounded albedo
//! or unbounded) and as scalars; normal and bump maps (`shading_normal`).
//!
//! Every lookup goes through a [`TextureContext`] (position, uv and their screen-space
//! derivatives, from `SurfaceInteraction::differentials`). A texture's uv transform maps
//! uv → st before the lookup, with the derivatives transformed alike (pbrt-v4
//! `UVMapping`). Images are read when the scene is built (`load`), through prism-image's
//! decoders, and validated for their use there.

pub mod bandwidth;
pub mod checkerboard;
pub mod footprint;
pub mod load;
pub mod mipmap;
pub mod noise;
pub mod shading_normal;

use std::sync::Arc;

use glam::{Mat2, Vec2, Vec3A};
use prism_geometry::SurfaceInteraction;
use prism_scene::{ImageChannel, NoiseKind, NoiseSpace, TextureFilter};
use prism_spectrum::{
    RgbAlbedoSpectrum, RgbGamut, RgbUnboundedSpectrum, SampledSpectrum, SampledWavelengths,
    Spectrum,
};

pub use bandwidth::TextureBandwidth;
pub use checkerboard::checkerboard_weight;
pub use footprint::CameraFootprint;
pub use load::{build_textures, TexturePurpose, TextureSet};
pub use mipmap::MipMap;
pub use noise::{perlin_noise, Octaves};

/// What a lookup needs from the hit (pbrt-v4 `TextureEvalContext`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureContext {
    /// World-space position, m.
    pub p: Vec3A,
    pub dpdx: Vec3A,
    pub dpdy: Vec3A,
    pub uv: Vec2,
    /// (∂u/∂x, ∂v/∂x) and (∂u/∂y, ∂v/∂y): one pixel step in uv.
    pub duvdx: Vec2,
    pub duvdy: Vec2,
}

impl TextureContext {
    #[inline]
    pub fn from_interaction(si: &SurfaceInteraction) -> Self {
        let d = &si.differentials;
        Self {
            p: si.p,
            dpdx: d.dpdx,
            dpdy: d.dpdy,
            uv: si.uv,
            duvdx: Vec2::new(d.dudx, d.dvdx),
            duvdy: Vec2::new(d.dudy, d.dvdy),
        }
    }
}

/// uv → st = R(θ)·(scale ⊙ uv) + offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvMapping {
    matrix: Mat2,
    offset: Vec2,
}

impl UvMapping {
    pub fn from_scene(t: &prism_scene::UvTransform) -> Self {
        let scale = Mat2::from_diagonal(Vec2::new(t.scale[0] as f32, t.scale[1] as f32));
        Self {
            matrix: Mat2::from_angle(t.rotation_rad as f32) * scale,
            offset: Vec2::new(t.offset[0] as f32, t.offset[1] as f32),
        }
    }

    pub fn identity() -> Self {
        Self {
            matrix: Mat2::IDENTITY,
            offset: Vec2::ZERO,
        }
    }

    /// st and its derivatives (one pixel in x, one in y).
    #[inline]
    pub fn map(&self, ctx: &TextureContext) -> (Vec2, Vec2, Vec2) {
        (
            self.matrix * ctx.uv + self.offset,
            self.matrix * ctx.duvdx,
            self.matrix * ctx.duvdy,
        )
    }
}

/// An image texture's pyramid and how it is looked up.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSource {
    pub mip: MipMap,
    pub filter: TextureFilter,
    pub channel: ImageChannel,
}

impl ImageSource {
    /// Filtered RGBA at st.
    #[inline]
    pub fn lookup(&self, st: Vec2, dst0: Vec2, dst1: Vec2) -> [f32; 4] {
        match self.filter {
            TextureFilter::Nearest => self.mip.nearest(st),
            TextureFilter::Bilinear => self.mip.bilinear(0, st),
            TextureFilter::Trilinear => self.mip.trilinear(st, dst0, dst1),
        }
    }

    #[inline]
    fn scalar(&self, rgba: [f32; 4]) -> f32 {
        match self.channel {
            ImageChannel::Average => (rgba[0] + rgba[1] + rgba[2]) * (1.0 / 3.0),
            ImageChannel::R => rgba[0],
            ImageChannel::G => rgba[1],
            ImageChannel::B => rgba[2],
            ImageChannel::A => rgba[3],
        }
    }
}

/// Procedural noise parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseSource {
    pub kind: NoiseKind,
    pub space: NoiseSpace,
    pub frequency: f32,
    pub octaves: Octaves,
}

impl NoiseSource {
    /// The blend weight t ∈ [0, 1].
    #[inline]
    fn weight(&self, ctx: &TextureContext, st: Vec2, dst0: Vec2, dst1: Vec2) -> f32 {
        let f = self.frequency;
        let (p, footprint) = match self.space {
            NoiseSpace::World => (ctx.p * f, f * ctx.dpdx.length().max(ctx.dpdy.length())),
            NoiseSpace::Uv => (
                Vec3A::new(st.x * f, st.y * f, 0.0),
                f * dst0.length().max(dst1.length()),
            ),
        };
        let footprint = f64::from(footprint);
        let t = match self.kind {
            // A single octave, faded to its mean like the sums.
            NoiseKind::Perlin => {
                let one = Octaves {
                    max_octaves: 1,
                    ..self.octaves
                };
                0.5 + 0.5 * one.fbm(p, footprint)
            }
            NoiseKind::Fbm => 0.5 + 0.5 * self.octaves.fbm(p, footprint),
            NoiseKind::Turbulence => self.octaves.turbulence(p, footprint),
        };
        t.clamp(0.0, 1.0) as f32
    }
}

/// Where a texture's values come from.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    Image(ImageSource),
    Checkerboard,
    Noise(NoiseSource),
}

/// A texture's raw value at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TexelValue {
    /// Linear sRGB (Rec.709 primaries) colour and alpha of an image.
    Rgba([f32; 4]),
    /// Weight of `b` in (1 − t)·a + t·b (checkerboard, noise).
    Blend(f32),
}

/// A texture as built for one use.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub mapping: UvMapping,
    pub source: TextureSource,
    /// The two values of a blend texture (checkerboard, noise) as spectra...
    pub a: Spectrum,
    pub b: Spectrum,
    /// ...and as scalars (their value at 560 nm; scalar uses require constants).
    pub a_scalar: f32,
    pub b_scalar: f32,
    /// `textures.NAME` or the JSON path of the definition (for messages).
    pub place: String,
}

impl Texture {
    #[inline]
    pub fn value(&self, ctx: &TextureContext) -> TexelValue {
        let (st, dst0, dst1) = self.mapping.map(ctx);
        match &self.source {
            TextureSource::Image(image) => TexelValue::Rgba(image.lookup(st, dst0, dst1)),
            TextureSource::Checkerboard => TexelValue::Blend(checkerboard_weight(st, dst0, dst1)),
            TextureSource::Noise(n) => TexelValue::Blend(n.weight(ctx, st, dst0, dst1)),
        }
    }

    /// The scalar value at `ctx` (image: its channel; blend: lerp of the scalars).
    #[inline]
    pub fn scalar(&self, ctx: &TextureContext) -> f32 {
        match self.value(ctx) {
            TexelValue::Rgba(rgba) => match &self.source {
                TextureSource::Image(image) => image.scalar(rgba),
                _ => unreachable!("only images give RGBA"),
            },
            TexelValue::Blend(t) => self.a_scalar + t * (self.b_scalar - self.a_scalar),
        }
    }
}

/// How an image's RGB becomes a spectrum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RgbUse {
    /// Reflectance: bounded sigmoid upsampling, values in [0, 1] (pbrt-v4
    /// `RGBAlbedoSpectrum`).
    Albedo,
    /// Any value ≥ 0: scale × sigmoid (pbrt-v4 `RGBUnboundedSpectrum`).
    Unbounded,
}

/// A spectrum-valued parameter: a constant spectrum or a texture.
#[derive(Clone, Debug, PartialEq)]
pub enum TexturedSpectrum {
    Constant(Spectrum),
    Texture { texture: Arc<Texture>, rgb: RgbUse },
}

impl TexturedSpectrum {
    #[inline]
    pub fn eval(
        &self,
        si: &SurfaceInteraction,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            TexturedSpectrum::Constant(s) => s.eval(wavelengths),
            TexturedSpectrum::Texture { texture, rgb } => eval_spectrum(
                texture,
                *rgb,
                &TextureContext::from_interaction(si),
                wavelengths,
            ),
        }
    }

    /// The spectrum of a constant; `None` for textures.
    pub fn constant(&self) -> Option<&Spectrum> {
        match self {
            TexturedSpectrum::Constant(s) => Some(s),
            TexturedSpectrum::Texture { .. } => None,
        }
    }
}

/// A texture's spectrum at `ctx`: a filtered image RGB upsampled per lookup with the
/// coefficient table (pbrt-v4 upsamples the filtered RGB, not per texel, since the sigmoid
/// is not linear), or the blend of `a` and `b`.
#[inline]
pub fn eval_spectrum(
    texture: &Texture,
    rgb_use: RgbUse,
    ctx: &TextureContext,
    wavelengths: &SampledWavelengths,
) -> SampledSpectrum {
    match texture.value(ctx) {
        TexelValue::Rgba(rgba) => {
            let lambda = wavelengths.lambda();
            match rgb_use {
                // Loading checked the texels are in [0, 1]; filtering (convex weights) keeps
                // them there up to rounding, which the clamp removes.
                RgbUse::Albedo => {
                    let rgb = [rgba[0], rgba[1], rgba[2]].map(|c| c.clamp(0.0, 1.0));
                    RgbAlbedoSpectrum::from_table(RgbGamut::Srgb, rgb)
                        .map(|s| SampledSpectrum::new(s.eval4(lambda)))
                        .unwrap_or(SampledSpectrum::splat(0.0))
                }
                RgbUse::Unbounded => {
                    let rgb = [rgba[0], rgba[1], rgba[2]].map(|c| c.max(0.0));
                    RgbUnboundedSpectrum::from_table(RgbGamut::Srgb, rgb)
                        .map(|s| SampledSpectrum::new(s.eval4(lambda)))
                        .unwrap_or(SampledSpectrum::splat(0.0))
                }
            }
        }
        TexelValue::Blend(t) => {
            let a = texture.a.eval(wavelengths);
            let b = texture.b.eval(wavelengths);
            a * (1.0 - t) + b * t
        }
    }
}

/// A scalar parameter driven by a texture (roughness, opacity, bump height).
#[derive(Clone, Debug, PartialEq)]
pub struct FloatTexture {
    pub texture: Arc<Texture>,
}

impl FloatTexture {
    #[inline]
    pub fn eval(&self, si: &SurfaceInteraction) -> f32 {
        self.texture.scalar(&TextureContext::from_interaction(si))
    }
}
