//! Radiance RGBE (.hdr) read/write: Ward, "Real Pixels", Graphics Gems II (1991), with the
//! adaptive run-length scanlines of Radiance's `color.c` (`fwritecolrs`/`freadcolrs`).
//!
//! Written by hand rather than through the `image` crate: the codec is ~200 lines, and the
//! header lines that matter here (`EXPOSURE=`, `PRIMARIES=`, `FORMAT=32-bit_rle_xyze`) are
//! not exposed by `image`'s HDR decoder, which would also pull in a large dependency tree.
//!
//! Values are stored as shared-exponent bytes: one 8-bit mantissa per channel and a common
//! exponent, so the relative precision is 1/256 of the largest channel; negative and
//! non-finite values cannot be represented and are written as 0. Without a `PRIMARIES=` line
//! the pixels are taken as linear sRGB (Rec.709 primaries, D65), as most producers intend.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::{color_space_from_chromaticities, write_stream_atomically};
use crate::error::{ImageError, Result};
use crate::image::Image;

/// Largest header we read before deciding the file is not Radiance.
const MAX_HEADER_BYTES: usize = 1 << 16;
/// Largest image side we accept from a header.
const MAX_SIDE: usize = 1 << 17;

/// Shared-exponent encoding (Ward 1991): e = ⌈log2 max⌉, mantissas = c · 256 / 2^e.
pub fn encode_rgbe(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|v| if v.is_finite() && v > 0.0 { v } else { 0.0 });
    let v = c[0].max(c[1]).max(c[2]);
    if v < 1e-32 {
        return [0; 4];
    }
    // v = m · 2^e with m in [0.5, 1).
    let e = v.log2().floor() as i32 + 1;
    let scale = (2.0f64).powi(8 - e) as f32;
    let m = |x: f32| ((x * scale) as u32).min(255) as u8;
    [m(c[0]), m(c[1]), m(c[2]), (e + 128).clamp(0, 255) as u8]
}

/// Decoding as Radiance's `colr_color`: c = (mantissa + 0.5) · 2^(e − 136), 0 when e = 0.
pub fn decode_rgbe(rgbe: [u8; 4]) -> [f32; 3] {
    if rgbe[3] == 0 {
        return [0.0; 3];
    }
    let f = (2.0f64).powi(rgbe[3] as i32 - (128 + 8)) as f32;
    [
        (rgbe[0] as f32 + 0.5) * f,
        (rgbe[1] as f32 + 0.5) * f,
        (rgbe[2] as f32 + 0.5) * f,
    ]
}

pub(crate) struct Header {
    pub(crate) width: usize,
    pub(crate) height: usize,
    xyz: bool,
    exposure: f64,
    primaries: Option<[f64; 8]>,
    lines: Vec<String>,
}

pub(crate) fn read_header(path: &Path, input: &mut impl BufRead) -> Result<Header> {
    let bad = |m: String| ImageError::format(path, m);
    let mut total = 0usize;
    let mut line = String::new();
    let mut next_line = |line: &mut String| -> Result<bool> {
        line.clear();
        let mut bytes = Vec::new();
        let n = input
            .by_ref()
            .take((MAX_HEADER_BYTES - total.min(MAX_HEADER_BYTES)) as u64)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| ImageError::io(path, "read", e))?;
        total += n;
        if n == 0 || !bytes.ends_with(b"\n") {
            return Ok(false);
        }
        *line = String::from_utf8_lossy(&bytes[..bytes.len() - 1]).into_owned();
        Ok(true)
    };
    if !next_line(&mut line)? || !line.starts_with("#?") {
        return Err(bad(
            "not a Radiance picture: expected the first line '#?RADIANCE' (or '#?RGBE')".into(),
        ));
    }
    let mut header = Header {
        width: 0,
        height: 0,
        xyz: false,
        exposure: 1.0,
        primaries: None,
        lines: Vec::new(),
    };
    loop {
        if !next_line(&mut line)? {
            return Err(bad(
                "header ends before the blank line and resolution string".into(),
            ));
        }
        let l = line.trim();
        if l.is_empty() {
            break;
        }
        if let Some(format) = l.strip_prefix("FORMAT=") {
            header.xyz = match format.trim() {
                "32-bit_rle_rgbe" => false,
                "32-bit_rle_xyze" => true,
                other => {
                    return Err(bad(format!(
                        "FORMAT={other}: expected 32-bit_rle_rgbe or 32-bit_rle_xyze"
                    )))
                }
            };
        } else if let Some(e) = l.strip_prefix("EXPOSURE=") {
            let e: f64 = e
                .trim()
                .parse()
                .ok()
                .filter(|e: &f64| e.is_finite() && *e > 0.0)
                .ok_or_else(|| bad(format!("'{l}': expected a positive number")))?;
            header.exposure *= e;
        } else if let Some(p) = l.strip_prefix("PRIMARIES=") {
            let v: Vec<f64> = p
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            let v: [f64; 8] = v
                .try_into()
                .map_err(|_| bad(format!("'{l}': expected 8 numbers rx ry gx gy bx by wx wy")))?;
            header.primaries = Some(v);
        }
        header.lines.push(l.to_string());
    }
    if !next_line(&mut line)? {
        return Err(bad("missing resolution string after the header".into()));
    }
    let parts: Vec<&str> = line.split_whitespace().collect();
    let dims = match parts.as_slice() {
        ["-Y", h, "+X", w] => h.parse::<usize>().ok().zip(w.parse::<usize>().ok()),
        _ => None,
    };
    let (height, width) = dims.ok_or_else(|| {
        bad(format!(
            "resolution string '{}': expected '-Y <height> +X <width>' (the standard orientation)",
            line.trim()
        ))
    })?;
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(bad(format!(
            "resolution {width}×{height}: expected sides between 1 and {MAX_SIDE}"
        )));
    }
    header.width = width;
    header.height = height;
    Ok(header)
}

