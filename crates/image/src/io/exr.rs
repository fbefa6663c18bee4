//! OpenEXR read/write with the `exr` crate: linear RGB in unprefixed `R`, `G`, `B`
//! channels, extra layers as prefixed channels (`depth.Z`, `normal.X`, …) in the same
//! part, the colour space in the standard `chromaticities` attribute and the absolute scale
//! in the custom attribute `prism:cd_m2_per_unit` (docs/architecture.md, "Units and conventions").

use std::collections::BTreeMap;
use std::path::Path;

use ::exr::meta::attribute::{AttributeValue, Chromaticities, Text};
use ::exr::prelude::{
    f16, AnyChannel, AnyChannels, Encoding, FlatSamples, LayerAttributes, ReadChannels, ReadLayers,
    SmallVec, Vec2, WritableImage,
};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::{color_space_from_chromaticities, spectral_exr, write_atomically};
use crate::error::{ImageError, Result};
use crate::image::Image;

/// Header attribute holding cd/m² per unit of relative luminance Y.
pub const CD_M2_PER_UNIT_ATTRIBUTE: &str = "prism:cd_m2_per_unit";

/// Sample type of written channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrSampleType {
    /// 16-bit half float (values above 65504 become infinite; exr rounds to nearest).
    F16,
    /// 32-bit float.
    F32,
}

/// Compression of written channels (all lossless).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrCompression {
    None,
    Rle,
    Zip,
    Piz,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExrWriteOptions {
    pub sample_type: ExrSampleType,
    pub compression: ExrCompression,
}

impl Default for ExrWriteOptions {
    fn default() -> Self {
        Self {
            sample_type: ExrSampleType::F32,
            compression: ExrCompression::Zip,
        }
    }
}

/// All channels of every part, as (full name, samples), with the common size.
pub(crate) struct ExrChannels {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<(String, FlatSamples)>,
    pub chromaticities: Option<Chromaticities>,
    pub attributes: BTreeMap<String, AttributeValue>,
}

fn exr_error(path: &Path, action: &'static str, e: ::exr::error::Error) -> ImageError {
    match e {
        ::exr::error::Error::Io(io) => ImageError::io(path, action, io),
        other => ImageError::format(path, format!("not a readable OpenEXR file: {other}")),
    }
}

/// The most decoded sample bytes an EXR file may need unless
/// [`set_exr_decode_limit_bytes`] says otherwise (16 GiB: a 16384² image with 16 float
/// channels).
pub const DEFAULT_EXR_DECODE_LIMIT_BYTES: u64 = 16 << 30;

static EXR_DECODE_LIMIT_BYTES: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(DEFAULT_EXR_DECODE_LIMIT_BYTES);

/// Sets the most decoded sample bytes an EXR file may need (the CLI passes its memory
/// limit; the fuzz tests a small one). Files whose headers declare more are refused
/// before any pixel is allocated.
pub fn set_exr_decode_limit_bytes(bytes: u64) {
    EXR_DECODE_LIMIT_BYTES.store(bytes, std::sync::atomic::Ordering::Relaxed);
}

/// The current limit ([`set_exr_decode_limit_bytes`]).
pub fn exr_decode_limit_bytes() -> u64 {
    EXR_DECODE_LIMIT_BYTES.load(std::sync::atomic::Ordering::Relaxed)
}

