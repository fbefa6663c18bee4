//! `prism color`: colorimetry of one spectrum, scriptable (`--json`) and checked against
//! colour-science (tests/fixtures/color_cli.json).

use std::path::PathBuf;

use clap::{ArgGroup, Args, ValueEnum};
use glam::DVec3;
use prism_spectrum::adaptation::AdaptationMethod;
use prism_spectrum::bfc::NegativesPolicy;
use prism_spectrum::cct::{CCT_MAX_K, CCT_MIN_K, DUV_MAX};
use prism_spectrum::color_report::{
    color_report, resolve_spectrum, ColorReport, ReportIlluminant, SpectrumRole,
    COLORCHECKER_PREFIX,
};
use prism_spectrum::{Observer, Tabulated};

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

/// Resolves `FILE.csv|NAME|colorchecker:PATCH` to a table and a label for the report.
pub(crate) fn resolve_illuminant(spec: &str, flag: &str) -> Result<(Tabulated, String), String> {
    resolve_spectrum(spec, SpectrumRole::Illuminant, flag)
}

fn compute(args: &ColorArgs, spectrum: &str) -> Result<ColorReport, String> {
    let observer = Observer::from(args.observer);
    match &args.illuminant {
        Some(illuminant_spec) => {
            let (spectrum, label) =
                resolve_spectrum(spectrum, SpectrumRole::Reflectance, "--spectrum")?;
            let (illuminant, illuminant_label) =
                resolve_spectrum(illuminant_spec, SpectrumRole::Illuminant, "--illuminant")?;
            let illuminant = ReportIlluminant {
                spec: illuminant_spec,
                table: &illuminant,
                label: illuminant_label,
            };
            color_report(
                &spectrum,
                label,
                Some(illuminant),
                observer,
                args.adapt.into(),
            )
        }
        None => {
            if spectrum.starts_with(COLORCHECKER_PREFIX) {
                eprintln!(
                    "warning: --spectrum {spectrum} is a reflectance but no --illuminant was \
                     given: it is treated as spectral radiance; give --illuminant D65 (or \
                     another) for its colour under a light"
                );
            }
            let (spectrum, label) =
                resolve_spectrum(spectrum, SpectrumRole::Emission, "--spectrum")?;
            color_report(&spectrum, label, None, observer, args.adapt.into())
        }
    }
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
        println!("{}", report.to_json());
    } else {
        print_table(&report);
    }
    Ok(())
}
