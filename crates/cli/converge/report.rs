//! `prism converge --report OUT.html`: the convergence study as one self-contained page
//! (prism_post::report): the chart, a table of each method's last checkpoint, and per
//! method its last image against the reference in the viewer, with its FLIP and ΔE2000
//! maps.

use prism_image::Image;
use prism_post::metrics::flip::DEFAULT_PPD;
use prism_post::metrics::{CompareOptions, PreparedReference};
use prism_post::report::compare_page::map_figures;
use prism_post::report::{Labelled, ReportImage, ReportPage, Section};

/// What the report keeps of one method (its image embedded, maps drawn).
pub struct MethodEntry {
    pub label: String,
    pub spp: u32,
    pub time_s: f64,
    pub row: Vec<String>,
    pub image: ReportImage,
    pub maps: Vec<Labelled>,
}

/// Columns of the methods table (filled by [`MethodEntry::new`]).
pub const COLUMNS: [&str; 10] = [
    "method",
    "spp",
    "time (s)",
    "RMSE",
    "relMSE",
    "ΔE2000 mean",
    "LDR-FLIP mean",
    "HDR-FLIP mean",
    "relMSE slope",
    "time to relMSE target (s)",
];

fn sci(v: f64) -> String {
    format!("{v:.4e}")
}

impl MethodEntry {
    /// Compares the method's last image with the reference (FLIP and the ΔE2000 map
    /// included: outside the method's clock, after its run) and embeds it.
    pub fn new(
        label: &str,
        spp: u32,
        time_s: f64,
        relmse_slope: Option<f64>,
        time_to_target_s: Option<f64>,
        image: &Image,
        reference: &PreparedReference,
    ) -> Result<Self, String> {
        let options = CompareOptions {
            ssim: false,
            flip_ppd: Some(DEFAULT_PPD),
            delta_e2000_map: true,
        };
        let (c, maps) = reference
            .compare_with_maps(image, &options)
            .map_err(|e| format!("--report: {label}: {e}"))?;
        let flip = c.flip.as_ref();
        let row = vec![
            label.to_string(),
            spp.to_string(),
            format!("{time_s:.3}"),
            sci(c.rmse),
            sci(c.relmse),
            format!("{:.4}", c.delta_e2000_mean),
            flip.map_or("n/a".into(), |f| format!("{:.4}", f.ldr_flip_mean)),
            flip.map_or("n/a".into(), |f| format!("{:.4}", f.hdr_flip_mean)),
            relmse_slope.map_or("n/a".into(), |s| format!("{s:.3}")),
            time_to_target_s.map_or("not reached".into(), |t| format!("{t:.3}")),
        ];
        let maps = map_figures(&maps, c.width, c.height, true).map_err(|e| e.to_string())?;
        Ok(Self {
            label: label.to_string(),
            spp,
            time_s,
            row,
            image: ReportImage::radiance(image).map_err(|e| e.to_string())?,
            maps,
        })
    }
}

/// The page: `chart_svg` is the chart `-o CHART.svg` would write.
pub fn converge_page(
    title: &str,
    intro: String,
    chart_svg: String,
    reference: &Image,
    exposure_ev: f64,
    methods: Vec<MethodEntry>,
) -> Result<ReportPage, String> {
    let reference_image = ReportImage::radiance(reference).map_err(|e| e.to_string())?;
    let mut sections = vec![
        Section::Paragraph(intro),
        Section::Svg {
            caption: "Error against the reference over time (log–log), with fitted slopes".into(),
            svg: chart_svg,
        },
        Section::Table {
            caption: "Each method's last checkpoint against the reference".into(),
            header: COLUMNS.iter().map(|c| c.to_string()).collect(),
            rows: methods.iter().map(|m| m.row.clone()).collect(),
        },
    ];
    for method in methods {
        sections.push(Section::Heading(format!(
            "{}: {} spp in {:.3} s",
            method.label, method.spp, method.time_s
        )));
        sections.push(Section::Pair {
            a: Labelled {
                label: format!("{} (last checkpoint)", method.label),
                image: method.image,
            },
            b: Labelled {
                label: "reference".into(),
                image: reference_image.clone(),
            },
            exposure_ev,
        });
        sections.push(Section::Figures(method.maps));
    }
    Ok(ReportPage {
        title: title.to_string(),
        sections,
    })
}
