//! Spectral OpenEXR in the layout of Fichet, Pacanowski & Wilkie 2021, "An OpenEXR Layout
//! for Spectral Images", JCGT 10(3): one channel per band named `S0.<λ>nm` (emissive,
//! unpolarised Stokes component 0) with a comma as decimal separator because `.` separates
//! layers (the reference implementation prints the wavelength with six decimals:
//! `S0.550,000000nm`), the string attributes `spectralLayoutVersion` = "1.0" and
//! `emissiveUnits` = "W.m^-2.sr^-1", and R, G, B channels for viewers that ignore the rest.
//!
//! Reduction to XYZ: samples are interpolated linearly onto the 1 nm grid of the CIE
//! observer, zero outside the sampled range, and X = Σ L(λ) x̄(λ) / Σ ȳ(λ) (likewise Y, Z),
//! so a flat spectrum of 1 over 360–830 nm has Y = 1 (the pbrt-v4 / Mitsuba 3 convention,
//! docs/architecture.md, "Units and conventions"). The absolute scale is then 683.002 lm/W × Σ ȳ(λ) Δλ cd/m² per unit.

use std::path::Path;

use ::exr::meta::attribute::AttributeValue;
use ::exr::prelude::FlatSamples;
use glam::DVec3;
use prism_spectrum::data::cmfs;
use prism_spectrum::photometry::y_bar_integral_nm;
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::{Observer, DENSE_SAMPLE_COUNT, LAMBDA_MIN_NM};
use rayon::prelude::*;

use super::exr::{
    chromaticities_of, flat_samples, image_channels, read_exr_channels, text, write_exr_channels,
    ExrChannels, ExrWriteOptions,
};
use crate::error::{ImageError, Result};
use crate::image::Image;

pub const VERSION_ATTRIBUTE: &str = "spectralLayoutVersion";
pub const EMISSIVE_UNITS_ATTRIBUTE: &str = "emissiveUnits";
/// The layout's unit string for radiance.
pub const RADIANCE_UNITS: &str = "W.m^-2.sr^-1";

/// What a spectral channel holds (Fichet et al. 2021, §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpectralChannelKind {
    /// `S<k>.<λ>`: Stokes component k (0 = unpolarised radiance) of an emissive spectrum.
    Emissive { stokes: u8 },
    /// `T.<λ>`: reflectance or transmittance.
    Reflective,
}

/// An emissive (Stokes 0) spectral image; samples are pixel-major:
/// band `k` of pixel `i` is `samples[i * wavelengths_nm.len() + k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralImage {
    pub width: usize,
    pub height: usize,
    /// Strictly increasing band wavelengths in nm.
    pub wavelengths_nm: Vec<f64>,
    pub samples: Vec<f32>,
    /// The `emissiveUnits` attribute, "W.m^-2.sr^-1" for radiance.
    pub emissive_units: String,
}

/// Channel name of an emissive, unpolarised band: `S0.550,000000nm`.
pub fn emissive_channel_name(wavelength_nm: f64) -> String {
    format!("S0.{}nm", format!("{wavelength_nm:.6}").replace('.', ","))
}

/// Parses a spectral channel name of the layout (§3.1: `S[0-3]` or `T`, a `.`, a number
/// with an optional comma decimal separator and exponent, an optional SI prefix and the
/// unit `m` or `Hz`) into its kind and wavelength in nm; `None` for any other channel.
pub fn parse_spectral_channel(name: &str) -> Option<(SpectralChannelKind, f64)> {
    let (kind, rest) = if let Some(rest) = name.strip_prefix("T.") {
        (SpectralChannelKind::Reflective, rest)
    } else {
        let rest = name.strip_prefix('S')?;
        let stokes = rest.chars().next()?.to_digit(10)?;
        if stokes > 3 {
            return None;
        }
        (
            SpectralChannelKind::Emissive {
                stokes: stokes as u8,
            },
            rest[1..].strip_prefix('.')?,
        )
    };
    let (rest, hertz) = if let Some(r) = rest.strip_suffix("Hz") {
        (r, true)
    } else {
        (rest.strip_suffix('m')?, false)
    };
    // SI prefixes as powers of ten (longest first so "da" is not read as "a").
    const PREFIXES: [(&str, i32); 16] = [
        ("da", 1),
        ("Y", 24),
        ("Z", 21),
        ("E", 18),
        ("P", 15),
        ("T", 12),
        ("G", 9),
        ("M", 6),
        ("k", 3),
        ("h", 2),
        ("d", -1),
        ("c", -2),
        ("m", -3),
        ("u", -6),
        ("n", -9),
        ("p", -12),
    ];
    let (number, exponent) = PREFIXES
        .iter()
        .find_map(|(p, e)| rest.strip_suffix(p).map(|n| (n, *e)))
        .unwrap_or((rest, 0));
    let valid = !number.is_empty()
        && number.starts_with(|c: char| c.is_ascii_digit() || c == ',')
        && number
            .chars()
            .all(|c| c.is_ascii_digit() || matches!(c, ',' | 'e' | 'E' | '+' | '-'));
    if !valid {
        return None;
    }
    let value: f64 = number.replace(',', ".").parse().ok()?;
    let nm = if hertz {
        prism_spectrum::SPEED_OF_LIGHT_M_PER_S / (value * 10f64.powi(exponent)) * 1e9
    } else {
        // Exact for nanometres (10^0): no round trip through metres.
        value * 10f64.powi(exponent + 9)
    };
    (nm.is_finite() && nm > 0.0).then_some((kind, nm))
}

