//! Contact sheet (`prism tonemap IN --op all -o sheet.png`): one tile per tone operator,
//! side by side, each labelled with the operator's name and its resolved parameters in a
//! 5×7 bitmap font ([`font5x7`]).
//!
//! Each operator maps the full-resolution image (so local operators see their real
//! scales); the result is box-downsampled by an integer factor to at most
//! [`TILE_MAX_WIDTH`] pixels wide, gamut-mapped into the target, and placed on a grid of
//! ⌈√n⌉ columns. Operators that fail (an absolute operator without a luminance scale) get
//! a grey tile whose label says why; the sheet itself only fails on bad parameters.
//! The sheet holds linear display values of the target space in [0, 1].

pub mod font5x7;

use std::collections::BTreeMap;

use serde::Serialize;

use crate::colour::{map_gamut, GamutMethod, GamutTarget};
use crate::metrics::tmqi::{self, Tmqi};
use crate::tonemap::{ToneOperator, ToneParams, ToneReport};
use font5x7::{draw_text, ADVANCE, GLYPH_HEIGHT};
use prism_image::Image;
use prism_image::{ImageError, Result};

/// Largest tile width in pixels (a 4K input gives 960-pixel tiles, factor 4).
pub const TILE_MAX_WIDTH: usize = 960;
/// Gap between tiles and around the sheet, in pixels.
const GAP_PX: usize = 6;
/// Background (linear display value), label text and failed-tile colours.
const BACKGROUND: [f32; 3] = [0.02; 3];
const TEXT: [f32; 3] = [1.0; 3];
const FAILED_TILE: [f32; 3] = [0.18; 3];

/// An operator that produced no tile, and why.
#[derive(Debug, Clone, Serialize)]
pub struct SheetFailure {
    pub operator: &'static str,
    pub error: String,
}

/// What `--score` measures on each tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SheetScore {
    /// TMQI (Yeganeh & Wang 2013) of the operator's full-resolution output, gamut-mapped
    /// into the target, against the HDR image the operators were given.
    Tmqi,
}

impl SheetScore {
    pub fn name(self) -> &'static str {
        match self {
            Self::Tmqi => "tmqi",
        }
    }
}

/// The order of the tiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileOrder {
    /// The order of the operator list ([`ToneOperator::ALL`] for `--op all`).
    Catalogue,
    /// Best score first; tiles without a score last, in catalogue order.
    ScoreDescending,
}

/// How a sheet is mapped, scored and ordered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetOptions {
    pub target: GamutTarget,
    pub gamut: GamutMethod,
    pub score: Option<SheetScore>,
    pub order: TileOrder,
}

/// One operator's score (`--score tmqi`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TileScore {
    pub operator: &'static str,
    #[serde(flatten)]
    pub tmqi: Tmqi,
}

/// A contact sheet with what each operator reported.
#[derive(Debug, Clone)]
pub struct ContactSheet {
    pub image: Image,
    pub reports: Vec<ToneReport>,
    pub failures: Vec<SheetFailure>,
    /// Fraction of tile pixels outside the target gamut before mapping.
    pub gamut_fraction_outside: f64,
    /// One per scored tile, in the sheet's tile order (empty without a score).
    pub scores: Vec<TileScore>,
}

/// One labelled tile before placement.
struct Tile {
    /// `None` for an operator that failed (a grey tile).
    pixels: Option<Vec<[f32; 3]>>,
    label: String,
    score: Option<TileScore>,
}

/// One tile per operator, labelled, gamut-clipped into `target` (see the module text).
/// Parameters in `params.values` go to the operators that have them.
pub fn contact_sheet(
    image: &Image,
    operators: &[ToneOperator],
    params: &ToneParams,
    target: GamutTarget,
) -> Result<Image> {
    Ok(contact_sheet_with_reports(image, operators, params, target, GamutMethod::Clip)?.image)
}

/// [`contact_sheet`] with a chosen gamut method, returning the operators' reports.
pub fn contact_sheet_with_reports(
    image: &Image,
    operators: &[ToneOperator],
    params: &ToneParams,
    target: GamutTarget,
    gamut: GamutMethod,
) -> Result<ContactSheet> {
    contact_sheet_scored(
        image,
        operators,
        params,
        &SheetOptions {
            target,
            gamut,
            score: None,
            order: TileOrder::Catalogue,
        },
    )
}

