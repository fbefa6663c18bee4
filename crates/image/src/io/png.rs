//! PNG read/write (8 or 16 bits per channel) with the `png` crate. Written pixels are
//! clipped to [0, 1] and encoded with the transfer function of the image's colour space
//! (IEC 61966-2-1 sRGB curve for sRGB and Display P3, BT.2020 OETF for Rec.2020); the file
//! carries an `sRGB` chunk for sRGB, else a `cHRM` chunk with the primaries and white.
//! Reading inverts this: the colour space is found from `cHRM` (sRGB without one).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use png::{BitDepth, ColorType, Decoder, Encoder, SourceChromaticities, Transformations};
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::quantise::Quantiser;
use super::zlib_strips;
use super::{color_space_from_chromaticities, write_stream_atomically};
use crate::error::{ImageError, Result};
use crate::image::Image;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngBitDepth {
    Eight,
    Sixteen,
}

/// Raw scan-line bytes per parallel strip (≈ 10 rows of a 4K 16-bit image): ~200 strips
/// for a 4K frame balance any thread count, and each strip costs only a 53-byte Huffman
/// table header and a 4–5 byte flush in the file (0.05 %).
const STRIP_BYTES: usize = 1 << 18;

/// Writes `image` as an RGB PNG of the given depth (see the module notes on encoding).
///
/// Quantisation, filtering and deflate run in parallel on strips of rows
/// (io/zlib_strips.rs joins the strips' deflate streams into the one zlib stream PNG
/// requires, one IDAT chunk per strip): every row gets the `Sub` filter (PNG §9.2, as the
/// `png` crate's default) and fdeflate's fast encoding, as the sequential writer did, so
/// files are as large as before to within 0.1 % (a strip that deflate would enlarge is
/// stored unfiltered instead, as the `png` crate does for a whole image).
pub fn write_png(path: &Path, image: &Image, depth: PngBitDepth) -> Result<()> {
    let (w, h) = (image.width(), image.height());
    if w > u32::MAX as usize || h > u32::MAX as usize {
        return Err(ImageError::invalid(format!(
            "{}: {w}×{h} is too large for PNG",
            path.display()
        )));
    }
    if !zlib_strips::joining_works() {
        return write_png_sequential(path, image, depth);
    }
    let transfer = image.color_space.transfer;
    let sample_bytes = match depth {
        PngBitDepth::Eight => 1,
        PngBitDepth::Sixteen => 2,
    };
    let q = Quantiser::new(transfer, if sample_bytes == 1 { 255 } else { 65535 });
    let row_bytes = 3 * sample_bytes * w;
    let rows_per_strip = (STRIP_BYTES / (row_bytes + 1)).max(1);
    let strips = image
        .pixels()
        .par_chunks(w * rows_per_strip)
        .map(|rows| {
            let mut filtered = vec![0u8; (row_bytes + 1) * (rows.len() / w)];
            let mut raw = vec![0u8; row_bytes];
            for (row, out) in rows
                .chunks_exact(w)
                .zip(filtered.chunks_exact_mut(row_bytes + 1))
            {
                quantise_row(&q, sample_bytes, row, &mut raw);
                sub_filter(&raw, 3 * sample_bytes, out);
            }
            let compressed = zlib_strips::compress_strip(&filtered)?;
            if compressed.len() <= zlib_strips::stored_size(filtered.len()) {
                return Ok(compressed);
            }
            // Incompressible (noise): unfiltered rows in stored blocks, as the `png`
            // crate does for a whole image, here per strip.
            for (row, out) in rows
                .chunks_exact(w)
                .zip(filtered.chunks_exact_mut(row_bytes + 1))
            {
                out[0] = 0;
                quantise_row(&q, sample_bytes, row, &mut out[1..]);
            }
            zlib_strips::store_strip(&filtered)
        })
        .collect::<std::io::Result<Vec<_>>>()
        .map_err(|e| ImageError::io(path, "compress", e))?;
    let Some(pieces) = zlib_strips::join(strips) else {
        return write_png_sequential(path, image, depth);
    };
    write_stream_atomically(path, |out| {
        let mut writer = header(out, image, depth)?;
        for piece in &pieces {
            writer
                .write_chunk(png::chunk::IDAT, piece)
                .map_err(std::io::Error::other)?;
        }
        writer.finish().map_err(std::io::Error::other)
    })
}

