//! `prism color --bispectral FILE.BFC`: colorimetry of a fluorescent sample from its
//! bispectral radiance factors (Labsphere BFC-450 file), checked against an independent
//! computation (tests/fixtures/bispectral_cli.json, tools/export_bispectral_fixture.py).
//!
//! Everything is a band sum on the file's grid, as bispectral colorimetry does: with D(μ, λ)
//! the file's radiance factor per band (D(λ, λ) = R(λ)) and S the illuminant's table,
//! XYZ = k·Σ_λ cmf(λ)·Σ_μ D(μ, λ)·S(μ), k = 100/Σ_λ S(λ)·ȳ(λ), βT(λ) = Σ_μ D(μ, λ)·S(μ)/S(λ).

use std::path::Path;

use glam::DVec3;
use prism_spectrum::bfc::{load_bfc, BfcData, NegativesPolicy, NegativesReport};
use prism_spectrum::colorimetry::{xyz_to_lab, xyz_to_xy};
use prism_spectrum::data::cmfs;
use prism_spectrum::{Observer, Tabulated};
use serde_json::{json, Value};

use crate::color::{resolve_illuminant, ColorArgs};

/// CIE 15:2018 §9 whiteness applies to samples with 40 < W < 5Y − 280 and −4 < T_W < 2.
const WHITENESS_W_MIN: f64 = 40.0;
const TINT_RANGE: (f64, f64) = (-4.0, 2.0);

/// The file as band radiance factors: emission rows × excitation columns.
struct BandMatrix {
    excitation_nm: Vec<f64>,
    emission_nm: Vec<f64>,
    /// D(μ, λ) at `d[e * excitation count + x]`, the diagonal holding R(λ).
    d: Vec<f64>,
    /// R(λ) per emission row.
    reflectance: Vec<f64>,
}

impl BandMatrix {
    fn new(data: &BfcData) -> Self {
        let excitation = data.matrix.excitation();
        let emission = data.matrix.emission();
        let step_nm = excitation.step_nm() as f64;
        let excitation_nm: Vec<f64> = (0..excitation.count())
            .map(|x| excitation.wavelength_nm(x) as f64)
            .collect();
        let emission_nm: Vec<f64> = (0..emission.count())
            .map(|e| emission.wavelength_nm(e) as f64)
            .collect();
        let reflectance = data.reflectance.values().to_vec();
        let mut d = Vec::with_capacity(emission_nm.len() * excitation_nm.len());
        for (e, &out_nm) in emission_nm.iter().enumerate() {
            for (x, &in_nm) in excitation_nm.iter().enumerate() {
                // The reader guarantees each emission wavelength is an excitation node; it
                // stores M = D / step (nm⁻¹), so D is M·step back.
                d.push(if (in_nm - out_nm).abs() < 1e-3 {
                    reflectance[e]
                } else {
                    data.matrix.node(x, e) as f64 * step_nm
                });
            }
        }
        Self {
            excitation_nm,
            emission_nm,
            d,
            reflectance,
        }
    }

    /// Σ_μ D(μ, λ)·S(μ) per emission row: the total radiance factor times S(λ).
    fn excited(&self, illuminant: &Tabulated) -> Vec<f64> {
        let s: Vec<f64> = self
            .excitation_nm
            .iter()
            .map(|&nm| illuminant.eval(nm))
            .collect();
        self.d
            .chunks_exact(self.excitation_nm.len())
            .map(|row| row.iter().zip(&s).map(|(d, s)| d * s).sum())
            .collect()
    }
}

/// A colour: XYZ (perfect diffuser Y = 100), xy, CIELAB against the illuminant's white.
struct Colour {
    xyz: DVec3,
    xy: Option<[f64; 2]>,
    lab: DVec3,
}

impl Colour {
    fn new(xyz: DVec3, white: DVec3) -> Self {
        Self {
            xyz,
            xy: xyz_to_xy(xyz).map(|v| v.to_array()),
            lab: xyz_to_lab(xyz, white),
        }
    }

    fn to_json(&self) -> Value {
        json!({
            "XYZ": [self.xyz.x, self.xyz.y, self.xyz.z],
            "xy": self.xy,
            "Lab": [self.lab.x, self.lab.y, self.lab.z],
        })
    }
}

/// The colorimetry of the sample under one illuminant.
struct IlluminantReport {
    illuminant: String,
    white: DVec3,
    reflected: Colour,
    total: Colour,
    /// (nm, βT); βT is undefined (None) where S(λ) = 0.
    beta_t: Vec<(f64, Option<f64>)>,
    beta_t_peak: Option<(f64, f64)>,
    beta_l_peak: Option<(f64, f64)>,
}

