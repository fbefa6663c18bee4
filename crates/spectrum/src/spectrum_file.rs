//! Reader for spectral CSV files: `wavelength_nm,value[,value…]` per line, separated by a
//! comma, tabs or spaces, `#` comments, one optional header line, strictly increasing
//! wavelengths at any spacing. Every error names the file and the line.

use std::path::Path;

use crate::error::SpectrumFileError;
use crate::table::Tabulated;

/// The columns of a spectral file, with the source line of every row kept for diagnostics.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralColumns {
    /// Column names from the header line, or `value`, `value2`, … when there is none.
    pub names: Vec<String>,
    pub wavelengths_nm: Vec<f64>,
    /// `columns[c][row]`.
    pub columns: Vec<Vec<f64>>,
    /// 1-based line of each row.
    pub lines: Vec<usize>,
}

impl SpectralColumns {
    /// The column `index` as a table (linear, zero outside its range).
    pub fn table(&self, index: usize) -> Tabulated {
        Tabulated::new(self.wavelengths_nm.clone(), self.columns[index].clone())
            .expect("parser guarantees strictly increasing finite wavelengths")
    }

    /// The column whose header name equals `name` (case-insensitive).
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n.eq_ignore_ascii_case(name))
    }

    /// Errors (with its line) if any value of column `index` is negative, for quantities
    /// that cannot be, such as emission.
    pub fn require_non_negative(
        &self,
        index: usize,
        path: &Path,
        what: &str,
    ) -> Result<(), SpectrumFileError> {
        match self.columns[index].iter().position(|&v| v < 0.0) {
            Some(row) => Err(SpectrumFileError::new(
                path,
                Some(self.lines[row]),
                format!(
                    "{what} must be non-negative, found {} at {} nm",
                    self.columns[index][row], self.wavelengths_nm[row]
                ),
            )),
            None => Ok(()),
        }
    }
}

impl SpectralColumns {
    /// Every value of column `index` at most 1 (a reflectance or transmittance); the error
    /// names the line and wavelength of the first above.
    pub fn require_at_most_one(
        &self,
        index: usize,
        path: &Path,
        what: &str,
    ) -> Result<(), SpectrumFileError> {
        match self.columns[index].iter().position(|&v| v > 1.0) {
            Some(row) => Err(SpectrumFileError::new(
                path,
                Some(self.lines[row]),
                format!(
                    "{what} must be at most 1, found {} at {} nm (a percentage? divide by 100)",
                    self.columns[index][row], self.wavelengths_nm[row]
                ),
            )),
            None => Ok(()),
        }
    }

    /// The table reaches into `range_nm` (the renderer's wavelengths) with at least two
    /// rows: a table is zero outside its rows, so one that misses the range is black.
    pub fn require_coverage(
        &self,
        path: &Path,
        range_nm: (f64, f64),
    ) -> Result<(), SpectrumFileError> {
        let (lo, hi) = range_nm;
        match self.wavelengths_nm.as_slice() {
            [] | [_] => Err(SpectrumFileError::new(
                path,
                self.lines.first().copied(),
                format!(
                    "{} row: expected a table of at least two wavelengths over {lo}–{hi} nm \
                     (for a constant, give a number instead of a file)",
                    self.wavelengths_nm.len()
                ),
            )),
            [first, .., last] if *last < lo || *first > hi => Err(SpectrumFileError::new(
                path,
                self.lines.first().copied(),
                format!(
                    "the table covers {first}–{last} nm, outside the {lo}–{hi} nm the renderer \
                     samples: it would be zero (black) there; expected wavelengths in nm"
                ),
            )),
            _ => Ok(()),
        }
    }
}

fn split_fields(line: &str) -> Vec<&str> {
    if line.contains(',') {
        line.split(',').map(str::trim).collect()
    } else {
        line.split_whitespace().collect()
    }
}

fn parse_number(field: &str) -> Option<f64> {
    field.parse::<f64>().ok()
}

