//! Images read a band of rows at a time, so that a pass over a large image holds a strip of
//! it rather than all of it (`prism compare` in bounded memory, docs/reliability.md).
//!
//! An OpenEXR file of one part with channels `R`, `G`, `B` (or a lone `Y`) of full
//! resolution — scan lines or single-level tiles, any other channels beside them (a
//! render's AOV layers) — is read through the `exr` crate's block API: for a band of rows
//! only the chunks that hold them are read (through the file's offset table), decompressed
//! in parallel on the global rayon pool and converted to f32 as [`super::exr::read_exr`]
//! converts them, so the rows are bit-identical to that reader's. Any other file (PNG,
//! Radiance HDR, a spectral or multi-part EXR) is decoded whole by [`super::read_image`]
//! and its rows served from memory: [`RowSource::is_streamed`] says which.

use std::fs::File;
use std::io::BufReader;
use std::ops::Range;
use std::path::{Path, PathBuf};

use ::exr::block::chunk::Chunk;
use ::exr::block::UncompressedBlock;
use ::exr::meta::attribute::{LevelMode, SampleType};
use ::exr::meta::{BlockDescription, MetaData};
use ::exr::prelude::f16;
use prism_spectrum::rgb_space::RgbColorSpace;
use rayon::prelude::*;

use super::exr::{exr_decode_limit_bytes, space_of};
use super::{read_image, ImageFormat};
use crate::error::{ImageError, Result};
use crate::image::Image;

/// Buffer of the file reader (chunks of a band are read in file order).
const READ_BUFFER: usize = 1 << 20;

/// An image whose rows can be read band by band.
#[derive(Debug)]
pub struct RowSource {
    width: usize,
    height: usize,
    color_space: RgbColorSpace,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    /// Rows read from the file on demand.
    Exr(ExrRows),
    /// The whole image, decoded once (formats the block reader does not cover).
    Whole(Vec<[f32; 3]>),
}

/// What the block reader needs to know of an EXR file's one part.
#[derive(Debug)]
struct ExrRows {
    path: PathBuf,
    /// Sample type of each channel, in the file's (alphabetical) channel order.
    channel_types: Vec<SampleType>,
    /// Positions of the channels that become R, G and B (the same one thrice for `Y`).
    rgb: [usize; 3],
}

impl RowSource {
    /// Opens `path` (format from the extension); errors name the file.
    pub fn open(path: &Path) -> Result<Self> {
        if ImageFormat::from_path(path)? == ImageFormat::Exr {
            if let Some(source) = ExrRows::open(path) {
                return Ok(source);
            }
        }
        Ok(Self::from_image(read_image(path)?))
    }

    /// Whether [`Self::open`] would read `path` in bands (from its header; false for any
    /// other format, or a file that does not open).
    pub fn streams(path: &Path) -> bool {
        matches!(ImageFormat::from_path(path), Ok(ImageFormat::Exr))
            && ExrRows::open(path).is_some()
    }