/// Reads the headers and refuses a file whose parts would need more sample memory than
/// the limit (a corrupt or hostile data window would otherwise be allocated as it is).
pub(crate) fn check_declared_size(path: &Path) -> Result<()> {
    let meta = ::exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| exr_error(path, "read the header of", e))?;
    let mut bytes: u128 = 0;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.0 as u128, header.layer_size.1 as u128);
        let per_pixel: u128 = header
            .channels
            .list
            .iter()
            .map(|c| c.sample_type.bytes_per_sample() as u128)
            .sum();
        bytes += w * h * per_pixel;
    }
    let limit = exr_decode_limit_bytes();
    // The decoder allocates a chunk's declared size up to the header's largest block (a
    // tile's area or a scan-line block) before it reads it: a hostile tile size in a small
    // file asked for 1.9 GB (found by the fuzzer).
    for (part, header) in meta.headers.iter().enumerate() {
        let block = header.max_block_byte_size() as u128;
        if block > u128::from(limit) {
            return Err(ImageError::format(
                path,
                format!(
                    "part {part}'s header declares blocks of {block} bytes ({}): more than \
                     the {limit}-byte limit for decoding an EXR (--max-memory)",
                    match header.blocks {
                        ::exr::meta::BlockDescription::Tiles(t) =>
                            format!("{}×{} tiles", t.tile_size.0, t.tile_size.1),
                        ::exr::meta::BlockDescription::ScanLines =>
                            format!("scan-line blocks {} px wide", header.layer_size.0),
                    }
                ),
            ));
        }
    }
    if bytes > u128::from(limit) {
        let first = meta
            .headers
            .first()
            .map_or((0, 0), |h| (h.layer_size.0, h.layer_size.1));
        return Err(ImageError::format(
            path,
            format!(
                "the header declares {} bytes of samples ({}×{} in the first of {} parts): \
                 more than the {limit}-byte limit for decoding an EXR (--max-memory)",
                bytes,
                first.0,
                first.1,
                meta.headers.len()
            ),
        ));
    }
    Ok(())
}

/// Reads every channel of every part of an EXR file (largest resolution level, flat data).
pub(crate) fn read_exr_channels(path: &Path) -> Result<ExrChannels> {
    check_declared_size(path)?;
    let image = ::exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(|e| exr_error(path, "read", e))?;
    let first = image
        .layer_data
        .first()
        .ok_or_else(|| ImageError::format(path, "the file holds no image part"))?;
    let (width, height) = (first.size.0, first.size.1);
    let mut channels = Vec::new();
    let mut attributes = BTreeMap::new();
    for layer in image.layer_data {
        if (layer.size.0, layer.size.1) != (width, height) {
            return Err(ImageError::format(
                path,
                format!(
                    "parts differ in size ({}×{} and {}×{}): expected every part the same size",
                    width, height, layer.size.0, layer.size.1
                ),
            ));
        }
        let prefix = layer
            .attributes
            .layer_name
            .as_ref()
            .map(|n| n.to_string())
            .filter(|n| !n.is_empty());
        for (name, value) in layer.attributes.other {
            attributes.entry(name.to_string()).or_insert(value);
        }
        if let Some(software) = layer.attributes.software_name {
            attributes
                .entry("software".to_string())
                .or_insert(AttributeValue::Text(software));
        }
        for channel in layer.channel_data.list {
            let name = channel.name.to_string();
            let full = match &prefix {
                Some(p) if !name.starts_with(&format!("{p}.")) => format!("{p}.{name}"),
                _ => name,
            };
            channels.push((full, channel.sample_data));
        }
    }
    Ok(ExrChannels {
        width,
        height,
        channels,
        chromaticities: image.attributes.chromaticities,
        attributes,
    })
}

