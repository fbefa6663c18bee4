//! Images embedded in a self-contained HTML report as `data:` URIs (no network, no side
//! files). Display-referred images (PNG inputs, false-colour maps) are one 8-bit sRGB PNG
//! shown as it is. Scene-referred images (EXR/HDR) travel as Ward's RGBE shared-exponent
//! code (1 % precision over 2⁻¹²⁸…2¹²⁷, 4 bytes per pixel) split into two opaque PNGs,
//! mantissas as RGB and exponents as grey: an alpha channel would be premultiplied by the
//! browser's canvas and lose the mantissas. The page's script decodes, exposes and
//! sRGB-encodes them (report/viewer.js).

use std::cell::RefCell;
use std::io::Write;
use std::rc::Rc;

use base64::Engine;
use prism_image::io::pixels_in;
use prism_image::io::rgbe::encode_rgbe;
use prism_image::{Image, ImageError, Result};
use prism_spectrum::rgb_space::{RgbColorSpace, TransferFunction};
use rayon::prelude::*;

/// How the viewer shows an image.
#[derive(Debug, Clone, PartialEq)]
pub enum ImageData {
    /// sRGB-encoded 8-bit RGB PNG, shown as it is.
    Display { png: Vec<u8> },
    /// Linear Rec.709 as RGBE: mantissas (RGB PNG) and biased exponents (grey PNG).
    Radiance {
        mantissa_png: Vec<u8>,
        exponent_png: Vec<u8>,
    },
}

/// One image ready to embed.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportImage {
    pub width: usize,
    pub height: usize,
    pub data: ImageData,
}

impl ReportImage {
    /// A display-referred image (linear display values in [0, 1], e.g. a decoded PNG or a
    /// false-colour map): clipped, sRGB-encoded, 8 bits.
    pub fn display(image: &Image) -> Result<Self> {
        let mut rows = ReportImageRows::display(image.width(), image.height())?;
        rows.push(image.pixels(), &image.color_space)?;
        rows.finish()
    }

    /// A scene-referred image (any scale): RGBE of its linear Rec.709 values; negative
    /// and non-finite components become 0.
    pub fn radiance(image: &Image) -> Result<Self> {
        let mut rows = ReportImageRows::radiance(image.width(), image.height())?;
        rows.push(image.pixels(), &image.color_space)?;
        rows.finish()
    }

    /// Bytes this image adds to the page (base64 of its PNGs).
    pub fn embedded_bytes(&self) -> usize {
        match &self.data {
            ImageData::Display { png } => base64_len(png.len()),
            ImageData::Radiance {
                mantissa_png,
                exponent_png,
            } => base64_len(mantissa_png.len()) + base64_len(exponent_png.len()),
        }
    }
}

fn base64_len(bytes: usize) -> usize {
    bytes.div_ceil(3) * 4
}

/// `data:image/png;base64,…`.
pub fn png_data_uri(png: &[u8]) -> String {
    let mut uri = String::with_capacity(22 + base64_len(png.len()));
    uri.push_str("data:image/png;base64,");
    base64::engine::general_purpose::STANDARD.encode_string(png, &mut uri);
    uri
}

/// A [`ReportImage`] encoded as its rows arrive (top to bottom, in bands of any height),
/// so that only the compressed PNGs grow with the image.
pub struct ReportImageRows {
    width: usize,
    height: usize,
    rows_done: usize,
    encoding: RowEncoding,
}

enum RowEncoding {
    Display(PngRows),
    Radiance {
        mantissas: PngRows,
        // Boxed: the variants stay the same size.
        exponents: Box<PngRows>,
    },
}

impl ReportImageRows {
    /// Rows of a display-referred image ([`ReportImage::display`]).
    pub fn display(width: usize, height: usize) -> Result<Self> {
        Ok(Self {
            width,
            height,
            rows_done: 0,
            encoding: RowEncoding::Display(PngRows::new(width, height, png::ColorType::Rgb)?),
        })
    }

    /// Rows of a scene-referred image ([`ReportImage::radiance`]).
    pub fn radiance(width: usize, height: usize) -> Result<Self> {
        Ok(Self {
            width,
            height,
            rows_done: 0,
            encoding: RowEncoding::Radiance {
                mantissas: PngRows::new(width, height, png::ColorType::Rgb)?,
                exponents: Box::new(PngRows::new(width, height, png::ColorType::Grayscale)?),
            },
        })
    }

