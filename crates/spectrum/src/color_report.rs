//! The colorimetry report of one spectrum (`prism color` and the Python package's
//! `prism.color`): XYZ, xy, CCT/Duv (Ohno 2013), CIELAB, linear and encoded sRGB, and the
//! resolution of a spectrum argument (CSV file, embedded name, ColorChecker patch,
//! blackbody) with the messages both front ends print.

use std::path::Path;

use glam::DVec3;
use serde_json::{json, Value};

use crate::adaptation::{adaptation_matrix, AdaptationMethod};
use crate::cct::{blackbody_dense, xyz_to_cct_ohno2013};
use crate::colorimetry::{
    emission_to_xyz_cd_per_m2, illuminant_white_xyz, reflectance_to_xyz, xyz_to_lab, xyz_to_xy,
};
use crate::data::{
    canonical_illuminant_name, colorchecker_patch, colorchecker_patch_index,
    colorchecker_patch_names, embedded_file, embedded_stems, Observer,
};
use crate::names::did_you_mean;
use crate::rgb_space::RgbColorSpace;
use crate::spectrum_file::read_single_spectrum;
use crate::table::{DenseSpectrum, Tabulated};

/// What a spectrum argument stands for, for validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumRole {
    Reflectance,
    Emission,
    Illuminant,
}

impl SpectrumRole {
    /// The description of what must not be negative, or `None` (reflectances may be:
    /// measurement noise near 0).
    fn must_be_non_negative(self) -> Option<&'static str> {
        match self {
            SpectrumRole::Reflectance => None,
            SpectrumRole::Emission => Some("emission (spectral radiance)"),
            SpectrumRole::Illuminant => Some("an illuminant's spectral power"),
        }
    }
}

pub const COLORCHECKER_PREFIX: &str = "colorchecker:";
pub const BLACKBODY_PREFIX: &str = "blackbody:";

fn looks_like_path(text: &str) -> bool {
    text.contains('/') || text.contains('\\') || text.contains('.')
}

/// Resolves `FILE.csv|NAME|colorchecker:PATCH|blackbody:K` to a table and a label for the
/// report; `flag` (e.g. `--spectrum`) starts every message.
pub fn resolve_spectrum(
    spec: &str,
    role: SpectrumRole,
    flag: &str,
) -> Result<(Tabulated, String), String> {
    let lower = spec.to_lowercase();
    if let Some(patch) = lower.strip_prefix(COLORCHECKER_PREFIX) {
        let index = colorchecker_patch_index(patch).map_err(|e| format!("{flag} {spec}: {e}"))?;
        let name = &colorchecker_patch_names()[index];
        return Ok((colorchecker_patch(index), format!("colorchecker:{name}")));
    }
    if let Some(temperature) = lower.strip_prefix(BLACKBODY_PREFIX) {
        let temperature_k = temperature
            .trim()
            .trim_end_matches('k')
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|t| t.is_finite() && *t > 0.0)
            .ok_or_else(|| {
                format!("{flag} {spec}: expected `blackbody:<temperature in K>` with a positive temperature, e.g. `blackbody:5000`")
            })?;
        let dense = blackbody_dense(temperature_k);
        let wavelengths: Vec<f64> = (0..dense.values().len())
            .map(DenseSpectrum::wavelength_nm)
            .collect();
        let table = Tabulated::new(wavelengths, dense.values().to_vec())
            .expect("the 1 nm grid is increasing");
        return Ok((table, format!("blackbody:{temperature_k}K")));
    }
    let path = Path::new(spec);
    if path.is_file() {
        let (table, columns) = read_single_spectrum(path).map_err(|e| e.to_string())?;
        if let Some(what) = role.must_be_non_negative() {
            columns
                .require_non_negative(0, path, what)
                .map_err(|e| e.to_string())?;
        }
        return Ok((table, spec.to_string()));
    }
    let named = canonical_illuminant_name(spec)
        .or_else(|| embedded_stems().find(|s| s.eq_ignore_ascii_case(spec)));
    if let Some(stem) = named {
        let columns = embedded_file(stem).expect("stem comes from the embedded list");
        if columns.columns.len() != 1 {
            return Err(format!(
                "{flag} {spec}: spectra/{stem}.csv holds {} columns ({}); name a single spectrum",
                columns.columns.len(),
                columns.names.join(", ")
            ));
        }
        return Ok((columns.table(0), stem.to_string()));
    }
    if path.exists() {
        return Err(format!("{flag} {spec}: not a regular file"));
    }
    if looks_like_path(spec) && !spec.contains(':') {
        return Err(format!(
            "{flag} {spec}: cannot read the file: no such file (expected a CSV of `wavelength_nm,value` lines)"
        ));
    }
    let mut candidates: Vec<String> = embedded_stems().map(str::to_string).collect();
    candidates.extend(
        colorchecker_patch_names()
            .iter()
            .map(|p| format!("{COLORCHECKER_PREFIX}{p}")),
    );
    Err(format!(
        "{flag} {spec}: unknown spectrum: not a file, not a name under spectra/ and not `colorchecker:<patch>`{}",
        did_you_mean(spec, candidates.iter().map(String::as_str))
    ))
}

