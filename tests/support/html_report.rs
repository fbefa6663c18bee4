//! Checks the structure of Prism's HTML reports without a browser (the browser check is
//! tools/report_browser_check.py): a well-formed HTML5 document (every non-void element
//! closed in order), nothing loaded from elsewhere (every `src`/`href` a `data:` URI), each
//! embedded PNG decodable at the size its viewer source declares, and the tables' text.

use base64::Engine;

/// What a report holds, as far as the checks read it.
#[derive(Debug, Default)]
pub struct ReportSummary {
    /// Every embedded PNG's (width, height), in document order.
    pub images: Vec<(u32, u32)>,
    /// Viewers (`<section class="viewer">`).
    pub viewers: usize,
    /// Exposure controls (viewers of scene-referred images).
    pub exposure_controls: usize,
    /// Every table's cells, row by row (header row included).
    pub tables: Vec<Vec<Vec<String>>>,
    pub inline_svgs: usize,
}

const VOID: [&str; 8] = ["meta", "img", "input", "br", "hr", "link", "source", "wbr"];

fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    let len = tag[at..].find('"')?;
    Some(&tag[at..at + len])
}

fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

fn png_size(uri: &str) -> (u32, u32) {
    let data = uri
        .strip_prefix("data:image/png;base64,")
        .unwrap_or_else(|| panic!("not an embedded PNG: {}…", &uri[..uri.len().min(40)]));
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(data)
        .expect("valid base64");
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .expect("a PNG header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("PNG data decodes");
    (info.width, info.height)
}

/// Parses `html` and panics with the reason on the first structural fault.
pub fn check_report(html: &str) -> ReportSummary {
    assert!(html.starts_with("<!DOCTYPE html>"), "no doctype");
    let mut summary = ReportSummary::default();
    let mut stack: Vec<String> = Vec::new();
    let mut rest = html["<!DOCTYPE html>".len()..].trim_start();
    let mut text = String::new();
    let mut row: Vec<String> = Vec::new();
    // The size a viewer source declares, and the depth of its element, while inside it.
    let mut source: Option<((u32, u32), usize)> = None;
    let mut in_svg = 0usize;
    while let Some(open) = rest.find('<') {
        text.push_str(&rest[..open]);
        rest = &rest[open..];
        let close = rest.find('>').expect("unterminated tag");
        let tag = &rest[..=close];
        rest = &rest[close + 1..];
        let name: String = tag
            .trim_start_matches("</")
            .trim_start_matches('<')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect::<String>()
            .to_ascii_lowercase();
        if tag.starts_with("</") {
            let top = stack
                .pop()
                .unwrap_or_else(|| panic!("{tag} closes nothing"));
            assert_eq!(top, name, "{tag} closes <{top}>");
            match name.as_str() {
                "td" | "th" => row.push(unescape(text.trim())),
                "tr" => {
                    let table = summary.tables.last_mut().expect("a row outside a table");
                    table.push(std::mem::take(&mut row));
                }
                "svg" => in_svg -= 1,
                "div" if source.is_some_and(|(_, depth)| depth == stack.len()) => source = None,
                _ => {}
            }
            text.clear();
            continue;
        }
        // Raw text elements: skip to their end tag.
        if name == "script" || name == "style" {
            let end = rest
                .find(&format!("</{name}>"))
                .unwrap_or_else(|| panic!("<{name}> not closed"));
            rest = &rest[end + name.len() + 3..];
            continue;
        }
        for key in ["src", "href"] {
            if let Some(url) = attribute(tag, key) {
                assert!(
                    url.starts_with("data:") || url.starts_with('#'),
                    "external {key}: {url}"
                );
            }
        }
        match name.as_str() {
            "table" => summary.tables.push(Vec::new()),
            "td" | "th" => text.clear(),
            "section" if attribute(tag, "class") == Some("viewer") => summary.viewers += 1,
            "input" if attribute(tag, "class") == Some("exposure") => {
                summary.exposure_controls += 1
            }
            "div" if attribute(tag, "class") == Some("source") => {
                let dim = |k| {
                    attribute(tag, k)
                        .expect("source size")
                        .parse()
                        .expect("a number")
                };
                source = Some(((dim("data-width"), dim("data-height")), stack.len()));
            }
            "img" => {
                let size = png_size(attribute(tag, "src").expect("img src"));
                if let Some((declared, _)) = source {
                    assert_eq!(size, declared, "embedded image size");
                }
                summary.images.push(size);
            }
            "svg" if in_svg == 0 => summary.inline_svgs += 1,
            _ => {}
        }
        if name == "svg" {
            in_svg += 1;
        }
        let self_closing = tag.ends_with("/>");
        if !VOID.contains(&name.as_str()) && !self_closing {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed elements: {stack:?}");
    summary
}
