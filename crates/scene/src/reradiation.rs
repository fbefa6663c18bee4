//! The `reradiation` section: named Donaldson matrices for fluorescent materials, from a
//! Labsphere BFC-450 file (`{"bfc": "file.BFC", "negatives": "clamp|keep|error"}`) or a
//! dye model (`{"absorption": "a.csv", "emission": "e.csv", "quantum_yield": Φ,
//! "peak_absorptance": a_max}`, prism-spectrum `dye.rs`). Files are read here, so every
//! error names the scene file, the JSON path and, inside a BFC file, the line and column.

use std::path::{Path, PathBuf};

use prism_spectrum::bfc::{load_bfc, BfcData, NegativesPolicy, EXCITATION_RANGE_NM};
use prism_spectrum::spectrum_file::{read_spectral_file, SpectralColumns};
use prism_spectrum::{Dye, EmissionUnits, WavelengthGrid};

use crate::reader::{quoted_list, Result, V};
use crate::schema::schema;

/// Node spacing of a dye's matrix: the CSVs (any spacing) are sampled every 5 nm.
pub const DYE_GRID_STEP_NM: f64 = 5.0;

/// One named entry of the `reradiation` section.
#[derive(Debug, Clone, PartialEq)]
pub struct Reradiation {
    pub name: String,
    pub kind: ReradiationKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ReradiationKind {
    /// A measured (or synthetic) bispectral file: its diagonal is the reflectance R(λ).
    Bfc { file: PathBuf, data: BfcData },
    /// A dye: M from absorption, emission, quantum yield and peak absorptance; the
    /// reflectance defaults to 1 − a(λ).
    Dye {
        absorption: PathBuf,
        emission: PathBuf,
        units: EmissionUnits,
        quantum_yield: f64,
        peak_absorptance: f64,
        dye: Dye,
    },
}

impl Reradiation {
    /// Whether the entry carries its own reflectance (a BFC file's diagonal), so that a
    /// material may not give one.
    pub fn has_own_reflectance(&self) -> bool {
        match self.kind {
            ReradiationKind::Bfc { .. } => true,
            ReradiationKind::Dye { .. } => false,
        }
    }