impl SpectralImage {
    /// A spectral image; wavelengths must be strictly increasing and positive, and
    /// `samples.len() == width * height * wavelengths_nm.len()`.
    pub fn new(
        width: usize,
        height: usize,
        wavelengths_nm: Vec<f64>,
        samples: Vec<f32>,
    ) -> Result<Self> {
        if wavelengths_nm.len() < 2 {
            return Err(ImageError::invalid(format!(
                "a spectral image needs at least 2 bands to interpolate, got {}",
                wavelengths_nm.len()
            )));
        }
        if !wavelengths_nm.windows(2).all(|w| w[0] < w[1]) || wavelengths_nm[0] <= 0.0 {
            return Err(ImageError::invalid(
                "spectral band wavelengths must be positive and strictly increasing",
            ));
        }
        if width == 0 || height == 0 || samples.len() != width * height * wavelengths_nm.len() {
            return Err(ImageError::invalid(format!(
                "a {width}×{height} spectral image with {} bands needs {} samples, got {}",
                wavelengths_nm.len(),
                width * height * wavelengths_nm.len(),
                samples.len()
            )));
        }
        Ok(Self {
            width,
            height,
            wavelengths_nm,
            samples,
            emissive_units: RADIANCE_UNITS.to_string(),
        })
    }

    /// Per-band weights w_k such that XYZ = Σ_k L_k w_k: the integral of the hat function
    /// of band k (linear interpolation) against x̄, ȳ, z̄ on the 1 nm grid, over Σ ȳ.
    pub fn xyz_weights(&self, observer: Observer) -> Vec<DVec3> {
        let cmf = cmfs(observer);
        let (xb, yb, zb) = (cmf.x_bar.values(), cmf.y_bar.values(), cmf.z_bar.values());
        let y_integral = y_bar_integral_nm(observer);
        let wl = &self.wavelengths_nm;
        let mut weights = vec![DVec3::ZERO; wl.len()];
        let mut band = 0;
        for i in 0..DENSE_SAMPLE_COUNT {
            let lambda = LAMBDA_MIN_NM as f64 + i as f64;
            if lambda < wl[0] || lambda > wl[wl.len() - 1] {
                continue;
            }
            while band + 2 < wl.len() && lambda > wl[band + 1] {
                band += 1;
            }
            let t = (lambda - wl[band]) / (wl[band + 1] - wl[band]);
            let cmf_value = DVec3::new(xb[i], yb[i], zb[i]) / y_integral;
            weights[band] += (1.0 - t) * cmf_value;
            weights[band + 1] += t * cmf_value;
        }
        weights
    }

    /// cd/m² per unit of Y for radiance in W·m⁻²·sr⁻¹·nm⁻¹: 683.002 lm/W × Σ ȳ Δλ.
    pub fn cd_m2_per_unit(observer: Observer) -> f64 {
        prism_spectrum::photometry::cd_m2_per_unit(observer)
    }

    /// Reduces every pixel to CIE XYZ (interleaved, Y = 1 for a flat spectrum of 1).
    pub fn to_xyz(&self, observer: Observer) -> Vec<[f32; 3]> {
        self.reduce(&self.xyz_weights(observer), glam::DMat3::IDENTITY)
    }

