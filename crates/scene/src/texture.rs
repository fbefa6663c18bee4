//! Texture descriptions: image textures (PNG/EXR/HDR, read by render through prism-post),
//! the checkerboard and procedural noise, with their uv transform, wrap mode and filter.
//! Textures are named in the `textures` section, or given inline where a material
//! parameter accepts one: `{"texture": "name"}` or `{"texture": {"type": "image", …}}`.
//! Inline definitions are appended to [`SceneDescription::textures`](crate::SceneDescription)
//! under their JSON path, so render loads every texture once and errors name the place.

use std::path::PathBuf;

use crate::reader::{quoted_list, suggest, Result, V};
use crate::schema::schema;
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};

/// One texture.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// `textures.NAME` or the JSON path of an inline definition (for messages).
    pub place: String,
    pub kind: TextureKind,
    pub uv: UvTransform,
}

#[derive(Debug, Clone, PartialEq)]
pub enum TextureKind {
    Image(ImageTexture),
    /// Unit squares in (transformed) uv alternating between `a` (even u+v cell) and `b`,
    /// box-filtered over the ray-differential footprint.
    Checkerboard {
        a: SpectrumRef,
        b: SpectrumRef,
    },
    /// Perlin's improved noise (Perlin 2002) and its sums, mapped to `a`..`b`.
    Noise(NoiseTexture),
}

/// An image file mapped over uv ∈ [0, 1]² (v = 0 is the image's bottom row).
#[derive(Debug, Clone, PartialEq)]
pub struct ImageTexture {
    /// Resolved path of a .png, .exr or .hdr file.
    pub path: PathBuf,
    pub encoding: ImageEncoding,
    pub filter: TextureFilter,
    pub wrap: WrapMode,
    /// Multiplies every texel (≥ 0).
    pub scale: f64,
    /// Which channel a scalar parameter (roughness, opacity, bump height) reads.
    pub channel: ImageChannel,
}

/// How 8/16-bit PNG codes become linear values. EXR and HDR files are linear already.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageEncoding {
    /// sRGB for colour and scalar parameters (IEC 61966-2-1), linear for normal maps
    /// (tangent-space normal maps store the vector's components linearly).
    Auto,
    Srgb,
    Linear,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureFilter {
    /// The texel containing the point (no interpolation, no MIP map).
    Nearest,
    /// Bilinear interpolation of the full-resolution image.
    Bilinear,
    /// Bilinear in the two MIP levels around the ray-differential footprint, blended
    /// linearly (Williams 1983).
    Trilinear,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WrapMode {
    Repeat,
    Clamp,
    Mirror,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageChannel {
    /// Mean of R, G and B.
    Average,
    R,
    G,
    B,
    /// The alpha channel (an error at load time when the file has none).
    A,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseKind {
    /// Improved noise n(p) ∈ [−1, 1] mapped to t = (1 + n)/2.
    Perlin,
    /// Fractional Brownian motion: Σ gainⁱ n(lacunarityⁱ p), mapped to [0, 1].
    Fbm,
    /// Σ gainⁱ |n(lacunarityⁱ p)| (Perlin 1985), normalised to [0, 1].
    Turbulence,
}

/// Where noise is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseSpace {
    /// Solid noise at the world-space hit point (metres × frequency).
    World,
    /// 2D noise over the (transformed) uv plane.
    Uv,
}

#[derive(Debug, Clone, PartialEq)]
pub struct NoiseTexture {
    pub noise: NoiseKind,
    pub space: NoiseSpace,
    /// Features per metre (world) or per uv unit.
    pub frequency: f64,
    pub octaves: u32,
    /// Amplitude ratio between octaves (0 < gain < 1).
    pub gain: f64,
    /// Frequency ratio between octaves (> 1).
    pub lacunarity: f64,
    pub a: SpectrumRef,
    pub b: SpectrumRef,
}

/// uv' = R(rotation)·(scale ⊙ uv) + offset, applied before every lookup.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvTransform {
    pub scale: [f64; 2],
    pub offset: [f64; 2],
    pub rotation_rad: f64,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
            rotation_rad: 0.0,
        }
    }
}

/// A spectrum-valued material parameter: a spectrum, or a texture (index into
/// `SceneDescription::textures`).
#[derive(Debug, Clone, PartialEq)]
pub enum SpectrumParam {
    Spectrum(SpectrumRef),
    Texture(usize),
}

