//! pbrt-v4 spectra → Prism spectrum references: numbers, `rgb`, `blackbody`, inline
//! (λ, value) pairs and .spd files (written as CSV side files), and pbrt's named spectra
//! mapped to Prism's tables (`stdillum-*` → CIE illuminants, `metal-*` → Prism's metals,
//! `glass-*` → Sellmeier coefficients).
//!
//! Light strength (pbrt-v4 lights.cpp): pbrt divides a light's spectrum by its photometric
//! integral (for RGB: the colour space's illuminant's), so `scale` 1 means luminance 1 for
//! non-RGB spectra, and RGB keeps its values. Prism's emitter RGB is the sigmoid × the
//! gamut's white normalised to Y = 1 (the same as pbrt's); other spectra get the factor
//! ∫ȳ / ∫S·ȳ here.

use prism_spectrum::colorimetry::tristimulus_sums;
use prism_spectrum::table::DenseSpectrum;
use prism_spectrum::Observer;
use serde_json::{json, Value};

use crate::error::ImportError;
use crate::output::SceneBuilder;
use crate::pbrt::params::{Param, ParamValue};

/// pbrt's metals with a Prism table.
pub const METALS: [&str; 4] = ["Ag", "Al", "Au", "Cu"];

/// Schott catalogue Sellmeier coefficients (B, C in µm²) of the glasses pbrt names; pbrt
/// tabulates the same glasses from the same catalogue.
const GLASSES: [(&str, [f64; 3], [f64; 3]); 2] = [
    (
        "glass-BK7",
        [1.03961212, 0.231792344, 1.01046945],
        [0.00600069867, 0.0200179144, 103.560653],
    ),
    (
        "glass-SF11",
        [1.73759695, 0.313747346, 1.89878101],
        [0.013188707, 0.0623068142, 155.23629],
    ),
];

/// A Prism spectrum and, for emission, how to evaluate it (for pbrt's normalisation).
pub struct PbrtSpectrum {
    pub value: Value,
    /// True for RGB (pbrt does not normalise it by its own luminance).
    pub is_rgb: bool,
    /// Values on Prism's 1 nm grid (360–830 nm) when known (None for RGB).
    pub dense: Option<DenseSpectrum>,
}

pub fn spectrum(out: &mut SceneBuilder, p: &Param) -> Result<PbrtSpectrum, ImportError> {
    let numbers = || -> Result<Vec<f64>, ImportError> {
        p.values
            .iter()
            .map(|v| match v {
                ParamValue::Number(x) => Ok(*x),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"{} {}\": expected numbers", p.ty, p.name),
                )),
            })
            .collect()
    };
    match p.ty.as_str() {
        "float" => {
            let xs = numbers()?;
            match xs.as_slice() {
                [x] => Ok(constant(*x)),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"float {}\": expected one number", p.name),
                )),
            }
        }
        "rgb" => {
            let xs = numbers()?;
            match xs.as_slice() {
                [r, g, b] => Ok(PbrtSpectrum {
                    value: json!({ "rgb": [r, g, b] }),
                    is_rgb: true,
                    dense: None,
                }),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"rgb {}\": expected 3 numbers", p.name),
                )),
            }
        }
        "blackbody" => {
            let xs = numbers()?;
            match xs.as_slice() {
                [t] if *t > 0.0 => Ok(PbrtSpectrum {
                    value: json!({ "blackbody_k": t }),
                    is_rgb: false,
                    dense: Some(DenseSpectrum::from_fn(|l| {
                        prism_spectrum::blackbody::blackbody_normalized(l, *t)
                    })),
                }),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"blackbody {}\": expected one temperature > 0 K", p.name),
                )),
            }
        }
        "spectrum" => {
            match p.values.as_slice() {
                [ParamValue::Str(s)] => named_or_file(out, p, s),
                _ => {
                    let xs = numbers()?;
                    match xs.as_slice() {
                    [x] => Ok(constant(*x)),
                    _ if xs.len() % 2 == 0 => {
                        let pairs: Vec<(f64, f64)> = xs.chunks(2).map(|c| (c[0], c[1])).collect();
                        Ok(side_csv(out, &pairs))
                    }
                    _ => Err(ImportError::at(
                        &p.at,
                        format!("\"spectrum {}\": expected (wavelength, value) pairs, found {} numbers", p.name, xs.len()),
                    )),
                }
                }
            }
        }
        other => Err(ImportError::at(
            &p.at,
            format!(
                "\"{other} {}\": expected a float, rgb, blackbody or spectrum parameter",
                p.name
            ),
        )),
    }
}

fn constant(x: f64) -> PbrtSpectrum {
    PbrtSpectrum {
        value: json!(x),
        is_rgb: false,
        dense: Some(DenseSpectrum::constant(x)),
    }
}

