//! Reader for Labsphere BFC-450 bispectral matrix files (the text export of the Labsphere
//! BFC-450 bispectral fluorescence colorimeter, as in the RIT bispectral database):
//!
//! ```text
//! VEC_01<TAB>N                  first line; N is not a value count and is ignored
//! BFC-450 Matrix File           title line
//! ; comment                     `;` lines anywhere (and blank lines) are skipped
//! 380 780 10 49 300 10          emission first, last, step; excitation count, first, step (nm)
//! r:c: 300 310 … 780            the excitation wavelengths
//! 380 v₁ v₂ … v₄₉               one row per emission wavelength: λ_out, then one value
//! …                             per excitation wavelength
//! EOD
//! ```
//!
//! Lines end in LF or CRLF (a leading byte-order mark is skipped); fields are separated by
//! tabs or spaces (runs of them, trailing ones ignored). Values are bispectral radiance factors per band D(λ_in, λ_out): the
//! diagonal (λ_in = λ_out) is the reflected radiance factor R(λ), an off-diagonal entry
//! divided by the excitation band width (the excitation step, nm) is the Donaldson matrix
//! M(λ_in, λ_out) in nm⁻¹, so Σ_μ D(μ, λ)·S(μ) ≈ ∫ M(λ_in, λ)·S(λ_in) dλ_in. Every emission
//! wavelength must therefore also be an excitation wavelength; M is 0 on the diagonal.
//!
//! Every error names the file, the line and the column (in characters, a tab counting one)
//! and what was expected there.

use std::path::Path;

use crate::error::SpectrumFileError;
use crate::reradiation::{ReradiationMatrix, WavelengthGrid};
use crate::table::Tabulated;

/// Excitation wavelengths a BFC file may use: the reach of the CIE illuminant tables that
/// excite it (300 nm) up to the end of the visible range Prism renders (830 nm).
pub const EXCITATION_RANGE_NM: (f64, f64) = (300.0, 830.0);

/// What to do with negative entries (measurement noise around zero: 32–45 % of the entries
/// of the RIT files, down to −0.05).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NegativesPolicy {
    /// Set them to 0 and report their count and the most negative one.
    #[default]
    Clamp,
    /// Keep the signed matrix (and signed R); sampling then draws ∝ |M|.
    Keep,
    /// Refuse the file, naming the most negative entry.
    Error,
}

impl NegativesPolicy {
    /// The policy for the scene key / CLI value `clamp`, `keep` or `error`.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "clamp" => Some(Self::Clamp),
            "keep" => Some(Self::Keep),
            "error" => Some(Self::Error),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Clamp => "clamp",
            Self::Keep => "keep",
            Self::Error => "error",
        }
    }
}

/// One entry of the file, located.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BfcEntry {
    pub excitation_nm: f32,
    pub emission_nm: f32,
    /// The radiance factor as written in the file.
    pub value: f32,
    pub line: usize,
    pub column: usize,
}

/// The negative entries of a file (diagonal included), before the policy was applied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NegativesReport {
    pub count: usize,
    /// All entries of the matrix.
    pub total: usize,
    /// The most negative entry, when there is one.
    pub worst: Option<BfcEntry>,
}

/// One line for the user (`prism color` and `--explain` print the policy): "2 of 75 entries
/// are negative, the most negative -0.03 at excitation 330 nm, emission 420 nm (line 8,
/// column 23)", or "no negative entries".
impl std::fmt::Display for NegativesReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.worst {
            None => f.write_str("no negative entries"),
            Some(w) => write!(
                f,
                "{} of {} entries are negative, the most negative {} at excitation {} nm, emission {} nm (line {}, column {})",
                self.count, self.total, w.value, w.excitation_nm, w.emission_nm, w.line, w.column
            ),
        }
    }
}

/// A BFC-450 file as R(λ) and a Donaldson matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct BfcData {
    /// R(λ) at the emission wavelengths (the diagonal), linear in between.
    pub reflectance: Tabulated,
    /// M(λ_in, λ_out) in nm⁻¹ on the file's excitation × emission grids, 0 on the diagonal.
    pub matrix: ReradiationMatrix,
    pub policy: NegativesPolicy,
    pub negatives: NegativesReport,
}