    /// The Donaldson matrix M(λ_in, λ_out), nm⁻¹.
    pub fn matrix(&self) -> &prism_spectrum::ReradiationMatrix {
        match &self.kind {
            ReradiationKind::Bfc { data, .. } => &data.matrix,
            ReradiationKind::Dye { dye, .. } => dye.matrix(),
        }
    }
}

pub(crate) fn parse_reradiation(v: &V) -> Result<Vec<Reradiation>> {
    let mut out = Vec::new();
    for (name, entry) in v.map()? {
        let kind = if entry.member("bfc").is_some() {
            let o = entry.object(schema!("reradiation.*<bfc>"))?;
            let file_v = o.req("bfc", "a Labsphere BFC-450 file")?;
            let file = file_v.asset("BFC-450", &["bfc", "txt"])?;
            let negatives = match o.get("negatives") {
                None => NegativesPolicy::Clamp,
                Some(n) => match n.one_of("negatives policy", &["clamp", "keep", "error"])? {
                    "keep" => NegativesPolicy::Keep,
                    "error" => NegativesPolicy::Error,
                    _ => NegativesPolicy::Clamp,
                },
            };
            // The reader also refuses matrices that re-radiate more than they absorb.
            let data = load_bfc(&file, negatives).map_err(|e| file_v.err(e.to_string()))?;
            ReradiationKind::Bfc { file, data }
        } else if entry.member("absorption").is_some() || entry.member("emission").is_some() {
            let o = entry.object(schema!("reradiation.*<dye>"))?;
            let absorption_v = o.req("absorption", "the dye's absorption spectrum (CSV)")?;
            let emission_v = o.req(
                "emission",
                "the dye's emission spectrum (CSV with a `photons` or `energy` column)",
            )?;
            let absorption = absorption_v.asset("absorption spectrum", &["csv", "txt"])?;
            let emission = emission_v.asset("emission spectrum", &["csv", "txt"])?;
            let quantum_yield = o
                .req("quantum_yield", "the quantum yield Φ in [0, 1]")?
                .in_range(0.0, 1.0)?;
            let peak_absorptance = o
                .req(
                    "peak_absorptance",
                    "the absorptance at the absorption peak, in [0, 1]",
                )?
                .in_range(0.0, 1.0)?;
            let a = read_columns(&absorption_v, &absorption)?;
            let e = read_columns(&emission_v, &emission)?;
            let units = emission_units(&emission_v, &emission, &e)?;
            let excitation = grid_of(&absorption_v, &absorption, &a, "absorption")?;
            let emission_grid = grid_of(&emission_v, &emission, &e, "emission")?;
            let (a_table, e_table) = (a.table(0), e.table(0));
            let dye = Dye::new(
                |nm| a_table.eval(nm),
                |nm| e_table.eval(nm),
                units,
                quantum_yield,
                peak_absorptance,
                excitation,
                emission_grid,
            )
            .map_err(|err| entry.err(format!("reradiation `{name}`: {err}")))?;
            ReradiationKind::Dye {
                absorption,
                emission,
                units,
                quantum_yield,
                peak_absorptance,
                dye,
            }
        } else {
            return Err(entry.err(
                "expected a BFC entry {\"bfc\": FILE, \"negatives\": …} or a dye {\"absorption\": \
                 CSV, \"emission\": CSV, \"quantum_yield\": …, \"peak_absorptance\": …}",
            ));
        };
        out.push(Reradiation {
            name: name.to_string(),
            kind,
        });
    }
    Ok(out)
}

pub(crate) fn read_columns(v: &V, path: &Path) -> Result<SpectralColumns> {
    let columns = read_spectral_file(path).map_err(|e| v.err(e.to_string()))?;
    if columns.columns.len() != 1 {
        return Err(v.err(format!(
            "{} has {} value columns, expected one",
            path.display(),
            columns.columns.len()
        )));
    }
    columns
        .require_non_negative(0, path, "the spectrum")
        .map_err(|e| v.err(e.to_string()))?;
    Ok(columns)
}

/// The emission CSV's header names its column `photons` (photon counts per nm) or
/// `energy` (radiant energy per nm): the two differ by a factor λ, so it must say.
pub(crate) fn emission_units(
    v: &V,
    path: &Path,
    columns: &SpectralColumns,
) -> Result<EmissionUnits> {
    match columns.names[0].to_ascii_lowercase().as_str() {
        "photons" => Ok(EmissionUnits::Photons),
        "energy" => Ok(EmissionUnits::Energy),
        other => Err(v.err(format!(
            "{}: the emission column is named `{other}`; name it {} in the header \
             (`wavelength_nm,photons`): photon counts and energy per nm differ by a factor λ",
            path.display(),
            quoted_list(&["photons", "energy"])
        ))),
    }
}

/// The 5 nm grid inside the file's wavelength range, which must lie in 300–830 nm.
pub(crate) fn grid_of(
    v: &V,
    path: &Path,
    columns: &SpectralColumns,
    what: &str,
) -> Result<WavelengthGrid> {
    let (low, high) = EXCITATION_RANGE_NM;
    let first = columns.wavelengths_nm[0];
    let last = *columns.wavelengths_nm.last().expect("parser gives ≥ 1 row");
    if first < low || last > high {
        return Err(v.err(format!(
            "{}: the {what} spectrum covers {first}–{last} nm, outside {low}–{high} nm (the \
             range Prism's illuminants cover)",
            path.display()
        )));
    }
    let start = (first / DYE_GRID_STEP_NM).ceil() * DYE_GRID_STEP_NM;
    let end = (last / DYE_GRID_STEP_NM).floor() * DYE_GRID_STEP_NM;
    let count = ((end - start) / DYE_GRID_STEP_NM).round() as usize + 1;
    WavelengthGrid::new(start as f32, DYE_GRID_STEP_NM as f32, count).map_err(|e| {
        v.err(format!(
            "{}: the {what} spectrum ({first}–{last} nm) needs two nodes {DYE_GRID_STEP_NM} nm \
             apart: {e}",
            path.display()
        ))
    })
}