fn named_or_file(out: &mut SceneBuilder, p: &Param, s: &str) -> Result<PbrtSpectrum, ImportError> {
    if let Some(illum) = s.strip_prefix("stdillum-") {
        let name = prism_spectrum::data::canonical_illuminant_name(illum).ok_or_else(|| {
            ImportError::at(
                &p.at,
                format!("named spectrum \"{s}\": Prism has no CIE illuminant {illum}"),
            )
        })?;
        let table = prism_spectrum::data::illuminant(name).ok_or_else(|| {
            ImportError::at(&p.at, format!("named spectrum \"{s}\": no embedded table"))
        })?;
        return Ok(PbrtSpectrum {
            value: json!(name),
            is_rgb: false,
            dense: Some(DenseSpectrum::from_fn(|l| table.eval(l))),
        });
    }
    if let Some((_, b, c)) = GLASSES.iter().find(|(n, _, _)| *n == s) {
        return Ok(PbrtSpectrum {
            value: json!({ "sellmeier": { "b": b, "c_um2": c } }),
            is_rgb: false,
            dense: None,
        });
    }
    if s.starts_with("metal-")
        || s.starts_with("glass-")
        || s.starts_with("canon")
        || s.starts_with("nikon")
        || s.starts_with("sony")
        || s.starts_with("illum-")
    {
        return Err(ImportError::at(
            &p.at,
            format!(
                "named spectrum \"{s}\": Prism has tables for stdillum-*, glass-BK7, glass-SF11 and the metals {} (as conductor eta/k pairs)",
                METALS.join(", ")
            ),
        ));
    }
    let path =
        p.at.file
            .parent()
            .unwrap_or(std::path::Path::new(""))
            .join(s);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        ImportError::at(
            &p.at,
            format!(
                "spectrum file {}: {e} (or an unknown named spectrum)",
                path.display()
            ),
        )
    })?;
    let mut xs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        for t in line
            .split('#')
            .next()
            .unwrap_or("")
            .split(|c: char| c.is_whitespace() || c == ',')
        {
            if t.is_empty() {
                continue;
            }
            xs.push(t.parse::<f64>().map_err(|_| ImportError {
                file: path.clone(),
                position: Some((i as u32 + 1, 1)),
                message: format!("expected numbers (wavelength value pairs), found `{t}`"),
            })?);
        }
    }
    if xs.len() % 2 != 0 || xs.is_empty() {
        return Err(ImportError::file(
            &path,
            "expected (wavelength, value) pairs",
        ));
    }
    let pairs: Vec<(f64, f64)> = xs.chunks(2).map(|c| (c[0], c[1])).collect();
    Ok(side_csv(out, &pairs))
}

fn side_csv(out: &mut SceneBuilder, pairs: &[(f64, f64)]) -> PbrtSpectrum {
    let mut text =
        String::from("# written by prism import from a pbrt spectrum\nwavelength_nm,value\n");
    for (l, v) in pairs {
        text.push_str(&format!("{l},{v}\n"));
    }
    let n = out.side_files.len();
    let path = out.add_side_file(&format!("spectrum-{n}.csv"), text.into_bytes());
    let interp = |l: f64| -> f64 {
        match pairs.iter().position(|(w, _)| *w >= l) {
            Some(0) => pairs[0].1,
            Some(i) => {
                let (w0, v0) = pairs[i - 1];
                let (w1, v1) = pairs[i];
                v0 + (v1 - v0) * (l - w0) / (w1 - w0)
            }
            None => pairs[pairs.len() - 1].1,
        }
    };
    PbrtSpectrum {
        value: json!(path),
        is_rgb: false,
        dense: Some(DenseSpectrum::from_fn(interp)),
    }
}

/// Σȳ Δλ over Prism's grid: ∫S·ȳ of a spectrum of pbrt's luminance 1 once
/// [`emission_factor`] is applied.
pub fn unit_luminance_sum() -> f64 {
    tristimulus_sums(&DenseSpectrum::constant(1.0), Observer::Cie1931).y
}

/// The factor that gives a pbrt light's spectrum pbrt's strength in Prism (module docs).
pub fn emission_factor(s: &PbrtSpectrum) -> Option<f64> {
    if s.is_rgb {
        return Some(1.0);
    }
    let dense = s.dense.as_ref()?;
    let y = tristimulus_sums(dense, Observer::Cie1931).y;
    (y > 0.0).then(|| unit_luminance_sum() / y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// pbrt normalises a light spectrum to luminance 1 (× scale): with the factor, Prism's
    /// spectrum has ∫S·ȳ = ∫ȳ (pixel luminance 1), whatever the spectrum's own level.
    #[test]
    fn emission_factor_gives_unit_luminance_and_leaves_rgb_alone() {
        let y_bar = tristimulus_sums(&DenseSpectrum::constant(1.0), Observer::Cie1931).y;
        for s in [constant(3.0), constant(0.25)] {
            let f = emission_factor(&s).unwrap();
            let y = tristimulus_sums(s.dense.as_ref().unwrap(), Observer::Cie1931).y;
            assert!((f * y / y_bar - 1.0).abs() < 1e-12);
        }
        assert_eq!(emission_factor(&constant(2.0)), Some(0.5));
        let rgb = PbrtSpectrum {
            value: json!({"rgb": [1, 2, 3]}),
            is_rgb: true,
            dense: None,
        };
        assert_eq!(emission_factor(&rgb), Some(1.0));
        assert_eq!(emission_factor(&constant(0.0)), None);
    }
}