/// [`contact_sheet_with_reports`] with an optional score under each tile and a tile order.
/// TMQI needs an image of at least [`tmqi::MIN_SIDE_PX`] on each side: smaller ones are
/// an error before any operator runs.
pub fn contact_sheet_scored(
    image: &Image,
    operators: &[ToneOperator],
    params: &ToneParams,
    options: &SheetOptions,
) -> Result<ContactSheet> {
    contact_sheet_from(
        image.clone(),
        || Ok(image.clone()),
        operators,
        params,
        options,
    )
}

/// [`contact_sheet_scored`] for an input that can be made again: each operator maps its own
/// copy in place, `first` for the first operator and one from `again` for each next one
/// (`prism tonemap` reads the file again), so that the input and an operator's output are
/// never held together. `again` must give the image `first` is.
pub fn contact_sheet_from(
    first: Image,
    mut again: impl FnMut() -> Result<Image>,
    operators: &[ToneOperator],
    params: &ToneParams,
    options: &SheetOptions,
) -> Result<ContactSheet> {
    let image = &first;
    if operators.is_empty() {
        return Err(ImageError::invalid(
            "contact sheet: no operators to show".to_string(),
        ));
    }
    // Every --param must belong to at least one operator shown.
    for name in params.values.keys() {
        if !operators
            .iter()
            .any(|op| op.info().params.iter().any(|p| p.name == name))
        {
            return Err(ImageError::invalid(format!(
                "--param {name}: none of the operators on the sheet has this parameter"
            )));
        }
    }
    match options.score {
        Some(SheetScore::Tmqi) => tmqi::check_size(image.width(), image.height())?,
        None => {}
    }
    let factor = image.width().div_ceil(TILE_MAX_WIDTH).max(1);
    let (tw, th) = (
        image.width().div_ceil(factor),
        image.height().div_ceil(factor),
    );
    let (width, height) = (image.width(), image.height());
    // TMQI's HDR side, once: the luminance of the input the operators are given.
    let hdr_luminance = options
        .score
        .map(|SheetScore::Tmqi| tmqi::hdr_luminance_of(image.pixels(), &image.color_space));
    let mut reports = Vec::new();
    let mut failures = Vec::new();
    let (mut outside, mut counted) = (0usize, 0usize);
    let mut tiles = Vec::with_capacity(operators.len());
    let mut spare = Some(first);
    for op in operators {
        let input = match spare.take() {
            Some(image) => image,
            None => {
                let image = again()?;
                if (image.width(), image.height()) != (width, height) {
                    return Err(ImageError::invalid(format!(
                        "contact sheet: the input was {width}×{height} for the first operator \
                         but {}×{} for {}",
                        image.width(),
                        image.height(),
                        op.name()
                    )));
                }
                image
            }
        };
        let own = ToneParams {
            values: params
                .values
                .iter()
                .filter(|(n, _)| op.info().params.iter().any(|p| p.name == n.as_str()))
                .map(|(n, v)| (n.clone(), *v))
                .collect(),
            ..params.clone()
        };
        let tile = match op.apply_in_place(input, &own) {
            Ok(result) => {
                let mut pixels = downsample(&result.image, factor, tw, th);
                let g = map_gamut(
                    &mut pixels,
                    &result.image.color_space,
                    options.target,
                    options.gamut,
                );
                outside += g.pixels_outside;
                counted += g.pixel_count;
                let label = label_for(*op, &own.values, &result.report.values);
                reports.push(result.report);
                let score = match &hdr_luminance {
                    Some(hdr) => Some(TileScore {
                        operator: op.name(),
                        tmqi: score_tmqi_owned(result.image, hdr.clone(), options)?,
                    }),
                    None => None,
                };
                Tile {
                    pixels: Some(pixels),
                    label,
                    score,
                }
            }
            Err(ImageError::Invalid(message)) => {
                let short = if op.info().absolute {
                    "needs --luminance-scale"
                } else {
                    "failed"
                };
                failures.push(SheetFailure {
                    operator: op.name(),
                    error: message,
                });
                Tile {
                    pixels: None,
                    label: format!("{}: {short}", op.name()),
                    score: None,
                }
            }
            Err(other) => return Err(other),
        };
        tiles.push(tile);
    }
    match options.order {
        TileOrder::Catalogue => {}
        // Stable: ties and unscored tiles keep the catalogue order.
        TileOrder::ScoreDescending => tiles.sort_by(|a, b| {
            let key = |t: &Tile| t.score.as_ref().map(|s| s.tmqi.tmqi);
            match (key(a), key(b)) {
                (Some(x), Some(y)) => y.total_cmp(&x),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => std::cmp::Ordering::Equal,
            }
        }),
    }

    let scale = if tw >= 480 { 2 } else { 1 };
    let lines = if options.score.is_some() { 2 } else { 1 };
    let line_h = GLYPH_HEIGHT * scale + 2 * scale;
    let label_h = lines * line_h;
    let cols = (operators.len() as f64).sqrt().ceil() as usize;
    let rows = operators.len().div_ceil(cols);
    let (sw, sh) = (
        cols * (tw + GAP_PX) + GAP_PX,
        rows * (th + label_h + GAP_PX) + GAP_PX,
    );
    let mut sheet = vec![BACKGROUND; sw * sh];
    let max_chars = (tw / (ADVANCE * scale)).max(1);
    for (k, tile) in tiles.iter().enumerate() {
        let (x0, y0) = (
            GAP_PX + (k % cols) * (tw + GAP_PX),
            GAP_PX + (k / cols) * (th + label_h + GAP_PX),
        );
        for y in 0..th {
            let row = &mut sheet[(y0 + y) * sw + x0..(y0 + y) * sw + x0 + tw];
            match &tile.pixels {
                Some(pixels) => row.copy_from_slice(&pixels[y * tw..(y + 1) * tw]),
                None => row.fill(FAILED_TILE),
            }
        }
        let text: String = tile.label.chars().take(max_chars).collect();
        draw_text(&mut sheet, sw, (x0, y0 + th + scale), &text, scale, TEXT);
        if let Some(score) = &tile.score {
            let text = format!(
                "TMQI {:.3} S {:.3} N {:.3}",
                score.tmqi.tmqi, score.tmqi.tmqi_structural_fidelity, score.tmqi.tmqi_naturalness
            );
            let text: String = text.chars().take(max_chars).collect();
            draw_text(
                &mut sheet,
                sw,
                (x0, y0 + th + line_h + scale),
                &text,
                scale,
                TEXT,
            );
        }
    }
    let mut out = Image::new(sw, sh, sheet, options.target.space())?;
    out.metadata
        .insert("prism:contact_sheet".into(), operators.len().to_string());
    Ok(ContactSheet {
        image: out,
        reports,
        failures,
        gamut_fraction_outside: if counted > 0 {
            outside as f64 / counted as f64
        } else {
            0.0
        },
        scores: tiles.into_iter().filter_map(|t| t.score).collect(),
    })
}

