//! EULUMDAT (.ldt) files: one value per line in a fixed order (the format of Stockmar,
//! "EULUMDAT — ein Leuchtendatenformat für den europäischen Beleuchtungsplaner", 1990, as
//! every lighting program reads it). Intensities are in cd per 1000 lm of lamp flux; the
//! symmetry indicator Isym says which C-planes are stored:
//! 0 none (Mc planes), 1 rotational (1), 2 about C0–C180 (Mc/2 + 1, C 0…180),
//! 3 about C90–C270 (Mc/2 + 1, C 90…270), 4 about both (Mc/4 + 1, C 0…90).

use std::path::Path;

use super::{
    expand_type_c, first_non_increasing, IntensityDistribution, PhotometricError,
    PhotometricFormat, PhotometryType,
};

struct Lines<'a> {
    lines: Vec<&'a str>,
    next: usize,
    file: &'a Path,
}

impl<'a> Lines<'a> {
    fn err(&self, line: usize, message: impl Into<String>) -> PhotometricError {
        PhotometricError {
            file: self.file.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }

    /// The next line (1-based number, trimmed text).
    fn text(&mut self, what: &str) -> Result<(usize, &'a str), PhotometricError> {
        match self.lines.get(self.next) {
            Some(l) => {
                self.next += 1;
                Ok((self.next, l.trim()))
            }
            None => Err(PhotometricError {
                file: self.file.to_path_buf(),
                line: None,
                message: format!(
                    "the file ends early after {} lines: expected {what} on line {}",
                    self.lines.len(),
                    self.next + 1
                ),
            }),
        }
    }

    fn f64(&mut self, what: &str) -> Result<f64, PhotometricError> {
        let (n, t) = self.text(what)?;
        // Some writers use a decimal comma.
        match t.replace(',', ".").parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.err(n, format!("expected {what} (a number), found `{t}`"))),
        }
    }

    fn int(&mut self, what: &str, lo: i64, hi: i64) -> Result<i64, PhotometricError> {
        let x = self.f64(what)?;
        if x.fract() != 0.0 || x < lo as f64 || x > hi as f64 {
            return Err(self.err(
                self.next,
                format!("expected {what} (a whole number in {lo}…{hi}), found {x}"),
            ));
        }
        Ok(x as i64)
    }
}

