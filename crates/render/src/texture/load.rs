//! Building textures from the scene description: images are read through prism-image's
//! decoders (`prism_image::io::png::read_png_raw` for PNG, `read_image` for EXR/HDR) and
//! checked for their use.
//!
//! Why here and not in prism-scene: the founding design let prism-scene own asset loading, but its
//! arrows say scene uses only geometry and spectrum, and the image decoders live in
//! prism-image, which render already uses (environment maps load the same way). Parsing
//! and path resolution (the file must exist) stay in prism-scene; decoding, which depends
//! on how a texture is used (sRGB vs linear normal maps, albedo bounds, channel needs), is
//! done here, once per (texture, use).
//!
//! Decoding: 8/16-bit PNG codes are sRGB-encoded (IEC 61966-2-1) unless the texture says
//! `"encoding": "linear"` or is a normal map with `"auto"`; alpha is always linear. A PNG
//! with a `cHRM` chunk and EXR files in other primaries are converted to linear sRGB
//! (Rec.709 primaries, the scene format's RGB). Rows are flipped so v = 0 is the bottom.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use prism_scene::{ImageChannel, ImageEncoding, SceneDescription, SpectrumRef, TextureKind};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::RgbGamut;

use super::{ImageSource, MipMap, NoiseSource, Octaves, Texture, TextureSource, UvMapping};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};
use crate::scene_build::SceneBuildError;

/// How a texture is used; decides decoding and validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexturePurpose {
    /// A reflectance (RGB in [0, 1] after `scale`).
    Albedo,
    /// Any value ≥ 0 (emission scale, coefficients).
    Unbounded,
    /// A scalar in [lo, hi] (roughness α, opacity) or any finite value (bump height).
    Scalar { lo_milli: i64, hi_milli: i64 },
    /// A tangent-space normal map: RGB, linear by default.
    NormalMap,
}

impl TexturePurpose {
    /// A scalar that must lie in [lo, hi] (stored in thousandths so the purpose hashes).
    pub fn scalar(lo: f64, hi: f64) -> Self {
        TexturePurpose::Scalar {
            lo_milli: (lo * 1000.0).round() as i64,
            hi_milli: if hi.is_finite() {
                (hi * 1000.0).round() as i64
            } else {
                i64::MAX
            },
        }
    }
}

/// The textures built so far, one per (texture index, purpose).
pub struct TextureSet<'a> {
    scene: &'a SceneDescription,
    built: HashMap<(usize, TexturePurpose), Arc<Texture>>,
}

/// A texture set for `scene` (textures are built on first use).
pub fn build_textures(scene: &SceneDescription) -> TextureSet<'_> {
    TextureSet {
        scene,
        built: HashMap::new(),
    }
}

impl TextureSet<'_> {
    /// Texture `index` built for `purpose`; `used_at` is the JSON path of the parameter
    /// (errors name it and the texture's own place).
    pub fn get(
        &mut self,
        index: usize,
        purpose: TexturePurpose,
        used_at: &str,
    ) -> Result<Arc<Texture>, SceneBuildError> {
        if let Some(t) = self.built.get(&(index, purpose)) {
            return Ok(t.clone());
        }
        let desc = &self.scene.textures[index];
        let place = if desc.place == used_at {
            used_at.to_string()
        } else {
            format!("{used_at} (texture {})", desc.place)
        };
        let texture = build_texture(desc, purpose)
            .map_err(|message| SceneBuildError::new(&self.scene.file, place, message))?;
        let texture = Arc::new(texture);
        self.built.insert((index, purpose), texture.clone());
        Ok(texture)
    }
}

fn scalar_of(r: &SpectrumRef, which: &str) -> Result<f32, String> {
    match r {
        SpectrumRef::Constant(c) => Ok(*c as f32),
        _ => Err(format!(
            "`{which}` must be a number where the texture gives a scalar (roughness, opacity, \
             height)"
        )),
    }
}

