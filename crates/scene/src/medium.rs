//! Participating media: homogeneous, or a density grid (Mitsuba `.vol`) scaling the
//! coefficients; absorption and scattering coefficients as spectra, an optional emission
//! and a phase function (isotropic, Henyey–Greenstein, Rayleigh or a table); optionally a
//! dissolved fluorophore (`fluorescence`) that re-emits what it absorbs.

use std::path::PathBuf;

use prism_spectrum::{Dye, EmissionUnits};

use crate::reader::{Result, V};
use crate::schema::schema;
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};

#[derive(Debug, Clone, PartialEq)]
pub struct Medium {
    pub name: String,
    pub kind: MediumKind,
    /// Absorption coefficient σₐ in m⁻¹ (times the density for a grid).
    pub sigma_a_per_m: SpectrumRef,
    /// Scattering coefficient σₛ in m⁻¹ (times the density for a grid).
    pub sigma_s_per_m: SpectrumRef,
    /// Radiance the medium emits, W·m⁻²·sr⁻¹·nm⁻¹: the source term is σₐ·emission
    /// (pbrt-v4 `Le`), so emitted power scales with the density. `None`: not emissive.
    pub emission: Option<SpectrumRef>,
    pub phase: Phase,
    /// A dissolved fluorophore: its absorption adds to σₐ, and what it absorbs is re-emitted
    /// isotropically. `None`: the medium does not fluoresce.
    pub fluorescence: Option<MediumFluorescence>,
}

/// `"fluorescence": {"absorption_per_m": CSV, "emission": CSV, "quantum_yield": Φ}`: the
/// dye model of `reradiation` entries (prism-spectrum `dye.rs`) with an absorption
/// coefficient in m⁻¹ instead of an absorptance. The medium's re-radiation matrix is
/// M(λi, λo) = σf(λi)·Φ·(λi/λo)·e(λo)/∫e (m⁻¹·nm⁻¹, photon-count e; energy e as there).
#[derive(Debug, Clone, PartialEq)]
pub struct MediumFluorescence {
    pub absorption: PathBuf,
    pub emission: PathBuf,
    pub units: EmissionUnits,
    pub quantum_yield: f64,
    /// The absorption coefficient's largest value on the dye's 5 nm excitation grid, m⁻¹.
    pub peak_absorption_per_m: f64,
    /// The dye at peak absorptance 1 (absorptance σf/peak): the medium's M is
    /// `peak_absorption_per_m` times its matrix, σf is `peak_absorption_per_m` times its
    /// absorptance.
    pub dye: Dye,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MediumKind {
    Homogeneous,
    /// Density from a Mitsuba `.vol` file (resolved path), over `bounds_m` (min, max) or,
    /// when `None`, the file's own box.
    Grid {
        density: PathBuf,
        bounds_m: Option<[[f64; 3]; 2]>,
    },
}

/// A phase function as the scene gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Phase {
    Isotropic,
    /// Henyey–Greenstein asymmetry g in (−1, 1).
    HenyeyGreenstein {
        g: f64,
    },
    Rayleigh,
    /// Values over the scattering angle's cosine (1 = forward), from a CSV file; ascending
    /// cos θ from −1 to 1, values ≥ 0 and not all 0 (render normalises them).
    Tabulated {
        file: PathBuf,
        cos_theta: Vec<f64>,
        values: Vec<f64>,
    },
}

/// The medium types.
pub const MEDIUM_TYPES: [&str; 2] = ["homogeneous", "grid"];
/// The phase function types.
pub const PHASE_TYPES: [&str; 4] = ["isotropic", "hg", "rayleigh", "tabulated"];

pub(crate) fn parse_media(v: &V, spectra: &NamedSpectra) -> Result<Vec<Medium>> {
    let mut out = Vec::new();
    for (name, entry) in v.map()? {
        let (o, kind) = match entry.tag("medium", &MEDIUM_TYPES, Some("homogeneous"))? {
            "homogeneous" => (
                entry.object(schema!("media.*<homogeneous>"))?,
                MediumKind::Homogeneous,
            ),
            _ => {
                let o = entry.object(schema!("media.*<grid>"))?;
                let density = o
                    .req("density", "a Mitsuba .vol file")?
                    .asset("density grid", &["vol"])?;
                let bounds_m = o.get("bounds_m").map(|b| parse_bounds(&b)).transpose()?;
                (o, MediumKind::Grid { density, bounds_m })
            }
        };
        let coefficient = |key: &str| match o.get(key) {
            None => Ok(SpectrumRef::Constant(0.0)),
            Some(c) => parse_spectrum(&c, spectra, SpectrumUse::NonNegative),
        };
        let phase = match o.at_most_one(&["g", "phase"])? {
            None => Phase::Isotropic,
            Some(("g", g)) => Phase::HenyeyGreenstein { g: hg_g(&g)? },
            Some((_, p)) => parse_phase(&p)?,
        };
        out.push(Medium {
            name: name.to_string(),
            kind,
            sigma_a_per_m: coefficient("sigma_a_per_m")?,
            sigma_s_per_m: coefficient("sigma_s_per_m")?,
            emission: o
                .get("emission")
                .map(|e| parse_spectrum(&e, spectra, SpectrumUse::NonNegative))
                .transpose()?,
            phase,
            fluorescence: o
                .get("fluorescence")
                .map(|f| parse_fluorescence(&f))
                .transpose()?,
        });
    }
    Ok(out)
}