    /// The next whole rows, linear RGB in `space`.
    pub fn push(&mut self, pixels: &[[f32; 3]], space: &RgbColorSpace) -> Result<()> {
        let rows = pixels.len() / self.width.max(1);
        if rows * self.width != pixels.len() || self.rows_done + rows > self.height {
            return Err(ImageError::invalid(format!(
                "report: {} pixels after {} of {} rows of a {}-pixel-wide image",
                pixels.len(),
                self.rows_done,
                self.height,
                self.width
            )));
        }
        let rec709 = pixels_in(pixels, space, &RgbColorSpace::srgb());
        match &mut self.encoding {
            RowEncoding::Display(png) => {
                let bytes: Vec<u8> = rec709
                    .par_iter()
                    .flat_map_iter(|p| {
                        p.map(|v| {
                            let v = if v.is_finite() { f64::from(v) } else { 0.0 };
                            (255.0 * TransferFunction::Srgb.encode(v.clamp(0.0, 1.0))).round() as u8
                        })
                    })
                    .collect();
                png.write(&bytes)?;
            }
            RowEncoding::Radiance {
                mantissas,
                exponents,
            } => {
                let codes: Vec<[u8; 4]> = rec709.par_iter().map(|p| encode_rgbe(*p)).collect();
                let m: Vec<u8> = codes.iter().flat_map(|c| [c[0], c[1], c[2]]).collect();
                mantissas.write(&m)?;
                let e: Vec<u8> = codes.iter().map(|c| c[3]).collect();
                exponents.write(&e)?;
            }
        }
        self.rows_done += rows;
        Ok(())
    }

    /// The image, once every row was pushed.
    pub fn finish(self) -> Result<ReportImage> {
        if self.rows_done != self.height {
            return Err(ImageError::invalid(format!(
                "report: {} of {} rows were given",
                self.rows_done, self.height
            )));
        }
        let data = match self.encoding {
            RowEncoding::Display(png) => ImageData::Display { png: png.finish()? },
            RowEncoding::Radiance {
                mantissas,
                exponents,
            } => ImageData::Radiance {
                mantissa_png: mantissas.finish()?,
                exponent_png: exponents.finish()?,
            },
        };
        Ok(ReportImage {
            width: self.width,
            height: self.height,
            data,
        })
    }
}

/// The bytes a PNG stream wrote, read back once it is finished.
#[derive(Clone, Default)]
struct SharedBytes(Rc<RefCell<Vec<u8>>>);

impl Write for SharedBytes {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// An untagged 8-bit PNG (no gAMA/cHRM/iCCP chunk, so browsers treat it as sRGB and draw
/// it to a canvas unchanged), compressed as its rows arrive.
struct PngRows {
    stream: png::StreamWriter<'static, SharedBytes>,
    bytes: SharedBytes,
}

fn png_error(e: impl std::fmt::Display) -> ImageError {
    ImageError::invalid(format!("report: cannot encode a PNG: {e}"))
}

impl PngRows {
    fn new(w: usize, h: usize, colour: png::ColorType) -> Result<Self> {
        let (Ok(w32), Ok(h32)) = (u32::try_from(w), u32::try_from(h)) else {
            return Err(ImageError::invalid(format!(
                "report: {w}×{h} is too large for PNG"
            )));
        };
        let bytes = SharedBytes::default();
        let mut encoder = png::Encoder::new(bytes.clone(), w32, h32);
        encoder.set_color(colour);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        let stream = encoder
            .write_header()
            .and_then(png::Writer::into_stream_writer)
            .map_err(png_error)?;
        Ok(Self { stream, bytes })
    }

    fn write(&mut self, data: &[u8]) -> Result<()> {
        self.stream.write_all(data).map_err(png_error)
    }