fn to_f32(samples: &FlatSamples) -> Vec<f32> {
    match samples {
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::F16(v) => v.par_iter().map(|h| h.to_f32()).collect(),
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

pub(crate) fn sample_at(samples: &FlatSamples, i: usize) -> f32 {
    match samples {
        FlatSamples::F32(v) => v[i],
        FlatSamples::F16(v) => v[i].to_f32(),
        FlatSamples::U32(v) => v[i] as f32,
    }
}

/// Reads an EXR image: `R`, `G`, `B` (or a lone `Y` as grey) become the pixels, other
/// channels become layers split at their last `.`; a spectral EXR without RGB channels is
/// reduced to XYZ with the CIE 1931 observer, then to linear sRGB.
pub fn read_exr(path: &Path) -> Result<Image> {
    check_declared_size(path)?;
    if let Some(rgb) = super::exr_rgb::read_rgb_exr(path) {
        let space = space_of(&rgb.chromaticities);
        let mut image = Image::new(rgb.width, rgb.height, rgb.pixels, space)
            .map_err(|e| ImageError::format(path, e.to_string()))?;
        apply_attributes(path, &mut image, &rgb.attributes)?;
        return Ok(image);
    }
    let data = read_exr_channels(path)?;
    let find = |n: &str| data.channels.iter().position(|(name, _)| name == n);
    let rgb = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => Some([r, g, b]),
        (None, None, None, Some(y)) => Some([y, y, y]),
        _ => None,
    };
    let Some(rgb) = rgb else {
        if data
            .channels
            .iter()
            .any(|(n, _)| spectral_exr::parse_spectral_channel(n).is_some())
        {
            let spectral = spectral_exr::spectral_from_channels(path, &data)?;
            return spectral
                .to_rgb_image(prism_spectrum::Observer::Cie1931, &RgbColorSpace::srgb());
        }
        let names: Vec<&str> = data.channels.iter().map(|(n, _)| n.as_str()).collect();
        return Err(ImageError::format(
            path,
            format!(
                "expected channels R, G, B (or Y, or spectral S0.<λ>nm), found: {}",
                names.join(", ")
            ),
        ));
    };
    let (r, g, b) = (
        &data.channels[rgb[0]].1,
        &data.channels[rgb[1]].1,
        &data.channels[rgb[2]].1,
    );
    let n = data.width * data.height;
    let mut pixels = vec![[0.0f32; 3]; n];
    pixels
        .par_chunks_mut(4096)
        .enumerate()
        .for_each(|(chunk_index, chunk)| {
            let base = chunk_index * 4096;
            for (k, p) in chunk.iter_mut().enumerate() {
                let i = base + k;
                *p = [sample_at(r, i), sample_at(g, i), sample_at(b, i)];
            }
        });
    let space = space_of(&data.chromaticities);
    let mut image = Image::new(data.width, data.height, pixels, space)
        .map_err(|e| ImageError::format(path, e.to_string()))?;

    // Extra layers, grouped by the prefix before the last '.', in file order.
    let mut groups: Vec<(String, Vec<(String, usize)>)> = Vec::new();
    for (index, (name, _)) in data.channels.iter().enumerate() {
        if rgb.contains(&index) || spectral_exr::parse_spectral_channel(name).is_some() {
            continue;
        }
        let (layer, channel) = match name.rfind('.') {
            Some(dot) => (&name[..dot], &name[dot + 1..]),
            None => ("", name.as_str()),
        };
        let (layer, channel) = (layer.replace('.', "_"), channel.to_string());
        match groups.iter_mut().find(|(l, _)| *l == layer) {
            Some((_, list)) => list.push((channel, index)),
            None => groups.push((layer, vec![(channel, index)])),
        }
    }
    for (layer, list) in groups {
        let planes: Vec<Vec<f32>> = list
            .iter()
            .map(|(_, i)| to_f32(&data.channels[*i].1))
            .collect();
        let k = planes.len();
        let mut samples = vec![0.0f32; n * k];
        for (c, plane) in planes.iter().enumerate() {
            for (i, v) in plane.iter().enumerate() {
                samples[i * k + c] = *v;
            }
        }
        let names: Vec<&str> = list.iter().map(|(c, _)| c.as_str()).collect();
        image
            .set_layer(&layer, &names, samples)
            .map_err(|e| ImageError::format(path, e.to_string()))?;
    }

    apply_attributes(path, &mut image, &data.attributes)?;
    Ok(image)
}

/// The colour space of a `chromaticities` attribute; OpenEXR's default (none) is that of
/// ITU-R BT.709 (= sRGB).
pub(crate) fn space_of(chromaticities: &Option<Chromaticities>) -> RgbColorSpace {
    match chromaticities {
        Some(c) => color_space_from_chromaticities(
            [
                [c.red.0 as f64, c.red.1 as f64],
                [c.green.0 as f64, c.green.1 as f64],
                [c.blue.0 as f64, c.blue.1 as f64],
            ],
            [c.white.0 as f64, c.white.1 as f64],
        ),
        None => RgbColorSpace::srgb(),
    }
}

/// `prism:cd_m2_per_unit` (checked) and text attributes as metadata.
fn apply_attributes(
    path: &Path,
    image: &mut Image,
    attributes: &BTreeMap<String, AttributeValue>,
) -> Result<()> {
    for (name, value) in attributes {
        match (name.as_str(), value) {
            (CD_M2_PER_UNIT_ATTRIBUTE, AttributeValue::F32(v)) => {
                image.cd_m2_per_unit = Some(*v as f64)
            }
            (CD_M2_PER_UNIT_ATTRIBUTE, AttributeValue::F64(v)) => image.cd_m2_per_unit = Some(*v),
            (CD_M2_PER_UNIT_ATTRIBUTE, _) => {
                return Err(ImageError::format(
                    path,
                    format!("attribute {CD_M2_PER_UNIT_ATTRIBUTE} must be a float or double"),
                ))
            }
            (_, AttributeValue::Text(t)) => {
                image.metadata.insert(name.clone(), t.to_string());
            }
            _ => {}
        }
    }
    if let Some(scale) = image.cd_m2_per_unit {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(ImageError::format(
                path,
                format!("{CD_M2_PER_UNIT_ATTRIBUTE} = {scale}: expected a positive finite number"),
            ));
        }
    }
    Ok(())
}