/// Reads and parses a BFC-450 file.
pub fn load_bfc(path: &Path, policy: NegativesPolicy) -> Result<BfcData, SpectrumFileError> {
    let text = prism_cpu::text_file::read_text(path).map_err(|e| {
        SpectrumFileError::new(path, None, format!("cannot read the BFC-450 file: {e}"))
    })?;
    parse_bfc(&text, path, policy)
}

/// A field of a line and its 1-based character column.
#[derive(Debug, Clone, Copy)]
struct Field<'a> {
    column: usize,
    text: &'a str,
}

/// A non-blank, non-comment line split into fields.
struct Line<'a> {
    number: usize,
    fields: Vec<Field<'a>>,
    /// Column just past the last field (where a missing field would start).
    end_column: usize,
}

impl Line<'_> {
    fn content(&self) -> String {
        self.fields
            .iter()
            .map(|f| f.text)
            .collect::<Vec<_>>()
            .join(" ")
    }
}

fn split_fields(raw: &str) -> (Vec<Field<'_>>, usize) {
    let mut fields = Vec::new();
    let mut start: Option<(usize, usize)> = None; // (byte offset, column)
    let mut column = 0;
    for (offset, c) in raw.char_indices() {
        column += 1;
        let separator = c == ' ' || c == '\t' || c == '\r';
        match (separator, start) {
            (true, Some((from, col))) => {
                fields.push(Field {
                    column: col,
                    text: &raw[from..offset],
                });
                start = None;
            }
            (false, None) => start = Some((offset, column)),
            (true, None) | (false, Some(_)) => {}
        }
    }
    if let Some((from, col)) = start {
        fields.push(Field {
            column: col,
            text: &raw[from..],
        });
    }
    let end_column = fields
        .last()
        .map_or(1, |f| f.column + f.text.chars().count());
    (fields, end_column)
}

fn near_integer(x: f64) -> Option<usize> {
    let r = x.round();
    ((x - r).abs() < 1e-6 && r >= 0.0).then_some(r as usize)
}