/// The textures parsed so far: the `textures` section, then inline definitions.
#[derive(Debug, Default)]
pub(crate) struct TextureTable {
    pub textures: Vec<Texture>,
    /// Names of the `textures` section's entries (the first `names.len()` textures).
    pub names: Vec<String>,
}

const TYPES: [&str; 3] = ["image", "checkerboard", "noise"];
const IMAGE_EXTENSIONS: [&str; 5] = ["png", "exr", "hdr", "pic", "rgbe"];

/// Parses the `textures` section.
pub(crate) fn parse_textures(v: &V, spectra: &NamedSpectra) -> Result<TextureTable> {
    let mut table = TextureTable::default();
    for (name, entry) in v.map()? {
        let kind_uv = parse_texture(&entry, spectra)?;
        table.textures.push(Texture {
            place: entry.path.to_string(),
            kind: kind_uv.0,
            uv: kind_uv.1,
        });
        table.names.push(name.to_string());
    }
    Ok(table)
}

/// True when `v` is a texture reference (`{"texture": …}`).
pub(crate) fn is_texture_ref(v: &V) -> bool {
    v.is_object() && v.member("texture").is_some()
}

/// A texture reference `{"texture": "name"}` or `{"texture": {definition}}` → index.
pub(crate) fn parse_texture_ref(
    v: &V,
    spectra: &NamedSpectra,
    table: &mut TextureTable,
) -> Result<usize> {
    let o = v.object(schema!("@texture_ref"))?;
    let t = o.req("texture", "a texture name or definition")?;
    if t.str().is_ok() {
        return texture_by_name(&t, table);
    }
    if !t.is_object() {
        return Err(t.type_err("a texture name or a texture object with a `type`"));
    }
    let (kind, uv) = parse_texture(&t, spectra)?;
    table.textures.push(Texture {
        place: t.path.to_string(),
        kind,
        uv,
    });
    Ok(table.textures.len() - 1)
}

/// The index of the `textures` entry named by the string `t`.
pub(crate) fn texture_by_name(t: &V, table: &TextureTable) -> Result<usize> {
    let name = t.str()?;
    table.names.iter().position(|n| n == name).ok_or_else(|| {
        let names: Vec<&str> = table.names.iter().map(String::as_str).collect();
        let known = if names.is_empty() {
            "the `textures` section is empty".to_string()
        } else {
            format!("defined: {}", quoted_list(&names))
        };
        t.err(format!(
            "unknown texture `{name}` ({known}){}",
            suggest(name, names.iter().copied())
        ))
    })
}

/// A spectrum or a texture reference.
pub(crate) fn parse_spectrum_param(
    v: &V,
    spectra: &NamedSpectra,
    usage: SpectrumUse,
    table: &mut TextureTable,
) -> Result<SpectrumParam> {
    if is_texture_ref(v) {
        Ok(SpectrumParam::Texture(parse_texture_ref(
            v, spectra, table,
        )?))
    } else {
        Ok(SpectrumParam::Spectrum(parse_spectrum(v, spectra, usage)?))
    }
}

pub(crate) fn parse_texture_definition(
    v: &V,
    spectra: &NamedSpectra,
) -> Result<(TextureKind, UvTransform)> {
    parse_texture(v, spectra)
}

