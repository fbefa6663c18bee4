//! Photometric files: IES LM-63 (1986/1991, 1995, 2002, 2019) and EULUMDAT (.ldt) read
//! into one plain description — a table of luminous intensities in candela over the
//! file's angles, expanded by its symmetry to the full range, with the rated lamp flux,
//! the luminous opening and the TILT table. The runtime emitter (prism-render
//! `light::goniometric`) interpolates it.
//!
//! Written here rather than taken from a crate: `eulumdat` (0.7) reports errors through
//! `anyhow` strings without the line, and carries diagrams, street layouts and 3-D scene
//! export we do not need; `lidrs` (0.2, 2022) reads LM-63 up to 2002 only and converts only
//! Type C. Every error here names the file, the line and what was expected.
//!
//! Angle systems (CIE 121, LM-63), in the luminaire's frame: aim a (γ = 0, nadir when
//! installed pointing down), length axis l (C = 0), width axis w = l × a (C = 90°):
//! - Type C (C, γ): d = sin γ (cos C l + sin C w) + cos γ a; C ∈ [0, 360), γ ∈ [0, 180].
//! - Type B (H, V): polar axis w; d = cos V (cos H a + sin H l) + sin V w.
//! - Type A (H, V): polar axis l; d = cos V (cos H a + sin H w) + sin V l.

mod ies;
mod ldt;

pub use ies::parse_ies;
pub use ldt::parse_ldt;

use std::fmt;
use std::path::{Path, PathBuf};

/// Which file format and revision a distribution came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotometricFormat {
    /// LM-63-1986 (no header line).
    Ies1986,
    /// `IESNA91`.
    Ies1991,
    /// `IESNA:LM-63-1995`.
    Ies1995,
    /// `IESNA:LM-63-2002`.
    Ies2002,
    /// `IES:LM-63-2019`.
    Ies2019,
    Eulumdat,
}

impl PhotometricFormat {
    pub fn name(self) -> &'static str {
        match self {
            PhotometricFormat::Ies1986 => "IES LM-63-1986",
            PhotometricFormat::Ies1991 => "IES LM-63-1991",
            PhotometricFormat::Ies1995 => "IES LM-63-1995",
            PhotometricFormat::Ies2002 => "IES LM-63-2002",
            PhotometricFormat::Ies2019 => "IES LM-63-2019",
            PhotometricFormat::Eulumdat => "EULUMDAT",
        }
    }
}

/// The goniometer's angle system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotometryType {
    /// C-planes about the vertical (aim) axis; γ from the aim.
    C,
    /// Planes about the horizontal width axis (floodlights).
    B,
    /// Planes about the horizontal length axis.
    A,
}

/// Lamp-output factors against the lamp's tilt (LM-63 `TILT=INCLUDE` or a tilt file).
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// 1: lamp vertical base up or down; 2: horizontal, stays horizontal when tilted about
    /// the length; 3: horizontal, tilts with the luminaire.
    pub lamp_to_luminaire_geometry: u32,
    /// Increasing, degrees.
    pub angles_deg: Vec<f64>,
    pub factors: Vec<f64>,
}

/// A luminous intensity distribution, expanded to the full angle range.
#[derive(Debug, Clone, PartialEq)]
pub struct IntensityDistribution {
    pub file: PathBuf,
    pub format: PhotometricFormat,
    pub photometry: PhotometryType,
    /// Type C: C-plane angles from 0 to 360 inclusive (the last plane repeats the first);
    /// a single plane 0 for rotationally symmetric distributions. Types A/B: H angles,
    /// increasing, from −h to h.
    pub horizontal_deg: Vec<f64>,
    /// Type C: γ, increasing within [0, 180] (light is zero outside). Types A/B: V,
    /// increasing within [−90, 90].
    pub vertical_deg: Vec<f64>,
    /// Candela at (horizontal i, vertical j): `candela[i * vertical_deg.len() + j]`, with
    /// the file's multipliers applied (candela multiplier, ballast factors; for EULUMDAT the
    /// cd/klm values times the lamp flux / 1000).
    pub candela: Vec<f64>,
    /// Total rated lamp flux in lm (lamps × lumens per lamp); `None` for absolute photometry
    /// (LM-63 lumens = −1, e.g. LED luminaires).
    pub lamp_flux_lm: Option<f64>,
    /// Luminous opening: width (along w), length (along l), height, metres. LM-63 negative
    /// values mean round shapes; they are kept as given (absolute values are sizes).
    pub opening_m: [f64; 3],
    pub tilt: Option<Tilt>,
    /// Header keywords (`[MANUFAC]`, `[TEST]` …) or EULUMDAT header lines, for reports.
    pub keywords: Vec<(String, String)>,
}