    fn finish(self) -> Result<Vec<u8>> {
        self.stream.finish().map_err(png_error)?;
        Ok(self.bytes.0.take())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_image::io::rgbe::decode_rgbe;

    fn decode(png_bytes: &[u8]) -> (png::OutputInfo, Vec<u8>) {
        let mut reader = png::Decoder::new(std::io::Cursor::new(png_bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    /// The two PNGs of a radiance image decode to the RGBE codes of every pixel, so the
    /// viewer's decoding (Radiance's `colr_color`) gives each value within RGBE's 1 %.
    #[test]
    fn radiance_images_round_trip_through_rgbe() {
        let values = [0.0f32, 1e-6, 0.18, 1.0, 37.5, 6.0e4];
        let pixels: Vec<[f32; 3]> = values.iter().map(|&v| [v, 0.5 * v, -1.0]).collect();
        let image = Image::new(values.len(), 1, pixels.clone(), RgbColorSpace::srgb()).unwrap();
        let embedded = ReportImage::radiance(&image).unwrap();
        let ImageData::Radiance {
            mantissa_png,
            exponent_png,
        } = &embedded.data
        else {
            panic!("not a radiance image");
        };
        let (m_info, m) = decode(mantissa_png);
        let (e_info, e) = decode(exponent_png);
        assert_eq!(
            (m_info.color_type, e_info.color_type),
            (png::ColorType::Rgb, png::ColorType::Grayscale)
        );
        for (i, p) in pixels.iter().enumerate() {
            let got = decode_rgbe([m[3 * i], m[3 * i + 1], m[3 * i + 2], e[i]]);
            // Mantissas are quantised relative to the pixel's largest component.
            let step = p[0] / 128.0;
            for c in 0..2 {
                let want = p[c];
                assert!(
                    (got[c] - want).abs() <= step,
                    "pixel {i} channel {c}: {} vs {want}",
                    got[c]
                );
            }
            // Negative → a zero mantissa, which decodes to half a step (as in Radiance).
            assert!(got[2] <= step, "negative → {}", got[2]);
        }
        assert!(embedded.embedded_bytes() > 0);
    }

    #[test]
    fn display_images_are_srgb_encoded_bytes() {
        let image = Image::new(
            3,
            1,
            vec![[0.0; 3], [0.214_041_14; 3], [2.0; 3]],
            RgbColorSpace::srgb(),
        )
        .unwrap();
        let ImageData::Display { png } = ReportImage::display(&image).unwrap().data else {
            panic!("not a display image");
        };
        let (_, bytes) = decode(&png);
        // sRGB(0.2140) = 0.5 → 128 (127.5 rounded); 2.0 clips to 255.
        assert_eq!(bytes, vec![0, 0, 0, 128, 128, 128, 255, 255, 255]);
        assert!(png_data_uri(&png).starts_with("data:image/png;base64,iVBORw0KGgo"));
    }

    /// Bands of any height give the image one push of every row gives, and a short or
    /// overlong image is an error, not a truncated PNG.
    #[test]
    fn images_pushed_in_bands_decode_to_the_whole_image() {
        let (w, h) = (7, 10);
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| [i as f32 * 0.013, 0.5, (i % 3) as f32 * 40.0])
            .collect();
        let srgb = RgbColorSpace::srgb();
        let image = Image::new(w, h, pixels.clone(), srgb.clone()).unwrap();
        for (whole, mut rows) in [
            (
                ReportImage::display(&image).unwrap(),
                ReportImageRows::display(w, h).unwrap(),
            ),
            (
                ReportImage::radiance(&image).unwrap(),
                ReportImageRows::radiance(w, h).unwrap(),
            ),
        ] {
            for band in [0..3, 3..4, 4..10] {
                rows.push(&pixels[band.start * w..band.end * w], &srgb)
                    .unwrap();
            }
            let banded = rows.finish().unwrap();
            let pngs = |image: &ReportImage| match &image.data {
                ImageData::Display { png } => vec![decode(png).1],
                ImageData::Radiance {
                    mantissa_png,
                    exponent_png,
                } => vec![decode(mantissa_png).1, decode(exponent_png).1],
            };
            assert_eq!(pngs(&banded), pngs(&whole));
        }
        let mut short = ReportImageRows::display(w, h).unwrap();
        short.push(&pixels[..3 * w], &srgb).unwrap();
        assert!(short.finish().is_err());
        let mut long = ReportImageRows::display(w, h).unwrap();
        assert!(long
            .push(&[pixels.clone(), pixels].concat(), &srgb)
            .is_err());
    }
}