/// Reads one scanline (new adaptive RLE, old RLE or flat) into `out` (RGBE quadruples).
fn read_scanline(input: &mut impl Read, out: &mut [[u8; 4]]) -> std::io::Result<()> {
    let width = out.len();
    let mut first = [0u8; 4];
    input.read_exact(&mut first)?;
    let new_rle =
        (8..=0x7fff).contains(&width) && first[0] == 2 && first[1] == 2 && first[2] & 0x80 == 0;
    if new_rle {
        if ((first[2] as usize) << 8 | first[3] as usize) != width {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                "scanline length does not match the image width",
            ));
        }
        for c in 0..4 {
            let mut x = 0;
            while x < width {
                let mut count = [0u8; 1];
                input.read_exact(&mut count)?;
                let (run, n) = if count[0] > 128 {
                    (true, (count[0] - 128) as usize)
                } else {
                    (false, count[0] as usize)
                };
                if n == 0 || x + n > width {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::InvalidData,
                        "run-length code overruns the scanline",
                    ));
                }
                if run {
                    let mut value = [0u8; 1];
                    input.read_exact(&mut value)?;
                    out[x..x + n].iter_mut().for_each(|p| p[c] = value[0]);
                } else {
                    let mut values = [0u8; 128];
                    input.read_exact(&mut values[..n])?;
                    for (p, v) in out[x..x + n].iter_mut().zip(&values[..n]) {
                        p[c] = *v;
                    }
                }
                x += n;
            }
        }
        return Ok(());
    }
    // Flat pixels, with old-style runs (1, 1, 1, n): repeat the previous pixel n << shift.
    let mut x = 0;
    let mut shift = 0;
    let mut pixel = first;
    loop {
        if pixel[0] == 1 && pixel[1] == 1 && pixel[2] == 1 {
            if x == 0 {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    "run at the start of a scanline",
                ));
            }
            let n = (pixel[3] as usize) << shift;
            if x + n > width {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    "old-style run overruns the scanline",
                ));
            }
            let previous = out[x - 1];
            out[x..x + n].iter_mut().for_each(|p| *p = previous);
            x += n;
            shift += 8;
        } else {
            out[x] = pixel;
            x += 1;
            shift = 0;
        }
        if x >= width {
            return Ok(());
        }
        input.read_exact(&mut pixel)?;
    }
}