/// The illuminant of a reflectance report, resolved, with the text it was given as (for
/// messages) and its label (for the report).
pub struct ReportIlluminant<'a> {
    pub spec: &'a str,
    pub table: &'a Tabulated,
    pub label: String,
}

/// Everything `prism color` reports; `None` where a quantity is undefined.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorReport {
    pub spectrum: String,
    pub illuminant: Option<String>,
    pub observer: Observer,
    pub xyz: DVec3,
    pub xy: Option<[f64; 2]>,
    pub cct_k: Option<f64>,
    pub duv: Option<f64>,
    /// CCT and Duv within Ohno 2013's valid range (false: an extrapolation).
    pub cct_in_range: Option<bool>,
    pub lab: Option<DVec3>,
    pub linear_srgb: DVec3,
    pub srgb: DVec3,
}

fn chromaticity(xyz: DVec3) -> Option<[f64; 2]> {
    xyz_to_xy(xyz).map(|xy| xy.to_array())
}

/// The illuminant's white (Y = 100 for a perfect reflector), or the message for an
/// illuminant without power in 360–830 nm.
pub fn illuminant_white(
    illuminant: &DenseSpectrum,
    spec: &str,
    observer: Observer,
) -> Result<DVec3, String> {
    let white = illuminant_white_xyz(illuminant, observer);
    if white.y.is_nan() || white.y <= 0.0 {
        return Err(format!(
            "--illuminant {spec}: expected an illuminant with power in 360–830 nm, found none"
        ));
    }
    Ok(white)
}

/// The report of `spectrum` (labelled `label`): a reflectance under `illuminant` (XYZ with
/// Y = 100 for a perfect reflector, sRGB after `adapt` from the illuminant's white to D65),
/// or without one spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹ (XYZ in cd/m²).
pub fn color_report(
    spectrum: &Tabulated,
    label: String,
    illuminant: Option<ReportIlluminant>,
    observer: Observer,
    adapt: AdaptationMethod,
) -> Result<ColorReport, String> {
    let srgb = RgbColorSpace::srgb();
    let (report_xyz, xyz_1931, lab, linear_srgb, illuminant_label);
    match illuminant {
        Some(illuminant) => {
            let reflectance = spectrum.to_dense();
            let light = illuminant.table.to_dense();
            let white = illuminant_white(&light, illuminant.spec, observer)?;
            report_xyz = reflectance_to_xyz(&reflectance, &light, observer);
            lab = Some(xyz_to_lab(report_xyz, white));
            xyz_1931 = reflectance_to_xyz(&reflectance, &light, Observer::Cie1931);
            let white_1931 = illuminant_white_xyz(&light, Observer::Cie1931) / 100.0;
            let adaptation = adaptation_matrix(adapt, white_1931, srgb.white_xyz());
            linear_srgb = srgb.xyz_to_rgb * (adaptation * (xyz_1931 / 100.0));
            illuminant_label = Some(illuminant.label);
        }
        None => {
            let radiance = spectrum.to_dense();
            report_xyz = emission_to_xyz_cd_per_m2(&radiance, observer);
            xyz_1931 = emission_to_xyz_cd_per_m2(&radiance, Observer::Cie1931);
            lab = None;
            linear_srgb = srgb.xyz_to_rgb * xyz_1931;
            illuminant_label = None;
        }
    }
    let cct = xyz_to_cct_ohno2013(xyz_1931);
    let (cct_k, duv) = (cct.map(|c| c.cct_k), cct.map(|c| c.duv));
    let encoded = linear_srgb.to_array().map(|v| srgb.transfer.encode(v));
    Ok(ColorReport {
        spectrum: label,
        illuminant: illuminant_label,
        observer,
        xyz: report_xyz,
        xy: chromaticity(report_xyz),
        cct_k,
        duv,
        cct_in_range: cct.map(|c| c.in_valid_range()),
        lab,
        linear_srgb,
        srgb: DVec3::from_array(encoded),
    })
}

impl ColorReport {
    /// The object `prism color --json` prints.
    pub fn to_json(&self) -> Value {
        let vec3 = |v: DVec3| json!([v.x, v.y, v.z]);
        json!({
            "spectrum": self.spectrum,
            "illuminant": self.illuminant,
            "observer": self.observer.name(),
            "XYZ": vec3(self.xyz),
            "xy": self.xy,
            "CCT_K": self.cct_k,
            "Duv": self.duv,
            "CCT_in_valid_range": self.cct_in_range,
            "Lab": self.lab.map(vec3),
            "linear_sRGB": vec3(self.linear_srgb),
            "sRGB": vec3(self.srgb),
        })
    }
}
