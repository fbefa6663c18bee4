//! The CIE tables and reference reflectances Prism ships (spectra/*.csv, embedded), parsed
//! once on first use: colour-matching functions, V(λ), V'(λ), CIE illuminants and the
//! ColorChecker patches, with name lookup and typo suggestions.

use std::collections::HashMap;
use std::path::Path;
use std::sync::OnceLock;

use crate::embedded_files::EMBEDDED_SPECTRA;
use crate::names::did_you_mean;
use crate::spectrum_file::{parse_spectral_text, SpectralColumns};
use crate::table::{DenseSpectrum, Tabulated};

/// CIE standard colorimetric observers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Observer {
    /// CIE 1931 2° standard observer.
    Cie1931,
    /// CIE 1964 10° standard observer.
    Cie1964,
}

impl Observer {
    pub fn name(self) -> &'static str {
        match self {
            Observer::Cie1931 => "cie1931",
            Observer::Cie1964 => "cie1964",
        }
    }

    fn file_stem(self) -> &'static str {
        match self {
            Observer::Cie1931 => "cie1931-2deg",
            Observer::Cie1964 => "cie1964-10deg",
        }
    }
}

/// Colour-matching functions x̄, ȳ, z̄ on the 1 nm grid 360–830 nm.
#[derive(Debug, Clone)]
pub struct Cmfs {
    pub x_bar: DenseSpectrum,
    pub y_bar: DenseSpectrum,
    pub z_bar: DenseSpectrum,
}

/// Illuminants shipped in spectra/, by their CIE names.
pub const ILLUMINANT_NAMES: &[&str] = &[
    "A", "D50", "D55", "D60", "D65", "D75", "E", "F1", "F2", "F3", "F4", "F5", "F6", "F7", "F8",
    "F9", "F10", "F11", "F12", "LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1",
    "LED-RGB1", "LED-V1", "LED-V2",
];

const COLORCHECKER_STEM: &str = "colorchecker";

fn parsed_files() -> &'static HashMap<&'static str, SpectralColumns> {
    static FILES: OnceLock<HashMap<&'static str, SpectralColumns>> = OnceLock::new();
    FILES.get_or_init(|| {
        EMBEDDED_SPECTRA
            .iter()
            .map(|(stem, text)| {
                let path = format!("spectra/{stem}.csv");
                let cols = parse_spectral_text(text, Path::new(&path))
                    .unwrap_or_else(|e| panic!("embedded data file is malformed: {e}"));
                (*stem, cols)
            })
            .collect()
    })
}

/// Every embedded file stem (spectra/<stem>.csv).
pub fn embedded_stems() -> impl Iterator<Item = &'static str> {
    EMBEDDED_SPECTRA.iter().map(|(stem, _)| *stem)
}

/// The parsed columns of spectra/<stem>.csv (exact stem, case-insensitive).
pub fn embedded_file(stem: &str) -> Option<&'static SpectralColumns> {
    let files = parsed_files();
    embedded_stems()
        .find(|s| s.eq_ignore_ascii_case(stem))
        .and_then(|s| files.get(s))
}

/// The colour-matching functions of `observer`.
pub fn cmfs(observer: Observer) -> &'static Cmfs {
    static CIE1931: OnceLock<Cmfs> = OnceLock::new();
    static CIE1964: OnceLock<Cmfs> = OnceLock::new();
    let cell = match observer {
        Observer::Cie1931 => &CIE1931,
        Observer::Cie1964 => &CIE1964,
    };
    cell.get_or_init(|| {
        let cols = embedded_file(observer.file_stem()).expect("CMF table is embedded");
        Cmfs {
            x_bar: cols.table(0).to_dense(),
            y_bar: cols.table(1).to_dense(),
            z_bar: cols.table(2).to_dense(),
        }
    })
}

/// CIE 1924 photopic luminous efficiency V(λ).
pub fn photopic_efficiency() -> &'static DenseSpectrum {
    static V: OnceLock<DenseSpectrum> = OnceLock::new();
    V.get_or_init(|| {
        embedded_file("cie1924-photopic")
            .unwrap()
            .table(0)
            .to_dense()
    })
}

/// CIE 1951 scotopic luminous efficiency V'(λ).
pub fn scotopic_efficiency() -> &'static DenseSpectrum {
    static V: OnceLock<DenseSpectrum> = OnceLock::new();
    V.get_or_init(|| {
        embedded_file("cie1951-scotopic")
            .unwrap()
            .table(0)
            .to_dense()
    })
}

