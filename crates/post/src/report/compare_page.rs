//! The page of `prism compare A B --report OUT.html`: the metric table, A and B in the
//! viewer (B the reference), and the FLIP and ΔE2000 maps in false colour with legends.

use prism_image::Image;
use prism_image::Result;

use super::{Labelled, ReportImage, ReportPage, Section};
use crate::auto_exposure::auto_exposure_ev;
use crate::falsecolour::{false_colour, FalseColourOptions, FalseColourScale, Palette};
use crate::metrics::{Comparison, ErrorMaps};

/// ΔE2000 the map's colour ramp spans; larger differences take the top colour. Fixed, so
/// that maps of different reports read alike (a just-noticeable difference is ≈ 1–2).
pub const DELTA_E_MAP_MAX: f64 = 10.0;

/// One input of the comparison as the report shows it.
pub struct CompareInput<'a> {
    /// The file name (or any label) shown above the viewer.
    pub label: String,
    pub image: &'a Image,
    /// Scene-referred (EXR, HDR: exposure control) or display-referred (PNG).
    pub scene_referred: bool,
}

fn embed(input: &CompareInput) -> Result<ReportImage> {
    if input.scene_referred {
        ReportImage::radiance(input.image)
    } else {
        ReportImage::display(input.image)
    }
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
                image: ReportImage::display(&flip.hdr.to_image("HDR-FLIP")?)?,
            });
        }
        figures.push(Labelled {
            label: "LDR-FLIP (0 … 1, magma)".into(),
            image: ReportImage::display(&flip.ldr.to_image("LDR-FLIP")?)?,
        });
    }
    if let Some(de) = &maps.delta_e2000 {
        let image = false_colour(
            de,
            width,
            height,
            &FalseColourOptions {
                scale: FalseColourScale::Linear,
                range: Some((0.0, DELTA_E_MAP_MAX)),
                unit: "dE2000".into(),
                cell_px: 1,
                palette: Palette::Lighting,
            },
        )?;
        figures.push(Labelled {
            label: format!("ΔE2000 (0 … {DELTA_E_MAP_MAX}, larger clipped)"),
            image: ReportImage::display(&image)?,
        });
    }
    Ok(figures)
}

/// The whole compare page: `test` is A, `reference` is B.
pub fn compare_page(
    test: &CompareInput,
    reference: &CompareInput,
    comparison: &Comparison,
    maps: &ErrorMaps,
) -> Result<ReportPage> {
    let hdr = test.scene_referred || reference.scene_referred;
    // The viewer starts where `--exposure auto` would put the reference.
    let exposure_ev = if hdr {
        auto_exposure_ev(reference.image).unwrap_or(0.0)
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
                label: test.label.clone(),
                image: embed(test)?,
            },
            b: Labelled {
                label: reference.label.clone(),
                image: embed(reference)?,
            },
            exposure_ev,
        },
    ];
    let figures = map_figures(maps, comparison.width, comparison.height, hdr)?;
    if !figures.is_empty() {
        sections.push(Section::Heading("Error maps".into()));
        sections.push(Section::Figures(figures));
    }
    Ok(ReportPage {
        title: format!("{} vs {}", test.label, reference.label),
        sections,
    })
}