/// `chromaticities` attribute of a colour space.
pub(crate) fn chromaticities_of(space: &RgbColorSpace) -> Chromaticities {
    let v = |xy: [f64; 2]| Vec2(xy[0] as f32, xy[1] as f32);
    Chromaticities {
        red: v(space.primaries_xy[0]),
        green: v(space.primaries_xy[1]),
        blue: v(space.primaries_xy[2]),
        white: v(space.white_xy),
    }
}

pub(crate) fn flat_samples(values: Vec<f32>, sample_type: ExrSampleType) -> FlatSamples {
    match sample_type {
        ExrSampleType::F32 => FlatSamples::F32(values),
        ExrSampleType::F16 => {
            FlatSamples::F16(values.par_iter().map(|&v| f16::from_f32(v)).collect())
        }
    }
}

pub(crate) fn encoding(options: &ExrWriteOptions) -> Encoding {
    use ::exr::compression::Compression;
    let compression = match options.compression {
        ExrCompression::None => Compression::Uncompressed,
        ExrCompression::Rle => Compression::RLE,
        ExrCompression::Zip => Compression::ZIP16,
        ExrCompression::Piz => Compression::PIZ,
    };
    Encoding {
        compression,
        ..Encoding::default()
    }
}

pub(crate) fn text(path: &Path, s: &str) -> Result<Text> {
    Text::new_or_none(s).ok_or_else(|| {
        ImageError::format(
            path,
            format!("cannot store '{s}' in an EXR header: expected non-empty Latin-1 text"),
        )
    })
}

/// Writes channels in one part, plus header attributes, through a temporary file.
pub(crate) fn write_exr_channels(
    path: &Path,
    width: usize,
    height: usize,
    channels: Vec<(String, FlatSamples)>,
    chromaticities: Option<Chromaticities>,
    attributes: Vec<(String, AttributeValue)>,
    options: &ExrWriteOptions,
) -> Result<()> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (name, samples) in channels {
        list.push(AnyChannel::new(text(path, &name)?, samples));
    }
    let mut layer_attributes = LayerAttributes::default();
    for (name, value) in attributes {
        layer_attributes.other.insert(text(path, &name)?, value);
    }
    let layer = ::exr::prelude::Layer::new(
        (width, height),
        layer_attributes,
        encoding(options),
        AnyChannels::sort(list),
    );
    let mut image = ::exr::prelude::Image::from_layer(layer);
    image.attributes.chromaticities = chromaticities;
    write_atomically(path, |tmp| {
        image
            .write()
            .to_file(tmp)
            .map_err(|e| exr_error(path, "write", e))
    })
}

/// Writes `image` as one EXR part: `R`, `G`, `B`, then every layer's channels prefixed
/// with its name, `chromaticities` from the colour space, `prism:cd_m2_per_unit` (double)
/// when the image has an absolute scale, and the metadata as text attributes.
pub fn write_exr(path: &Path, image: &Image, options: &ExrWriteOptions) -> Result<()> {
    if image.layers().is_empty() {
        return write_rgb_exr(path, image, options);
    }
    let (channels, attributes) = image_channels(path, image, options)?;
    write_exr_channels(
        path,
        image.width(),
        image.height(),
        channels,
        Some(chromaticities_of(&image.color_space)),
        attributes,
        options,
    )
}

