//! The named metals of the scene format (`prism_scene::METAL_NAMES`): complex indices of
//! refraction η + ik from spectra/metals/<symbol>.csv, embedded at build time. Each file's
//! header names its measurement (Johnson & Christy 1972 for Ag, Au, Cu; Johnson & Christy
//! 1974 for Cr, Fe, Ni, Ti; Rakić 1995 for Al; Rakić et al. 1998 Brendel–Bormann fit for
//! Pt) and how it was exported (tools/export_metals.py, from the refractiveindex.info
//! database). Every table covers at least 292–900 nm, so 360–830 nm interpolates linearly
//! between measured samples and never extrapolates.

use std::path::Path;
use std::sync::OnceLock;

use prism_spectrum::spectrum_file::{parse_spectral_text, SpectralColumns};
use prism_spectrum::{DenseSpectrum, Spectrum, Tabulated};

/// (chemical symbol, file text) of every shipped metal, in `METAL_NAMES` order.
const METAL_FILES: [(&str, &str); 9] = [
    ("Ag", include_str!("../../../../spectra/metals/Ag.csv")),
    ("Al", include_str!("../../../../spectra/metals/Al.csv")),
    ("Au", include_str!("../../../../spectra/metals/Au.csv")),
    ("Cr", include_str!("../../../../spectra/metals/Cr.csv")),
    ("Cu", include_str!("../../../../spectra/metals/Cu.csv")),
    ("Fe", include_str!("../../../../spectra/metals/Fe.csv")),
    ("Ni", include_str!("../../../../spectra/metals/Ni.csv")),
    ("Pt", include_str!("../../../../spectra/metals/Pt.csv")),
    ("Ti", include_str!("../../../../spectra/metals/Ti.csv")),
];

/// η(λ) and k(λ) of one metal as tabulated (linear interpolation between samples).
#[derive(Clone, Debug, PartialEq)]
pub struct MetalOptics {
    pub eta: Tabulated,
    pub k: Tabulated,
}

impl MetalOptics {
    /// Normal-incidence reflectance F₀(λ) = ((η−1)² + k²)/((η+1)² + k²) (Born & Wolf §14.2
    /// eq. 25) on the 1 nm grid 360–830 nm.
    pub fn normal_reflectance(&self) -> DenseSpectrum {
        DenseSpectrum::from_fn(|wl| {
            let (n, k) = (self.eta.eval(wl), self.k.eval(wl));
            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
        })
    }

    /// The runtime spectra (η, k), piecewise linear over the measured samples.
    pub fn spectra(&self) -> (Spectrum, Spectrum) {
        (
            Spectrum::from_tabulated(&self.eta).expect("metal tables are validated by tests"),
            Spectrum::from_tabulated(&self.k).expect("metal tables are validated by tests"),
        )
    }
}

fn parsed() -> &'static [(&'static str, SpectralColumns); 9] {
    static PARSED: OnceLock<[(&'static str, SpectralColumns); 9]> = OnceLock::new();
    PARSED.get_or_init(|| {
        METAL_FILES.map(|(symbol, text)| {
            let path = format!("spectra/metals/{symbol}.csv");
            let columns = parse_spectral_text(text, Path::new(&path))
                .unwrap_or_else(|e| panic!("embedded metal table is malformed: {e}"));
            (symbol, columns)
        })
    })
}

/// Every shipped metal's chemical symbol.
pub fn metal_symbols() -> impl Iterator<Item = &'static str> {
    METAL_FILES.iter().map(|(s, _)| *s)
}

/// η and k of the metal `symbol` (exact chemical symbol, e.g. `Au`), or `None` if Prism
/// ships no table for it.
pub fn metal_optics(symbol: &str) -> Option<MetalOptics> {
    let (_, columns) = parsed().iter().find(|(s, _)| *s == symbol)?;
    let eta = columns.column_index("eta")?;
    let k = columns.column_index("k")?;
    Some(MetalOptics {
        eta: columns.table(eta),
        k: columns.table(k),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_scene::material::METAL_NAMES;

    #[test]
    fn every_scene_metal_name_has_a_valid_table_covering_the_visible_range() {
        let shipped: Vec<&str> = metal_symbols().collect();
        assert_eq!(shipped, METAL_NAMES.to_vec());
        for symbol in METAL_NAMES {
            let m = metal_optics(symbol).unwrap_or_else(|| panic!("{symbol}"));
            let wl = m.eta.wavelengths_nm();
            assert!(
                wl[0] <= 360.0 && *wl.last().unwrap() >= 830.0,
                "{symbol}: {wl:?}"
            );
            assert_eq!(wl, m.k.wavelengths_nm());
            assert!(
                m.eta.values().iter().all(|&v| v.is_finite() && v > 0.0),
                "{symbol}"
            );
            assert!(
                m.k.values().iter().all(|&v| v.is_finite() && v >= 0.0),
                "{symbol}"
            );
            // Metals reflect: F₀ between 0.3 (gold and copper in the violet) and 1
            // everywhere in 360–830 nm.
            let f0 = m.normal_reflectance();
            assert!(
                f0.values().iter().all(|&r| (0.3..1.0).contains(&r)),
                "{symbol}: F₀ from {} to {}",
                f0.values().iter().cloned().fold(f64::INFINITY, f64::min),
                f0.values().iter().cloned().fold(0.0, f64::max)
            );
            eprintln!(
                "{symbol}: F₀ 450/550/650 nm = {:.3}/{:.3}/{:.3}",
                f0.eval(450.0),
                f0.eval(550.0),
                f0.eval(650.0)
            );
            let text = METAL_FILES.iter().find(|(s, _)| *s == symbol).unwrap().1;
            assert!(text.starts_with(&format!("# {symbol}:")) && text.contains("# source:"));
        }
        assert!(metal_optics("Xx").is_none());
    }

    #[test]
    fn gold_is_yellow_with_the_reflectance_of_its_table() {
        let au = metal_optics("Au").unwrap();
        // Johnson & Christy 1972 around 550 nm: the two samples bracketing it, interpolated
        // as the table says, then F₀ = ((η−1)² + k²)/((η+1)² + k²).
        let (n, k) = (au.eta.eval(550.0), au.k.eval(550.0));
        let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let f0 = au.normal_reflectance();
        assert!((f0.eval(550.0) - expected).abs() < 1e-12);
        assert!(
            (0.75..0.85).contains(&expected),
            "Au F₀(550 nm) = {expected}"
        );
        // The textbook picture: ≈ 0.4 in the blue, ≈ 0.8–0.9 from 560–600 nm, > 0.93 in
        // the red (Johnson & Christy 1972 fig. 6).
        assert!(f0.eval(450.0) < 0.45, "{}", f0.eval(450.0));
        assert!((0.8..0.95).contains(&f0.eval(600.0)), "{}", f0.eval(600.0));
        assert!(f0.eval(700.0) > 0.93, "{}", f0.eval(700.0));
        // Silver is bright and neutral, aluminium ≈ 0.9.
        let ag = metal_optics("Ag").unwrap().normal_reflectance();
        assert!(ag.eval(450.0) > 0.9 && ag.eval(650.0) > 0.95);
        let al = metal_optics("Al").unwrap().normal_reflectance();
        assert!((0.85..0.95).contains(&al.eval(550.0)), "{}", al.eval(550.0));
    }
}