/// Reads a Radiance picture: pixels divided by the product of its `EXPOSURE=` lines, XYZE
/// pictures converted to linear sRGB, colour space from `PRIMARIES=` (else sRGB).
pub fn read_hdr(path: &Path) -> Result<Image> {
    let file = File::open(path).map_err(|e| ImageError::io(path, "open", e))?;
    let mut input = BufReader::new(file);
    let header = read_header(path, &mut input)?;
    let (w, h) = (header.width, header.height);
    let mut rgbe = vec![[0u8; 4]; w * h];
    for (y, row) in rgbe.chunks_mut(w).enumerate() {
        read_scanline(&mut input, row).map_err(|e| {
            ImageError::format(path, format!("scanline {y} of {h} is unreadable: {e}"))
        })?;
    }
    let scale = (1.0 / header.exposure) as f32;
    let pixels: Vec<[f32; 3]> = rgbe
        .par_iter()
        .map(|q| decode_rgbe(*q).map(|v| v * scale))
        .collect();
    let space = match header.primaries {
        Some(p) => color_space_from_chromaticities(
            [[p[0], p[1]], [p[2], p[3]], [p[4], p[5]]],
            [p[6], p[7]],
        ),
        None => RgbColorSpace::srgb(),
    };
    let mut image = if header.xyz {
        let srgb = RgbColorSpace::srgb();
        let m = srgb.xyz_to_rgb.as_mat3();
        let pixels = pixels
            .into_par_iter()
            .map(|p| (m * glam::Vec3::from(p)).to_array())
            .collect();
        Image::new(w, h, pixels, srgb)?
    } else {
        Image::new(w, h, pixels, space)?
    };
    image
        .metadata
        .insert("radiance:header".into(), header.lines.join("\n"));
    Ok(image)
}

/// Appends one component of a scanline in Radiance's adaptive run-length code: runs of at
/// least 4 equal bytes become (128 + n, byte), everything else literal blocks of ≤ 128.
fn encode_component(values: &[u8], out: &mut Vec<u8>) {
    const MIN_RUN: usize = 4;
    let w = values.len();
    let mut i = 0;
    while i < w {
        // Find the next run of at least MIN_RUN starting at or after i.
        let mut run_start = i;
        let mut run_len = 0;
        while run_start < w {
            run_len = 1;
            while run_start + run_len < w
                && run_len < 127
                && values[run_start + run_len] == values[run_start]
            {
                run_len += 1;
            }
            if run_len >= MIN_RUN {
                break;
            }
            run_start += run_len;
        }
        if run_start >= w {
            run_len = 0;
            run_start = w;
        }
        while i < run_start {
            let n = (run_start - i).min(128);
            out.push(n as u8);
            out.extend_from_slice(&values[i..i + n]);
            i += n;
        }
        if run_len >= MIN_RUN {
            out.push((128 + run_len) as u8);
            out.push(values[run_start]);
            i = run_start + run_len;
        }
    }
}

/// Writes a Radiance picture (run-length coded when 8 ≤ width ≤ 32767) with a `PRIMARIES=`
/// line naming the image's colour space. Negative and non-finite values become 0.
pub fn write_hdr(path: &Path, image: &Image) -> Result<()> {
    let (w, h) = (image.width(), image.height());
    let rows: Vec<Vec<u8>> = image
        .pixels()
        .par_chunks(w)
        .map(|row| {
            let q: Vec<[u8; 4]> = row.iter().map(|p| encode_rgbe(*p)).collect();
            let mut out = Vec::with_capacity(w * 4 + 16);
            if (8..=0x7fff).contains(&w) {
                out.extend_from_slice(&[2, 2, (w >> 8) as u8, (w & 0xff) as u8]);
                let mut component = vec![0u8; w];
                for c in 0..4 {
                    for (v, p) in component.iter_mut().zip(&q) {
                        *v = p[c];
                    }
                    encode_component(&component, &mut out);
                }
            } else {
                q.iter().for_each(|p| out.extend_from_slice(p));
            }
            out
        })
        .collect();
    let s = &image.color_space;
    let primaries = format!(
        "PRIMARIES= {} {} {} {} {} {} {} {}",
        s.primaries_xy[0][0],
        s.primaries_xy[0][1],
        s.primaries_xy[1][0],
        s.primaries_xy[1][1],
        s.primaries_xy[2][0],
        s.primaries_xy[2][1],
        s.white_xy[0],
        s.white_xy[1]
    );
    // SOFTWARE keeps the name this writer had in prism-post, so files stay byte-identical.
    write_stream_atomically(path, |out| {
        write!(
            out,
            "#?RADIANCE\nSOFTWARE=prism-post\nFORMAT=32-bit_rle_rgbe\n{primaries}\n\n-Y {h} +X {w}\n"
        )?;
        for row in &rows {
            out.write_all(row)?;
        }
        Ok(())
    })
}
