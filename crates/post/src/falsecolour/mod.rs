//! False-colour renderings of a photometric quantity (luminance in cd/m², illuminance in lx)
//! with a legend: a colour bar and labelled ticks in the quantity's unit, on a linear or a
//! logarithmic scale — the lighting engineer's view of a result (Radiance's `falsecolor`).
//!
//! Two palettes ([`Palette`]): the lighting ramp, dark blue → blue → cyan → green → yellow →
//! red through six sRGB control colours interpolated linearly in display space; and
//! matplotlib's magma (256 entries, nearest), the colour map FLIP error maps are shown in.
//! Values below the range take the first colour, above it the last; on a log scale values
//! ≤ 0 take the first.

mod magma;

use crate::sheet::font5x7::{draw_text, GLYPH_HEIGHT};
use prism_image::Image;
use prism_image::{ImageError, Result};
use prism_spectrum::rgb_space::RgbColorSpace;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FalseColourScale {
    Linear,
    Log,
}

/// The colour ramp of a false-colour image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Palette {
    /// Radiance-style blue → red (lighting quantities).
    Lighting,
    /// matplotlib's magma, black → purple → orange → pale yellow (FLIP error maps).
    Magma,
}

impl Palette {
    /// The palette's linear-RGB colour at t ∈ [0, 1] (NaN → t = 0).
    pub fn colour(self, t: f64) -> [f32; 3] {
        match self {
            Palette::Lighting => ramp(t),
            Palette::Magma => {
                let t = if t.is_finite() {
                    t.clamp(0.0, 1.0)
                } else {
                    0.0
                };
                // Nearest entry, as FLIP indexes its table (round(255 t)).
                magma::MAGMA_SRGB[(t * 255.0).round() as usize].map(srgb_decode)
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct FalseColourOptions {
    pub scale: FalseColourScale,
    /// Value range [min, max] of the ramp; `None`: linear [0, max], log [max/1000 (or the
    /// smallest positive value if larger), max].
    pub range: Option<(f64, f64)>,
    /// The unit shown on the legend (`cd/m2`, `lx`).
    pub unit: String,
    /// Each input value becomes a block of `cell_px × cell_px` pixels.
    pub cell_px: usize,
    pub palette: Palette,
}

/// sRGB display colours of the ramp at t = 0, 0.2, …, 1.
const RAMP: [[f32; 3]; 6] = [
    [0.05, 0.0, 0.35],
    [0.0, 0.25, 1.0],
    [0.0, 0.8, 0.85],
    [0.2, 0.8, 0.1],
    [1.0, 0.85, 0.0],
    [0.9, 0.0, 0.0],
];

fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The ramp's linear-RGB colour at t ∈ [0, 1].
pub fn ramp(t: f64) -> [f32; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    } as f32
        * 5.0;
    let i = (t.floor() as usize).min(4);
    let f = t - i as f32;
    let (a, b) = (RAMP[i], RAMP[i + 1]);
    [0, 1, 2].map(|k| srgb_decode(a[k] + (b[k] - a[k]) * f))
}

/// The ramp position of `v` in `range`.
fn position(v: f64, scale: FalseColourScale, (lo, hi): (f64, f64)) -> f64 {
    match scale {
        FalseColourScale::Linear => (v - lo) / (hi - lo),
        FalseColourScale::Log => {
            if v <= 0.0 {
                0.0
            } else {
                (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
            }
        }
    }
}

/// "123", "1.25", "0.0312", "1.2e+05": three significant digits, compact.
pub fn format_value(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(0.01..100_000.0).contains(&a) {
        return format!("{v:.1e}");
    }
    let digits = (2 - a.log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// The range the ramp spans for `values` under `options` (checked: finite, lo < hi, and
/// lo > 0 on a log scale).
pub fn resolve_range(values: &[f32], options: &FalseColourOptions) -> Result<(f64, f64)> {
    let max = values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, &v| m.max(f64::from(v)));
    let (lo, hi) = match (options.range, options.scale) {
        (Some(r), _) => r,
        (None, FalseColourScale::Linear) => (0.0, max),
        (None, FalseColourScale::Log) => {
            let min_pos = values
                .iter()
                .filter(|v| v.is_finite() && **v > 0.0)
                .fold(f64::INFINITY, |m, &v| m.min(f64::from(v)));
            ((max * 1e-3).max(min_pos.min(max)), max)
        }
    };
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Err(ImageError::Invalid(format!(
            "false-colour range [{lo}, {hi}] is empty (every value is the same, or the range is reversed)"
        )));
    }
    if options.scale == FalseColourScale::Log && lo <= 0.0 {
        return Err(ImageError::Invalid(format!(
            "a log false-colour scale needs a minimum > 0, found {lo}"
        )));
    }
    Ok((lo, hi))
}

/// The false-colour image of `values` (`width × height`, row-major, row 0 at the top) with
/// a legend to its right.
pub fn false_colour(
    values: &[f32],
    width: usize,
    height: usize,
    options: &FalseColourOptions,
) -> Result<Image> {
    let rows = FalseColourRows::new(values, width, height, options)?;
    let mut px = Vec::with_capacity(rows.width() * rows.height());
    for y in 0..rows.height() {
        rows.extend_with_row(y, &mut px);
    }
    Image::new(rows.width(), rows.height(), px, RgbColorSpace::srgb())
}

/// [`false_colour`]'s image one row at a time, so that a large map can be encoded without
/// its false-colour image ever existing whole: the legend panel is drawn once (150 px wide,
/// the image's height), the map's colours as each row is asked for.
pub struct FalseColourRows<'a> {
    values: &'a [f32],
    width: usize,
    scale: FalseColourScale,
    palette: Palette,
    range: (f64, f64),
    cell_px: usize,
    /// The map's size in output pixels (cells of `cell_px`).
    map_size: (usize, usize),
    out_height: usize,
    legend: Vec<[f32; 3]>,
}

const LEGEND_WIDTH_PX: usize = 150;
const LEGEND_MIN_HEIGHT_PX: usize = 220;
const BACKGROUND: [f32; 3] = [0.02; 3];

impl<'a> FalseColourRows<'a> {
    pub fn new(
        values: &'a [f32],
        width: usize,
        height: usize,
        options: &FalseColourOptions,
    ) -> Result<Self> {
        if values.len() != width * height || width == 0 || height == 0 {
            return Err(ImageError::Invalid(format!(
                "false colour: {} values for a {width} × {height} image",
                values.len()
            )));
        }
        let range = resolve_range(values, options)?;
        let cell = options.cell_px.max(1);
        let (iw, ih) = (width * cell, height * cell);
        let out_height = ih.max(LEGEND_MIN_HEIGHT_PX);
        Ok(Self {
            values,
            width,
            scale: options.scale,
            palette: options.palette,
            range,
            cell_px: cell,
            map_size: (iw, ih),
            out_height,
            legend: legend_panel(out_height, range, options),
        })
    }

    /// Output width in pixels: the map and its legend.
    pub fn width(&self) -> usize {
        self.map_size.0 + LEGEND_WIDTH_PX
    }

    pub fn height(&self) -> usize {
        self.out_height
    }

    /// Appends output row `y` (linear sRGB) to `out`.
    pub fn extend_with_row(&self, y: usize, out: &mut Vec<[f32; 3]>) {
        let (iw, ih) = self.map_size;
        if y < ih {
            let row = &self.values[(y / self.cell_px) * self.width..][..self.width];
            out.extend((0..iw).map(|x| {
                let v = f64::from(row[x / self.cell_px]);
                self.palette.colour(position(v, self.scale, self.range))
            }));
        } else {
            out.extend(std::iter::repeat_n(BACKGROUND, iw));
        }
        out.extend_from_slice(&self.legend[y * LEGEND_WIDTH_PX..][..LEGEND_WIDTH_PX]);
    }
}

/// The legend beside the map: the quantity's unit, a colour bar (top = maximum) and six
/// labelled ticks, `LEGEND_WIDTH_PX × height`.
fn legend_panel(height: usize, range: (f64, f64), options: &FalseColourOptions) -> Vec<[f32; 3]> {
    let w = LEGEND_WIDTH_PX;
    let text = [1.0f32; 3];
    let mut px = vec![BACKGROUND; w * height];
    let (bar_x, bar_w, bar_top, bar_h) = (12, 18, 24usize, height - 40);
    for y in 0..bar_h {
        let t = 1.0 - y as f64 / (bar_h - 1).max(1) as f64;
        for x in 0..bar_w {
            px[(bar_top + y) * w + bar_x + x] = options.palette.colour(t);
        }
    }
    draw_text(&mut px, w, (8, 6), &options.unit, 2, text);
    let ticks = 6;
    for k in 0..ticks {
        let t = k as f64 / (ticks - 1) as f64;
        let v = match options.scale {
            FalseColourScale::Linear => range.0 + t * (range.1 - range.0),
            FalseColourScale::Log => (range.0.ln() + t * (range.1.ln() - range.0.ln())).exp(),
        };
        let y = bar_top + ((1.0 - t) * (bar_h - 1) as f64) as usize;
        for x in 0..5 {
            px[y * w + bar_x + bar_w + x] = text;
        }
        let ty = y.saturating_sub(GLYPH_HEIGHT / 2);
        draw_text(
            &mut px,
            w,
            (bar_x + bar_w + 8, ty),
            &format_value(v),
            1,
            text,
        );
    }
    px
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(scale: FalseColourScale) -> FalseColourOptions {
        FalseColourOptions {
            scale,
            range: None,
            unit: "lx".into(),
            cell_px: 4,
            palette: Palette::Lighting,
        }
    }

    #[test]
    fn ramp_ends_and_positions() {
        assert_eq!(ramp(0.0), RAMP[0].map(srgb_decode));
        assert_eq!(ramp(1.0), RAMP[5].map(srgb_decode));
        assert_eq!(ramp(2.0), ramp(1.0));
        assert_eq!(ramp(f64::NAN), ramp(0.0));
        let r = (1.0, 1000.0);
        assert!((position(10.0, FalseColourScale::Log, r) - 1.0 / 3.0).abs() < 1e-12);
        assert!((position(500.5, FalseColourScale::Linear, r) - 0.5).abs() < 1e-12);
        assert_eq!(position(0.0, FalseColourScale::Log, r), 0.0);
    }

    #[test]
    fn image_has_the_legend_and_the_values_colours() {
        let values: Vec<f32> = (0..12).map(|i| i as f32 * 100.0).collect();
        let img = false_colour(&values, 4, 3, &options(FalseColourScale::Linear)).unwrap();
        assert_eq!(img.width(), 16 + 150);
        assert_eq!(img.height(), 220);
        // The largest value (bottom-right cell) is the ramp's last colour; the first is 0.
        assert_eq!(img.pixel(15, 11), ramp(1.0));
        assert_eq!(img.pixel(0, 0), ramp(0.0));
        assert_eq!(format_value(1234.5), "1234");
        assert_eq!(format_value(0.03125), "0.0312");
        assert_eq!(format_value(250_000.0), "2.5e5");
    }

    #[test]
    fn magma_runs_black_to_pale_yellow() {
        let (lo, hi) = (Palette::Magma.colour(0.0), Palette::Magma.colour(1.0));
        assert!(lo.iter().all(|c| *c < 0.01), "{lo:?}");
        assert!(
            hi[0] > 0.9 && hi[1] > 0.9 && hi[2] > 0.5 && hi[2] < hi[1],
            "{hi:?}"
        );
        assert_eq!(Palette::Magma.colour(f64::NAN), lo);
        let mut o = options(FalseColourScale::Linear);
        o.palette = Palette::Magma;
        o.range = Some((0.0, 1.0));
        let img = false_colour(&[0.0, 1.0], 2, 1, &o).unwrap();
        assert_eq!((img.pixel(0, 0), img.pixel(7, 0)), (lo, hi));
    }

    #[test]
    fn empty_or_invalid_ranges_are_errors() {
        let e = false_colour(&[5.0; 4], 2, 2, &options(FalseColourScale::Log)).unwrap_err();
        assert!(e.to_string().contains("is empty"), "{e}");
        let mut o = options(FalseColourScale::Log);
        o.range = Some((0.0, 10.0));
        let e = false_colour(&[1.0, 2.0], 2, 1, &o).unwrap_err();
        assert!(e.to_string().contains("minimum > 0"), "{e}");
        assert!(false_colour(&[1.0], 2, 1, &options(FalseColourScale::Linear)).is_err());
    }
}
