//! `prism color`: colorimetry of one spectrum, scriptable (`--json`) and checked against
//! colour-science (tests/fixtures/color_cli.json).

use std::path::{Path, PathBuf};

use clap::{ArgGroup, Args, ValueEnum};
use glam::DVec3;
use prism_spectrum::adaptation::{adaptation_matrix, AdaptationMethod};
use prism_spectrum::bfc::NegativesPolicy;
use prism_spectrum::cct::{blackbody_dense, xyz_to_cct_ohno2013, CCT_MAX_K, CCT_MIN_K, DUV_MAX};
use prism_spectrum::colorimetry::{
    emission_to_xyz_cd_per_m2, illuminant_white_xyz, reflectance_to_xyz, xyz_to_lab, xyz_to_xy,
};
use prism_spectrum::data::{
    canonical_illuminant_name, colorchecker_patch, colorchecker_patch_index,
    colorchecker_patch_names, embedded_file, embedded_stems,
};
use prism_spectrum::names::did_you_mean;
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::spectrum_file::read_single_spectrum;
use prism_spectrum::{DenseSpectrum, Observer, Tabulated};
use serde_json::{json, Value};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ObserverArg {
    /// CIE 1931 2° standard observer.
    Cie1931,
    /// CIE 1964 10° standard observer.
    Cie1964,
}