/// Parses the text of a spectral file; `path` is used only in error messages.
pub fn parse_spectral_text(text: &str, path: &Path) -> Result<SpectralColumns, SpectrumFileError> {
    let err = |line: usize, msg: String| SpectrumFileError::new(path, Some(line), msg);
    let mut names: Option<Vec<String>> = None;
    let mut wavelengths = Vec::new();
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut lines = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields = split_fields(content);
        let is_first_row = names.is_none() && wavelengths.is_empty();
        if is_first_row && parse_number(fields[0]).is_none() {
            if fields.len() < 2 {
                return Err(err(
                    line_no,
                    format!("expected a header `wavelength_nm,value` or a data line `wavelength_nm,value`, found `{content}`"),
                ));
            }
            names = Some(fields[1..].iter().map(|s| s.to_string()).collect());
            continue;
        }
        let expected_fields = match (&names, columns.len()) {
            (Some(n), _) => Some(n.len() + 1),
            (None, 0) => None,
            (None, c) => Some(c + 1),
        };
        if fields.len() < 2 {
            return Err(err(
                line_no,
                format!("expected `wavelength_nm,value`, found `{content}` (one field)"),
            ));
        }
        if let Some(n) = expected_fields {
            if fields.len() != n {
                return Err(err(
                    line_no,
                    format!(
                        "expected {n} fields like the lines before, found {}",
                        fields.len()
                    ),
                ));
            }
        }
        let mut numbers = Vec::with_capacity(fields.len());
        for (col, field) in fields.iter().enumerate() {
            let what = if col == 0 {
                "wavelength in nm"
            } else {
                "value"
            };
            match parse_number(field) {
                Some(v) if v.is_finite() => numbers.push(v),
                Some(_) => {
                    return Err(err(
                        line_no,
                        format!("expected a finite {what}, found `{field}`"),
                    ))
                }
                None => {
                    return Err(err(
                        line_no,
                        format!("expected a number ({what}), found `{field}`"),
                    ))
                }
            }
        }
        let wl = numbers[0];
        if wl <= 0.0 {
            return Err(err(
                line_no,
                format!("expected a positive wavelength in nm, found {wl}"),
            ));
        }
        if let Some(&prev) = wavelengths.last() {
            if wl <= prev {
                return Err(err(
                    line_no,
                    format!("wavelengths must increase strictly: {wl} nm follows {prev} nm"),
                ));
            }
        }
        if columns.is_empty() {
            columns = vec![Vec::new(); numbers.len() - 1];
        }
        wavelengths.push(wl);
        for (c, v) in numbers[1..].iter().enumerate() {
            columns[c].push(*v);
        }
        lines.push(line_no);
    }
    if wavelengths.is_empty() {
        return Err(SpectrumFileError::new(
            path,
            None,
            "no data: expected lines `wavelength_nm,value`",
        ));
    }
    let names = names.unwrap_or_else(|| {
        (0..columns.len())
            .map(|i| {
                if i == 0 {
                    "value".to_string()
                } else {
                    format!("value{}", i + 1)
                }
            })
            .collect()
    });
    Ok(SpectralColumns {
        names,
        wavelengths_nm: wavelengths,
        columns,
        lines,
    })
}

/// Reads a spectral file from disk.
pub fn read_spectral_file(path: &Path) -> Result<SpectralColumns, SpectrumFileError> {
    let text = prism_cpu::text_file::read_text(path)
        .map_err(|e| SpectrumFileError::new(path, None, format!("cannot read: {e}")))?;
    parse_spectral_text(&text, path)
}

/// Reads a file with exactly one value column (`wavelength_nm,value`).
pub fn read_single_spectrum(
    path: &Path,
) -> Result<(Tabulated, SpectralColumns), SpectrumFileError> {
    let cols = read_spectral_file(path)?;
    if cols.columns.len() != 1 {
        return Err(SpectrumFileError::new(
            path,
            Some(cols.lines[0]),
            format!(
                "expected one value column (`wavelength_nm,value`), found {}",
                cols.columns.len()
            ),
        ));
    }
    Ok((cols.table(0), cols))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SpectralColumns, SpectrumFileError> {
        parse_spectral_text(text, Path::new("s.csv"))
    }

    #[test]
    fn accepts_commas_tabs_spaces_comments_and_a_header() {
        let c = parse("# made by hand\nwavelength_nm,value\n400,1\n410\t2\n420   3 # note\n\n")
            .unwrap();
        assert_eq!(c.wavelengths_nm, vec![400.0, 410.0, 420.0]);
        assert_eq!(c.columns, vec![vec![1.0, 2.0, 3.0]]);
        assert_eq!(c.lines, vec![3, 4, 5]);
        assert_eq!(c.names, vec!["value"]);
    }

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        let e = parse("400,1\n399,2\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(
            e.to_string()
                .contains("s.csv:2: wavelengths must increase strictly"),
            "{e}"
        );
        let e = parse("400,1\n410,abc\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("s.csv:2: expected a number (value), found `abc`"),
            "{e}"
        );
        let e = parse("400,1\n410,NaN\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("s.csv:2: expected a finite value, found `NaN`"),
            "{e}"
        );
        let e = parse("400,1\n410,1,2\n").unwrap_err();
        assert!(e.to_string().contains("s.csv:2: expected 2 fields"), "{e}");
        let e = parse("# nothing\n").unwrap_err();
        assert!(e.to_string().contains("no data"), "{e}");
    }

    #[test]
    fn negative_values_are_reported_when_forbidden() {
        let c = parse("400,1\n410,-2\n").unwrap();
        let e = c
            .require_non_negative(0, Path::new("s.csv"), "emission")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("s.csv:2: emission must be non-negative"),
            "{e}"
        );
    }
}