/// Parses the text of a BFC-450 file; `path` is used only in error messages.
pub fn parse_bfc(
    text: &str,
    path: &Path,
    policy: NegativesPolicy,
) -> Result<BfcData, SpectrumFileError> {
    let err =
        |line: usize, column: usize, msg: String| SpectrumFileError::at(path, line, column, msg);
    // Windows tools may prefix a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let end_of_file_line = text.lines().count() + 1;
    let mut lines = text.lines().enumerate().filter_map(|(index, raw)| {
        let (fields, end_column) = split_fields(raw);
        match fields.first() {
            None => None,
            Some(f) if f.text.starts_with(';') => None,
            Some(_) => Some(Line {
                number: index + 1,
                fields,
                end_column,
            }),
        }
    });
    let number = |line: usize, field: Field, what: &str| -> Result<f64, SpectrumFileError> {
        match field.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(err(
                line,
                field.column,
                format!("expected a finite number ({what}), found `{}`", field.text),
            )),
            Err(_) => Err(err(
                line,
                field.column,
                format!("expected a number ({what}), found `{}`", field.text),
            )),
        }
    };

    // First line: VEC_01.
    let first = lines.next().ok_or_else(|| {
        err(
            1,
            1,
            "expected the first line `VEC_01<TAB>N` of a Labsphere BFC-450 file, found an empty file".into(),
        )
    })?;
    if !first.fields[0].text.eq_ignore_ascii_case("VEC_01") {
        return Err(err(
            first.number,
            first.fields[0].column,
            format!(
                "expected the first line `VEC_01<TAB>N` of a Labsphere BFC-450 file, found `{}`",
                first.content()
            ),
        ));
    }

    // Title.
    const TITLE: &str = "BFC-450 Matrix File";
    let title = lines.next().ok_or_else(|| {
        err(
            end_of_file_line,
            1,
            format!("expected the title line `{TITLE}`, found the end of the file"),
        )
    })?;
    if !title.content().eq_ignore_ascii_case(TITLE) {
        return Err(err(
            title.number,
            title.fields[0].column,
            format!(
                "expected the title line `{TITLE}`, found `{}`",
                title.content()
            ),
        ));
    }

    // Header.
    const HEADER: &str = "emission_first emission_last emission_step excitation_count excitation_first excitation_step (e.g. `380 780 10 49 300 10`)";
    let header = lines.next().ok_or_else(|| {
        err(
            end_of_file_line,
            1,
            format!("missing header: expected `{HEADER}`, found the end of the file"),
        )
    })?;
    if header.fields[0].text.parse::<f64>().is_err() {
        return Err(err(
            header.number,
            header.fields[0].column,
            format!(
                "missing header: expected `{HEADER}`, found `{}`",
                header.content()
            ),
        ));
    }
    if header.fields.len() != 6 {
        let column = header.fields.get(6).map_or(header.end_column, |f| f.column);
        return Err(err(
            header.number,
            column,
            format!(
                "header has {} fields, expected 6: `{HEADER}`",
                header.fields.len()
            ),
        ));
    }
    let names = [
        "emission first wavelength in nm",
        "emission last wavelength in nm",
        "emission step in nm",
        "excitation count",
        "excitation first wavelength in nm",
        "excitation step in nm",
    ];
    let mut h = [0.0f64; 6];
    for (k, value) in h.iter_mut().enumerate() {
        *value = number(header.number, header.fields[k], names[k])?;
    }
    let [em_first, em_last, em_step, ex_count, ex_first, ex_step] = h;
    let hcol = |k: usize| header.fields[k].column;
    if em_step <= 0.0 {
        return Err(err(
            header.number,
            hcol(2),
            format!("expected a positive emission step in nm, found {em_step}"),
        ));
    }
    let em_count = match near_integer((em_last - em_first) / em_step) {
        Some(n) if n >= 1 => n + 1,
        _ => {
            return Err(err(
                header.number,
                hcol(1),
                format!(
                    "emission last wavelength {em_last} nm must be the first, {em_first} nm, plus a whole positive number of {em_step} nm steps"
                ),
            ))
        }
    };
    let ex_count = match near_integer(ex_count) {
        Some(n) if n >= 2 => n,
        _ => {
            return Err(err(
                header.number,
                hcol(3),
                format!("expected a whole excitation count of at least 2, found {ex_count}"),
            ))
        }
    };
    if ex_step <= 0.0 {
        return Err(err(
            header.number,
            hcol(5),
            format!("expected a positive excitation step in nm, found {ex_step}"),
        ));
    }
    let ex_last = ex_first + (ex_count - 1) as f64 * ex_step;
    let (range_low, range_high) = EXCITATION_RANGE_NM;
    if ex_first < range_low || ex_last > range_high {
        let column = if ex_first < range_low {
            hcol(4)
        } else {
            hcol(3)
        };
        return Err(err(
            header.number,
            column,
            format!(
                "excitation {ex_first}–{ex_last} nm ({ex_count} × {ex_step} nm from {ex_first} nm) leaves {range_low}–{range_high} nm, the range Prism's illuminants cover"
            ),
        ));
    }
    // Each emission wavelength must be an excitation wavelength, so the diagonal holds R.
    let em_offset = (em_first - ex_first) / ex_step;
    let em_ratio = em_step / ex_step;
    let diagonal_start = match (near_integer(em_offset), near_integer(em_ratio)) {
        (Some(offset), Some(ratio))
            if ratio >= 1 && offset + (em_count - 1) * ratio < ex_count =>
        {
            (offset, ratio)
        }
        _ => {
            return Err(err(
                header.number,
                hcol(0),
                format!(
                    "emission wavelengths {em_first}–{em_last} nm (step {em_step} nm) must all be excitation wavelengths ({ex_first} nm + k × {ex_step} nm up to {ex_last} nm): the diagonal gives R(λ) at each"
                ),
            ))
        }
    };

    // r:c: line of excitation wavelengths.
    let rc = lines.next().ok_or_else(|| {
        err(
            end_of_file_line,
            1,
            format!("missing `r:c:` line: expected `r:c:` and the {ex_count} excitation wavelengths, found the end of the file"),
        )
    })?;
    if !rc.fields[0].text.eq_ignore_ascii_case("r:c:") {
        return Err(err(
            rc.number,
            rc.fields[0].column,
            format!(
                "missing `r:c:` line: expected `r:c:` and the {ex_count} excitation wavelengths, found `{}`",
                rc.content()
            ),
        ));
    }
    check_count(&rc, ex_count, "excitation wavelengths after `r:c:`")
        .map_err(|(c, m)| err(rc.number, c, m))?;
    for k in 0..ex_count {
        let field = rc.fields[k + 1];
        let value = number(rc.number, field, "excitation wavelength in nm")?;
        let expected = ex_first + k as f64 * ex_step;
        if (value - expected).abs() > 1e-3 {
            return Err(err(
                rc.number,
                field.column,
                format!(
                    "non-uniform excitation wavelengths: expected {expected} nm (the header's {ex_first} nm + {k} × {ex_step} nm), found {value} nm"
                ),
            ));
        }
    }

    // Emission rows: D[e][x] row-major by emission.
    let mut radiance_factors = Vec::with_capacity(em_count * ex_count);
    let mut positions = Vec::with_capacity(em_count * ex_count);
    let mut last_line = rc.number;
    for e in 0..em_count {
        let expected_nm = em_first + e as f64 * em_step;
        let Some(row) = lines.next() else {
            return Err(err(
                end_of_file_line,
                1,
                format!("the file ends after {e} of the {em_count} emission rows ({em_first}–{em_last} nm) and has no `EOD`"),
            ));
        };
        if row.fields[0].text.eq_ignore_ascii_case("EOD") {
            return Err(err(
                row.number,
                row.fields[0].column,
                format!("expected {em_count} emission rows ({em_first}–{em_last} nm), found {e} before `EOD`"),
            ));
        }
        let value = number(row.number, row.fields[0], "emission wavelength in nm")?;
        if (value - expected_nm).abs() > 1e-3 {
            return Err(err(
                row.number,
                row.fields[0].column,
                format!(
                    "non-uniform emission wavelengths: expected {expected_nm} nm (the header's {em_first} nm + {e} × {em_step} nm), found {value} nm"
                ),
            ));
        }
        check_count(
            &row,
            ex_count,
            "values (one per excitation wavelength) after the emission wavelength",
        )
        .map_err(|(c, m)| err(row.number, c, m))?;
        for x in 0..ex_count {
            let field = row.fields[x + 1];
            let what = format!(
                "radiance factor for excitation {} nm",
                ex_first + x as f64 * ex_step
            );
            let v = number(row.number, field, &what)?;
            radiance_factors.push(v);
            positions.push((row.number, field.column));
        }
        last_line = row.number;
    }
    match lines.next() {
        None => {
            return Err(err(
                end_of_file_line,
                1,
                format!("missing `EOD` after the {em_count} emission rows (the last on line {last_line}): found the end of the file"),
            ))
        }
        Some(line) if line.fields[0].text.eq_ignore_ascii_case("EOD") => {}
        Some(line) => {
            return Err(err(
                line.number,
                line.fields[0].column,
                format!(
                    "expected `EOD` after the {em_count} emission rows ({em_first}–{em_last} nm), found `{}`",
                    line.content()
                ),
            ))
        }
    }

    // Negatives, over every entry (the diagonal too: R is measured as noisily).
    let ex_nm = |x: usize| (ex_first + x as f64 * ex_step) as f32;
    let em_nm = |e: usize| (em_first + e as f64 * em_step) as f32;
    let mut negatives = NegativesReport {
        count: 0,
        total: radiance_factors.len(),
        worst: None,
    };
    for (index, &v) in radiance_factors.iter().enumerate() {
        if v < 0.0 {
            negatives.count += 1;
            if negatives.worst.is_none_or(|w| (v as f32) < w.value) {
                let (e, x) = (index / ex_count, index % ex_count);
                negatives.worst = Some(BfcEntry {
                    excitation_nm: ex_nm(x),
                    emission_nm: em_nm(e),
                    value: v as f32,
                    line: positions[index].0,
                    column: positions[index].1,
                });
            }
        }
    }
    let signed = match (policy, negatives.worst) {
        (NegativesPolicy::Error, Some(w)) => {
            return Err(err(
                w.line,
                w.column,
                format!(
                    "{} of {} entries are negative, the most negative {} at excitation {} nm, emission {} nm; negatives \"error\" refuses them (\"clamp\" sets them to 0, \"keep\" keeps the signed matrix)",
                    negatives.count, negatives.total, w.value, w.excitation_nm, w.emission_nm
                ),
            ))
        }
        (NegativesPolicy::Keep, _) => true,
        (NegativesPolicy::Clamp | NegativesPolicy::Error, _) => false,
    };
    let clean = |v: f64| if signed { v } else { v.max(0.0) };

    let (diagonal_offset, diagonal_ratio) = diagonal_start;
    let diagonal = |e: usize| diagonal_offset + e * diagonal_ratio;
    let reflectance = Tabulated::new(
        (0..em_count).map(|e| em_nm(e) as f64).collect(),
        (0..em_count)
            .map(|e| clean(radiance_factors[e * ex_count + diagonal(e)]))
            .collect(),
    )
    .expect("the emission grid is strictly increasing and the values finite");
    let mut values = vec![0.0f32; ex_count * em_count];
    for e in 0..em_count {
        for x in 0..ex_count {
            if x != diagonal(e) {
                values[x * em_count + e] =
                    (clean(radiance_factors[e * ex_count + x]) / ex_step) as f32;
            }
        }
    }
    let grid_err = |m: crate::ReradiationError| err(header.number, 1, m.message);
    let excitation =
        WavelengthGrid::new(ex_first as f32, ex_step as f32, ex_count).map_err(grid_err)?;
    let emission =
        WavelengthGrid::new(em_first as f32, em_step as f32, em_count).map_err(grid_err)?;
    let matrix = if signed {
        ReradiationMatrix::from_dense_signed(excitation, emission, values)
    } else {
        ReradiationMatrix::from_dense(excitation, emission, values)
    }
    .map_err(grid_err)?;
    if let Err(e) = matrix.check_energy_conservation(1e-4) {
        let (worst_nm, _) = matrix.max_row_integral();
        let x = (((worst_nm as f64 - ex_first) / ex_step).round() as usize).min(ex_count - 1);
        return Err(err(rc.number, rc.fields[x + 1].column, e.message));
    }
    Ok(BfcData {
        reflectance,
        matrix,
        policy,
        negatives,
    })
}