/// Band sums of `samples` (per emission row) against the colour-matching functions.
fn tristimulus(bands: &BandMatrix, observer: Observer, samples: &[f64], k: f64) -> DVec3 {
    let cmf = cmfs(observer);
    bands
        .emission_nm
        .iter()
        .zip(samples)
        .map(|(&nm, &v)| DVec3::new(cmf.x_bar.eval(nm), cmf.y_bar.eval(nm), cmf.z_bar.eval(nm)) * v)
        .sum::<DVec3>()
        * k
}

/// XYZ of the total and of the perfect diffuser, and the per-row sums, under `illuminant`.
struct Sums {
    excited: Vec<f64>,
    s_emission: Vec<f64>,
    k: f64,
    white: DVec3,
    total: DVec3,
}

fn sums(
    bands: &BandMatrix,
    illuminant: &Tabulated,
    observer: Observer,
    label: &str,
) -> Result<Sums, String> {
    let excited = bands.excited(illuminant);
    let s_emission: Vec<f64> = bands
        .emission_nm
        .iter()
        .map(|&nm| illuminant.eval(nm))
        .collect();
    let white_unscaled = tristimulus(bands, observer, &s_emission, 1.0);
    // NaN (an illuminant CSV with no overlap) fails too.
    if white_unscaled.y.is_nan() || white_unscaled.y <= 0.0 {
        return Err(format!(
            "illuminant {label}: no power where the file's emission wavelengths ({}–{} nm) meet the colour-matching functions",
            bands.emission_nm[0],
            bands.emission_nm[bands.emission_nm.len() - 1]
        ));
    }
    let k = 100.0 / white_unscaled.y;
    Ok(Sums {
        total: tristimulus(bands, observer, &excited, k),
        white: white_unscaled * k,
        excited,
        s_emission,
        k,
    })
}

fn peak(values: impl Iterator<Item = (f64, Option<f64>)>) -> Option<(f64, f64)> {
    values.filter_map(|(nm, v)| v.map(|v| (nm, v))).fold(
        None,
        |best: Option<(f64, f64)>, (nm, v)| match best {
            Some((_, b)) if b >= v => best,
            _ => Some((nm, v)),
        },
    )
}

fn report(
    bands: &BandMatrix,
    illuminant: &Tabulated,
    label: String,
    observer: Observer,
) -> Result<IlluminantReport, String> {
    let sums = sums(bands, illuminant, observer, &label)?;
    let reflected_samples: Vec<f64> = bands
        .reflectance
        .iter()
        .zip(&sums.s_emission)
        .map(|(r, s)| r * s)
        .collect();
    let reflected = tristimulus(bands, observer, &reflected_samples, sums.k);
    let beta_t: Vec<(f64, Option<f64>)> = bands
        .emission_nm
        .iter()
        .zip(sums.excited.iter().zip(&sums.s_emission))
        .map(|(&nm, (&excited, &s))| (nm, (s > 0.0).then(|| excited / s)))
        .collect();
    let beta_l = beta_t
        .iter()
        .zip(&bands.reflectance)
        .map(|(&(nm, bt), r)| (nm, bt.map(|bt| bt - r)));
    Ok(IlluminantReport {
        illuminant: label,
        white: sums.white,
        reflected: Colour::new(reflected, sums.white),
        total: Colour::new(sums.total, sums.white),
        beta_t_peak: peak(beta_t.iter().copied()),
        beta_l_peak: peak(beta_l),
        beta_t,
    })
}

/// CIE whiteness and tint of the D65 total, 10° observer (CIE 15:2018 §9).
struct Whiteness {
    xyz: DVec3,
    w: f64,
    tint: f64,
    valid: bool,
}

fn whiteness(bands: &BandMatrix) -> Result<Whiteness, String> {
    let (d65, _) = resolve_illuminant("D65", "whiteness")?;
    let sums = sums(bands, &d65, Observer::Cie1964, "D65")?;
    let undefined = || "whiteness: the D65 total has no chromaticity (XYZ sum 0)".to_string();
    let [x_n, y_n] = xyz_to_xy(sums.white).ok_or_else(undefined)?.to_array();
    let [x, y] = xyz_to_xy(sums.total).ok_or_else(undefined)?.to_array();
    let big_y = sums.total.y;
    let w = big_y + 800.0 * (x_n - x) + 1700.0 * (y_n - y);
    let tint = 900.0 * (x_n - x) - 650.0 * (y_n - y);
    let valid = WHITENESS_W_MIN < w
        && w < 5.0 * big_y - 280.0
        && TINT_RANGE.0 < tint
        && tint < TINT_RANGE.1;
    Ok(Whiteness {
        xyz: sums.total,
        w,
        tint,
        valid,
    })
}

fn negatives_json(policy: NegativesPolicy, report: &NegativesReport) -> Value {
    json!({
        "policy": policy.name(),
        "count": report.count,
        "total": report.total,
        "worst": report.worst.map(|w| json!({
            "excitation_nm": w.excitation_nm,
            "emission_nm": w.emission_nm,
            "value": w.value,
            "line": w.line,
            "column": w.column,
        })),
        "summary": report.to_string(),
    })
}