    /// Rows of an image already in memory.
    pub fn from_image(image: Image) -> Self {
        Self {
            width: image.width(),
            height: image.height(),
            color_space: image.color_space.clone(),
            kind: Kind::Whole(image.into_pixels()),
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The colour space of the pixels (from the EXR `chromaticities`, as `read_image`).
    pub fn color_space(&self) -> &RgbColorSpace {
        &self.color_space
    }

    /// True when rows come from the file band by band, false when the whole image was
    /// decoded into memory (its size then counts in full).
    pub fn is_streamed(&self) -> bool {
        match self.kind {
            Kind::Exr(_) => true,
            Kind::Whole(_) => false,
        }
    }

    /// Calls `each` with the image's rows in bands of `rows_per_band` (the last one
    /// shorter), top to bottom; stops at the first error.
    pub fn for_each_band(
        &self,
        rows_per_band: usize,
        mut each: impl FnMut(&[[f32; 3]]) -> Result<()>,
    ) -> Result<()> {
        for start in (0..self.height).step_by(rows_per_band.max(1)) {
            each(&self.read_rows(start..(start + rows_per_band.max(1)).min(self.height))?)?;
        }
        Ok(())
    }

    /// Rows `rows` (within the image), row-major: the pixels `read_image` gives there.
    pub fn read_rows(&self, rows: Range<usize>) -> Result<Vec<[f32; 3]>> {
        assert!(
            rows.start <= rows.end && rows.end <= self.height,
            "rows {rows:?} of a {}-row image",
            self.height
        );
        match &self.kind {
            Kind::Whole(pixels) => {
                Ok(pixels[rows.start * self.width..rows.end * self.width].to_vec())
            }
            Kind::Exr(exr) => exr.read_rows(self.width, rows),
        }
    }
}

impl ExrRows {
    /// A source for `path` when its one part can be read by blocks (module text); `None`
    /// for anything else, which `read_image` then reads or refuses with its message.
    fn open(path: &Path) -> Option<RowSource> {
        // A header the limits refuse goes to `read_image`, which says why.
        super::exr::check_declared_size(path).ok()?;
        let meta = MetaData::read_from_file(path, false).ok()?;
        let [header] = meta.headers.as_slice() else {
            return None;
        };
        let single_level = match header.blocks {
            BlockDescription::ScanLines => true,
            BlockDescription::Tiles(t) => t.level_mode == LevelMode::Singular,
        };
        let list = &header.channels.list;
        if header.deep
            || !single_level
            || list.iter().any(|c| c.sampling.0 != 1 || c.sampling.1 != 1)
        {
            return None;
        }
        let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
        let position = |n: &str| names.iter().position(|m| m == n);
        // As read_exr: R, G, B, else a lone Y as grey; layer-named parts are not plain RGB.
        let rgb = match (position("R"), position("G"), position("B"), position("Y")) {
            (Some(r), Some(g), Some(b), _) => [r, g, b],
            (None, None, None, Some(y)) => [y, y, y],
            _ => return None,
        };
        let layer_named = header
            .own_attributes
            .layer_name
            .as_ref()
            .is_some_and(|n| !n.to_string().is_empty());
        let (width, height) = (header.layer_size.0, header.layer_size.1);
        if layer_named || width == 0 || height == 0 {
            return None;
        }
        Some(RowSource {
            width,
            height,
            color_space: space_of(&header.shared_attributes.chromaticities),
            kind: Kind::Exr(ExrRows {
                path: path.to_path_buf(),
                channel_types: list.iter().map(|c| c.sample_type).collect(),
                rgb,
            }),
        })
    }

    fn error(&self, rows: &Range<usize>, what: impl std::fmt::Display) -> ImageError {
        ImageError::format(
            &self.path,
            format!(
                "not a readable OpenEXR file: rows {}..{}: {what}",
                rows.start, rows.end
            ),
        )
    }

    fn read_rows(&self, width: usize, rows: Range<usize>) -> Result<Vec<[f32; 3]>> {
        let n = (rows.end - rows.start) * width;
        if (n as u128) * 12 > u128::from(exr_decode_limit_bytes()) {
            return Err(self.error(
                &rows,
                format!(
                    "a band of {n} pixels is more than the {}-byte decode limit (--max-memory)",
                    exr_decode_limit_bytes()
                ),
            ));
        }
        let file = File::open(&self.path).map_err(|e| ImageError::io(&self.path, "open", e))?;
        let reader = ::exr::block::read(BufReader::with_capacity(READ_BUFFER, file), false)
            .map_err(|e| self.error(&rows, e))?;
        let meta = reader.meta_data().clone();
        let (y0, y1) = (rows.start, rows.end);
        let chunks: Vec<Chunk> = reader
            .filter_chunks(false, |_, tile, block| {
                let top = block.pixel_position.1;
                tile.level_index.0 == 0
                    && tile.level_index.1 == 0
                    && top < y1
                    && top + block.pixel_size.1 > y0
            })
            .map_err(|e| self.error(&rows, e))?
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| self.error(&rows, e))?;
        let blocks: Vec<UncompressedBlock> = chunks
            .into_par_iter()
            .map(|chunk| UncompressedBlock::decompress_chunk(chunk, &meta, false))
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| self.error(&rows, e))?;
        let mut pixels = vec![[0.0f32; 3]; n];
        let mut covered = vec![false; n];
        for block in &blocks {
            self.scatter(block, width, &rows, &mut pixels, &mut covered)
                .map_err(|what| self.error(&rows, what))?;
        }
        if covered.iter().any(|c| !c) {
            return Err(self.error(&rows, "some pixels are in no block"));
        }
        Ok(pixels)
    }