fn parse_texture(v: &V, spectra: &NamedSpectra) -> Result<(TextureKind, UvTransform)> {
    let kind = v.tag("texture", &TYPES, None)?;
    let o = match kind {
        "image" => v.object(schema!("@texture<image>"))?,
        "checkerboard" => v.object(schema!("@texture<checkerboard>"))?,
        _ => v.object(schema!("@texture<noise>"))?,
    };
    let uv = {
        let scale = match o.get("uv_scale") {
            None => [1.0, 1.0],
            Some(s) => {
                let pair = if s.f64().is_ok() {
                    let x = s.f64()?;
                    [x, x]
                } else {
                    s.numbers::<2>()?
                };
                if !pair.iter().all(|x| *x > 0.0) {
                    return Err(s.err(format!(
                        "expected a uv scale > 0 (a number or [s_u, s_v]), found {pair:?}; \
                         flip a texture with `wrap: \"mirror\"` or `uv_rotate_deg: 180`"
                    )));
                }
                pair
            }
        };
        let offset = match o.get("uv_offset") {
            None => [0.0, 0.0],
            Some(s) => s.numbers::<2>()?,
        };
        UvTransform {
            scale,
            offset,
            rotation_rad: o.f64_or("uv_rotate_deg", 0.0)?.to_radians(),
        }
    };
    let pair = |default_a: f64, default_b: f64| -> Result<(SpectrumRef, SpectrumRef)> {
        let one = |key: &str, default: f64| {
            o.get(key).map_or(Ok(SpectrumRef::Constant(default)), |s| {
                parse_spectrum(&s, spectra, SpectrumUse::NonNegative)
            })
        };
        Ok((one("a", default_a)?, one("b", default_b)?))
    };
    let kind = match kind {
        "image" => {
            let file = o.req("file", "an image file (.png, .exr or .hdr)")?;
            TextureKind::Image(ImageTexture {
                path: file.asset("texture image", &IMAGE_EXTENSIONS)?,
                encoding: match o.one_of_or(
                    "encoding",
                    "image encoding",
                    &["auto", "srgb", "linear"],
                    "auto",
                )? {
                    "srgb" => ImageEncoding::Srgb,
                    "linear" => ImageEncoding::Linear,
                    _ => ImageEncoding::Auto,
                },
                filter: match o.one_of_or(
                    "filter",
                    "texture filter",
                    &["nearest", "bilinear", "trilinear"],
                    "trilinear",
                )? {
                    "nearest" => TextureFilter::Nearest,
                    "bilinear" => TextureFilter::Bilinear,
                    _ => TextureFilter::Trilinear,
                },
                wrap: match o.one_of_or(
                    "wrap",
                    "wrap mode",
                    &["repeat", "clamp", "mirror"],
                    "repeat",
                )? {
                    "clamp" => WrapMode::Clamp,
                    "mirror" => WrapMode::Mirror,
                    _ => WrapMode::Repeat,
                },
                scale: o.get("scale").map_or(Ok(1.0), |s| s.non_negative())?,
                channel: match o.one_of_or(
                    "channel",
                    "image channel",
                    &["average", "r", "g", "b", "a"],
                    "average",
                )? {
                    "r" => ImageChannel::R,
                    "g" => ImageChannel::G,
                    "b" => ImageChannel::B,
                    "a" => ImageChannel::A,
                    _ => ImageChannel::Average,
                },
            })
        }
        "checkerboard" => {
            let (a, b) = pair(0.2, 0.8)?;
            TextureKind::Checkerboard { a, b }
        }
        _ => {
            let (a, b) = pair(0.0, 1.0)?;
            let gain = o.get("gain").map_or(Ok(0.5), |g| g.in_range(0.0, 1.0))?;
            if gain <= 0.0 || gain >= 1.0 {
                return Err(o
                    .get("gain")
                    .unwrap_or(v.clone())
                    .err(format!("expected a gain in (0, 1), found {gain}")));
            }
            let lacunarity = o.positive_or("lacunarity", 2.0)?;
            if lacunarity <= 1.0 {
                return Err(o
                    .get("lacunarity")
                    .unwrap_or(v.clone())
                    .err(format!("expected a lacunarity > 1, found {lacunarity}")));
            }
            let octaves = o.u32_or("octaves", 1, 6)?;
            if octaves > 16 {
                return Err(o
                    .get("octaves")
                    .unwrap_or(v.clone())
                    .err(format!("expected 1 to 16 octaves, found {octaves}")));
            }
            TextureKind::Noise(NoiseTexture {
                noise: match o.one_of_or(
                    "noise",
                    "noise kind",
                    &["perlin", "fbm", "turbulence"],
                    "fbm",
                )? {
                    "perlin" => NoiseKind::Perlin,
                    "turbulence" => NoiseKind::Turbulence,
                    _ => NoiseKind::Fbm,
                },
                space: match o.one_of_or("space", "noise space", &["world", "uv"], "world")? {
                    "uv" => NoiseSpace::Uv,
                    _ => NoiseSpace::World,
                },
                frequency: o.positive_or("frequency", 1.0)?,
                octaves,
                gain,
                lacunarity,
                a,
                b,
            })
        }
    };
    Ok((kind, uv))
}
