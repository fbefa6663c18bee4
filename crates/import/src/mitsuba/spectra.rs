//! Mitsuba spectra → Prism spectrum references: `<float>` and `<spectrum value="x">` constants,
//! `<rgb>` (Prism upsamples RGB as Mitsuba's spectral variants do: a bounded sigmoid for
//! reflectances; for emitters the sigmoid × D65, Mitsuba's `d65` plugin and Prism's
//! illuminant RGB alike), `<spectrum value="λ:v, …">` and `filename` (written as a CSV side
//! file) and `blackbody` (Mitsuba's absolute radiance: Prism's relative blackbody × its
//! peak radiance, returned as a scale).

use serde_json::{json, Value};

use crate::error::ImportError;
use crate::mitsuba::props::{number, number_list, parse_number, Props};
use crate::mitsuba::xml::Element;
use crate::output::SceneBuilder;

/// What a spectrum describes (decides whether a scale may be returned).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpectrumRole {
    Reflectance,
    Emission,
    Coefficient,
}

/// A Prism spectrum reference and the radiometric factor an emitter must apply to it.
pub struct ImportedSpectrum {
    pub spectrum: Value,
    pub scale: f64,
}

pub fn spectrum(
    out: &mut SceneBuilder,
    el: &Element,
    role: SpectrumRole,
) -> Result<ImportedSpectrum, ImportError> {
    let plain = |spectrum: Value| {
        Ok(ImportedSpectrum {
            spectrum,
            scale: 1.0,
        })
    };
    match el.tag.as_str() {
        "float" | "integer" => plain(json!(number(el)?)),
        "rgb" => {
            let v = el.require_attr("value")?;
            let xs = number_list(el, v)?;
            match xs.as_slice() {
                [r, g, b] => plain(json!({ "rgb": [r, g, b] })),
                [x] => plain(json!({ "rgb": [x, x, x] })),
                _ => Err(ImportError::at(
                    &el.at,
                    format!("<rgb>: expected 3 numbers (r, g, b), found \"{v}\""),
                )),
            }
        }
        "spectrum" => match el.attr("type") {
            Some("blackbody") => {
                let props = Props::new(el);
                let t = props.float("temperature")?.ok_or_else(|| {
                    ImportError::at(
                        &el.at,
                        "blackbody spectrum: needs <float name=\"temperature\">",
                    )
                })?;
                props.finish("spectrum blackbody", &mut out.unsupported);
                if t <= 0.0 {
                    return Err(ImportError::at(
                        &el.at,
                        format!("blackbody temperature: expected > 0 K, found {t}"),
                    ));
                }
                let scale = match role {
                    SpectrumRole::Emission => prism_spectrum::blackbody::blackbody_peak_radiance(t),
                    SpectrumRole::Reflectance | SpectrumRole::Coefficient => {
                        out.unsupported.note(
                            "blackbody spectrum outside an emitter",
                            "imported relative to its peak (Prism's blackbody_k), not in absolute units",
                            &el.at,
                        );
                        1.0
                    }
                };
                Ok(ImportedSpectrum {
                    spectrum: json!({ "blackbody_k": t }),
                    scale,
                })
            }
            Some("d65") => {
                let props = Props::new(el);
                let scale = props.float_or("scale", 1.0)?;
                props.finish("spectrum d65", &mut out.unsupported);
                // Mitsuba's d65 is normalised to luminance 1, as is Prism's RGB white (1, 1, 1)
                // for emitters (the gamut's white illuminant); Prism's "D65" is the raw table.
                Ok(ImportedSpectrum {
                    spectrum: json!({ "rgb": [1.0, 1.0, 1.0] }),
                    scale,
                })
            }
            Some(other) => Err(ImportError::at(
                &el.at,
                format!(
                    "<spectrum type=\"{other}\">: expected blackbody or d65, or a value/filename"
                ),
            )),
            None => {
                if let Some(v) = el.attr("value") {
                    if let Some(x) = parse_number(v.trim()) {
                        return plain(json!(x));
                    }
                    let pairs = parse_pairs(el, v)?;
                    return plain(side_csv(out, &pairs));
                }
                if let Some(file) = el.attr("filename") {
                    let path = el.base_dir().join(file);
                    let text = std::fs::read_to_string(&path).map_err(|e| {
                        ImportError::at(&el.at, format!("spectrum file {}: {e}", path.display()))
                    })?;
                    let pairs = parse_spd(&path, &text)?;
                    return plain(side_csv(out, &pairs));
                }
                Err(ImportError::at(
                    &el.at,
                    "<spectrum>: expected `value` (a number or \"λ:v, …\") or `filename`",
                ))
            }
        },
        other => Err(ImportError::at(
            &el.at,
            format!(
                "parameter `{}`: expected <float>, <rgb> or <spectrum>, found <{other}>",
                el.attr("name").unwrap_or("?")
            ),
        )),
    }
}

/// `"400:0.1, 500:0.2"` → (λ nm, value) pairs.
fn parse_pairs(el: &Element, v: &str) -> Result<Vec<(f64, f64)>, ImportError> {
    v.split(',')
        .map(|p| {
            let (l, x) = p.split_once(':').unwrap_or((p, ""));
            match (parse_number(l.trim()), parse_number(x.trim())) {
                (Some(l), Some(x)) => Ok((l, x)),
                _ => Err(ImportError::at(
                    &el.at,
                    format!(
                        "<spectrum value>: expected \"wavelength_nm:value\" pairs, found \"{}\"",
                        p.trim()
                    ),
                )),
            }
        })
        .collect()
}

/// Mitsuba's `.spd`: `wavelength value` per line, `#` comments.
fn parse_spd(path: &std::path::Path, text: &str) -> Result<Vec<(f64, f64)>, ImportError> {
    let mut pairs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let xs: Vec<Option<f64>> = line.split_whitespace().map(parse_number).collect();
        match xs.as_slice() {
            [Some(l), Some(v)] => pairs.push((*l, *v)),
            _ => {
                return Err(ImportError {
                    file: path.to_path_buf(),
                    position: Some((i as u32 + 1, 1)),
                    message: format!("expected `wavelength_nm value`, found \"{line}\""),
                })
            }
        }
    }
    Ok(pairs)
}

fn side_csv(out: &mut SceneBuilder, pairs: &[(f64, f64)]) -> Value {
    let mut text =
        String::from("# written by prism import from a Mitsuba spectrum\nwavelength_nm,value\n");
    for (l, v) in pairs {
        text.push_str(&format!("{l},{v}\n"));
    }
    let n = out.side_files.len();
    json!(out.add_side_file(&format!("spectrum-{n}.csv"), text.into_bytes()))
}
