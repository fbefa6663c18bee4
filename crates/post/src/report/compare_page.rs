//! The page of `prism compare A B --report OUT.html`: the metric table, A and B in the
//! viewer (B the reference), and the FLIP and ΔE2000 maps in false colour with legends.

use prism_image::Result;
use prism_spectrum::rgb_space::RgbColorSpace;

use super::embed::ReportImageRows;
use super::{Labelled, ReportImage, ReportPage, Section};
use crate::falsecolour::{FalseColourOptions, FalseColourRows, FalseColourScale, Palette};
use crate::metrics::flip::FlipMap;
use crate::metrics::{Comparison, ErrorMaps};

/// ΔE2000 the map's colour ramp spans; larger differences take the top colour. Fixed, so
/// that maps of different reports read alike (a just-noticeable difference is ≈ 1–2).
pub const DELTA_E_MAP_MAX: f64 = 10.0;

/// One input of the comparison as the report shows it.
pub struct CompareInput {
    /// The file name (or any label) shown above the viewer.
    pub label: String,
    /// Embedded as [`ReportImage::radiance`] when scene-referred (EXR, HDR: the viewer gets
    /// an exposure control), else as [`ReportImage::display`] (PNG).
    pub image: ReportImage,
    pub scene_referred: bool,
}

fn number(v: f64) -> String {
    if v.is_infinite() {
        if v > 0.0 { "+∞" } else { "−∞" }.into()
    } else if v == 0.0 || (1e-3..1e5).contains(&v.abs()) {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

/// The metric table's rows (name, value), in `prism compare`'s order.
pub fn metric_rows(c: &Comparison) -> Vec<Vec<String>> {
    let mut rows = vec![
        vec!["size".into(), format!("{} × {} px", c.width, c.height)],
        vec!["MSE".into(), number(c.mse)],
        vec!["RMSE".into(), number(c.rmse)],
        vec!["relMSE".into(), number(c.relmse)],
        vec!["PSNR (dB)".into(), number(c.psnr_db)],
        vec!["SSIM".into(), c.ssim.map_or("n/a (< 11×11)".into(), number)],
        vec!["ΔE2000 mean".into(), number(c.delta_e2000_mean)],
        vec!["ΔE2000 p95".into(), number(c.delta_e2000_p95)],
    ];
    if let Some(f) = &c.flip {
        rows.extend([
            vec!["LDR-FLIP mean".into(), number(f.ldr_flip_mean)],
            vec!["LDR-FLIP p95".into(), number(f.ldr_flip_p95)],
            vec!["HDR-FLIP mean".into(), number(f.hdr_flip_mean)],
            vec!["HDR-FLIP p95".into(), number(f.hdr_flip_p95)],
            vec![
                "HDR-FLIP exposures".into(),
                format!(
                    "{:.2} … {:.2} stops ({})",
                    f.hdr_flip_exposures.start_stops,
                    f.hdr_flip_exposures.stop_stops,
                    f.hdr_flip_exposures.count
                ),
            ],
            vec![
                "FLIP pixels per degree".into(),
                format!("{:.2}", f.flip_ppd),
            ],
        ]);
    }
    for (name, v) in [
        ("relMSE R, G, B", c.per_channel.relmse),
        ("PSNR R, G, B (dB)", c.per_channel.psnr_db),
    ] {
        rows.push(vec![name.into(), v.map(number).join(", ")]);
    }
    rows.push(vec![
        "non-finite pixels".into(),
        c.non_finite_pixels.to_string(),
    ]);
    rows
}

/// Rows per band when a false-colour map is encoded.
const MAP_BAND_ROWS: usize = 256;

/// A false-colour map encoded band by band (its image never exists whole).
fn false_colour_figure(
    values: &[f32],
    width: usize,
    height: usize,
    options: &FalseColourOptions,
) -> Result<ReportImage> {
    let rows = FalseColourRows::new(values, width, height, options)?;
    let mut encoded = ReportImageRows::display(rows.width(), rows.height())?;
    let srgb = RgbColorSpace::srgb();
    let mut band = Vec::new();
    for start in (0..rows.height()).step_by(MAP_BAND_ROWS) {
        band.clear();
        for y in start..(start + MAP_BAND_ROWS).min(rows.height()) {
            rows.extend_with_row(y, &mut band);
        }
        encoded.push(&band, &srgb)?;
    }
    encoded.finish()
}

/// The false-colour maps of a comparison (FLIP's in magma over [0, 1], ΔE2000 on the
/// lighting ramp over [0, [`DELTA_E_MAP_MAX`]]), each with its legend. LDR-FLIP only for
/// two display-referred inputs, else both FLIP maps.
pub fn map_figures(
    maps: &ErrorMaps,
    width: usize,
    height: usize,
    hdr: bool,
) -> Result<Vec<Labelled>> {
    let mut figures = Vec::new();
    if let Some(flip) = &maps.flip {
        if hdr {
            figures.push(Labelled {
                label: "HDR-FLIP (0 … 1, magma)".into(),
                image: flip_figure(&flip.hdr, "HDR-FLIP")?,
            });
        }
        figures.push(Labelled {
            label: "LDR-FLIP (0 … 1, magma)".into(),
            image: flip_figure(&flip.ldr, "LDR-FLIP")?,
        });
    }
    if let Some(de) = &maps.delta_e2000 {
        let options = FalseColourOptions {
            scale: FalseColourScale::Linear,
            range: Some((0.0, DELTA_E_MAP_MAX)),
            unit: "dE2000".into(),
            cell_px: 1,
            palette: Palette::Lighting,
        };
        figures.push(Labelled {
            label: format!("ΔE2000 (0 … {DELTA_E_MAP_MAX}, larger clipped)"),
            image: false_colour_figure(de, width, height, &options)?,
        });
    }
    Ok(figures)
}

/// A FLIP map in magma over [0, 1] with its legend ([`FlipMap::to_image`]'s image).
fn flip_figure(map: &FlipMap, title: &str) -> Result<ReportImage> {
    let options = FlipMap::false_colour_options(title);
    false_colour_figure(&map.values, map.width, map.height, &options)
}

/// The whole compare page: `test` is A, `reference` is B; the viewer starts at
/// `reference_exposure_ev` (where `--exposure auto` would put the reference) when either is
/// scene-referred; `figures` are the error maps ([`map_figures`]).
pub fn compare_page(
    test: CompareInput,
    reference: CompareInput,
    reference_exposure_ev: Option<f64>,
    comparison: &Comparison,
    figures: Vec<Labelled>,
) -> ReportPage {
    let title = format!("{} vs {}", test.label, reference.label);
    let hdr = test.scene_referred || reference.scene_referred;
    let exposure_ev = if hdr {
        reference_exposure_ev.unwrap_or(0.0)
    } else {
        0.0
    };
    let mut sections = vec![
        Section::Paragraph(format!(
            "A = {} (under test), B = {} (reference). Drag the split, press F or the button \
             to flip between A and B; zoom is nearest-neighbour.{}",
            test.label,
            reference.label,
            if hdr {
                " Scene-referred images start at the exposure that maps the reference's \
                 log-average luminance to 0.18."
            } else {
                ""
            }
        )),
        Section::Table {
            caption: "Metrics of A against B (prism compare)".into(),
            header: vec!["metric".into(), "value".into()],
            rows: metric_rows(comparison),
        },
        Section::Heading("A and B".into()),
        Section::Pair {
            a: Labelled {
                label: test.label,
                image: test.image,
            },
            b: Labelled {
                label: reference.label,
                image: reference.image,
            },
            exposure_ev,
        },
    ];
    if !figures.is_empty() {
        sections.push(Section::Heading("Error maps".into()));
        sections.push(Section::Figures(figures));
    }
    ReportPage { title, sections }
}