/// Display codes of one row, big-endian for 16 bits (PNG §7.1).
#[inline]
fn quantise_row(q: &Quantiser, sample_bytes: usize, row: &[[f32; 3]], raw: &mut [u8]) {
    if sample_bytes == 1 {
        for (o, p) in raw.chunks_exact_mut(3).zip(row) {
            for c in 0..3 {
                o[c] = q.code(p[c]) as u8;
            }
        }
    } else {
        for (o, p) in raw.chunks_exact_mut(6).zip(row) {
            for c in 0..3 {
                o[2 * c..2 * c + 2].copy_from_slice(&q.code(p[c]).to_be_bytes());
            }
        }
    }
}

/// PNG filter type 1, `Sub` (PNG §9.2): the filter byte, then each byte minus the byte one
/// pixel (`bpp` bytes) to its left, modulo 256.
#[inline]
fn sub_filter(raw: &[u8], bpp: usize, out: &mut [u8]) {
    out[0] = 1;
    let out = &mut out[1..];
    out[..bpp].copy_from_slice(&raw[..bpp]);
    for ((o, a), b) in out[bpp..].iter_mut().zip(&raw[bpp..]).zip(raw) {
        *o = a.wrapping_sub(*b);
    }
}

/// The encoder after the signature, IHDR and the colour chunks (`sRGB`, or `cHRM`).
fn header<W: std::io::Write>(
    out: W,
    image: &Image,
    depth: PngBitDepth,
) -> std::io::Result<png::Writer<W>> {
    let mut encoder = Encoder::new(out, image.width() as u32, image.height() as u32);
    encoder.set_color(ColorType::Rgb);
    // Fast deflate (fdeflate): lossless, ~2× larger files than the default level but
    // several times faster to write — a 4K 16-bit frame is ~50 MB of samples and the
    // default zlib level dominated `tonemap_file`'s time (docs/post.md, benchmark).
    encoder.set_compression(png::Compression::Fast);
    encoder.set_depth(match depth {
        PngBitDepth::Eight => BitDepth::Eight,
        PngBitDepth::Sixteen => BitDepth::Sixteen,
    });
    let space = &image.color_space;
    if *space == RgbColorSpace::srgb() {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    } else {
        let xy = |v: [f64; 2]| (v[0] as f32, v[1] as f32);
        encoder.set_source_chromaticities(SourceChromaticities::new(
            xy(space.white_xy),
            xy(space.primaries_xy[0]),
            xy(space.primaries_xy[1]),
            xy(space.primaries_xy[2]),
        ));
    }
    encoder.write_header().map_err(std::io::Error::other)
}

/// [`write_png`] on one thread through the `png` crate's own encoder: the fallback should
/// the strip joining not work with this build's fdeflate (io/zlib_strips.rs), and the
/// reference the parallel writer is tested against.
pub fn write_png_sequential(path: &Path, image: &Image, depth: PngBitDepth) -> Result<()> {
    // Exact codes without a transcendental per sample (io/quantise.rs).
    let transfer = image.color_space.transfer;
    let bytes: Vec<u8> = match depth {
        PngBitDepth::Eight => {
            let q = Quantiser::new(transfer, 255);
            image
                .pixels()
                .par_iter()
                .flat_map_iter(|p| p.map(|c| q.code(c) as u8))
                .collect()
        }
        PngBitDepth::Sixteen => {
            let q = Quantiser::new(transfer, 65535);
            let mut bytes = vec![0u8; image.pixels().len() * 6];
            bytes
                .par_chunks_mut(6 * 4096)
                .zip(image.pixels().par_chunks(4096))
                .for_each(|(o, i)| {
                    for (o, p) in o.chunks_exact_mut(6).zip(i) {
                        for c in 0..3 {
                            o[2 * c..2 * c + 2].copy_from_slice(&q.code(p[c]).to_be_bytes());
                        }
                    }
                });
            bytes
        }
    };
    write_stream_atomically(path, |out| {
        let mut writer = header(out, image, depth)?;
        writer
            .write_image_data(&bytes)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })
}