    fn reduce(&self, weights: &[DVec3], matrix: glam::DMat3) -> Vec<[f32; 3]> {
        let w: Vec<glam::Vec3> = weights.iter().map(|w| (matrix * *w).as_vec3()).collect();
        let n = self.wavelengths_nm.len();
        self.samples
            .par_chunks(n)
            .map(|spectrum| {
                let sum = spectrum
                    .iter()
                    .zip(&w)
                    .fold(glam::Vec3::ZERO, |acc, (l, w)| acc + *l * *w);
                sum.to_array()
            })
            .collect()
    }

    /// Reduces to XYZ with `observer`, then to linear RGB in `space`; when the units are
    /// radiance the absolute scale is set from [`SpectralImage::cd_m2_per_unit`].
    pub fn to_rgb_image(&self, observer: Observer, space: &RgbColorSpace) -> Result<Image> {
        let pixels = self.reduce(&self.xyz_weights(observer), space.xyz_to_rgb);
        let mut image = Image::new(self.width, self.height, pixels, space.clone())?;
        if self.emissive_units == RADIANCE_UNITS {
            image.cd_m2_per_unit = Some(Self::cd_m2_per_unit(observer));
        }
        image
            .metadata
            .insert("prism:observer".into(), observer.name().into());
        Ok(image)
    }
}

/// Builds a spectral image from the `S0.*` channels of an already read EXR file.
pub(crate) fn spectral_from_channels(path: &Path, data: &ExrChannels) -> Result<SpectralImage> {
    let mut bands: Vec<(f64, usize)> = data
        .channels
        .iter()
        .enumerate()
        .filter_map(|(i, (name, _))| match parse_spectral_channel(name) {
            Some((SpectralChannelKind::Emissive { stokes: 0 }, nm)) => Some((nm, i)),
            _ => None,
        })
        .collect();
    if bands.is_empty() {
        return Err(ImageError::format(
            path,
            "expected emissive spectral channels S0.<wavelength>nm (Fichet et al. 2021 layout); \
             reflective (T.*) images are not supported",
        ));
    }
    bands.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(w) = bands.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(ImageError::format(
            path,
            format!(
                "two spectral channels at {} nm: expected one per wavelength",
                w[0].0
            ),
        ));
    }
    let n = bands.len();
    let pixels = data.width * data.height;
    let mut samples = vec![0.0f32; pixels * n];
    for (k, (_, index)) in bands.iter().enumerate() {
        let values = &data.channels[*index].1;
        samples
            .par_chunks_mut(n)
            .enumerate()
            .for_each(|(i, px)| px[k] = super::exr::sample_at(values, i));
    }
    let wavelengths = bands.iter().map(|b| b.0).collect();
    let mut image = SpectralImage::new(data.width, data.height, wavelengths, samples)
        .map_err(|e| ImageError::format(path, e.to_string()))?;
    if let Some(AttributeValue::Text(units)) = data.attributes.get(EMISSIVE_UNITS_ATTRIBUTE) {
        image.emissive_units = units.to_string();
    }
    Ok(image)
}

/// Whether the EXR file at `path` has emissive spectral channels (`S0.<λ>nm`), from its
/// header only: callers that read an image and want its bands too (the Python package's
/// `read_image`) read them only when there are some.
pub fn has_emissive_channels(path: &Path) -> Result<bool> {
    let file = std::fs::File::open(path).map_err(|e| ImageError::io(path, "open", e))?;
    let meta = ::exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
        .map_err(|e| ImageError::format(path, format!("not a readable EXR file: {e}")))?;
    Ok(meta.headers.iter().any(|header| {
        header.channels.list.iter().any(|channel| {
            matches!(
                parse_spectral_channel(&channel.name.to_string()),
                Some((SpectralChannelKind::Emissive { stokes: 0 }, _))
            )
        })
    }))
}

/// Reads the emissive bands of a spectral EXR file.
pub fn read_spectral_exr(path: &Path) -> Result<SpectralImage> {
    spectral_from_channels(path, &read_exr_channels(path)?)
}