fn negatives_line(policy: NegativesPolicy, report: &NegativesReport) -> String {
    let effect = match (policy, report.count) {
        (_, 0) => "",
        (NegativesPolicy::Clamp, _) => ": set to 0",
        (NegativesPolicy::Keep, _) => ": kept (signed matrix)",
        // `error` refuses such a file before anything is printed.
        (NegativesPolicy::Error, _) => "",
    };
    format!("{} ({report}{effect})", policy.name())
}

fn print_colour(name: &str, c: &Colour) {
    let row = |label: &str, v: [f64; 3]| {
        println!("  {label:<16}{:>14.6}{:>14.6}{:>14.6}", v[0], v[1], v[2])
    };
    println!("  {name}");
    row("  XYZ (Y=100)", c.xyz.to_array());
    match c.xy {
        Some([x, y]) => println!("  {:<16}{x:>14.6}{y:>14.6}", "  xy"),
        None => println!("  {:<16}{:>14}", "  xy", "undefined"),
    }
    row("  L*a*b*", c.lab.to_array());
}

fn print_peak(name: &str, peak: Option<(f64, f64)>) {
    match peak {
        Some((nm, v)) => println!("  {name:<18}{v:>12.6} at {nm} nm"),
        None => println!("  {name:<18}{:>12}", "undefined"),
    }
}

pub fn run(args: &ColorArgs, path: &Path) -> Result<(), String> {
    let policy = args
        .negatives
        .map_or(NegativesPolicy::default(), NegativesPolicy::from);
    let data = load_bfc(path, policy).map_err(|e| e.to_string())?;
    let bands = BandMatrix::new(&data);
    let observer = Observer::from(args.observer);
    let mut specs = vec![args.illuminant.as_deref().unwrap_or("D65")];
    specs.extend(args.compare_illuminant.as_deref());
    let mut reports = Vec::with_capacity(specs.len());
    for (spec, flag) in specs.iter().zip(["--illuminant", "--compare-illuminant"]) {
        let (table, label) = resolve_illuminant(spec, flag)?;
        reports.push(report(&bands, &table, label, observer)?);
    }
    let whiteness = whiteness(&bands)?;
    if args.json {
        let illuminants: Vec<Value> = reports
            .iter()
            .map(|r| {
                json!({
                    "illuminant": r.illuminant,
                    "white_XYZ": [r.white.x, r.white.y, r.white.z],
                    "reflected": r.reflected.to_json(),
                    "total": r.total.to_json(),
                    "beta_t": r.beta_t.iter().map(|(nm, v)| json!([nm, v])).collect::<Vec<_>>(),
                    "beta_t_peak": r.beta_t_peak.map(|(nm, v)| json!([nm, v])),
                    "beta_l_peak": r.beta_l_peak.map(|(nm, v)| json!([nm, v])),
                })
            })
            .collect();
        let out = json!({
            "bispectral": path.display().to_string(),
            "observer": observer.name(),
            "negatives": negatives_json(data.policy, &data.negatives),
            "illuminants": illuminants,
            "whiteness": {
                "illuminant": "D65",
                "observer": Observer::Cie1964.name(),
                "XYZ": [whiteness.xyz.x, whiteness.xyz.y, whiteness.xyz.z],
                "W": whiteness.w,
                "T_W": whiteness.tint,
                "valid": whiteness.valid,
            },
        });
        println!("{out}");
        return Ok(());
    }
    println!("{:<13}{} (bispectral, BFC-450)", "sample", path.display());
    println!("{:<13}{}", "observer", observer.name());
    println!(
        "{:<13}{}",
        "negatives",
        negatives_line(data.policy, &data.negatives)
    );
    for r in &reports {
        println!("illuminant {}", r.illuminant);
        print_colour("reflected (R alone)", &r.reflected);
        print_colour("total (R + fluorescence)", &r.total);
        print_peak("βT peak", r.beta_t_peak);
        print_peak("βL peak (βT − R)", r.beta_l_peak);
    }
    if reports.len() == 2 {
        // The accepted check: βT depends on the illuminant, R does not.
        let r_peak = peak(
            bands
                .emission_nm
                .iter()
                .zip(&bands.reflectance)
                .map(|(&nm, &r)| (nm, Some(r))),
        );
        println!("βT vs illuminant (R is the same under both)");
        for r in &reports {
            print_peak(&format!("βT peak {}", r.illuminant), r.beta_t_peak);
        }
        print_peak("R peak (both)", r_peak);
    }
    println!(
        "whiteness (CIE 15:2018 §9, D65 total, cie1964)  W {:.4}  T_W {:+.4}{}",
        whiteness.w,
        whiteness.tint,
        if whiteness.valid {
            ""
        } else {
            "  (outside the formula's validity: 40 < W < 5Y − 280, −4 < T_W < 2)"
        }
    );
    Ok(())
}