impl From<ObserverArg> for Observer {
    fn from(arg: ObserverArg) -> Self {
        match arg {
            ObserverArg::Cie1931 => Observer::Cie1931,
            ObserverArg::Cie1964 => Observer::Cie1964,
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum AdaptArg {
    Bradford,
    Cat16,
    Cat02,
    VonKries,
    None,
}

impl From<AdaptArg> for AdaptationMethod {
    fn from(arg: AdaptArg) -> Self {
        match arg {
            AdaptArg::Bradford => AdaptationMethod::Bradford,
            AdaptArg::Cat16 => AdaptationMethod::Cat16,
            AdaptArg::Cat02 => AdaptationMethod::Cat02,
            AdaptArg::VonKries => AdaptationMethod::VonKries,
            AdaptArg::None => AdaptationMethod::None,
        }
    }
}

/// The `--negatives` policy for bispectral files.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum NegativesArg {
    /// Set negative entries to 0 and report their count and the most negative one.
    Clamp,
    /// Keep the signed matrix.
    Keep,
    /// Refuse a file with negative entries.
    Error,
}

impl From<NegativesArg> for NegativesPolicy {
    fn from(arg: NegativesArg) -> Self {
        match arg {
            NegativesArg::Clamp => NegativesPolicy::Clamp,
            NegativesArg::Keep => NegativesPolicy::Keep,
            NegativesArg::Error => NegativesPolicy::Error,
        }
    }
}

#[derive(Args, Debug)]
#[command(group(ArgGroup::new("input").required(true).args(["spectrum", "bispectral"])))]
pub struct ColorArgs {
    /// Spectrum: a CSV file (`wavelength_nm,value`), a file stem under spectra/ (e.g. D65, F11,
    /// LED-B3), a ColorChecker patch (e.g. `colorchecker:dark skin`) or a blackbody's absolute
    /// spectral radiance (e.g. `blackbody:5000` in K).
    #[arg(long, value_name = "FILE.csv|NAME")]
    pub spectrum: Option<String>,
    /// A fluorescent sample: a Labsphere BFC-450 bispectral matrix file; prints the reflected
    /// and total colour, βT and CIE whiteness (docs/colour.md "prism color --bispectral").
    #[arg(long, value_name = "FILE.BFC")]
    pub bispectral: Option<PathBuf>,
    /// Treat the spectrum as a reflectance under this illuminant (CIE name or CSV file);
    /// XYZ is then normalised so a perfect reflector has Y = 100. Without it the spectrum is
    /// spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹ and Y is luminance in cd/m². With --bispectral
    /// it defaults to D65.
    #[arg(long, value_name = "NAME|FILE.csv")]
    pub illuminant: Option<String>,
    /// With --bispectral: a second illuminant, reported alongside (βT changes with the
    /// illuminant, R does not).
    #[arg(long, value_name = "NAME|FILE.csv")]
    pub compare_illuminant: Option<String>,
    /// With --bispectral: what to do with negative matrix entries (measurement noise);
    /// default clamp.
    #[arg(long, value_enum)]
    pub negatives: Option<NegativesArg>,
    /// Colour-matching functions for XYZ, xy and Lab (CCT and sRGB always use CIE 1931).
    #[arg(long, value_enum, default_value = "cie1931")]
    pub observer: ObserverArg,
    /// Chromatic adaptation from the illuminant's white to D65 for sRGB (reflectances only).
    #[arg(long, value_enum, default_value = "bradford")]
    pub adapt: AdaptArg,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// What a spectrum argument stands for, for validation.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Reflectance,
    Emission,
    Illuminant,
}

impl Role {
    fn must_be_non_negative(self) -> Option<&'static str> {
        match self {
            Role::Reflectance => None,
            Role::Emission => Some("emission (spectral radiance)"),
            Role::Illuminant => Some("an illuminant's spectral power"),
        }
    }
}

const COLORCHECKER_PREFIX: &str = "colorchecker:";
const BLACKBODY_PREFIX: &str = "blackbody:";

fn looks_like_path(text: &str) -> bool {
    text.contains('/') || text.contains('\\') || text.contains('.')
}

/// Resolves `FILE.csv|NAME|colorchecker:PATCH` to a table and a label for the report.
pub(crate) fn resolve_illuminant(spec: &str, flag: &str) -> Result<(Tabulated, String), String> {
    resolve_spectrum(spec, Role::Illuminant, flag)
}

fn resolve_spectrum(spec: &str, role: Role, flag: &str) -> Result<(Tabulated, String), String> {
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

/// Everything `prism color` reports; `None` where a quantity is undefined.
struct ColorReport {
    spectrum: String,
    illuminant: Option<String>,
    observer: Observer,
    xyz: DVec3,
    xy: Option<[f64; 2]>,
    cct_k: Option<f64>,
    duv: Option<f64>,
    /// CCT and Duv within Ohno 2013's valid range (false: an extrapolation).
    cct_in_range: Option<bool>,
    lab: Option<DVec3>,
    linear_srgb: DVec3,
    srgb: DVec3,
}

fn chromaticity(xyz: DVec3) -> Option<[f64; 2]> {
    xyz_to_xy(xyz).map(|xy| xy.to_array())
}

fn compute(args: &ColorArgs, spectrum: &str) -> Result<ColorReport, String> {
    let observer = Observer::from(args.observer);
    let srgb = RgbColorSpace::srgb();
    let (report_xyz, xyz_1931, lab, linear_srgb, illuminant_label, spectrum_label);
    match &args.illuminant {
        Some(illuminant_spec) => {
            let (spectrum, label) = resolve_spectrum(spectrum, Role::Reflectance, "--spectrum")?;
            let (illuminant, illum_label) =
                resolve_spectrum(illuminant_spec, Role::Illuminant, "--illuminant")?;
            let reflectance = spectrum.to_dense();
            let illuminant = illuminant.to_dense();
            let white = illuminant_white_xyz(&illuminant, observer);
            if white.y.is_nan() || white.y <= 0.0 {
                return Err(format!(
                    "--illuminant {illuminant_spec}: expected an illuminant with power in 360–830 nm, found none"
                ));
            }
            report_xyz = reflectance_to_xyz(&reflectance, &illuminant, observer);
            lab = Some(xyz_to_lab(report_xyz, white));
            xyz_1931 = reflectance_to_xyz(&reflectance, &illuminant, Observer::Cie1931);
            let white_1931 = illuminant_white_xyz(&illuminant, Observer::Cie1931) / 100.0;
            let adapt = adaptation_matrix(args.adapt.into(), white_1931, srgb.white_xyz());
            linear_srgb = srgb.xyz_to_rgb * (adapt * (xyz_1931 / 100.0));
            illuminant_label = Some(illum_label);
            spectrum_label = label;
        }
        None => {
            if spectrum.starts_with(COLORCHECKER_PREFIX) {
                eprintln!(
                    "warning: --spectrum {spectrum} is a reflectance but no --illuminant was \
                     given: it is treated as spectral radiance; give --illuminant D65 (or \
                     another) for its colour under a light"
                );
            }
            let (spectrum, label) = resolve_spectrum(spectrum, Role::Emission, "--spectrum")?;
            let radiance = spectrum.to_dense();
            report_xyz = emission_to_xyz_cd_per_m2(&radiance, observer);
            xyz_1931 = emission_to_xyz_cd_per_m2(&radiance, Observer::Cie1931);
            lab = None;
            linear_srgb = srgb.xyz_to_rgb * xyz_1931;
            illuminant_label = None;
            spectrum_label = label;
        }
    }
    let cct = xyz_to_cct_ohno2013(xyz_1931);
    let (cct_k, duv) = (cct.map(|c| c.cct_k), cct.map(|c| c.duv));
    let encoded = linear_srgb.to_array().map(|v| srgb.transfer.encode(v));
    Ok(ColorReport {
        spectrum: spectrum_label,
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

fn to_json(r: &ColorReport) -> Value {
    let vec3 = |v: DVec3| json!([v.x, v.y, v.z]);
    json!({
        "spectrum": r.spectrum,
        "illuminant": r.illuminant,
        "observer": r.observer.name(),
        "XYZ": vec3(r.xyz),
        "xy": r.xy,
        "CCT_K": r.cct_k,
        "Duv": r.duv,
        "CCT_in_valid_range": r.cct_in_range,
        "Lab": r.lab.map(vec3),
        "linear_sRGB": vec3(r.linear_srgb),
        "sRGB": vec3(r.srgb),
    })
}

/// `v` with seven significant digits in at most 13 characters: fixed notation between
/// 10⁻³ and 10⁷, scientific outside, so columns never run together.
fn number(v: f64) -> String {
    let magnitude = v.abs();
    if v == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if (1e-3..1e7).contains(&magnitude) {
        let decimals = (6 - magnitude.log10().floor() as i32).clamp(0, 9) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.6e}")
    }
}

/// Right-aligned columns of width 14 (one space at least between numbers).
fn columns(values: &[f64]) -> String {
    values
        .iter()
        .map(|&v| format!(" {:>13}", number(v)))
        .collect()
}

fn print_table(r: &ColorReport) {
    let row = |name: &str, v: DVec3| println!("{name:<13}{}", columns(&[v.x, v.y, v.z]));
    match &r.illuminant {
        Some(illum) => {
            println!("{:<13}{} (reflectance)", "spectrum", r.spectrum);
            println!("{:<13}{illum}", "illuminant");
        }
        None => println!(
            "{:<13}{} (spectral radiance, W·m⁻²·sr⁻¹·nm⁻¹)",
            "spectrum", r.spectrum
        ),
    }
    println!("{:<13}{}", "observer", r.observer.name());
    row(
        if r.illuminant.is_some() {
            "XYZ (Y=100)"
        } else {
            "XYZ (cd/m²)"
        },
        r.xyz,
    );
    match r.xy {
        Some([x, y]) => println!("{:<13}{}", "xy", columns(&[x, y])),
        None => println!("{:<13}{:>14}", "xy", "undefined"),
    }
    match (r.cct_k, r.duv) {
        (Some(t), Some(d)) => {
            let flag = if r.cct_in_range == Some(true) {
                String::new()
            } else {
                format!(
                    "  outside the method's valid range ({CCT_MIN_K}–{CCT_MAX_K} K, \
                     |Duv| ≤ {DUV_MAX}): an extrapolation, not a temperature"
                )
            };
            println!(
                "{:<13}{} K   Duv {d:+.5}  (CIE 1931){flag}",
                "CCT",
                columns(&[t])
            )
        }
        _ => println!("{:<13}{:>14}", "CCT", "undefined"),
    }
    if let Some(lab) = r.lab {
        row("L*a*b*", lab);
    }
    row("linear sRGB", r.linear_srgb);
    row("sRGB", r.srgb);
}

pub fn run(args: &ColorArgs) -> Result<(), String> {
    // clap's "input" group requires exactly one of --spectrum and --bispectral.
    let spectrum = match (&args.spectrum, &args.bispectral) {
        (Some(spectrum), None) => spectrum,
        (None, Some(path)) => return crate::bispectral::run(args, path),
        (Some(_), Some(_)) | (None, None) => {
            return Err("give exactly one of --spectrum and --bispectral".into())
        }
    };
    // Checked here rather than by clap's `requires`, which does not fire for a member of
    // the "input" group.
    if args.compare_illuminant.is_some() || args.negatives.is_some() {
        return Err(
            "--compare-illuminant and --negatives apply to --bispectral only, not to --spectrum"
                .into(),
        );
    }
    let report = compute(args, spectrum)?;
    if args.json {
        println!("{}", to_json(&report));
    } else {
        print_table(&report);
    }
    Ok(())
}