/// Writes `image` in the Fichet et al. 2021 layout, with R, G, B (CIE 1931, linear sRGB)
/// beside the bands and `prism:cd_m2_per_unit` for that RGB when the units are radiance.
pub fn write_spectral_exr(
    path: &Path,
    image: &SpectralImage,
    options: &ExrWriteOptions,
) -> Result<()> {
    let n = image.wavelengths_nm.len();
    let pixels = image.width * image.height;
    let space = RgbColorSpace::srgb();
    let rgb = image.to_rgb_image(Observer::Cie1931, &space)?;
    let mut channels = Vec::with_capacity(n + 3);
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let plane = rgb.pixels().iter().map(|p| p[c]).collect();
        channels.push((name.to_string(), flat_samples(plane, options.sample_type)));
    }
    for (k, wl) in image.wavelengths_nm.iter().enumerate() {
        let plane: Vec<f32> = (0..pixels).map(|i| image.samples[i * n + k]).collect();
        channels.push((
            emissive_channel_name(*wl),
            flat_samples(plane, options.sample_type),
        ));
    }
    let mut attributes = vec![
        (
            VERSION_ATTRIBUTE.to_string(),
            AttributeValue::Text(text(path, "1.0")?),
        ),
        (
            EMISSIVE_UNITS_ATTRIBUTE.to_string(),
            AttributeValue::Text(text(path, &image.emissive_units)?),
        ),
    ];
    if let Some(scale) = rgb.cd_m2_per_unit {
        attributes.push((
            super::exr::CD_M2_PER_UNIT_ATTRIBUTE.to_string(),
            AttributeValue::F64(scale),
        ));
    }
    write_exr_channels(
        path,
        image.width,
        image.height,
        channels,
        Some(chromaticities_of(&space)),
        attributes,
        options,
    )
}

/// Writes `image` (R, G, B, its layers and attributes, as `exr::write_exr`) with spectral
/// radiance bands beside them in the same part, in the Fichet et al. 2021 layout: one
/// channel `S0.<λ>nm` per entry of `wavelengths_nm` (strictly increasing, > 0) holding the
/// row-major plane of the same index, in W·m⁻²·sr⁻¹·nm⁻¹, and the attributes
/// `spectralLayoutVersion` = "1.0" and `emissiveUnits` = "W.m^-2.sr^-1". What `prism
/// render --spectral-bins` writes (bin centres as the wavelengths). One band is allowed
/// here; [`read_spectral_exr`] needs two to interpolate.
pub fn write_exr_with_spectral_bands(
    path: &Path,
    image: &Image,
    wavelengths_nm: &[f64],
    planes: &[Vec<f32>],
    options: &ExrWriteOptions,
) -> Result<()> {
    write_exr_with_spectral_bands_and_raw(path, image, wavelengths_nm, planes, Vec::new(), options)
}

/// [`write_exr_with_spectral_bands`] with `raw` channels beside them in the same part
/// (what `crate::io::raw_exr::write_exr_with_raw` adds to a spectral image).
pub(crate) fn write_exr_with_spectral_bands_and_raw(
    path: &Path,
    image: &Image,
    wavelengths_nm: &[f64],
    planes: &[Vec<f32>],
    raw: Vec<(String, FlatSamples)>,
    options: &ExrWriteOptions,
) -> Result<()> {
    let pixels = image.width() * image.height();
    if wavelengths_nm.is_empty() || planes.len() != wavelengths_nm.len() {
        return Err(ImageError::invalid(format!(
            "spectral bands: {} wavelengths and {} planes; expected the same number, at least 1",
            wavelengths_nm.len(),
            planes.len()
        )));
    }
    if !(wavelengths_nm[0] > 0.0 && wavelengths_nm.windows(2).all(|w| w[0] < w[1])) {
        return Err(ImageError::invalid(
            "spectral band wavelengths must be positive and strictly increasing",
        ));
    }
    if let Some((k, p)) = planes.iter().enumerate().find(|(_, p)| p.len() != pixels) {
        return Err(ImageError::invalid(format!(
            "spectral band {k} ({} nm) has {} values; a {}×{} image needs {pixels}",
            wavelengths_nm[k],
            p.len(),
            image.width(),
            image.height()
        )));
    }
    let (mut channels, mut attributes) = image_channels(path, image, options)?;
    channels.extend(raw);
    for (wl, plane) in wavelengths_nm.iter().zip(planes) {
        channels.push((
            emissive_channel_name(*wl),
            flat_samples(plane.clone(), options.sample_type),
        ));
    }
    attributes.push((
        VERSION_ATTRIBUTE.to_string(),
        AttributeValue::Text(text(path, "1.0")?),
    ));
    attributes.push((
        EMISSIVE_UNITS_ATTRIBUTE.to_string(),
        AttributeValue::Text(text(path, RADIANCE_UNITS)?),
    ));
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