fn parse_fluorescence(v: &V) -> Result<MediumFluorescence> {
    use crate::reradiation::{emission_units, grid_of, read_columns};
    let o = v.object(schema!("media.*.fluorescence"))?;
    let absorption_v = o.req(
        "absorption_per_m",
        "the fluorophore's absorption coefficient in m⁻¹ (CSV)",
    )?;
    let emission_v = o.req(
        "emission",
        "the fluorophore's emission spectrum (CSV with a `photons` or `energy` column)",
    )?;
    let absorption = absorption_v.asset("absorption spectrum", &["csv", "txt"])?;
    let emission = emission_v.asset("emission spectrum", &["csv", "txt"])?;
    let quantum_yield = o
        .req("quantum_yield", "the quantum yield Φ in [0, 1]")?
        .in_range(0.0, 1.0)?;
    let a = read_columns(&absorption_v, &absorption)?;
    let e = read_columns(&emission_v, &emission)?;
    let units = emission_units(&emission_v, &emission, &e)?;
    let excitation = grid_of(&absorption_v, &absorption, &a, "absorption")?;
    let emission_grid = grid_of(&emission_v, &emission, &e, "emission")?;
    let (a_table, e_table) = (a.table(0), e.table(0));
    // Dye::new scales the absorption to its largest grid node: the same nodes here.
    let peak_absorption_per_m = (0..excitation.count())
        .map(|k| a_table.eval(f64::from(excitation.wavelength_nm(k))))
        .fold(0.0, f64::max);
    let dye = Dye::new(
        |nm| a_table.eval(nm),
        |nm| e_table.eval(nm),
        units,
        quantum_yield,
        1.0,
        excitation,
        emission_grid,
    )
    .map_err(|err| v.err(err.message))?;
    Ok(MediumFluorescence {
        absorption,
        emission,
        units,
        quantum_yield,
        peak_absorption_per_m,
        dye,
    })
}

fn hg_g(v: &V) -> Result<f64> {
    let g = v.f64()?;
    if g <= -1.0 || g >= 1.0 {
        return Err(v.err(format!(
            "expected a Henyey–Greenstein g in (-1, 1), found {g}"
        )));
    }
    Ok(g)
}

/// `[[xmin, ymin, zmin], [xmax, ymax, zmax]]` with min < max on every axis.
fn parse_bounds(v: &V) -> Result<[[f64; 3]; 2]> {
    let corners = v.array()?;
    if corners.len() != 2 {
        return Err(v.type_err("[[xmin, ymin, zmin], [xmax, ymax, zmax]]"));
    }
    let (min, max) = (corners[0].numbers::<3>()?, corners[1].numbers::<3>()?);
    if (0..3).any(|a| min[a] >= max[a]) {
        return Err(v.err(format!(
            "empty box: expected min < max on every axis, found min {min:?}, max {max:?}"
        )));
    }
    Ok([min, max])
}

fn parse_phase(v: &V) -> Result<Phase> {
    Ok(match v.tag("phase function", &PHASE_TYPES, None)? {
        "isotropic" => {
            v.tagged_object(schema!("@phase<isotropic>"))?;
            Phase::Isotropic
        }
        "rayleigh" => {
            v.tagged_object(schema!("@phase<rayleigh>"))?;
            Phase::Rayleigh
        }
        "hg" => {
            let o = v.tagged_object(schema!("@phase<hg>"))?;
            Phase::HenyeyGreenstein {
                g: hg_g(&o.req("g", "a Henyey–Greenstein g in (-1, 1)")?)?,
            }
        }
        _ => {
            let o = v.tagged_object(schema!("@phase<tabulated>"))?;
            let f = o.req("file", "a CSV file of cos θ and value")?;
            let file = f.asset("phase function table", &["csv", "txt"])?;
            let (cos_theta, values) = read_phase_table(&file).map_err(|e| f.err(e))?;
            Phase::Tabulated {
                file,
                cos_theta,
                values,
            }
        }
    })
}

/// Reads a table of (cos θ, value) rows: comma, tab or space separated; `#` comments and
/// a header line of names are skipped. Errors give the file's line.
fn read_phase_table(path: &std::path::Path) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
    let text = prism_cpu::text_file::read_text(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let (mut cos_theta, mut values) = (Vec::new(), Vec::new());
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let numbers: Vec<Option<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        if cos_theta.is_empty() && numbers.iter().all(Option::is_none) {
            continue; // a header
        }
        let at = format!("{}:{}", path.display(), i + 1);
        let [Some(c), Some(p)] = numbers[..] else {
            return Err(format!(
                "{at}: expected two numbers (cos θ, value), found `{line}`"
            ));
        };
        if !(-1.0..=1.0).contains(&c) || !p.is_finite() || p < 0.0 {
            return Err(format!(
                "{at}: expected cos θ in [-1, 1] and a value ≥ 0, found {c}, {p}"
            ));
        }
        if cos_theta.last().is_some_and(|&last| c <= last) {
            return Err(format!(
                "{at}: cos θ must increase, found {c} after {}",
                cos_theta[cos_theta.len() - 1]
            ));
        }
        cos_theta.push(c);
        values.push(p);
    }
    if cos_theta.first() != Some(&-1.0) || cos_theta.last() != Some(&1.0) {
        return Err(format!(
            "{}: the table must run from cos θ = -1 to 1 (found {} rows{})",
            path.display(),
            cos_theta.len(),
            match (cos_theta.first(), cos_theta.last()) {
                (Some(a), Some(b)) => format!(", from {a} to {b}"),
                _ => String::new(),
            }
        ));
    }
    if values.iter().all(|&p| p == 0.0) {
        return Err(format!("{}: every value is 0", path.display()));
    }
    Ok((cos_theta, values))
}

/// The index of the medium named by `v` in `names`; unknown names list the known ones.
pub(crate) fn medium_index(v: &V, names: &[&str]) -> Result<usize> {
    crate::shape::named_index(v, "medium", "media", names)
}
