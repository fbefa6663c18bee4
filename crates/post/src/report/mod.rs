//! Self-contained HTML reports (`prism compare A B --report OUT.html`,
//! `prism converge … --report OUT.html`): one file, images embedded ([`embed`]), no
//! network. A page is a list of [`Section`]s; image pairs get a viewer (report/viewer.js)
//! that flips between A and B (button or the F key), splits them with a slider, zooms
//! (fit, 1:1 … 8:1, nearest-neighbour) and, for scene-referred images, sets the exposure.
//! When every image has been decoded and drawn the script sets `data-ready="true"` and
//! `data-decoded-images` on `<body>`, which tools/report_browser_check.py reads from the
//! headless browser's DOM.

pub mod compare_page;
pub mod embed;

use std::fmt::Write;

pub use embed::{ImageData, ReportImage};

const VIEWER_JS: &str = include_str!("viewer.js");
const VIEWER_CSS: &str = include_str!("viewer.css");

/// One side of an image pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Labelled {
    pub label: String,
    pub image: ReportImage,
}

/// A block of the page, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Section {
    Heading(String),
    Paragraph(String),
    /// A table: header cells, then rows (all text, escaped).
    Table {
        caption: String,
        header: Vec<String>,
        rows: Vec<Vec<String>>,
    },
    /// Two images of one size in the viewer; `exposure_ev` is the viewer's starting
    /// exposure for scene-referred images (ignored when both are display-referred).
    Pair {
        a: Labelled,
        b: Labelled,
        exposure_ev: f64,
    },
    /// Display-referred figures side by side (false-colour maps with their legends).
    Figures(Vec<Labelled>),
    /// An SVG drawing inlined as it is (a chart Prism drew; not user text).
    Svg {
        caption: String,
        svg: String,
    },
}

/// A whole page.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportPage {
    pub title: String,
    pub sections: Vec<Section>,
}

/// Text for HTML element content and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            other => out.push(other),
        }
    }
    out
}

/// The `<img>` elements the viewer decodes for one image (hidden sources).
fn source_images(out: &mut impl Write, role: &str, image: &ReportImage) {
    match &image.data {
        ImageData::Display { png } => {
            let _ = write!(
                out,
                "<div class=\"source\" data-role=\"{role}\" data-kind=\"display\" \
                 data-width=\"{}\" data-height=\"{}\"><img alt=\"\" src=\"{}\"></div>",
                image.width,
                image.height,
                embed::png_data_uri(png)
            );
        }
        ImageData::Radiance {
            mantissa_png,
            exponent_png,
        } => {
            let _ = write!(
                out,
                "<div class=\"source\" data-role=\"{role}\" data-kind=\"radiance\" \
                 data-width=\"{}\" data-height=\"{}\"><img alt=\"\" src=\"{}\"><img alt=\"\" \
                 src=\"{}\"></div>",
                image.width,
                image.height,
                embed::png_data_uri(mantissa_png),
                embed::png_data_uri(exponent_png)
            );
        }
    }
}

fn is_radiance(image: &ReportImage) -> bool {
    match image.data {
        ImageData::Radiance { .. } => true,
        ImageData::Display { .. } => false,
    }
}

impl ReportPage {
    /// The whole page as one HTML5 document.
    pub fn to_html(&self) -> String {
        let mut out = String::new();
        self.write_html(&mut out);
        out
    }

    /// [`Self::to_html`] into `out` a piece at a time (an image's data URI is the largest
    /// piece), so that a large page never exists whole in memory.
    pub fn write_html(&self, out: &mut impl Write) {
        let _ = write!(
            out,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"generator\" content=\"prism {}\">\n<title>{}</title>\n\
             <style>\n{VIEWER_CSS}</style>\n</head>\n<body data-ready=\"false\">\n\
             <header><h1>{}</h1></header>\n<main>\n",
            env!("CARGO_PKG_VERSION"),
            escape(&self.title),
            escape(&self.title)
        );
        for (index, section) in self.sections.iter().enumerate() {
            section_html(out, index, section);
        }
        let _ = write!(
            out,
            "</main>\n<script>\n{VIEWER_JS}</script>\n</body>\n</html>\n"
        );
    }
}

/// `fmt::Write` into an `io::Write`, keeping the first I/O error.
struct IoText<'a, W: std::io::Write> {
    out: &'a mut W,
    error: Option<std::io::Error>,
}

impl<W: std::io::Write> Write for IoText<'_, W> {
    fn write_str(&mut self, text: &str) -> std::fmt::Result {
        if self.error.is_none() {
            if let Err(e) = self.out.write_all(text.as_bytes()) {
                self.error = Some(e);
            }
        }
        Ok(())
    }
}