fn build_texture(desc: &prism_scene::Texture, purpose: TexturePurpose) -> Result<Texture, String> {
    let mapping = UvMapping::from_scene(&desc.uv);
    let role = match purpose {
        TexturePurpose::Albedo => SpectrumRole::Albedo,
        _ => SpectrumRole::Unbounded,
    };
    let blend_values = |a: &SpectrumRef, b: &SpectrumRef| -> Result<_, String> {
        let (sa, sb) = (
            build_spectrum(a, role).map_err(|e| format!("a: {e}"))?,
            build_spectrum(b, role).map_err(|e| format!("b: {e}"))?,
        );
        let (fa, fb) = match purpose {
            TexturePurpose::Scalar { .. } => (scalar_of(a, "a")?, scalar_of(b, "b")?),
            TexturePurpose::NormalMap => {
                return Err("a normal map must be an image texture".to_string());
            }
            _ => (sa.eval_nm(560.0) as f32, sb.eval_nm(560.0) as f32),
        };
        if let TexturePurpose::Albedo = purpose {
            for (name, r) in [("a", a), ("b", b)] {
                check_reflectance(r).map_err(|e| format!("{name}: {e}"))?;
            }
        }
        if let TexturePurpose::Scalar { lo_milli, hi_milli } = purpose {
            check_scalar_range(fa.min(fb), fa.max(fb), lo_milli, hi_milli)?;
        }
        Ok((sa, sb, fa, fb))
    };
    let (source, values) = match &desc.kind {
        TextureKind::Image(image) => {
            let mip = load_image(image, purpose)?;
            (
                TextureSource::Image(ImageSource {
                    mip,
                    filter: image.filter,
                    channel: image.channel,
                }),
                None,
            )
        }
        TextureKind::Checkerboard { a, b } => {
            (TextureSource::Checkerboard, Some(blend_values(a, b)?))
        }
        TextureKind::Noise(n) => (
            TextureSource::Noise(NoiseSource {
                kind: n.noise,
                space: n.space,
                frequency: n.frequency as f32,
                octaves: Octaves {
                    max_octaves: n.octaves,
                    gain: n.gain,
                    lacunarity: n.lacunarity,
                },
            }),
            Some(blend_values(&n.a, &n.b)?),
        ),
    };
    let (a, b, a_scalar, b_scalar) = values.unwrap_or((
        prism_spectrum::Spectrum::constant(0.0),
        prism_spectrum::Spectrum::constant(0.0),
        0.0,
        0.0,
    ));
    Ok(Texture {
        mapping,
        source,
        a,
        b,
        a_scalar,
        b_scalar,
        place: desc.place.clone(),
    })
}

fn check_reflectance(r: &SpectrumRef) -> Result<(), String> {
    let bad = match r {
        SpectrumRef::Constant(c) => !(0.0..=1.0).contains(c),
        SpectrumRef::Rgb { rgb } => rgb.iter().any(|c| !(0.0..=1.0).contains(c)),
        _ => false,
    };
    if bad {
        Err("a reflectance must be in [0, 1]".to_string())
    } else {
        Ok(())
    }
}

fn check_scalar_range(min: f32, max: f32, lo_milli: i64, hi_milli: i64) -> Result<(), String> {
    let lo = lo_milli as f64 / 1000.0;
    let hi = if hi_milli == i64::MAX {
        f64::INFINITY
    } else {
        hi_milli as f64 / 1000.0
    };
    if !(f64::from(min) >= lo && f64::from(max) <= hi) {
        return Err(format!(
            "texture values span [{min}, {max}]; this parameter needs values in [{lo}, {hi}] \
             (use the texture's `scale`, or `a`/`b`)"
        ));
    }
    Ok(())
}

