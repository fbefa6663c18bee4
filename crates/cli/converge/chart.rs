//! The error-against-time chart of `prism converge` (plotters): three log–log panels (RMSE,
//! relMSE, mean ΔE2000 against wall or CPU time), one curve per method with its checkpoints as
//! dots, the fitted power law dashed, and the fitted slope in the legend. A grey line shows
//! the Monte Carlo rate (RMSE ∝ t^−½, relMSE ∝ t^−1) through the first method's first point.
//!
//! Text is drawn with an embedded subset of DejaVu Sans (assets/fonts, Bitstream Vera
//! licence) through plotters' `ab_glyph` feature, so charts render the same on a machine
//! without any system font. PNG: the bitmap backend's RGB buffer encoded with `png`; SVG:
//! plotters' SVG backend (text as `<text>` elements in the `sans-serif` family).

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::fit::PowerFit;

static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");
const FAMILY: &str = "sans-serif";

/// Chart size in pixels (three panels side by side).
pub const CHART_SIZE_PX: (u32, u32) = (1800, 560);

/// The panels: (title, axis label, Monte Carlo slope if there is one).
pub const PANELS: [(&str, &str, Option<f64>); 3] = [
    ("RMSE", "RMSE (linear Rec.709)", Some(-0.5)),
    ("relMSE", "relMSE", Some(-1.0)),
    ("mean ΔE2000", "mean ΔE2000", None),
];

/// One method's curve: label, checkpoints as (time s, [rmse, relmse, ΔE]), and the fits
/// of the three panels.
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, [f64; 3])>,
    pub fits: [Option<PowerFit>; 3],
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
                .map_err(|_| "the chart's embedded font cannot be read".to_string())
        })
        .clone()
}

/// A slope as the legend shows it (and as tests read it back): two decimals, U+2212 minus.
pub fn format_slope(slope: f64) -> String {
    format!("{slope:.2}").replace('-', "−")
}

/// The legend entry of a curve in panel `panel`.
pub fn legend_label(curve: &Curve, panel: usize) -> String {
    match &curve.fits[panel] {
        Some(f) => format!("{}  slope {}", curve.label, format_slope(f.slope)),
        None => format!("{}  (too few points to fit)", curve.label),
    }
}

fn tick(v: f64) -> String {
    if (0.01..10_000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}").replace('-', "−")
    }
}