/// [`write_exr`] of an image without layers: the encoder pulls `R`, `G`, `B` from the pixels
/// block by block, so no planar copy of the image is made (`prism tonemap` writes its
/// output within the memory of one image). The file holds what the general path writes.
fn write_rgb_exr(path: &Path, image: &Image, options: &ExrWriteOptions) -> Result<()> {
    let mut layer_attributes = LayerAttributes::default();
    for (name, value) in image_attributes(path, image)? {
        layer_attributes.other.insert(text(path, &name)?, value);
    }
    let (width, pixels) = (image.width(), image.pixels());
    let rgb = move |pos: ::exr::math::Vec2<usize>| pixels[pos.y() * width + pos.x()];
    macro_rules! write_layer {
        ($channels:expr) => {{
            let layer = ::exr::prelude::Layer::new(
                (image.width(), image.height()),
                layer_attributes,
                encoding(options),
                $channels,
            );
            let mut exr_image = ::exr::prelude::Image::from_layer(layer);
            exr_image.attributes.chromaticities = Some(chromaticities_of(&image.color_space));
            write_atomically(path, |tmp| {
                exr_image
                    .write()
                    .to_file(tmp)
                    .map_err(|e| exr_error(path, "write", e))
            })
        }};
    }
    match options.sample_type {
        ExrSampleType::F32 => write_layer!(::exr::prelude::SpecificChannels::rgb(
            move |pos: ::exr::math::Vec2<usize>| {
                let [r, g, b] = rgb(pos);
                (r, g, b)
            }
        )),
        ExrSampleType::F16 => write_layer!(::exr::prelude::SpecificChannels::rgb(
            move |pos: ::exr::math::Vec2<usize>| {
                let [r, g, b] = rgb(pos);
                (f16::from_f32(r), f16::from_f32(g), f16::from_f32(b))
            }
        )),
    }
}

/// Channels and header attributes of `image` as [`write_exr`] writes them.
pub(crate) type ChannelsAndAttributes = (Vec<(String, FlatSamples)>, Vec<(String, AttributeValue)>);

/// The channels (R, G, B, then prefixed layer channels) and attributes (absolute scale,
/// metadata as text) of `image`, as [`write_exr`] writes them.
pub(crate) fn image_channels(
    path: &Path,
    image: &Image,
    options: &ExrWriteOptions,
) -> Result<ChannelsAndAttributes> {
    let n = image.width() * image.height();
    let mut planes = [vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]];
    {
        let [r, g, b] = &mut planes;
        r.par_iter_mut()
            .zip(g.par_iter_mut())
            .zip(b.par_iter_mut())
            .zip(image.pixels().par_iter())
            .for_each(|(((r, g), b), p)| {
                *r = p[0];
                *g = p[1];
                *b = p[2];
            });
    }
    let mut channels = Vec::new();
    for (name, plane) in ["R", "G", "B"].into_iter().zip(planes) {
        channels.push((name.to_string(), flat_samples(plane, options.sample_type)));
    }
    for layer in image.layers() {
        let k = layer.channels.len();
        for (c, channel) in layer.channels.iter().enumerate() {
            let plane: Vec<f32> = (0..n).map(|i| layer.samples[i * k + c]).collect();
            let name = if layer.name.is_empty() {
                channel.clone()
            } else {
                format!("{}.{}", layer.name, channel)
            };
            channels.push((name, flat_samples(plane, options.sample_type)));
        }
    }
    Ok((channels, image_attributes(path, image)?))
}