/// Ok when `line` has exactly `count` fields after its first; otherwise the column of the
/// first extra field (or where the first missing one would start) and a message.
fn check_count(line: &Line, count: usize, what: &str) -> Result<(), (usize, String)> {
    let found = line.fields.len() - 1;
    if found == count {
        return Ok(());
    }
    let column = line
        .fields
        .get(count + 1)
        .map_or(line.end_column, |f| f.column);
    Err((column, format!("expected {count} {what}, found {found}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATH: &str = "test.BFC";

    /// Excitation 300–440 nm (15 × 10 nm), emission 400–440 nm (5 rows): R = 0.8 − 0.01·e on
    /// the diagonal, D = 0.02 where λ_in < λ_out, 0 elsewhere.
    fn lines() -> Vec<String> {
        let mut lines = vec![
            "VEC_01\t1234".to_string(),
            "BFC-450 Matrix File".to_string(),
            "; synthetic test matrix".to_string(),
            "400\t440\t10\t15\t300\t10".to_string(),
        ];
        let excitation: Vec<String> = (0..15).map(|x| (300 + 10 * x).to_string()).collect();
        lines.push(format!("r:c:\t{}", excitation.join("\t")));
        for e in 0..5 {
            let em = 400 + 10 * e;
            let values: Vec<String> = (0..15)
                .map(|x| {
                    let ex = 300 + 10 * x;
                    if ex == em {
                        format!("{}", 0.8 - 0.01 * e as f64)
                    } else if ex < em {
                        "0.02".to_string()
                    } else {
                        "0".to_string()
                    }
                })
                .collect();
            lines.push(format!("{em}\t{}", values.join("\t")));
        }
        lines.push("EOD".to_string());
        lines
    }

    fn parse(lines: &[String]) -> Result<BfcData, SpectrumFileError> {
        parse_bfc(&lines.join("\n"), Path::new(PATH), NegativesPolicy::Clamp)
    }

    /// The error's (line, column) and message.
    fn error_at(lines: &[String]) -> (usize, usize, String) {
        let e = parse(lines).unwrap_err();
        assert_eq!(e.path, Path::new(PATH));
        (e.line.unwrap(), e.column.unwrap(), e.message)
    }

    /// 1-based column of the first occurrence of `needle` in `line`.
    fn column_of(line: &str, needle: &str) -> usize {
        line.find(needle).unwrap() + 1
    }

    #[test]
    fn a_tab_separated_lf_file_gives_r_and_m() {
        let data = parse(&lines()).unwrap();
        let m = &data.matrix;
        assert_eq!(m.excitation().start_nm(), 300.0);
        assert_eq!(m.excitation().count(), 15);
        assert_eq!(m.emission().start_nm(), 400.0);
        assert_eq!(m.emission().end_nm(), 440.0);
        assert_eq!(
            data.reflectance.wavelengths_nm(),
            &[400.0, 410.0, 420.0, 430.0, 440.0]
        );
        for (e, &r) in data.reflectance.values().iter().enumerate() {
            assert!((r - (0.8 - 0.01 * e as f64)).abs() < 1e-12);
        }
        // Off-diagonal: radiance factor per band ÷ 10 nm; the diagonal is R, not M.
        assert!((m.eval(300.0, 400.0) - 0.002).abs() < 1e-9);
        assert!((m.eval(400.0, 440.0) - 0.002).abs() < 1e-9);
        assert_eq!(m.eval(420.0, 420.0), 0.0);
        assert_eq!(m.eval(430.0, 420.0), 0.0);
        // Row 300 nm: 0.002 nm⁻¹ over 40 nm.
        assert!((m.row_integral(300.0) - 0.08).abs() < 1e-6);
        assert_eq!(data.negatives.count, 0);
        assert_eq!(data.negatives.total, 75);
        assert!(!m.is_signed());
    }

    #[test]
    fn crlf_spaces_mixed_separators_comments_and_trailing_separators_read_the_same() {
        let reference = parse(&lines()).unwrap();
        let mut variant: Vec<String> = lines()
            .into_iter()
            .enumerate()
            .map(|(i, line)| match i % 3 {
                0 => line.replace('\t', " "),
                1 => format!("{}\t \t", line.replace('\t', " \t  ")),
                _ => format!("  {line} "),
            })
            .collect();
        variant.insert(4, "; a comment between header and r:c:".into());
        variant.insert(6, String::new());
        variant.insert(8, "   ;indented comment".into());
        let text = variant.join("\r\n") + "\r\n";
        let data = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Clamp).unwrap();
        assert_eq!(data, reference);
        let with_bom = format!("\u{feff}{text}");
        let data = parse_bfc(&with_bom, Path::new(PATH), NegativesPolicy::Clamp).unwrap();
        assert_eq!(data, reference);
    }

    #[test]
    fn positions_count_lines_and_characters_in_crlf_files_with_mixed_separators() {
        // Line 9 (after a comment and a blank line) reads `  410 \t 0.02\t\t0.x2 …`: the bad
        // token starts at character 15, a tab counting one.
        let mut l = lines();
        l.insert(5, "; comment".into());
        l.insert(6, String::new());
        l[8] = format!(
            "  410 \t 0.02\t\t0.x2\t{}",
            l[8].splitn(4, '\t').nth(3).unwrap()
        );
        let text = l.join("\r\n") + "\r\n";
        let e = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Clamp).unwrap_err();
        assert_eq!((e.line, e.column), (Some(9), Some(15)), "{e}");
        assert!(
            e.message.contains(
                "expected a number (radiance factor for excitation 310 nm), found `0.x2`"
            ),
            "{e}"
        );
        // The end of the file is the line after the last CRLF-terminated one.
        let mut l = lines();
        l.insert(5, "; comment".into());
        l.pop();
        let text = l.join("\r\n") + "\r\n";
        let e = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Clamp).unwrap_err();
        assert_eq!(e.line, Some(l.len() + 1), "{e}");
    }

    #[test]
    fn the_first_line_title_and_header_are_required() {
        let mut l = lines();
        l[0] = "VEC_02\t1".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (1, 1), "{message}");
        assert!(
            message.contains("expected the first line `VEC_01<TAB>N`"),
            "{message}"
        );

        let (line, column, message) = error_at(&[]);
        assert_eq!((line, column), (1, 1));
        assert!(message.contains("empty file"), "{message}");

        let mut l = lines();
        l[1] = "  BFC-400 Matrix File".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (2, 3), "{message}");
        assert!(
            message.contains("expected the title line `BFC-450 Matrix File`"),
            "{message}"
        );

        // Missing header: the r:c: line comes where the header belongs.
        let mut l = lines();
        l.remove(3);
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 1), "{message}");
        assert!(
            message.starts_with("missing header: expected `emission_first"),
            "{message}"
        );

        // A header with 5 fields: the missing one would start after the last.
        let mut l = lines();
        l[3] = "400\t440\t10\t15\t300".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 18), "{message}");
        assert!(
            message.contains("header has 5 fields, expected 6"),
            "{message}"
        );

        let mut l = lines();
        l[3] = "400 440 10 15 300 10 7".into();
        let (line, column, _) = error_at(&l);
        assert_eq!((line, column), (4, 22));
    }

    #[test]
    fn header_grids_are_checked() {
        // Excitation below 300 nm.
        let mut l = lines();
        l[3] = "400 440 10 15 290 10".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 15), "{message}");
        assert!(message.contains("leaves 300–830 nm"), "{message}");
        // Excitation beyond 830 nm: 300 + 59 × 10 = 890.
        l[3] = "400 440 10 60 300 10".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 12), "{message}");
        assert!(message.contains("300–890 nm"), "{message}");
        // Emission off the excitation grid: no diagonal.
        l[3] = "405 445 10 15 300 10".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 1), "{message}");
        assert!(
            message.contains("must all be excitation wavelengths"),
            "{message}"
        );
        // Emission last not on its own grid.
        l[3] = "400 445 10 15 300 10".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 5), "{message}");
        assert!(
            message.contains("whole positive number of 10 nm steps"),
            "{message}"
        );
        // Non-numeric header field.
        l[3] = "400 440 ten 15 300 10".into();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (4, 9), "{message}");
        assert!(
            message.contains("expected a number (emission step in nm), found `ten`"),
            "{message}"
        );
    }

    #[test]
    fn the_rc_line_is_required_and_uniform() {
        let mut l = lines();
        l.remove(4);
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (5, 1), "{message}");
        assert!(message.starts_with("missing `r:c:` line"), "{message}");

        let mut l = lines();
        l[4] = l[4].replace("\t350\t", "\t355\t");
        let expected_column = column_of(&l[4], "355");
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (5, expected_column), "{message}");
        assert!(
            message.contains("non-uniform excitation wavelengths: expected 350 nm"),
            "{message}"
        );

        let mut l = lines();
        l[4] = l[4].replace("\t440", "");
        let expected_column = l[4].chars().count() + 1;
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (5, expected_column), "{message}");
        assert!(
            message.contains("expected 15 excitation wavelengths after `r:c:`, found 14"),
            "{message}"
        );
    }

    #[test]
    fn rows_are_counted_and_their_values_checked() {
        // Too few values on a row.
        let mut l = lines();
        l[7] = l[7].rsplit_once('\t').unwrap().0.to_string();
        let expected_column = l[7].chars().count() + 1;
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (8, expected_column), "{message}");
        assert!(message.contains("expected 15 values (one per excitation wavelength) after the emission wavelength, found 14"), "{message}");
        // Too many: the first extra one.
        let mut l = lines();
        l[7].push_str("\t0.5");
        let expected_column = l[7].rfind('\t').unwrap() + 2;
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (8, expected_column), "{message}");
        assert!(message.contains("found 16"), "{message}");
        // Non-numeric value.
        let mut l = lines();
        l[8] = l[8].replacen("0.02", "0.O2", 3);
        let expected_column = column_of(&l[8], "0.O2");
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (9, expected_column), "{message}");
        assert!(
            message.contains(
                "expected a number (radiance factor for excitation 300 nm), found `0.O2`"
            ),
            "{message}"
        );
        // Non-uniform emission wavelength.
        let mut l = lines();
        l[7] = l[7].replacen("420", "425", 1);
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (8, 1), "{message}");
        assert!(
            message.contains("non-uniform emission wavelengths: expected 420 nm"),
            "{message}"
        );
        // EOD after 4 of 5 rows.
        let mut l = lines();
        l.remove(9);
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (10, 1), "{message}");
        assert!(
            message.contains("expected 5 emission rows (400–440 nm), found 4 before `EOD`"),
            "{message}"
        );
        // A sixth row where EOD belongs.
        let mut l = lines();
        l.insert(10, l[9].clone());
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (11, 1), "{message}");
        assert!(
            message.contains("expected `EOD` after the 5 emission rows"),
            "{message}"
        );
        // No EOD: the end of the file is the line after the last.
        let mut l = lines();
        l.pop();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (11, 1), "{message}");
        assert!(message.contains("missing `EOD`"), "{message}");
        // The file ends inside the rows.
        let l = lines()[..8].to_vec();
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (9, 1), "{message}");
        assert!(
            message.contains("ends after 3 of the 5 emission rows"),
            "{message}"
        );
    }

    /// `lines()` with two negative entries: −0.01 at (λ_in 300, λ_out 410) on line 7 and
    /// −0.03 at (λ_in 330, λ_out 420) on line 8.
    fn with_negatives() -> Vec<String> {
        let mut l = lines();
        l[6] = l[6].replacen("0.02", "-0.01", 1);
        let mut fields: Vec<String> = l[7].split('\t').map(String::from).collect();
        fields[4] = "-0.03".into();
        l[7] = fields.join("\t");
        l
    }

    #[test]
    fn negatives_clamp_keep_or_error() {
        let l = with_negatives();
        let text = l.join("\n");
        let clamped = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Clamp).unwrap();
        let worst = clamped.negatives.worst.unwrap();
        assert_eq!(clamped.negatives.count, 2);
        assert_eq!(
            (worst.excitation_nm, worst.emission_nm, worst.value),
            (330.0, 420.0, -0.03)
        );
        assert_eq!((worst.line, worst.column), (8, column_of(&l[7], "-0.03")));
        assert_eq!(clamped.matrix.eval(330.0, 420.0), 0.0);
        assert_eq!(clamped.matrix.eval(300.0, 410.0), 0.0);
        assert!(!clamped.matrix.is_signed());

        let kept = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Keep).unwrap();
        assert!(kept.matrix.is_signed());
        assert!((kept.matrix.eval(330.0, 420.0) + 0.003).abs() < 1e-9);
        assert!((kept.matrix.eval(300.0, 410.0) + 0.001).abs() < 1e-9);
        assert_eq!(kept.negatives, clamped.negatives);

        assert_eq!(
            clamped.negatives.to_string(),
            format!(
                "2 of 75 entries are negative, the most negative -0.03 at excitation 330 nm, emission 420 nm (line 8, column {})",
                column_of(&l[7], "-0.03")
            )
        );
        assert_eq!(
            parse(&lines()).unwrap().negatives.to_string(),
            "no negative entries"
        );
        let e = parse_bfc(&text, Path::new(PATH), NegativesPolicy::Error).unwrap_err();
        assert_eq!(
            (e.line, e.column),
            (Some(8), Some(column_of(&l[7], "-0.03")))
        );
        assert!(e.message.contains("2 of 75 entries are negative, the most negative -0.03 at excitation 330 nm, emission 420 nm"), "{e}");
        assert_eq!(
            e.to_string(),
            format!("{PATH}:8:{}: {}", column_of(&l[7], "-0.03"), e.message)
        );
        // Without negatives every policy reads the same matrix.
        let plain = lines().join("\n");
        let [a, b, c] = [
            NegativesPolicy::Clamp,
            NegativesPolicy::Keep,
            NegativesPolicy::Error,
        ]
        .map(|p| parse_bfc(&plain, Path::new(PATH), p).unwrap().matrix);
        assert_eq!(a, b);
        assert_eq!(a, c);
        for p in [
            NegativesPolicy::Clamp,
            NegativesPolicy::Keep,
            NegativesPolicy::Error,
        ] {
            assert_eq!(NegativesPolicy::parse(p.name()), Some(p));
        }
        assert_eq!(NegativesPolicy::parse("ignore"), None);
        assert_eq!(NegativesPolicy::default(), NegativesPolicy::Clamp);
    }

    #[test]
    fn energy_violations_name_the_excitation() {
        // λ_in = 320 nm re-radiates 0.3 / 10 nm⁻¹ over the 40 nm of emission = 1.2 of what
        // it absorbs.
        let mut l = lines();
        for row in &mut l[5..10] {
            let mut fields: Vec<String> = row.split('\t').map(String::from).collect();
            fields[3] = "0.3".into();
            *row = fields.join("\t");
        }
        let (line, column, message) = error_at(&l);
        assert_eq!((line, column), (5, column_of(&l[4], "320")), "{message}");
        assert!(message.contains("at excitation 320 nm"), "{message}");
    }
}
