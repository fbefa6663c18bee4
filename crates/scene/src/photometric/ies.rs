//! IES LM-63 files (ANSI/IES LM-63-19 and its 1986, 1991, 1995 and 2002 predecessors).
//!
//! Layout: an optional format line (`IESNA91`, `IESNA:LM-63-1995`, `IESNA:LM-63-2002`,
//! `IES:LM-63-2019`; none for 1986), keyword lines (`[TEST] …`), `TILT=NONE`,
//! `TILT=INCLUDE` (followed by the tilt block) or `TILT=<file>`, then numbers separated by
//! blanks, commas or line breaks: lamps, lumens per lamp (−1: absolute photometry),
//! candela multiplier, number of vertical and horizontal angles, photometric type
//! (1 C, 2 B, 3 A), units (1 feet, 2 metres), width, length, height; ballast factor, a
//! field that is the ballast-lamp factor before 2019 and the file-generation type in 2019,
//! input watts; the vertical angles, the horizontal angles, and the candela values, one
//! horizontal angle after another.

use std::path::Path;

use super::{
    expand_type_c, first_non_increasing, IntensityDistribution, PhotometricError,
    PhotometricFormat, PhotometryType, Tilt,
};

const FEET_TO_M: f64 = 0.3048;

/// Numbers after the TILT line with the line each came from.
struct Numbers<'a> {
    tokens: Vec<(usize, &'a str)>,
    next: usize,
    file: &'a Path,
    /// Last line of the file (for "ends early" messages).
    last_line: usize,
}