/// The header attributes of `image`: its absolute scale and its metadata as text.
fn image_attributes(path: &Path, image: &Image) -> Result<Vec<(String, AttributeValue)>> {
    let mut attributes = Vec::new();
    if let Some(scale) = image.cd_m2_per_unit {
        attributes.push((
            CD_M2_PER_UNIT_ATTRIBUTE.to_string(),
            AttributeValue::F64(scale),
        ));
    }
    for (key, value) in &image.metadata {
        // Spectral-layout markers describe spectral channels this RGB file does not have.
        if key == spectral_exr::VERSION_ATTRIBUTE
            || key == spectral_exr::EMISSIVE_UNITS_ATTRIBUTE
            || key == "software"
        {
            continue;
        }
        attributes.push((key.clone(), AttributeValue::Text(text(path, value)?)));
    }
    Ok(attributes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header whose tiles would need more than the decode limit per block (a small file
    /// declaring 65536×32768 tiles; the fuzzer found one that made the decoder allocate
    /// 1.9 GB before reading a byte of the block) is refused with the block size, by every
    /// reader, before any block is read.
    #[test]
    fn huge_declared_blocks_are_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tiles.exr");
        let image = Image::filled(8, 8, [0.5; 3], RgbColorSpace::srgb()).unwrap();
        write_exr(&path, &image, &ExrWriteOptions::default()).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let at = bytes
            .windows(9)
            .position(|w| w == b"tiledesc\0")
            .expect("the writer writes tiles");
        // The attribute "tiles": its type name "tiledesc\0", its size (4 bytes), then the
        // x and y tile sizes (u32 each).
        let sizes = at + 9 + 4;
        bytes[sizes..sizes + 4].copy_from_slice(&65536u32.to_le_bytes());
        bytes[sizes + 4..sizes + 8].copy_from_slice(&32768u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let e = crate::io::read_image(&path).unwrap_err().to_string();
        assert!(
            e.contains("tiles.exr") && e.contains("65536×32768 tiles") && e.contains("limit"),
            "{e}"
        );
        // compare's strip reader too.
        let Err(e) = crate::io::strips::RowSource::open(&path) else {
            panic!("the strip reader opened a file with 65536×32768 tiles");
        };
        assert!(e.to_string().contains("65536×32768 tiles"), "{e}");
    }

    /// The layer-less writer (samples pulled from the pixels) writes what the general one
    /// (planar copies) writes — the same pixels bit for bit, size, scale, metadata and
    /// colour space — for every sample type and compression. (Not the same bytes: the
    /// crate orders the header's custom attributes from a hash map.)
    #[test]
    fn rgb_writer_writes_what_the_general_writer_writes() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (37, 23);
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let v = i as f32 * 0.37;
                [
                    v.sin().abs() * 40.0,
                    (v * 0.5).cos(),
                    -0.25 + (i % 7) as f32,
                ]
            })
            .collect();
        let mut image = Image::new(w, h, pixels, RgbColorSpace::rec2020()).unwrap();
        image.cd_m2_per_unit = Some(179.0);
        image
            .metadata
            .insert("prism:tone_operator".into(), "aces".into());
        for sample_type in [ExrSampleType::F32, ExrSampleType::F16] {
            for compression in [
                ExrCompression::None,
                ExrCompression::Rle,
                ExrCompression::Zip,
                ExrCompression::Piz,
            ] {
                let options = ExrWriteOptions {
                    sample_type,
                    compression,
                };
                let (fast, general) = (dir.path().join("fast.exr"), dir.path().join("general.exr"));
                write_rgb_exr(&fast, &image, &options).unwrap();
                let (channels, attributes) = image_channels(&general, &image, &options).unwrap();
                write_exr_channels(
                    &general,
                    w,
                    h,
                    channels,
                    Some(chromaticities_of(&image.color_space)),
                    attributes,
                    &options,
                )
                .unwrap();
                let (a, b) = (
                    crate::io::read_image(&fast).unwrap(),
                    crate::io::read_image(&general).unwrap(),
                );
                let bits = |i: &Image| -> Vec<u32> {
                    i.pixels().iter().flatten().map(|c| c.to_bits()).collect()
                };
                let what = format!("{sample_type:?} {compression:?}");
                assert!(bits(&a) == bits(&b), "{what}");
                assert_eq!((a.width(), a.height()), (w, h), "{what}");
                assert_eq!(a.cd_m2_per_unit, b.cd_m2_per_unit, "{what}");
                assert_eq!(a.metadata, b.metadata, "{what}");
                assert_eq!(a.color_space, b.color_space, "{what}");
                assert!(a.layers().is_empty() && b.layers().is_empty(), "{what}");
            }
        }
    }
}