    /// Writes the rows of `block` inside `rows` into `pixels` (row `rows.start` first).
    /// A block's data is, per line, each channel's samples in channel order.
    fn scatter(
        &self,
        block: &UncompressedBlock,
        width: usize,
        rows: &Range<usize>,
        pixels: &mut [[f32; 3]],
        covered: &mut [bool],
    ) -> std::result::Result<(), &'static str> {
        let (x0, by0) = (block.index.pixel_position.0, block.index.pixel_position.1);
        let (w, h) = (block.index.pixel_size.0, block.index.pixel_size.1);
        if x0 + w > width {
            return Err("a block lies outside the data window");
        }
        let bytes = |t: SampleType| t.bytes_per_sample();
        let line_bytes: usize = self.channel_types.iter().map(|t| bytes(*t) * w).sum();
        if block.data.len() != line_bytes * h {
            return Err("a block's size does not match its channels");
        }
        // Byte offset of each channel within a line.
        let mut offsets = Vec::with_capacity(self.channel_types.len());
        let mut at = 0;
        for t in &self.channel_types {
            offsets.push(at);
            at += bytes(*t) * w;
        }
        for (j, line) in block.data.chunks_exact(line_bytes).enumerate() {
            let y = by0 + j;
            if y < rows.start || y >= rows.end {
                continue;
            }
            let first = (y - rows.start) * width + x0;
            if covered[first..first + w].iter().any(|c| *c) {
                return Err("two blocks hold the same pixel");
            }
            covered[first..first + w].fill(true);
            let out = &mut pixels[first..first + w];
            for (c, &k) in self.rgb.iter().enumerate() {
                let samples = &line[offsets[k]..offsets[k] + bytes(self.channel_types[k]) * w];
                // The conversions of read_exr's `sample_at`.
                match self.channel_types[k] {
                    SampleType::F32 => {
                        for (p, s) in out.iter_mut().zip(samples.chunks_exact(4)) {
                            p[c] = f32::from_ne_bytes([s[0], s[1], s[2], s[3]]);
                        }
                    }
                    SampleType::F16 => {
                        for (p, s) in out.iter_mut().zip(samples.chunks_exact(2)) {
                            p[c] = f16::from_bits(u16::from_ne_bytes([s[0], s[1]])).to_f32();
                        }
                    }
                    SampleType::U32 => {
                        for (p, s) in out.iter_mut().zip(samples.chunks_exact(4)) {
                            p[c] = u32::from_ne_bytes([s[0], s[1], s[2], s[3]]) as f32;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::exr::{write_exr, ExrCompression, ExrSampleType, ExrWriteOptions};
    use ::exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image as ExrImage, Layer,
        LayerAttributes, SmallVec, WritableImage,
    };

    fn value(i: usize, c: usize) -> f32 {
        match (i * 7 + c * 13) % 97 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => -3.5,
            k => (k as f32 * 0.37 + c as f32).powf(2.3) * 1e-2,
        }
    }

    /// Every band of `source` equals the same rows of `read_image`, bit for bit.
    fn check_bands(path: &Path, streamed: bool) {
        let whole = read_image(path).unwrap();
        let source = RowSource::open(path).unwrap();
        assert_eq!(source.is_streamed(), streamed, "{}", path.display());
        assert_eq!(
            (source.width(), source.height()),
            (whole.width(), whole.height())
        );
        assert_eq!(source.color_space().name, whole.color_space.name);
        let w = whole.width();
        for rows in [
            0..whole.height(),
            0..1,
            3..20,
            17..18,
            40..whole.height(),
            5..5,
        ] {
            let band = source.read_rows(rows.clone()).unwrap();
            let want = &whole.pixels()[rows.start * w..rows.end * w];
            assert_eq!(band.len(), want.len());
            for (a, b) in band.iter().zip(want) {
                assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "{rows:?}");
            }
        }
    }

    #[test]
    fn bands_are_the_rows_read_image_gives() {
        let (w, h) = (67usize, 45usize);
        let temp = tempfile::tempdir().unwrap();
        let mut cases = 0;
        for sample in ["f32", "f16", "u32"] {
            for blocks in [
                Blocks::ScanLines,
                Blocks::Tiles(::exr::prelude::Vec2(16, 8)),
            ] {
                for compression in [
                    ::exr::compression::Compression::Uncompressed,
                    ::exr::compression::Compression::ZIP16,
                    ::exr::compression::Compression::PIZ,
                ] {
                    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
                    // R, G, B and a layer channel of another type between them.
                    for (c, name) in ["R", "G", "B", "depth.Z"].into_iter().enumerate() {
                        let v: Vec<f32> = (0..w * h).map(|i| value(i, c)).collect();
                        let samples = match (sample, c) {
                            (_, 3) => FlatSamples::F32(v),
                            ("f16", _) => {
                                FlatSamples::F16(v.iter().map(|x| f16::from_f32(*x)).collect())
                            }
                            ("u32", _) => FlatSamples::U32(
                                v.iter().map(|x| (x.abs().min(1e6)) as u32).collect(),
                            ),
                            _ => FlatSamples::F32(v),
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
                    let path = temp.path().join(format!("case{cases}.exr"));
                    ExrImage::from_layer(layer).write().to_file(&path).unwrap();
                    check_bands(&path, true);
                    cases += 1;
                }
            }
        }
        assert_eq!(cases, 18);
        // Prism's own writer, in another colour space; a PNG is decoded whole.
        let pixels: Vec<[f32; 3]> = (0..w * h).map(|i| [0, 1, 2].map(|c| value(i, c))).collect();
        let image = Image::new(w, h, pixels, RgbColorSpace::display_p3()).unwrap();
        let exr = temp.path().join("p3.exr");
        write_exr(
            &exr,
            &image,
            &ExrWriteOptions {
                sample_type: ExrSampleType::F16,
                compression: ExrCompression::Zip,
            },
        )
        .unwrap();
        check_bands(&exr, true);
        let png = temp.path().join("p3.png");
        crate::io::write_image(&png, &image).unwrap();
        check_bands(&png, false);
    }

    #[test]
    fn a_damaged_chunk_is_an_error_naming_the_file_and_the_rows() {
        let (w, h) = (40usize, 64usize);
        let pixels: Vec<[f32; 3]> = (0..w * h).map(|i| [0, 1, 2].map(|c| value(i, c))).collect();
        let image = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        let temp = tempfile::tempdir().unwrap();
        let path = temp.path().join("damaged.exr");
        write_exr(&path, &image, &ExrWriteOptions::default()).unwrap();
        let source = RowSource::open(&path).unwrap();
        // Truncate the file after the header was read: the last band's chunks are gone.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 200]).unwrap();
        let e = source.read_rows(48..64).unwrap_err().to_string();
        assert!(
            e.contains("damaged.exr") && e.contains("rows 48..64"),
            "{e}"
        );
    }
}