impl<'a> Numbers<'a> {
    fn new(lines: &[(usize, &'a str)], file: &'a Path) -> Self {
        let tokens = lines
            .iter()
            .flat_map(|&(n, l)| {
                l.split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                    .map(move |t| (n, t))
            })
            .collect();
        Self {
            tokens,
            next: 0,
            file,
            last_line: lines.last().map_or(1, |l| l.0),
        }
    }

    fn err(&self, line: Option<usize>, message: impl Into<String>) -> PhotometricError {
        PhotometricError {
            file: self.file.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    fn line(&self) -> usize {
        self.tokens
            .get(self.next.saturating_sub(1))
            .map_or(self.last_line, |t| t.0)
    }

    fn f64(&mut self, what: &str) -> Result<f64, PhotometricError> {
        let Some(&(line, tok)) = self.tokens.get(self.next) else {
            return Err(self.err(
                Some(self.last_line),
                format!("the file ends early: expected {what}"),
            ));
        };
        self.next += 1;
        match tok.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.err(
                Some(line),
                format!("expected {what} (a number), found `{tok}`"),
            )),
        }
    }

    fn count(&mut self, what: &str, min: usize) -> Result<usize, PhotometricError> {
        let x = self.f64(what)?;
        if x.fract() != 0.0 || x < min as f64 || x > 100_000.0 {
            return Err(self.err(
                Some(self.line()),
                format!("expected {what} (a whole number ≥ {min}), found {x}"),
            ));
        }
        Ok(x as usize)
    }

    fn list(&mut self, n: usize, what: &str) -> Result<(Vec<f64>, usize), PhotometricError> {
        let first_line = self.tokens.get(self.next).map_or(self.last_line, |t| t.0);
        let mut v = Vec::with_capacity(n);
        for i in 0..n {
            v.push(self.f64(&format!("{what} {} of {n}", i + 1))?);
        }
        Ok((v, first_line))
    }
}

/// The tilt block (after `TILT=INCLUDE`, or a whole tilt file).
fn parse_tilt(nums: &mut Numbers) -> Result<Tilt, PhotometricError> {
    let geometry = nums.count("the lamp-to-luminaire geometry (1, 2 or 3)", 1)?;
    if !(1..=3).contains(&geometry) {
        return Err(nums.err(
            Some(nums.line()),
            format!("expected the lamp-to-luminaire geometry 1, 2 or 3, found {geometry}"),
        ));
    }
    let n = nums.count("the number of tilt angle/factor pairs", 1)?;
    let (angles_deg, line) = nums.list(n, "tilt angle")?;
    if let Some(i) = first_non_increasing(&angles_deg) {
        return Err(nums.err(
            Some(line),
            format!(
                "tilt angles must increase, but angle {} ({}°) follows {}°",
                i + 1,
                angles_deg[i],
                angles_deg[i - 1]
            ),
        ));
    }
    let (factors, line) = nums.list(n, "tilt multiplying factor")?;
    if let Some(f) = factors.iter().find(|f| **f < 0.0) {
        return Err(nums.err(Some(line), format!("tilt factors must be ≥ 0, found {f}")));
    }
    Ok(Tilt {
        lamp_to_luminaire_geometry: geometry as u32,
        angles_deg,
        factors,
    })
}

pub fn parse_ies(text: &str, file: &Path) -> Result<IntensityDistribution, PhotometricError> {
    let err = |line: Option<usize>, m: String| PhotometricError {
        file: file.to_path_buf(),
        line,
        message: m,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .collect();
    if lines.iter().all(|l| l.1.trim().is_empty()) {
        return Err(err(None, "the file is empty".into()));
    }
    let first = lines[0].1.trim();
    let upper = first.to_ascii_uppercase();
    let (format, mut at) = if upper.starts_with("IESNA:LM-63-2002") {
        (PhotometricFormat::Ies2002, 1)
    } else if upper.starts_with("IESNA:LM-63-1995") {
        (PhotometricFormat::Ies1995, 1)
    } else if upper.starts_with("IES:LM-63-2019") {
        (PhotometricFormat::Ies2019, 1)
    } else if upper.starts_with("IESNA91") {
        (PhotometricFormat::Ies1991, 1)
    } else if upper.starts_with("IES") && upper.contains("LM-63") {
        return Err(err(
            Some(1),
            format!(
                "unknown LM-63 revision `{first}`: expected IESNA91, IESNA:LM-63-1995, \
                 IESNA:LM-63-2002 or IES:LM-63-2019"
            ),
        ));
    } else {
        (PhotometricFormat::Ies1986, 0)
    };
    // Keyword lines up to TILT=.
    let mut keywords: Vec<(String, String)> = Vec::new();
    let tilt_line = loop {
        let Some(&(n, l)) = lines.get(at) else {
            return Err(err(
                None,
                "no `TILT=` line: expected TILT=NONE, TILT=INCLUDE or TILT=<file> after the \
                 keywords"
                    .into(),
            ));
        };
        at += 1;
        let t = l.trim();
        if t.to_ascii_uppercase().starts_with("TILT") {
            break (n, t);
        }
        if let Some(rest) = t.strip_prefix('[') {
            if let Some((k, v)) = rest.split_once(']') {
                keywords.push((k.trim().to_string(), v.trim().to_string()));
                continue;
            }
            return Err(err(
                Some(n),
                format!("keyword line `{t}` has no closing `]`"),
            ));
        }
        // 1986 files: free text lines before TILT; later revisions require keywords.
        if format == PhotometricFormat::Ies1986 || t.is_empty() {
            continue;
        }
        return Err(err(
            Some(n),
            format!("expected a `[KEYWORD] value` line or `TILT=…`, found `{t}`"),
        ));
    };
    if format == PhotometricFormat::Ies2019 {
        // LM-63-19 §5.2: these keywords are required.
        for required in ["TEST", "TESTLAB", "ISSUEDATE", "MANUFAC"] {
            if !keywords
                .iter()
                .any(|(k, _)| k.eq_ignore_ascii_case(required))
            {
                return Err(err(
                    Some(tilt_line.0),
                    format!("an LM-63-2019 file needs the keyword [{required}] before TILT="),
                ));
            }
        }
    }
    let (tilt_n, tilt_text) = tilt_line;
    let tilt_value = tilt_text
        .split_once('=')
        .map(|(_, v)| v.trim())
        .ok_or_else(|| {
            err(
                Some(tilt_n),
                format!("expected `TILT=…`, found `{tilt_text}`"),
            )
        })?;
    let rest = &lines[at..];
    let mut nums = Numbers::new(rest, file);
    let tilt = match tilt_value.to_ascii_uppercase().as_str() {
        "NONE" => None,
        "INCLUDE" => Some(parse_tilt(&mut nums)?),
        "" => {
            return Err(err(
                Some(tilt_n),
                "expected TILT=NONE, TILT=INCLUDE or TILT=<file>".into(),
            ))
        }
        _ => {
            let tilt_path = file.parent().unwrap_or(Path::new("")).join(tilt_value);
            let tilt_text = prism_cpu::text_file::read_text(&tilt_path).map_err(|e| {
                err(
                    Some(tilt_n),
                    format!("cannot read the tilt file {}: {e}", tilt_path.display()),
                )
            })?;
            let tl: Vec<(usize, &str)> = tilt_text
                .lines()
                .enumerate()
                .map(|(i, l)| (i + 1, l))
                .collect();
            let mut tn = Numbers::new(&tl, &tilt_path);
            Some(parse_tilt(&mut tn)?)
        }
    };

    let lamps = nums.f64("the number of lamps")?;
    let lumens_per_lamp = nums.f64("the lumens per lamp (−1 for absolute photometry)")?;
    let multiplier = nums.f64("the candela multiplier")?;
    let n_v = nums.count("the number of vertical angles", 1)?;
    let n_h = nums.count("the number of horizontal angles", 1)?;
    let kind = nums.count("the photometric type (1 C, 2 B, 3 A)", 1)?;
    let photometry = match kind {
        1 => PhotometryType::C,
        2 => PhotometryType::B,
        3 => PhotometryType::A,
        _ => {
            return Err(err(
                Some(nums.line()),
                format!("expected the photometric type 1 (C), 2 (B) or 3 (A), found {kind}"),
            ))
        }
    };
    let units = nums.count("the units type (1 feet, 2 metres)", 1)?;
    let to_m = match units {
        1 => FEET_TO_M,
        2 => 1.0,
        _ => {
            return Err(err(
                Some(nums.line()),
                format!("expected the units type 1 (feet) or 2 (metres), found {units}"),
            ))
        }
    };
    let width = nums.f64("the luminous opening's width")? * to_m;
    let length = nums.f64("the luminous opening's length")? * to_m;
    let height = nums.f64("the luminous opening's height")? * to_m;
    let ballast = nums.f64("the ballast factor")?;
    let second = nums.f64(if format == PhotometricFormat::Ies2019 {
        "the file generation type"
    } else {
        "the ballast-lamp photometric factor"
    })?;
    let _input_watts = nums.f64("the input watts")?;
    if multiplier <= 0.0 {
        return Err(err(
            Some(nums.line()),
            format!("the candela multiplier must be > 0, found {multiplier}"),
        ));
    }
    if ballast <= 0.0 {
        return Err(err(
            Some(nums.line()),
            format!("the ballast factor must be > 0, found {ballast}"),
        ));
    }
    // Before 2019 the second field multiplies the candela values too (LM-63-2002 §3.15);
    // 2019 reuses it for the file-generation type (1.00001 …), which does not.
    let factor = multiplier
        * ballast
        * if format == PhotometricFormat::Ies2019 || second <= 0.0 {
            1.0
        } else {
            second
        };
    let (vertical, v_line) = nums.list(n_v, "vertical angle")?;
    let (horizontal, h_line) = nums.list(n_h, "horizontal angle")?;
    for (angles, line, what) in [
        (&vertical, v_line, "vertical"),
        (&horizontal, h_line, "horizontal"),
    ] {
        if let Some(i) = first_non_increasing(angles) {
            return Err(err(
                Some(line),
                format!(
                    "{what} angles must increase, but angle {} ({}°) follows {}°",
                    i + 1,
                    angles[i],
                    angles[i - 1]
                ),
            ));
        }
    }
    let mut rows = Vec::with_capacity(n_h);
    for angle in &horizontal {
        let (row, line) = nums.list(n_v, &format!("candela value at horizontal angle {angle}"))?;
        if let Some(x) = row.iter().find(|x| **x < 0.0) {
            return Err(err(
                Some(line),
                format!("candela values must be ≥ 0, found {x}"),
            ));
        }
        rows.push(row.into_iter().map(|x| x * factor).collect::<Vec<f64>>());
    }
    if let Some(&(line, tok)) = nums.tokens.get(nums.next) {
        return Err(err(
            Some(line),
            format!(
                "unexpected `{tok}` after the {n_h} × {n_v} candela values: the counts in the \
                 header do not match the data"
            ),
        ));
    }
    let (vmin, vmax) = (vertical[0], vertical[n_v - 1]);
    let (horizontal_deg, rows) = match photometry {
        PhotometryType::C => {
            if vmin < -1e-9 || vmax > 180.0 + 1e-9 {
                return Err(err(
                    Some(v_line),
                    format!("Type C vertical angles must lie in [0, 180]°, found {vmin}–{vmax}°"),
                ));
            }
            expand_type_c(&horizontal, rows).map_err(|m| err(Some(h_line), m))?
        }
        PhotometryType::A | PhotometryType::B => {
            if vmin < -90.0 - 1e-9 || vmax > 90.0 + 1e-9 {
                return Err(err(
                    Some(v_line),
                    format!(
                        "Type {} vertical angles must lie in [−90, 90]°, found {vmin}–{vmax}°",
                        if photometry == PhotometryType::A {
                            "A"
                        } else {
                            "B"
                        }
                    ),
                ));
            }
            expand_type_ab(&horizontal, rows).map_err(|m| err(Some(h_line), m))?
        }
    };
    let lamp_flux_lm = (lumens_per_lamp > 0.0 && lamps > 0.0).then_some(lamps * lumens_per_lamp);
    let candela = rows.into_iter().flatten().collect();
    Ok(IntensityDistribution {
        file: file.to_path_buf(),
        format,
        photometry,
        horizontal_deg,
        vertical_deg: vertical,
        candela,
        lamp_flux_lm,
        opening_m: [width, length, height],
        tilt,
        keywords,
    })
}

/// Types A/B: horizontal angles −h…h as given, or 0…h mirrored to −h…h (LM-63: "the
/// distribution is laterally symmetric"). Must stay within [−180, 180].
pub(crate) fn expand_type_ab(
    h: &[f64],
    rows: Vec<Vec<f64>>,
) -> Result<(Vec<f64>, Vec<Vec<f64>>), String> {
    let (first, last) = (h[0], *h.last().unwrap());
    if first < -180.0 - 1e-9 || last > 180.0 + 1e-9 {
        return Err(format!(
            "Type A/B horizontal angles must lie in [−180, 180]°, found {first}–{last}°"
        ));
    }
    if first.abs() < 1e-9 && h.len() > 1 {
        let mut hs: Vec<f64> = h[1..].iter().rev().map(|x| -x).collect();
        let mut rs: Vec<Vec<f64>> = rows[1..].iter().rev().cloned().collect();
        hs.extend_from_slice(h);
        rs.extend(rows);
        return Ok((hs, rs));
    }
    if h.len() == 1 {
        return Err(format!(
            "a Type A/B file needs at least two horizontal angles, found one ({first}°)"
        ));
    }
    if first < 0.0 {
        return Ok((h.to_vec(), rows));
    }
    Err(format!(
        "Type A/B horizontal angles must start at 0° (symmetric) or below, found {first}°"
    ))
}
