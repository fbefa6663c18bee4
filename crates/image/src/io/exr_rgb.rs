//! Fast path of [`super::exr::read_exr`] for the common file: one part of scan lines or
//! single-level tiles (what the `exr` crate, and so Prism, writes by default), exactly the
//! channels B, G, R of one sample type (float or half), no layer name. It uses the `exr`
//! crate's block-level API: the compressed chunks are read in file order and grouped into
//! bands of rows (a scan-line block, or a row of tiles); each complete band is
//! decompressed by a task on the global rayon pool while the file is still being read,
//! and each block's lines are written straight into its rows of the interleaved RGB
//! pixels — no per-channel planes, no separate interleaving
//! pass, no second thread pool (the general reader builds one per file). Anything else (or
//! any error here) goes to the general reader, which also gives the error messages.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use ::exr::block::chunk::{Chunk, CompressedBlock};
use ::exr::block::UncompressedBlock;
use ::exr::meta::attribute::{AttributeValue, Chromaticities, LevelMode, SampleType};
use ::exr::meta::BlockDescription;
use ::exr::prelude::f16;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// What the fast path read: size, interleaved pixels, chromaticities and the attributes the
/// general path collects (custom attributes and `software`).
pub(crate) struct RgbExr {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
    pub chromaticities: Option<Chromaticities>,
    pub attributes: BTreeMap<String, AttributeValue>,
}

/// Buffer of the file reader (chunks are read sequentially, ~0.7 MB each for ZIP).
const READ_BUFFER: usize = 1 << 20;