/// Reads, decodes, validates and MIP-maps an image for `purpose`.
fn load_image(
    image: &prism_scene::ImageTexture,
    purpose: TexturePurpose,
) -> Result<MipMap, String> {
    let path = &image.path;
    let (width, height, mut texels, channels) = decode(path, image.encoding, purpose)?;
    if purpose == TexturePurpose::NormalMap && channels < 3 {
        return Err(format!(
            "{}: a normal map needs RGB channels (tangent-space x, y, z); this file has {channels} \
             ({})",
            path.display(),
            if channels == 1 { "grey" } else { "grey + alpha" }
        ));
    }
    if image.channel == ImageChannel::A && channels != 2 && channels != 4 {
        return Err(format!(
            "{}: `channel: \"a\"` reads alpha, but this file has no alpha channel",
            path.display()
        ));
    }
    let scale = image.scale as f32;
    if scale != 1.0 && purpose != TexturePurpose::NormalMap {
        for t in texels.iter_mut() {
            for c in &mut t[..3] {
                *c *= scale;
            }
        }
    }
    // Validate for the use, naming the first offending texel (x from the left, y from the
    // top, as image viewers count).
    let check = |ok: &dyn Fn(&[f32; 4]) -> bool, need: &str| -> Result<(), String> {
        if let Some(i) = texels.iter().position(|t| !ok(t)) {
            let (x, y) = (i % width, height - 1 - i / width);
            let t = texels[i];
            return Err(format!(
                "{}: texel ({x}, {y}) is ({}, {}, {}) after scale {scale}; {need}",
                path.display(),
                t[0],
                t[1],
                t[2]
            ));
        }
        Ok(())
    };
    match purpose {
        TexturePurpose::Albedo => check(
            &|t| t[..3].iter().all(|c| (0.0..=1.0).contains(c)),
            "a reflectance texture needs RGB in [0, 1] (lower `scale`)",
        )?,
        TexturePurpose::Unbounded | TexturePurpose::NormalMap => check(
            &|t| t.iter().all(|c| c.is_finite() && *c >= 0.0),
            "texture values must be finite and ≥ 0",
        )?,
        TexturePurpose::Scalar { lo_milli, hi_milli } => {
            let channel = image.channel;
            let value = |t: &[f32; 4]| match channel {
                ImageChannel::Average => (t[0] + t[1] + t[2]) / 3.0,
                ImageChannel::R => t[0],
                ImageChannel::G => t[1],
                ImageChannel::B => t[2],
                ImageChannel::A => t[3],
            };
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for t in &texels {
                let v = value(t);
                if !v.is_finite() {
                    check(&|t| value(t).is_finite(), "texture values must be finite")?;
                }
                lo = lo.min(v);
                hi = hi.max(v);
            }
            check_scalar_range(lo, hi, lo_milli, hi_milli)
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
    }
    Ok(MipMap::new(width, height, texels, image.wrap))
}

/// (width, height, RGBA texels with row 0 at the bottom, channel count of the file).
type Decoded = (usize, usize, Vec<[f32; 4]>, usize);

fn decode(
    path: &Path,
    encoding: ImageEncoding,
    purpose: TexturePurpose,
) -> Result<Decoded, String> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let srgb_target = RgbGamut::Srgb.color_space();
    let (w, h, mut texels, channels, space) = if is_png {
        let raw = prism_image::io::png::read_png_raw(path).map_err(|e| e.to_string())?;
        let linear = match encoding {
            ImageEncoding::Linear => true,
            ImageEncoding::Srgb => false,
            ImageEncoding::Auto => purpose == TexturePurpose::NormalMap,
        };
        let max = raw.max_code as f64;
        let lut: Vec<f32> = (0..=raw.max_code)
            .map(|c| {
                let x = f64::from(c) / max;
                if linear {
                    x as f32
                } else {
                    raw.space.transfer.decode(x) as f32
                }
            })
            .collect();
        let n = raw.channels;
        let texels: Vec<[f32; 4]> = raw
            .samples
            .chunks_exact(n)
            .map(|px| {
                let c = |i: usize| lut[px[i] as usize];
                let alpha = |i: usize| (f64::from(px[i]) / max) as f32;
                match n {
                    1 => [c(0), c(0), c(0), 1.0],
                    2 => [c(0), c(0), c(0), alpha(1)],
                    3 => [c(0), c(1), c(2), 1.0],
                    _ => [c(0), c(1), c(2), alpha(3)],
                }
            })
            .collect();
        (raw.width, raw.height, texels, n, raw.space)
    } else {
        let image = prism_image::io::read_image(path).map_err(|e| e.to_string())?;
        let (w, h) = (image.width(), image.height());
        let alpha = image
            .layer("")
            .filter(|l| l.channels.len() == 1 && l.channels[0] == "A")
            .map(|l| l.samples.clone());
        let channels = if alpha.is_some() { 4 } else { 3 };
        let space = image.color_space.clone();
        let texels = image
            .pixels()
            .iter()
            .enumerate()
            .map(|(i, p)| [p[0], p[1], p[2], alpha.as_ref().map_or(1.0, |a| a[i])])
            .collect();
        (w, h, texels, channels, space)
    };
    // Colour in Rec.709 primaries (not for normal maps: their components are a vector).
    if purpose != TexturePurpose::NormalMap && !same_primaries(&space, &srgb_target) {
        let mut rgb: Vec<[f32; 3]> = texels.iter().map(|t| [t[0], t[1], t[2]]).collect();
        prism_image::io::convert_pixels(&mut rgb, &space, &srgb_target);
        for (t, c) in texels.iter_mut().zip(rgb) {
            t[..3].copy_from_slice(&c);
        }
    }
    // Image rows run top to bottom; v = 0 is the bottom row.
    let mut flipped = Vec::with_capacity(texels.len());
    for row in texels.chunks_exact(w).rev() {
        flipped.extend_from_slice(row);
    }
    texels = flipped;
    Ok((w, h, texels, channels))
}

fn same_primaries(a: &RgbColorSpace, b: &RgbColorSpace) -> bool {
    let close = |x: &[f64; 2], y: &[f64; 2]| (x[0] - y[0]).abs().max((x[1] - y[1]).abs()) < 5e-4;
    close(&a.white_xy, &b.white_xy)
        && a.primaries_xy
            .iter()
            .zip(b.primaries_xy.iter())
            .all(|(x, y)| close(x, y))
}