/// A PNG's samples as stored (still encoded), for callers that decode them themselves
/// (textures: linear-coded normal maps, per-channel access, the channel count).
#[derive(Debug, Clone, PartialEq)]
pub struct RawPng {
    pub width: usize,
    pub height: usize,
    /// 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA); palettes are expanded to RGB(A).
    pub channels: usize,
    /// 255 or 65535.
    pub max_code: u32,
    /// `width × height × channels` codes, rows top to bottom.
    pub samples: Vec<u16>,
    /// The colour space named by the file (`cHRM` without `sRGB`), else sRGB; its transfer
    /// function is the encoding `read_png` removes.
    pub space: RgbColorSpace,
}

/// Reads a PNG's encoded samples (see [`RawPng`]).
pub fn read_png_raw(path: &Path) -> Result<RawPng> {
    let file = File::open(path).map_err(|e| ImageError::io(path, "open", e))?;
    let mut decoder = Decoder::new(BufReader::new(file));
    decoder.set_transformations(Transformations::EXPAND);
    let mut reader = decoder
        .read_info()
        .map_err(|e| ImageError::format(path, format!("not a readable PNG file: {e}")))?;
    let mut buffer = vec![0u8; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buffer)
        .map_err(|e| ImageError::format(path, format!("PNG image data is unreadable: {e}")))?;
    let (w, h) = (info.width as usize, info.height as usize);
    let channels = match info.color_type {
        ColorType::Grayscale => 1,
        ColorType::GrayscaleAlpha => 2,
        ColorType::Rgb => 3,
        ColorType::Rgba => 4,
        ColorType::Indexed => {
            return Err(ImageError::format(
                path,
                "palette PNG was not expanded to RGB",
            ))
        }
    };
    let sixteen = info.bit_depth == BitDepth::Sixteen;
    let chrm = reader
        .info()
        .chrm_chunk
        .or(reader.info().source_chromaticities);
    let space = match chrm {
        Some(c) if reader.info().srgb.is_none() => {
            let xy = |v: (png::ScaledFloat, png::ScaledFloat)| {
                [v.0.into_value() as f64, v.1.into_value() as f64]
            };
            color_space_from_chromaticities([xy(c.red), xy(c.green), xy(c.blue)], xy(c.white))
        }
        _ => RgbColorSpace::srgb(),
    };
    let n = w * h * channels;
    let samples: Vec<u16> = if sixteen {
        buffer[..2 * n]
            .chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect()
    } else {
        buffer[..n].iter().map(|&b| u16::from(b)).collect()
    };
    Ok(RawPng {
        width: w,
        height: h,
        channels,
        max_code: if sixteen { 65535 } else { 255 },
        samples,
        space,
    })
}

/// Reads an 8- or 16-bit PNG (grey, grey+alpha, RGB, RGBA or palette) to linear RGB; an
/// alpha channel becomes the unprefixed layer channel `A`.
pub fn read_png(path: &Path) -> Result<Image> {
    let raw = read_png_raw(path)?;
    let (channels, max_code) = (raw.channels, raw.max_code as usize);
    let lut: Vec<f32> = (0..=max_code)
        .map(|code| raw.space.transfer.decode(code as f64 / max_code as f64) as f32)
        .collect();
    let pixels: Vec<[f32; 3]> = raw
        .samples
        .par_chunks(channels)
        .map(|px| {
            if channels >= 3 {
                [
                    lut[px[0] as usize],
                    lut[px[1] as usize],
                    lut[px[2] as usize],
                ]
            } else {
                [lut[px[0] as usize]; 3]
            }
        })
        .collect();
    let mut image = Image::new(raw.width, raw.height, pixels, raw.space.clone())?;
    if channels == 2 || channels == 4 {
        let alpha: Vec<f32> = raw
            .samples
            .chunks(channels)
            .map(|px| px[channels - 1] as f32 / max_code as f32)
            .collect();
        image.set_layer("", &["A"], alpha)?;
    }
    Ok(image)
}