/// Reads `path` when it is an RGB scan-line EXR (see the module text); `None` otherwise or
/// on any error (the caller then uses the general reader).
pub(crate) fn read_rgb_exr(path: &Path) -> Option<RgbExr> {
    let file = File::open(path).ok()?;
    let reader = ::exr::block::read(BufReader::with_capacity(READ_BUFFER, file), false).ok()?;
    let meta = reader.meta_data().clone();
    let [header] = meta.headers.as_slice() else {
        return None;
    };
    let list = &header.channels.list;
    let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
    let sample_type = list.first()?.sample_type;
    // Rows per band: a scan-line block, or a row of tiles.
    let band_rows = match header.blocks {
        BlockDescription::ScanLines => header.compression.scan_lines_per_block(),
        BlockDescription::Tiles(t) if t.level_mode == LevelMode::Singular => t.tile_size.1,
        BlockDescription::Tiles(_) => return None,
    };
    if header.deep
        || header
            .own_attributes
            .layer_name
            .as_ref()
            .is_some_and(|n| !n.to_string().is_empty())
        || names.len() != 3
        || list
            .iter()
            .any(|c| c.sample_type != sample_type || c.sampling.0 != 1 || c.sampling.1 != 1)
        || sample_type == SampleType::U32
    {
        return None;
    }
    // Position of R, G and B in the block's channel order.
    let position = |n: &str| names.iter().position(|m| m == n);
    let order = [position("R")?, position("G")?, position("B")?];
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    if width == 0 || height == 0 || band_rows == 0 {
        return None;
    }
    // Above the decode limit: the general reader refuses the file with a message.
    if (width as u128) * (height as u128) * 12 > u128::from(super::exr::exr_decode_limit_bytes()) {
        return None;
    }
    let top = header.own_attributes.layer_position.1 as i64;

    // Chunks in file order, each put in its band; a band whose chunks have all arrived
    // (1 scan-line block, or a full row of tiles) is decompressed and scattered by a rayon
    // task at once, so decompression overlaps the reading of the rest of the file.
    let bands = height.div_ceil(band_rows);
    let per_band = match header.blocks {
        BlockDescription::ScanLines => 1,
        BlockDescription::Tiles(t) => width.div_ceil(t.tile_size.0.max(1)),
    };
    let mut pixels = vec![[0.0f32; 3]; width * height];
    let mut rows: Vec<Option<&mut [[f32; 3]]>> =
        pixels.chunks_mut(width * band_rows).map(Some).collect();
    let mut pending: Vec<Vec<Chunk>> = (0..bands).map(|_| Vec::new()).collect();
    let failed = AtomicBool::new(false);
    let in_flight = AtomicUsize::new(0);
    let max_in_flight = 4 * rayon::current_num_threads();
    let meta = &meta;
    let complete = rayon::scope(|scope| {
        for chunk in reader.all_chunks(false).ok()? {
            let chunk = chunk.ok()?;
            let band = match &chunk.compressed_block {
                CompressedBlock::ScanLine(block) => {
                    let offset = block.y_coordinate as i64 - top;
                    if offset < 0 || offset % band_rows as i64 != 0 {
                        return None;
                    }
                    (offset / band_rows as i64) as usize
                }
                CompressedBlock::Tile(tile) => {
                    if tile.coordinates.level_index.0 != 0 || tile.coordinates.level_index.1 != 0 {
                        return None;
                    }
                    tile.coordinates.tile_index.1
                }
                _ => return None,
            };
            let chunks = pending.get_mut(band)?;
            chunks.push(chunk);
            if chunks.len() == per_band {
                let chunks = std::mem::take(chunks);
                let band_pixels = rows[band].take()?;
                let (failed, in_flight) = (&failed, &in_flight);
                let decode = move || {
                    let ok = decode_band(
                        chunks,
                        band_pixels,
                        band,
                        band_rows,
                        width,
                        meta,
                        order,
                        sample_type,
                    );
                    if !ok {
                        failed.store(true, Ordering::Relaxed);
                    }
                };
                // Reading outpaces decompression: past a few bands per thread waiting,
                // the reader decodes this band itself, so that the compressed chunks held
                // stay a few bands instead of growing towards the whole file.
                if in_flight.load(Ordering::Acquire) >= max_in_flight {
                    decode();
                } else {
                    in_flight.fetch_add(1, Ordering::AcqRel);
                    scope.spawn(move |_| {
                        decode();
                        in_flight.fetch_sub(1, Ordering::AcqRel);
                    });
                }
            } else if chunks.len() > per_band {
                return None;
            }
        }
        Some(())
    });
    // Every band complete (no rows left unclaimed) and decoded.
    if complete.is_none() || rows.iter().any(Option::is_some) || failed.load(Ordering::Relaxed) {
        return None;
    }
    drop(rows);

    let mut attributes = BTreeMap::new();
    for (name, value) in &header.own_attributes.other {
        attributes.insert(name.to_string(), value.clone());
    }
    if let Some(software) = &header.own_attributes.software_name {
        attributes
            .entry("software".to_string())
            .or_insert(AttributeValue::Text(software.clone()));
    }
    Some(RgbExr {
        width,
        height,
        pixels,
        chromaticities: header.shared_attributes.chromaticities,
        attributes,
    })
}

/// Decompresses the chunks of band `band` and writes them into its rows; false on any
/// mismatch (wrong position or size, a column written twice or never).
#[allow(clippy::too_many_arguments)]
fn decode_band(
    chunks: Vec<Chunk>,
    rows: &mut [[f32; 3]],
    band: usize,
    band_rows: usize,
    width: usize,
    meta: &::exr::meta::MetaData,
    order: [usize; 3],
    sample_type: SampleType,
) -> bool {
    let rows_here = rows.len() / width;
    let mut covered = vec![false; width];
    for chunk in chunks {
        let Ok(block) = UncompressedBlock::decompress_chunk(chunk, meta, false) else {
            return false;
        };
        let (x0, y0) = (block.index.pixel_position.0, block.index.pixel_position.1);
        let (w, h) = (block.index.pixel_size.0, block.index.pixel_size.1);
        if y0 != band * band_rows
            || h != rows_here
            || x0 + w > width
            || covered[x0..x0 + w].iter().any(|c| *c)
        {
            return false;
        }
        covered[x0..x0 + w].fill(true);
        if !scatter_block(&block.data, rows, width, x0, w, order, sample_type) {
            return false;
        }
    }
    covered.iter().all(|c| *c)
}