/// Canonical CIE name of an illuminant: case-insensitive, `FL2` accepted for `F2`,
/// an optional `cie-`/`cie ` prefix ignored.
pub fn canonical_illuminant_name(name: &str) -> Option<&'static str> {
    let trimmed = name.trim();
    let lower = trimmed.to_ascii_lowercase();
    let stripped = lower
        .strip_prefix("cie-")
        .or_else(|| lower.strip_prefix("cie "))
        .or_else(|| lower.strip_prefix("cie_"))
        .unwrap_or(&lower);
    let stripped = match stripped.strip_prefix("fl") {
        Some(rest) if rest.chars().all(|c| c.is_ascii_digit()) && !rest.is_empty() => {
            format!("f{rest}")
        }
        _ => stripped.to_string(),
    };
    ILLUMINANT_NAMES
        .iter()
        .copied()
        .find(|n| n.eq_ignore_ascii_case(&stripped))
}

/// The relative spectral power distribution of a CIE illuminant, as tabulated.
pub fn illuminant(name: &str) -> Option<Tabulated> {
    let canonical = canonical_illuminant_name(name)?;
    embedded_file(canonical).map(|c| c.table(0))
}

/// " (did you mean …?)" for an unknown illuminant name.
pub fn illuminant_suggestion(name: &str) -> String {
    did_you_mean(name, ILLUMINANT_NAMES.iter().copied())
}

/// Names of the 24 ColorChecker patches, in chart order (row by row from dark skin).
pub fn colorchecker_patch_names() -> &'static [String] {
    &embedded_file(COLORCHECKER_STEM).unwrap().names
}

/// Looks up a ColorChecker patch by name (case-insensitive; a unique prefix such as
/// `white` or `neutral 8` suffices) or by its 1-based chart index.
pub fn colorchecker_patch_index(name: &str) -> Result<usize, String> {
    let names = colorchecker_patch_names();
    let wanted = name.trim().to_lowercase();
    if let Ok(number) = wanted.parse::<usize>() {
        if (1..=names.len()).contains(&number) {
            return Ok(number - 1);
        }
        return Err(format!(
            "ColorChecker patch number {number} is out of range: expected 1 to {}",
            names.len()
        ));
    }
    if let Some(i) = names.iter().position(|n| n.to_lowercase() == wanted) {
        return Ok(i);
    }
    let prefixed: Vec<usize> = (0..names.len())
        .filter(|&i| names[i].to_lowercase().starts_with(&wanted))
        .collect();
    if prefixed.len() == 1 {
        return Ok(prefixed[0]);
    }
    Err(format!(
        "unknown ColorChecker patch `{name}`{}; patches are: {}",
        did_you_mean(name, names.iter().map(String::as_str)),
        names.join(", ")
    ))
}

/// The reflectance of ColorChecker patch `index` (0-based), as tabulated.
pub fn colorchecker_patch(index: usize) -> Tabulated {
    embedded_file(COLORCHECKER_STEM).unwrap().table(index)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_file_parses_with_a_provenance_header() {
        for (stem, text) in EMBEDDED_SPECTRA {
            assert!(text.starts_with("# "), "{stem} lacks a provenance header");
            assert!(
                text.contains("colour-science"),
                "{stem} does not name its exporter"
            );
            assert!(embedded_file(stem).is_some());
        }
    }

    #[test]
    fn observers_cover_360_to_830_nm_and_peak_where_the_cie_says() {
        let c = cmfs(Observer::Cie1931);
        // ȳ(555 nm) = 1.0 exactly in CIE 1931; 1964 ȳ10 peaks at 1.0 near 555–557 nm.
        assert!((c.y_bar.eval(555.0) - 1.0).abs() < 1e-12);
        assert!(c.x_bar.values()[0] > 0.0 && c.x_bar.values()[470] > 0.0);
        let v = photopic_efficiency();
        assert!((v.eval(555.0) - 1.0).abs() < 1e-12);
        assert!((scotopic_efficiency().eval(507.0) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn illuminant_names_resolve_with_aliases_and_suggest_on_typos() {
        assert_eq!(canonical_illuminant_name("d65"), Some("D65"));
        assert_eq!(canonical_illuminant_name("FL11"), Some("F11"));
        assert_eq!(canonical_illuminant_name("cie-a"), Some("A"));
        assert_eq!(canonical_illuminant_name("led-b3"), Some("LED-B3"));
        assert!(illuminant("D66").is_none());
        assert!(illuminant_suggestion("D66").contains("D65"));
        for name in ILLUMINANT_NAMES {
            assert!(illuminant(name).is_some(), "{name} missing");
        }
    }

    #[test]
    fn colorchecker_patches_resolve_by_name_prefix_and_number() {
        assert_eq!(colorchecker_patch_names().len(), 24);
        assert_eq!(colorchecker_patch_index("dark skin"), Ok(0));
        assert_eq!(colorchecker_patch_index("Dark Skin"), Ok(0));
        assert_eq!(colorchecker_patch_index("white"), Ok(18));
        assert_eq!(colorchecker_patch_index("24"), Ok(23));
        let e = colorchecker_patch_index("dark skn").unwrap_err();
        assert!(e.contains("`dark skin`"), "{e}");
        assert!(colorchecker_patch_index("neutral").is_err()); // ambiguous prefix
    }
}