fn section_html(out: &mut impl Write, index: usize, section: &Section) {
    match section {
        Section::Heading(text) => {
            let _ = writeln!(out, "<h2>{}</h2>", escape(text));
        }
        Section::Paragraph(text) => {
            let _ = writeln!(out, "<p>{}</p>", escape(text));
        }
        Section::Table {
            caption,
            header,
            rows,
        } => {
            let _ = write!(
                out,
                "<table class=\"metrics\">\n<caption>{}</caption>\n<thead><tr>",
                escape(caption)
            );
            for cell in header {
                let _ = write!(out, "<th>{}</th>", escape(cell));
            }
            let _ = out.write_str("</tr></thead>\n<tbody>\n");
            for row in rows {
                let _ = out.write_str("<tr>");
                for cell in row {
                    let _ = write!(out, "<td>{}</td>", escape(cell));
                }
                let _ = out.write_str("</tr>\n");
            }
            let _ = out.write_str("</tbody>\n</table>\n");
        }
        Section::Pair { a, b, exposure_ev } => {
            let hdr = is_radiance(&a.image) || is_radiance(&b.image);
            let _ = write!(
                out,
                "<section class=\"viewer\" id=\"viewer-{index}\" data-exposure-ev=\"{exposure_ev}\">\n\
                 <div class=\"controls\">\
                 <button type=\"button\" class=\"toggle\" title=\"F\">show B</button>\
                 <label>split <input type=\"range\" class=\"split\" min=\"0\" max=\"100\" value=\"50\"></label>\
                 <label>zoom <select class=\"zoom\"><option value=\"fit\">fit</option>\
                 <option value=\"1\" selected>1:1</option><option value=\"2\">2:1</option>\
                 <option value=\"4\">4:1</option><option value=\"8\">8:1</option></select></label>",
            );
            if hdr {
                let _ = write!(
                    out,
                    "<label>exposure <input type=\"range\" class=\"exposure\" min=\"{}\" \
                     max=\"{}\" step=\"0.1\" value=\"{exposure_ev:.1}\"> <output \
                     class=\"ev\">{exposure_ev:+.1} EV</output></label>",
                    (exposure_ev - 12.0).floor(),
                    (exposure_ev + 12.0).ceil()
                );
            }
            let _ = write!(
                out,
                "<span class=\"state\"></span></div>\n<div class=\"names\"><span class=\"name-a\">A \
                 (left): {}</span> <span class=\"name-b\">B (right): {}</span></div>\n\
                 <div class=\"stage\"><div class=\"layers\"><canvas class=\"layer-b\"></canvas>\
                 <canvas class=\"layer-a\"></canvas><div class=\"divider\"></div></div></div>\n",
                escape(&a.label),
                escape(&b.label)
            );
            source_images(out, "a", &a.image);
            source_images(out, "b", &b.image);
            let _ = out.write_str("\n</section>\n");
        }
        Section::Figures(figures) => {
            let _ = out.write_str("<div class=\"figures\">\n");
            for figure in figures {
                match &figure.image.data {
                    ImageData::Display { png } => {
                        let _ = writeln!(
                            out,
                            "<figure><img class=\"map\" alt=\"{}\" width=\"{}\" height=\"{}\" \
                             src=\"{}\"><figcaption>{}</figcaption></figure>",
                            escape(&figure.label),
                            figure.image.width,
                            figure.image.height,
                            embed::png_data_uri(png),
                            escape(&figure.label)
                        );
                    }
                    // A figure is display-referred by construction; a scene-referred one
                    // gets its own viewer with B = A.
                    ImageData::Radiance { .. } => section_html(
                        out,
                        index,
                        &Section::Pair {
                            a: figure.clone(),
                            b: figure.clone(),
                            exposure_ev: 0.0,
                        },
                    ),
                }
            }
            let _ = out.write_str("</div>\n");
        }
        Section::Svg { caption, svg } => {
            // The XML declaration is not allowed inside HTML.
            let body = svg.find("<svg").map_or(svg.as_str(), |i| &svg[i..]);
            let body = with_view_box(body);
            let _ = writeln!(
                out,
                "<figure class=\"chart\">{body}<figcaption>{}</figcaption></figure>",
                escape(caption)
            );
        }
    }
}

/// An `<svg width="W" height="H" …>` without a `viewBox` gets `viewBox="0 0 W H"`, so
/// that the page can scale it to its width (CSS `max-width`) instead of cropping it.
fn with_view_box(svg: &str) -> String {
    let Some(end) = svg.find('>') else {
        return svg.to_string();
    };
    let open = &svg[..end];
    if open.contains("viewBox") {
        return svg.to_string();
    }
    let attribute = |name: &str| -> Option<f64> {
        let at = open.find(&format!(" {name}=\""))? + name.len() + 3;
        let len = open[at..].find('"')?;
        open[at..at + len].trim_end_matches("px").parse().ok()
    };
    match (attribute("width"), attribute("height")) {
        (Some(w), Some(h)) => format!("{open} viewBox=\"0 0 {w} {h}\"{}", &svg[end..]),
        _ => svg.to_string(),
    }
}

/// Writes `page` to `path` atomically (temporary sibling, then rename).
pub fn write_report(path: &std::path::Path, page: &ReportPage) -> prism_image::Result<()> {
    prism_image::io::write_stream_atomically(path, |out| {
        let mut text = IoText { out, error: None };
        page.write_html(&mut text);
        text.error.map_or(Ok(()), Err)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_svg_gets_a_view_box() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>"),
            "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;"
        );
        assert_eq!(
            with_view_box("<svg width=\"1600\" height=\"700\" xmlns=\"x\"><g/></svg>"),
            "<svg width=\"1600\" height=\"700\" xmlns=\"x\" viewBox=\"0 0 1600 700\"><g/></svg>"
        );
        let kept = "<svg viewBox=\"0 0 1 1\"></svg>";
        assert_eq!(with_view_box(kept), kept);
    }
}