/// [`score_tmqi`] on an output it may overwrite, against the input's luminance
/// ([`tmqi::hdr_luminance_of`]): the output's luminance is taken and the output dropped
/// before TMQI's planes are made.
fn score_tmqi_owned(
    mut tone_mapped: Image,
    hdr_luminance: Vec<f64>,
    options: &SheetOptions,
) -> Result<Tmqi> {
    let space = tone_mapped.color_space.clone();
    map_gamut(
        tone_mapped.pixels_mut(),
        &space,
        options.target,
        options.gamut,
    );
    let (w, h) = (tone_mapped.width(), tone_mapped.height());
    let ldr = tmqi::ldr_luminance_of(tone_mapped.pixels(), &options.target.space());
    drop(tone_mapped);
    tmqi::tmqi_owned(ldr, hdr_luminance, w, h)
}

/// TMQI of an operator's full-resolution output, gamut-mapped into the target as a
/// single-operator `prism tonemap` would write it, against the operators' input.
pub fn score_tmqi(tone_mapped: &Image, hdr: &Image, options: &SheetOptions) -> Result<Tmqi> {
    // Different sizes are an error of tmqi_owned (plane lengths).
    score_tmqi_owned(
        tone_mapped.clone(),
        tmqi::hdr_luminance_of(hdr.pixels(), &hdr.color_space),
        options,
    )
}