impl IntensityDistribution {
    pub fn candela_at(&self, h: usize, v: usize) -> f64 {
        self.candela[h * self.vertical_deg.len() + v]
    }
}

/// A file that could not be read: `file:line: message`.
#[derive(Debug, Clone, PartialEq)]
pub struct PhotometricError {
    pub file: PathBuf,
    /// 1-based line; `None` for the whole file (unreadable, ends early).
    pub line: Option<usize>,
    pub message: String,
}

impl fmt::Display for PhotometricError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for PhotometricError {}

/// Reads an `.ies` or `.ldt` file by its extension.
pub fn load_photometric_file(path: &Path) -> Result<IntensityDistribution, PhotometricError> {
    let bytes = std::fs::read(path).map_err(|e| PhotometricError {
        file: path.to_path_buf(),
        line: None,
        message: format!("cannot read the photometric file: {e}"),
    })?;
    // Files from Windows tools are often Latin-1: keep them readable.
    let text = match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("ldt") | Some("eul") => parse_ldt(&text, path),
        _ => parse_ies(&text, path),
    }
}

/// Checks that angles increase strictly; the index of the first offender otherwise.
pub(crate) fn first_non_increasing(angles: &[f64]) -> Option<usize> {
    angles.windows(2).position(|w| w[1] <= w[0]).map(|i| i + 1)
}

/// Expands a Type C table over stored C-planes `c` (first 0, or 90 for LM-63-2019's
/// 90–270 files) to C ∈ [0, 360] by the symmetry the range implies: one plane (rotational),
/// 0–90 (quadrants), 0–180 (C0–C180 plane), 90–270 (C90–C270 plane), 0–360 (none).
/// `rows[i]` holds plane i's values over γ. `Err` names what is wrong.
pub(crate) fn expand_type_c(
    c: &[f64],
    rows: Vec<Vec<f64>>,
) -> Result<(Vec<f64>, Vec<Vec<f64>>), String> {
    let first = c[0];
    let last = *c.last().expect("at least one plane");
    let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
    if c.len() == 1 {
        if !close(first, 0.0) {
            return Err(format!(
                "a single C-plane (rotational symmetry) must be at 0°, found {first}°"
            ));
        }
        return Ok((vec![0.0], rows));
    }
    // Mirror a table over [a, b] about the plane b: values at 2b − C.
    let mirror = |c: &[f64], rows: &[Vec<f64>], about: f64| -> (Vec<f64>, Vec<Vec<f64>>) {
        let mut cs = c.to_vec();
        let mut rs = rows.to_vec();
        for i in (0..c.len() - 1).rev() {
            cs.push(2.0 * about - c[i]);
            rs.push(rows[i].clone());
        }
        (cs, rs)
    };
    match (first, last) {
        (f, l) if close(f, 0.0) && close(l, 360.0) => Ok((c.to_vec(), rows)),
        (f, l) if close(f, 0.0) && close(l, 180.0) => Ok(mirror(c, &rows, 180.0)),
        (f, l) if close(f, 0.0) && close(l, 90.0) => {
            let (c2, r2) = mirror(c, &rows, 90.0);
            Ok(mirror(&c2, &r2, 180.0))
        }
        (f, l) if close(f, 90.0) && close(l, 270.0) => {
            // Symmetric about the C90–C270 plane: I(C) = I(180° − C). Build 270…450 from
            // the mirror, then rotate to 0…360.
            let (c2, r2) = mirror(c, &rows, 270.0);
            // c2 covers 90…450; wrap [360, 450] to [0, 90] and close the circle at 360.
            let mut pairs: Vec<(f64, Vec<f64>)> = c2
                .into_iter()
                .zip(r2)
                .map(|(a, r)| (if a >= 360.0 - 1e-9 { a - 360.0 } else { a }, r))
                .collect();
            pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
            pairs.dedup_by(|a, b| close(a.0, b.0));
            let (mut cs, mut rs): (Vec<f64>, Vec<Vec<f64>>) = pairs.into_iter().unzip();
            if !close(cs[0], 0.0) {
                return Err("internal error: 90–270 expansion does not start at 0°".into());
            }
            cs[0] = 0.0;
            cs.push(360.0);
            rs.push(rs[0].clone());
            Ok((cs, rs))
        }
        _ => Err(format!(
            "the C-planes must run 0–0 (rotational symmetry), 0–90, 0–180, 90–270 or 0–360°, \
             found {first}–{last}°"
        )),
    }
}

#[cfg(test)]
mod tests;
