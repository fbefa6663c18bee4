//! Spectrum references in a scene: a constant, `{"blackbody_k": 3000}`, a CIE illuminant
//! name (`"D65"`), a spectral CSV file (`"spectra/paint.csv"` or `{"file": …, "column": …}`),
//! `{"rgb": [r, g, b]}`, or the name of an entry in the scene's `spectra` section.

use std::path::PathBuf;

use prism_spectrum::data::{canonical_illuminant_name, illuminant, ILLUMINANT_NAMES};
use prism_spectrum::spectrum_file::read_spectral_file;
use prism_spectrum::Tabulated;

use crate::reader::{quoted_list, suggest, Result, V};
use crate::schema::schema;

/// A spectrum as the scene gives it; files are already loaded.
#[derive(Debug, Clone, PartialEq)]
pub enum SpectrumRef {
    /// The same value at every wavelength.
    Constant(f64),
    /// Planck's law at this temperature (relative; strengths normalise it).
    Blackbody { temperature_k: f64 },
    /// A CIE standard illuminant by canonical name (`D65`, `A`, `F11`, `LED-B1`, …).
    Illuminant {
        name: &'static str,
        table: Tabulated,
    },
    /// One column of a spectral CSV file (resolved path).
    File {
        path: PathBuf,
        column: String,
        table: Tabulated,
    },
    /// Linear Rec.709/sRGB-primaries RGB, to be upsampled (Jakob & Hanika 2019).
    Rgb { rgb: [f64; 3] },
}

/// What a spectrum is used for decides which values are valid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SpectrumUse {
    /// Reflectance/transmittance: constants and RGB within [0, 1].
    Reflectance,
    /// Emission, coefficients: anything ≥ 0.
    NonNegative,
    /// Indices of refraction and the like: anything > 0.
    Positive,
}

impl SpectrumUse {
    fn check(self, x: f64) -> std::result::Result<(), &'static str> {
        match self {
            SpectrumUse::Reflectance if !(0.0..=1.0).contains(&x) => Err("a reflectance in [0, 1]"),
            SpectrumUse::NonNegative if x < 0.0 => Err("a value ≥ 0"),
            SpectrumUse::Positive if x <= 0.0 => Err("a value > 0"),
            _ => Ok(()),
        }
    }
}

/// The named spectra a reference may use, in file order.
pub(crate) type NamedSpectra = [(String, SpectrumRef)];

const FORMS: &str = "a number, a spectrum name, a CIE illuminant, a .csv file, \
                     {\"blackbody_k\": K} or {\"rgb\": [r, g, b]}";

pub(crate) fn parse_spectrum(
    v: &V,
    named: &NamedSpectra,
    usage: SpectrumUse,
) -> Result<SpectrumRef> {
    if let Ok(x) = v.f64() {
        usage
            .check(x)
            .map_err(|e| v.err(format!("expected {e}, found {x}")))?;
        return Ok(SpectrumRef::Constant(x));
    }
    if let Ok(s) = v.str() {
        if let Some((_, spectrum)) = named.iter().find(|(n, _)| n == s) {
            return Ok(spectrum.clone());
        }
        if let Some(name) = canonical_illuminant_name(s) {
            return illuminant_ref(v, name);
        }
        if s.contains('.') || s.contains('/') || s.contains('\\') {
            return load_file(v, v, None, usage);
        }
        let candidates = named
            .iter()
            .map(|(n, _)| n.as_str())
            .chain(ILLUMINANT_NAMES.iter().copied());
        let names: Vec<&str> = named.iter().map(|(n, _)| n.as_str()).collect();
        let named_list = if names.is_empty() {
            String::from("the `spectra` section is empty")
        } else {
            format!("named spectra: {}", quoted_list(&names))
        };
        return Err(v.err(format!(
            "unknown spectrum `{s}`: expected a name from `spectra` ({named_list}), \
             a CIE illuminant or a .csv file{}",
            suggest(s, candidates)
        )));
    }
    let o = v.object(schema!("@spectrum")).map_err(|e| {
        if !v.is_object() {
            v.type_err(FORMS)
        } else {
            e
        }
    })?;
    match o.at_most_one(&["blackbody_k", "rgb", "file"])? {
        Some(("blackbody_k", t)) => Ok(SpectrumRef::Blackbody {
            temperature_k: t.positive()?,
        }),
        Some(("rgb", c)) => {
            let rgb = c.numbers::<3>()?;
            for x in rgb {
                usage.check(x).map_err(|e| {
                    c.err(format!("expected components that are each {e}, found {x}"))
                })?;
            }
            Ok(SpectrumRef::Rgb { rgb })
        }
        Some((_, f)) => load_file(v, &f, o.get("column").as_ref(), usage),
        None => Err(v.err(format!(
            "expected one of `blackbody_k`, `rgb` or `file` in a spectrum object ({FORMS})"
        ))),
    }
}

fn illuminant_ref(v: &V, name: &'static str) -> Result<SpectrumRef> {
    let table = illuminant(name)
        .ok_or_else(|| v.err(format!("CIE illuminant `{name}` has no embedded table")))?;
    Ok(SpectrumRef::Illuminant { name, table })
}

fn load_file(v: &V, file: &V, column: Option<&V>, usage: SpectrumUse) -> Result<SpectrumRef> {
    let path = file.asset("spectrum", &["csv", "txt", "spd"])?;
    let columns =
        read_spectral_file(&path).map_err(|e| file.err(format!("cannot load spectrum: {e}")))?;
    let index = match column {
        Some(c) => {
            let name = c.str()?;
            columns.column_index(name).ok_or_else(|| {
                let names: Vec<&str> = columns.names.iter().map(String::as_str).collect();
                c.err(format!(
                    "no column `{name}` in {}, expected one of {}{}",
                    path.display(),
                    quoted_list(&names),
                    suggest(name, names.iter().copied())
                ))
            })?
        }
        None if columns.columns.len() == 1 => 0,
        None => {
            let names: Vec<&str> = columns.names.iter().map(String::as_str).collect();
            return Err(v.err(format!(
                "{} has {} value columns: choose one with {{\"file\": …, \"column\": …}}, one of {}",
                path.display(),
                names.len(),
                quoted_list(&names)
            )));
        }
    };
    // Every spectrum a scene uses (reflectance, emission, coefficients, IOR) is ≥ 0; a
    // reflectance is ≤ 1 (as constants and RGB are); and every table must reach the
    // wavelengths the renderer samples, or it is silently black.
    let at_file = |e: prism_spectrum::error::SpectrumFileError| {
        file.err(format!("cannot load spectrum: {e}"))
    };
    columns
        .require_non_negative(index, &path, "spectral values")
        .map_err(at_file)?;
    match usage {
        SpectrumUse::Reflectance => columns
            .require_at_most_one(index, &path, "a reflectance")
            .map_err(at_file)?,
        SpectrumUse::NonNegative | SpectrumUse::Positive => {}
    }
    columns
        .require_coverage(&path, (360.0, 830.0))
        .map_err(at_file)?;
    Ok(SpectrumRef::File {
        path,
        column: columns.names[index].clone(),
        table: columns.table(index),
    })
}