/// Writes one decompressed block `w` pixels wide at column `x0` (per line: each channel's
/// `w` native-endian samples, channels in file order) into its rows of interleaved RGB
/// (`rows`, `width` pixels each); false if the size is wrong.
fn scatter_block(
    data: &[u8],
    rows: &mut [[f32; 3]],
    width: usize,
    x0: usize,
    w: usize,
    order: [usize; 3],
    sample_type: SampleType,
) -> bool {
    let bytes = match sample_type {
        SampleType::F32 => 4,
        SampleType::F16 => 2,
        SampleType::U32 => return false,
    };
    let line_bytes = 3 * w * bytes;
    if data.len() != line_bytes * (rows.len() / width) {
        return false;
    }
    for (line, out) in data
        .chunks_exact(line_bytes)
        .zip(rows.chunks_exact_mut(width))
    {
        let out = &mut out[x0..x0 + w];
        for (c, &k) in order.iter().enumerate() {
            let samples = &line[k * w * bytes..(k + 1) * w * bytes];
            match sample_type {
                SampleType::F32 => {
                    for (p, s) in out.iter_mut().zip(samples.chunks_exact(4)) {
                        p[c] = f32::from_ne_bytes([s[0], s[1], s[2], s[3]]);
                    }
                }
                _ => {
                    for (p, s) in out.iter_mut().zip(samples.chunks_exact(2)) {
                        p[c] = f16::from_bits(u16::from_ne_bytes([s[0], s[1]])).to_f32();
                    }
                }
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use ::exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image as ExrImage, Layer,
        LayerAttributes, SmallVec, WritableImage,
    };

    /// The general reader's pixels (per-channel planes, interleaved afterwards).
    fn general(path: &Path) -> Vec<[f32; 3]> {
        let data = super::super::exr::read_exr_channels(path).unwrap();
        let find = |n: &str| &data.channels.iter().find(|(m, _)| m == n).unwrap().1;
        let (r, g, b) = (find("R"), find("G"), find("B"));
        (0..data.width * data.height)
            .map(|i| {
                use super::super::exr::sample_at;
                [sample_at(r, i), sample_at(g, i), sample_at(b, i)]
            })
            .collect()
    }

    #[test]
    fn fast_path_reads_the_same_bits_as_the_general_reader() {
        use ::exr::compression::Compression;
        let (w, h) = (67usize, 45usize);
        let value = |i: usize, c: usize| match (i * 7 + c * 13) % 97 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => -3.5,
            k => (k as f32 * 0.37 + c as f32).powf(2.3) * 1e-2,
        };
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        let mut cases = 0;
        for half in [false, true] {
            for compression in [
                Compression::Uncompressed,
                Compression::RLE,
                Compression::ZIP16,
                Compression::ZIP1,
                Compression::PIZ,
            ] {
                for blocks in [
                    Blocks::ScanLines,
                    Blocks::Tiles(::exr::prelude::Vec2(16, 8)),
                ] {
                    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
                    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
                        let v: Vec<f32> = (0..w * h).map(|i| value(i, c)).collect();
                        let samples = if half {
                            FlatSamples::F16(v.iter().map(|x| f16::from_f32(*x)).collect())
                        } else {
                            FlatSamples::F32(v)
                        };
                        list.push(AnyChannel::new(name, samples));
                    }
                    let layer = Layer::new(
                        (w, h),
                        LayerAttributes::default(),
                        Encoding {
                            compression,
                            blocks,
                            line_order: ::exr::meta::attribute::LineOrder::Increasing,
                        },
                        AnyChannels::sort(list),
                    );
                    let path = dir.join(format!("case{cases}.exr"));
                    ExrImage::from_layer(layer).write().to_file(&path).unwrap();
                    let fast = read_rgb_exr(&path).expect("fast path taken");
                    assert_eq!((fast.width, fast.height), (w, h));
                    let want = general(&path);
                    for (a, b) in fast.pixels.iter().zip(&want) {
                        for c in 0..3 {
                            assert_eq!(a[c].to_bits(), b[c].to_bits(), "{compression:?}");
                        }
                    }
                    cases += 1;
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(cases, 20);
    }
}