/// (min, max) of the positive finite values, widened by a factor on each side.
fn log_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    let (lo, hi) = if hi / lo < 1.5 {
        (lo / 1.5, hi * 1.5)
    } else {
        (lo, hi)
    };
    (lo / pad, hi * pad)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    x_axis: &str,
    curves: &[Curve],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("cannot draw the chart: {e}");
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(title, (FAMILY, 22).into_font().color(&BLACK))
        .map_err(err)?;
    let panels = root.split_evenly((1, PANELS.len()));
    let (t0, t1) = log_range(
        curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)),
        1.3,
    );
    for (m, area) in panels.iter().enumerate() {
        let (name, axis, mc_slope) = PANELS[m];
        let (y0, y1) = log_range(
            curves
                .iter()
                .flat_map(|c| c.points.iter().map(move |p| p.1[m])),
            1.5,
        );
        let mut chart = ChartBuilder::on(area)
            .caption(name, (FAMILY, 20))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d((t0..t1).log_scale(), (y0..y1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_axis)
            .y_desc(axis)
            .label_style((FAMILY, 14))
            .axis_desc_style((FAMILY, 15))
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(err)?;
        if let (Some(slope), Some(first)) =
            (mc_slope, curves.first().and_then(|c| c.points.first()))
        {
            let (ta, ya) = (first.0, first.1[m]);
            if ta > 0.0 && ya > 0.0 {
                let line = [ta, t1].map(|t| (t, ya * (t / ta).powf(slope)));
                let grey = RGBColor(150, 150, 150);
                chart
                    .draw_series(DashedLineSeries::new(line, 3, 5, grey.stroke_width(1)))
                    .map_err(err)?
                    .label(format!("Monte Carlo rate, slope {}", format_slope(slope)))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1))
                    });
            }
        }
        for (c, curve) in curves.iter().enumerate() {
            let color = PALETTE[c % PALETTE.len()];
            let pts: Vec<(f64, f64)> = curve
                .points
                .iter()
                .map(|p| (p.0, p.1[m]))
                .filter(|&(t, y)| t > 0.0 && y > 0.0 && y.is_finite())
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(err)?
                .label(legend_label(curve, m))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(err)?;
            if let (Some(fit), Some(a), Some(b)) = (&curve.fits[m], pts.first(), pts.last()) {
                let line = [a.0, b.0].map(|t| (t, fit.at(t)));
                chart
                    .draw_series(DashedLineSeries::new(
                        line,
                        8,
                        5,
                        color.mix(0.7).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font((FAMILY, 14))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// The chart as SVG text (what `-o CHART.svg` writes; the HTML report inlines it).
pub fn chart_svg(title: &str, x_axis: &str, curves: &[Curve]) -> Result<String, String> {
    register_font()?;
    let (w, h) = CHART_SIZE_PX;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
        draw(&root, title, x_axis, curves)?;
    }
    Ok(text)
}

/// Draws the chart to `path` (.png or .svg) atomically.
pub fn write_chart(path: &Path, title: &str, x_axis: &str, curves: &[Curve]) -> Result<(), String> {
    register_font()?;
    let (w, h) = CHART_SIZE_PX;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match ext.as_deref() {
        Some("svg") => chart_svg(title, x_axis, curves)?.into_bytes(),
        Some("png") => {
            let mut rgb = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
                draw(&root, title, x_axis, curves)?;
            }
            let mut out = Vec::new();
            let mut encoder = png::Encoder::new(&mut out, w, h);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_compression(png::Compression::Best);
            let mut writer = encoder
                .write_header()
                .map_err(|e| format!("{}: cannot encode the PNG: {e}", path.display()))?;
            writer
                .write_image_data(&rgb)
                .map_err(|e| format!("{}: cannot encode the PNG: {e}", path.display()))?;
            writer
                .finish()
                .map_err(|e| format!("{}: cannot encode the PNG: {e}", path.display()))?;
            out
        }
        _ => {
            return Err(format!(
                "chart {}: expected a .png or .svg file name",
                path.display()
            ))
        }
    };
    crate::atomic_write::write_atomic(path, &bytes, "chart")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curves() -> Vec<Curve> {
        let pts: Vec<(f64, [f64; 3])> = (0..6)
            .map(|k| {
                let t = 0.05 * 2f64.powi(k);
                (t, [0.1 * t.powf(-0.5), 0.02 / t, 3.0 * t.powf(-0.4)])
            })
            .collect();
        let fit = |m: usize| PowerFit::new(pts.iter().map(|p| (p.0, p.1[m])));
        vec![Curve {
            label: "path".into(),
            fits: [fit(0), fit(1), fit(2)],
            points: pts.clone(),
        }]
    }

    #[test]
    fn svg_and_png_charts_carry_the_fitted_slopes() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("c.svg");
        write_chart(&svg, "test", "wall time (s)", &curves()).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.contains("path  slope −0.50"),
            "legend of the RMSE panel"
        );
        assert!(text.contains("path  slope −1.00"));
        assert!(text.contains("path  slope −0.40"));
        assert!(text.contains("Monte Carlo rate, slope −0.50"));
        let png = dir.path().join("c.png");
        write_chart(&png, "test", "wall time (s)", &curves()).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // Text was rasterised: the title row holds dark pixels (no system font needed).
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), CHART_SIZE_PX);
        let dark = buf[..info.width as usize * 3 * 30]
            .chunks(3)
            .filter(|p| p.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 20, "{dark} dark pixels in the title band");
    }

    #[test]
    fn other_extensions_are_refused_before_drawing() {
        let e = write_chart(Path::new("chart.jpg"), "t", "x", &curves()).unwrap_err();
        assert!(e.contains(".png or .svg"), "{e}");
    }
}
