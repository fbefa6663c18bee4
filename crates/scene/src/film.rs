//! Film: resolution, pixel reconstruction filter, samples per pixel, seed, output file and
//! the extra images (AOVs) to write beside the beauty image.

use std::path::{Path, PathBuf};

use crate::reader::{quoted_list, Result, V};
use crate::schema::schema;

#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    /// Width and height in pixels.
    pub resolution: [u32; 2],
    pub filter: PixelFilter,
    /// Samples per pixel (a uniform plan; the CLI's `--spp` overrides it).
    pub spp: u32,
    pub seed: u64,
    /// Output image (.exr or .png), resolved relative to the scene file; `None`: the CLI
    /// chooses.
    pub output: Option<PathBuf>,
    /// Extra layers to write, in the order given.
    pub aovs: Vec<Aov>,
    /// How samples become pixels.
    pub reconstruction: Reconstruction,
}

/// How the pixel filter turns samples into pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reconstruction {
    /// Every sample is added to every pixel within the filter's radius with the filter's
    /// weight; pixel = Σ f·L / Σ f (Mitsuba 3's `ImageBlock`). With independent samples
    /// the noise per pixel is lower (≈ π·spp effective samples for a σ = 0.5 px Gaussian),
    /// neighbouring pixels are correlated, and a pixel's Sobol stratification is lost (its
    /// value mixes weighted samples of its neighbours).
    Splat,
    /// Each sample's film position is drawn from the filter and the sample counts for its
    /// own pixel only, with weight f/p (pbrt-v4 §8.8); pixels independent, and a pixel's
    /// low-discrepancy samples stay stratified. The default.
    ImportanceSampled,
}

/// Pixel filters; radii in pixels. Gaussian: exp(−x²/2σ²) minus its value at the radius
/// (pbrt-v4 §8.8.3); Mitchell–Netravali (1988) with parameters B, C; Blackman–Harris
/// four-term window (Harris 1978) over [−radius, radius].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PixelFilter {
    Box { radius_px: f64 },
    Gaussian { radius_px: f64, sigma_px: f64 },
    BlackmanHarris { radius_px: f64 },
    Mitchell { radius_px: f64, b: f64, c: f64 },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aov {
    /// Distance along the camera ray to the first hit, in metres.
    Depth,
    /// World-space shading normal at the first hit.
    Normal,
    /// Reflectance of the first hit's material.
    Albedo,
    /// World-space position of the first hit, in metres.
    Position,
}

pub const AOV_NAMES: [&str; 4] = ["depth", "normal", "albedo", "position"];

impl Default for PixelFilter {
    /// pbrt-v4's default: Gaussian, radius 1.5 px, σ = 0.5 px.
    fn default() -> Self {
        PixelFilter::Gaussian {
            radius_px: 1.5,
            sigma_px: 0.5,
        }
    }
}

impl Default for Film {
    fn default() -> Self {
        Film {
            resolution: [640, 480],
            filter: PixelFilter::default(),
            spp: 16,
            seed: 0,
            output: None,
            aovs: Vec::new(),
            reconstruction: Reconstruction::ImportanceSampled,
        }
    }
}

/// Largest integer an f64 (a JSON number) holds exactly.
const MAX_EXACT_INTEGER: f64 = 9_007_199_254_740_992.0;

pub(crate) fn parse_film(v: &V, base_dir: &Path) -> Result<Film> {
    let o = v.object(schema!("film"))?;
    let defaults = Film::default();
    let resolution = match o.get("resolution") {
        None => defaults.resolution,
        Some(r) => {
            let items = r.array()?;
            if items.len() != 2 {
                return Err(r.err(format!(
                    "expected [width, height] in pixels, found {} numbers",
                    items.len()
                )));
            }
            [items[0].u32_at_least(1)?, items[1].u32_at_least(1)?]
        }
    };
    let filter = o
        .get("filter")
        .map_or(Ok(defaults.filter), |f| parse_filter(&f))?;
    let spp = o.u32_or("spp", 1, defaults.spp)?;
    let seed = match o.get("seed") {
        None => 0,
        Some(s) => {
            let x = s.f64()?;
            if x.fract() != 0.0 || !(0.0..=MAX_EXACT_INTEGER).contains(&x) {
                return Err(s.err(format!("expected a whole number in [0, 2^53], found {x}")));
            }
            x as u64
        }
    };
    let output = match o.get("output") {
        None => None,
        Some(p) => {
            let s = p.str()?;
            let ext = Path::new(s)
                .extension()
                .and_then(|e| e.to_str())
                .map(|e| e.to_ascii_lowercase());
            if !matches!(ext.as_deref(), Some("exr" | "png")) {
                return Err(p.err(format!(
                    "expected an output file ending in `.exr` or `.png`, found `{s}`"
                )));
            }
            Some(base_dir.join(s))
        }
    };
    let mut aovs = Vec::new();
    if let Some(list) = o.get("aovs") {
        for item in list.array()? {
            let aov = match item.one_of("AOV", &AOV_NAMES)? {
                "depth" => Aov::Depth,
                "normal" => Aov::Normal,
                "albedo" => Aov::Albedo,
                _ => Aov::Position,
            };
            if aovs.contains(&aov) {
                return Err(item.err(format!(
                    "AOV listed twice; each of {} may appear once",
                    quoted_list(&AOV_NAMES)
                )));
            }
            aovs.push(aov);
        }
    }
    let reconstruction = match o.one_of_or(
        "reconstruction",
        "pixel reconstruction",
        &["importance", "splat"],
        "importance",
    )? {
        "splat" => Reconstruction::Splat,
        _ => Reconstruction::ImportanceSampled,
    };
    Ok(Film {
        reconstruction,
        resolution,
        filter,
        spp,
        seed,
        output,
        aovs,
    })
}

fn parse_filter(v: &V) -> Result<PixelFilter> {
    let kind = v.tag(
        "filter",
        &["box", "gaussian", "blackman_harris", "mitchell"],
        None,
    )?;
    Ok(match kind {
        "box" => {
            let o = v.tagged_object(schema!("film.filter<box>"))?;
            PixelFilter::Box {
                radius_px: o.positive_or("radius_px", 0.5)?,
            }
        }
        "gaussian" => {
            let o = v.tagged_object(schema!("film.filter<gaussian>"))?;
            PixelFilter::Gaussian {
                radius_px: o.positive_or("radius_px", 1.5)?,
                sigma_px: o.positive_or("sigma_px", 0.5)?,
            }
        }
        "blackman_harris" => {
            let o = v.tagged_object(schema!("film.filter<blackman_harris>"))?;
            PixelFilter::BlackmanHarris {
                radius_px: o.positive_or("radius_px", 2.0)?,
            }
        }
        _ => {
            let o = v.tagged_object(schema!("film.filter<mitchell>"))?;
            PixelFilter::Mitchell {
                radius_px: o.positive_or("radius_px", 2.0)?,
                b: o.f64_or("b", 1.0 / 3.0)?,
                c: o.f64_or("c", 1.0 / 3.0)?,
            }
        }
    })
}