pub fn parse_ldt(text: &str, file: &Path) -> Result<IntensityDistribution, PhotometricError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut l = Lines {
        lines: text.lines().map(|s| s.trim_end_matches('\r')).collect(),
        next: 0,
        file,
    };
    if l.lines.iter().all(|s| s.trim().is_empty()) {
        return Err(PhotometricError {
            file: file.to_path_buf(),
            line: None,
            message: "the file is empty".into(),
        });
    }
    let mut keywords = Vec::new();
    let (_, company) = l.text("the company identification")?;
    keywords.push(("company".to_string(), company.to_string()));
    let _ityp = l.int("the type indicator Ityp (0–3)", 0, 3)?;
    let isym = l.int("the symmetry indicator Isym (0–4)", 0, 4)?;
    let mc = l.int("the number of C-planes Mc", 0, 3600)? as usize;
    let _dc = l.f64("the distance between C-planes Dc")?;
    let ng = l.int("the number of intensities per C-plane Ng", 1, 3600)? as usize;
    let _dg = l.f64("the distance between γ angles Dg")?;
    for what in [
        "measurement report number",
        "luminaire name",
        "luminaire number",
        "file name",
        "date/user",
    ] {
        let (_, t) = l.text(&format!("the {what}"))?;
        keywords.push((what.to_string(), t.to_string()));
    }
    let _length_mm = l.f64("the luminaire length/diameter (mm)")?;
    let _width_mm = l.f64("the luminaire width (mm)")?;
    let _height_mm = l.f64("the luminaire height (mm)")?;
    let area_length_mm = l.f64("the luminous area's length/diameter (mm)")?;
    let area_width_mm = l.f64("the luminous area's width (mm, 0 for round)")?;
    let area_height_mm = l.f64("the luminous area's height at C0 (mm)")?;
    for c in ["C90", "C180", "C270"] {
        l.f64(&format!("the luminous area's height at {c} (mm)"))?;
    }
    let _dff = l.f64("the downward flux fraction DFF (%)")?;
    let _lor = l.f64("the light output ratio LORL (%)")?;
    let conversion = l.f64("the conversion factor for luminous intensities")?;
    let _tilt = l.f64("the tilt of the luminaire during measurement (°)")?;
    let n_sets = l.int("the number of standard sets of lamps n", 1, 20)? as usize;
    let mut lamp_counts = Vec::with_capacity(n_sets);
    for i in 0..n_sets {
        lamp_counts.push(l.f64(&format!("the number of lamps of set {}", i + 1))?);
    }
    for i in 0..n_sets {
        l.text(&format!("the lamp type of set {}", i + 1))?;
    }
    let mut fluxes = Vec::with_capacity(n_sets);
    for i in 0..n_sets {
        fluxes.push(l.f64(&format!(
            "the total luminous flux of lamp set {} (lm)",
            i + 1
        ))?);
    }
    for what in ["colour temperature", "colour rendering index"] {
        for i in 0..n_sets {
            l.text(&format!("the {what} of lamp set {}", i + 1))?;
        }
    }
    for i in 0..n_sets {
        l.f64(&format!("the wattage of lamp set {} (W)", i + 1))?;
    }
    for k in 0..10 {
        l.f64(&format!("direct ratio {} of 10", k + 1))?;
    }
    let c_line = l.next + 1;
    let mut c = Vec::with_capacity(mc);
    for i in 0..mc {
        c.push(l.f64(&format!("C-plane angle {} of {mc}", i + 1))?);
    }
    let g_line = l.next + 1;
    let mut gamma = Vec::with_capacity(ng);
    for i in 0..ng {
        gamma.push(l.f64(&format!("γ angle {} of {ng}", i + 1))?);
    }
    for (angles, line, what) in [(&c, c_line, "C-plane"), (&gamma, g_line, "γ")] {
        if let Some(i) = first_non_increasing(angles) {
            return Err(l.err(
                line + i,
                format!(
                    "{what} angles must increase, but angle {} ({}°) follows {}°",
                    i + 1,
                    angles[i],
                    angles[i - 1]
                ),
            ));
        }
    }
    if gamma[0] < -1e-9 || gamma[ng - 1] > 180.0 + 1e-9 {
        return Err(l.err(
            g_line,
            format!(
                "γ angles must lie in [0, 180]°, found {}–{}°",
                gamma[0],
                gamma[ng - 1]
            ),
        ));
    }
    // Which stored planes (indices into c) the symmetry implies.
    let stored: Vec<usize> = match isym {
        1 => vec![0],
        0 => (0..mc).collect(),
        2 => (0..=mc / 2).collect(),
        3 => (mc / 4..=3 * mc / 4).collect(),
        _ => (0..=mc / 4).collect(),
    };
    if mc == 0 || stored.iter().any(|&i| i >= mc) {
        return Err(l.err(
            4,
            format!("Mc = {mc} C-planes cannot hold the planes symmetry Isym = {isym} stores"),
        ));
    }
    if isym != 1 && isym != 0 && !mc.is_multiple_of(if isym == 4 { 4 } else { 2 }) {
        return Err(l.err(
            4,
            format!(
                "Isym = {isym} needs Mc divisible by {}, found {mc}",
                if isym == 4 { 4 } else { 2 }
            ),
        ));
    }
    let flux = fluxes[0];
    let per_klm = if flux > 0.0 { flux / 1000.0 } else { 1.0 };
    let factor = per_klm * if conversion > 0.0 { conversion } else { 1.0 };
    let mut rows = Vec::with_capacity(stored.len());
    for &i in &stored {
        let line = l.next + 1;
        let mut row = Vec::with_capacity(ng);
        for (j, g) in gamma.iter().enumerate() {
            let x = l.f64(&format!(
                "the intensity at C = {}°, γ = {g}° (cd/klm)",
                c[i]
            ))?;
            if x < 0.0 {
                return Err(l.err(line + j, format!("intensities must be ≥ 0, found {x}")));
            }
            row.push(x * factor);
        }
        rows.push(row);
    }
    if let Some((k, extra)) = l.lines[l.next..]
        .iter()
        .enumerate()
        .find(|(_, s)| !s.trim().is_empty())
    {
        return Err(l.err(
            l.next + k + 1,
            format!(
                "unexpected `{}` after the {} × {ng} intensities: Mc, Ng or Isym do not match the data",
                extra.trim(),
                stored.len()
            ),
        ));
    }
    let planes: Vec<f64> = stored.iter().map(|&i| c[i]).collect();
    // Isym 0: C 0…(360 − Dc); close the circle at 360.
    let (planes, rows) = if isym == 0 {
        let mut p = planes;
        let mut r = rows;
        if (p[p.len() - 1] - 360.0).abs() > 1e-6 {
            p.push(360.0);
            r.push(r[0].clone());
        }
        (p, r)
    } else {
        (planes, rows)
    };
    let (horizontal_deg, rows) = expand_type_c(&planes, rows).map_err(|m| l.err(c_line, m))?;
    let lamps: f64 = lamp_counts[0];
    Ok(IntensityDistribution {
        file: file.to_path_buf(),
        format: PhotometricFormat::Eulumdat,
        photometry: PhotometryType::C,
        horizontal_deg,
        vertical_deg: gamma,
        candela: rows.into_iter().flatten().collect(),
        // A negative lamp count marks absolute photometry (values already in cd).
        lamp_flux_lm: (flux > 0.0 && lamps > 0.0).then_some(flux),
        opening_m: [
            area_width_mm / 1000.0,
            area_length_mm / 1000.0,
            area_height_mm / 1000.0,
        ],
        tilt: None,
        keywords,
    })
}