/// `name k=v …`: each parameter's given value, else the value the operator resolved (in
/// its report), else its default; `auto` when none is known.
pub fn label_for(
    op: ToneOperator,
    given: &BTreeMap<String, f64>,
    resolved: &BTreeMap<String, f64>,
) -> String {
    let mut label = op.name().to_string();
    for spec in op.info().params {
        let value = given
            .get(spec.name)
            .or_else(|| resolved.get(spec.name))
            .copied()
            .or(spec.default);
        label.push(' ');
        label.push_str(spec.name);
        label.push('=');
        label.push_str(&value.map_or("auto".to_string(), short_number));
    }
    label
}

/// Up to 3 significant digits, trailing zeros dropped; exponent form outside [1e-3, 1e5).
pub fn short_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&v.abs()) {
        return format!("{v:.2e}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Box average over `factor × factor` blocks (partial blocks at the edges averaged over
/// what they hold).
fn downsample(image: &Image, factor: usize, tw: usize, th: usize) -> Vec<[f32; 3]> {
    if factor == 1 {
        return image.pixels().to_vec();
    }
    let (w, h) = (image.width(), image.height());
    let mut out = vec![[0.0f32; 3]; tw * th];
    for (i, o) in out.iter_mut().enumerate() {
        let (tx, ty) = (i % tw, i / tw);
        let mut acc = [0.0f32; 3];
        let mut n = 0.0f32;
        for y in ty * factor..((ty + 1) * factor).min(h) {
            for x in tx * factor..((tx + 1) * factor).min(w) {
                let p = image.pixels()[y * w + x];
                acc = [acc[0] + p[0], acc[1] + p[1], acc[2] + p[2]];
                n += 1.0;
            }
        }
        *o = acc.map(|c| c / n);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::rgb_space::RgbColorSpace;

    #[test]
    fn sheet_has_one_labelled_tile_per_operator() {
        let (w, h) = (64, 40);
        let pixels = (0..w * h)
            .map(|i| {
                let v = 10f32.powf(-2.0 + 4.0 * (i % w) as f32 / (w - 1) as f32);
                [v, 0.7 * v, 0.4 * v]
            })
            .collect();
        let img = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        let ops = ToneOperator::ALL;
        let sheet = contact_sheet_with_reports(
            &img,
            &ops,
            &ToneParams::default(),
            GamutTarget::Srgb,
            GamutMethod::Clip,
        )
        .unwrap();
        // 15 operators → 4 columns × 4 rows of 64×40 tiles plus 9-pixel label strips.
        let label_h = GLYPH_HEIGHT + 2;
        assert_eq!(sheet.image.width(), 4 * (64 + GAP_PX) + GAP_PX);
        assert_eq!(sheet.image.height(), 4 * (40 + label_h + GAP_PX) + GAP_PX);
        // No absolute scale: the three absolute operators (and ward97) fail, labelled.
        let absolute = ops.iter().filter(|o| o.info().absolute).count();
        assert_eq!(sheet.failures.len(), absolute);
        assert_eq!(sheet.reports.len(), ops.len() - absolute);
        assert!(sheet
            .image
            .pixels()
            .iter()
            .flatten()
            .all(|c| (0.0..=1.0).contains(c)));
        // The first tile's label strip holds white text pixels; the tile holds the image.
        let sw = sheet.image.width();
        let strip = (GAP_PX + 40)..(GAP_PX + 40 + label_h);
        let text_pixels = strip
            .flat_map(|y| (GAP_PX..GAP_PX + 64).map(move |x| y * sw + x))
            .filter(|i| sheet.image.pixels()[*i] == TEXT)
            .count();
        assert!(text_pixels > 20, "{text_pixels}");
        assert_eq!(
            label_for(ToneOperator::Reinhard02, &BTreeMap::new(), &BTreeMap::new()),
            "reinhard02 key=0.18 white=auto"
        );
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(short_number(0.18), "0.18");
        assert_eq!(short_number(100.0), "100");
        assert_eq!(short_number(0.85), "0.85");
        assert_eq!(short_number(12.3456), "12.3");
        assert_eq!(short_number(1e30), "1.00e30");
    }
}
