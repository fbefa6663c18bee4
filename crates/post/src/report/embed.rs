//! Images embedded in a self-contained HTML report as `data:` URIs (no network, no side
//! files). Display-referred images (PNG inputs, false-colour maps) are one 8-bit sRGB PNG
//! shown as it is. Scene-referred images (EXR/HDR) travel as Ward's RGBE shared-exponent
//! code (1 % precision over 2⁻¹²⁸…2¹²⁷, 4 bytes per pixel) split into two opaque PNGs,
//! mantissas as RGB and exponents as grey: an alpha channel would be premultiplied by the
//! browser's canvas and lose the mantissas. The page's script decodes, exposes and
//! sRGB-encodes them (report/viewer.js).

use base64::Engine;
use prism_image::io::convert_pixels;
use prism_image::io::rgbe::encode_rgbe;
use prism_image::rgb_matrix::same_colorimetry;
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

/// The image's pixels in linear Rec.709 (a copy, converted when in another space).
fn rec709_pixels(image: &Image) -> Vec<[f32; 3]> {
    let mut pixels = image.pixels().to_vec();
    let srgb = RgbColorSpace::srgb();
    if !same_colorimetry(&image.color_space, &srgb) {
        convert_pixels(&mut pixels, &image.color_space, &srgb);
    }
    pixels
}

impl ReportImage {
    /// A display-referred image (linear display values in [0, 1], e.g. a decoded PNG or a
    /// false-colour map): clipped, sRGB-encoded, 8 bits.
    pub fn display(image: &Image) -> Result<Self> {
        let bytes: Vec<u8> = rec709_pixels(image)
            .par_iter()
            .flat_map_iter(|p| {
                p.map(|v| {
                    let v = if v.is_finite() { f64::from(v) } else { 0.0 };
                    (255.0 * TransferFunction::Srgb.encode(v.clamp(0.0, 1.0))).round() as u8
                })
            })
            .collect();
        Ok(Self {
            width: image.width(),
            height: image.height(),
            data: ImageData::Display {
                png: encode_png(&bytes, image.width(), image.height(), png::ColorType::Rgb)?,
            },
        })
    }

    /// A scene-referred image (any scale): RGBE of its linear Rec.709 values; negative
    /// and non-finite components become 0.
    pub fn radiance(image: &Image) -> Result<Self> {
        let codes: Vec<[u8; 4]> = rec709_pixels(image)
            .par_iter()
            .map(|p| encode_rgbe(*p))
            .collect();
        let mantissas: Vec<u8> = codes.iter().flat_map(|c| [c[0], c[1], c[2]]).collect();
        let exponents: Vec<u8> = codes.iter().map(|c| c[3]).collect();
        let (w, h) = (image.width(), image.height());
        Ok(Self {
            width: w,
            height: h,
            data: ImageData::Radiance {
                mantissa_png: encode_png(&mantissas, w, h, png::ColorType::Rgb)?,
                exponent_png: encode_png(&exponents, w, h, png::ColorType::Grayscale)?,
            },
        })
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

/// An untagged 8-bit PNG (no gAMA/cHRM/iCCP chunk, so browsers treat it as sRGB and draw
/// it to a canvas unchanged).
fn encode_png(bytes: &[u8], w: usize, h: usize, colour: png::ColorType) -> Result<Vec<u8>> {
    let fail =
        |e: png::EncodingError| ImageError::invalid(format!("report: cannot encode a PNG: {e}"));
    let (Ok(w32), Ok(h32)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(ImageError::invalid(format!(
            "report: {w}×{h} is too large for PNG"
        )));
    };
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, w32, h32);
        encoder.set_color(colour);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        let mut writer = encoder.write_header().map_err(fail)?;
        writer.write_image_data(bytes).map_err(fail)?;
        writer.finish().map_err(fail)?;
    }
    Ok(out)
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
}
