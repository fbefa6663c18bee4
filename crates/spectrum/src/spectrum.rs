//! `Spectrum`: every kind of spectral distribution a scene can name, as one enum evaluated
//! with `match` (pbrt-v4 §4.5 `Spectrum`, without the tagged pointer). Evaluation at a
//! `SampledWavelengths` is allocation-free; tables live behind `Arc` so cloning a spectrum
//! is cheap.

use std::fmt;
use std::sync::Arc;

use crate::blackbody::{blackbody_peak_radiance, blackbody_radiance, blackbody_radiance_4};
use crate::constants::{DENSE_SAMPLE_COUNT, LAMBDA_MIN_NM};
use crate::data;
use crate::rgb_upsample::{
    RgbAlbedoSpectrum, RgbGamut, RgbIlluminantSpectrum, RgbUnboundedSpectrum, RgbUpsampleError,
};
use crate::sampled_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};
use crate::sampled_wavelengths::SampledWavelengths;
use crate::table::{DenseSpectrum, Tabulated};

/// Why spectral data could not become a `Spectrum`.
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidSpectrum {
    pub message: String,
}

impl InvalidSpectrum {
    fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }
}

impl fmt::Display for InvalidSpectrum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for InvalidSpectrum {}

/// A spectral distribution (radiance, reflectance, index of refraction, …) over wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f32),
    /// A table at arbitrary increasing wavelengths, linear between them, zero outside.
    PiecewiseLinear(PiecewiseLinear),
    /// The 1 nm grid over 360–830 nm, linear between samples, zero outside. Named CIE
    /// illuminants are stored this way.
    Dense(DenseTable),
    /// `scale` · B(λ, T), Planck's law in W·m⁻²·sr⁻¹·nm⁻¹ (see `blackbody.rs`).
    /// `Spectrum::blackbody_normalized` sets `scale = 1 / B(λ_max, T)`.
    Blackbody { temperature_k: f32, scale: f32 },
    /// A reflectance in [0, 1] upsampled from RGB (Jakob & Hanika 2019 sigmoid polynomial).
    RgbAlbedo(RgbAlbedoSpectrum),
    /// scale · sigmoid polynomial, from a non-negative RGB (pbrt-v4 `RGBUnboundedSpectrum`);
    /// also what a scaled `RgbAlbedo` becomes.
    RgbUnbounded(RgbUnboundedSpectrum),
    /// The unbounded spectrum times the gamut's white illuminant (pbrt-v4
    /// `RGBIlluminantSpectrum`), for emission.
    RgbIlluminant(RgbIlluminantSpectrum),
}

impl Spectrum {
    /// A constant spectrum.
    pub const fn constant(value: f32) -> Self {
        Spectrum::Constant(value)
    }

    /// A piecewise-linear spectrum (zero outside the table). Uniformly spaced tables are
    /// detected and evaluated by direct indexing, others through a per-1-nm segment index
    /// (one lookup, plus a forward step per node inside the cell); `eval_nm`
    /// binary-searches.
    pub fn piecewise_linear(
        wavelengths_nm: &[f64],
        values: &[f64],
    ) -> Result<Self, InvalidSpectrum> {
        PiecewiseLinear::new(wavelengths_nm, values).map(Spectrum::PiecewiseLinear)
    }

    /// A piecewise-linear spectrum holding the table's samples as they are.
    pub fn from_tabulated(table: &Tabulated) -> Result<Self, InvalidSpectrum> {
        Self::piecewise_linear(table.wavelengths_nm(), table.values())
    }

    /// The table resampled onto the 1 nm grid 360–830 nm (exact for tables whose
    /// wavelengths are whole nanometres).
    pub fn dense_from_tabulated(table: &Tabulated) -> Result<Self, InvalidSpectrum> {
        Self::from_dense(&table.to_dense())
    }

    /// A dense 1 nm spectrum.
    pub fn from_dense(dense: &DenseSpectrum) -> Result<Self, InvalidSpectrum> {
        DenseTable::new(dense).map(Spectrum::Dense)
    }

    /// A CIE illuminant by name (`D65`, `A`, `F11`, `LED-B1`, …; see
    /// `data::canonical_illuminant_name`), as its relative spectral power distribution as
    /// published (e.g. D65 = 100 at 560 nm), on the 1 nm grid.
    pub fn cie_illuminant(name: &str) -> Result<Self, InvalidSpectrum> {
        let table = data::illuminant(name).ok_or_else(|| {
            InvalidSpectrum::new(format!(
                "unknown CIE illuminant '{name}'{}",
                data::illuminant_suggestion(name)
            ))
        })?;
        Self::dense_from_tabulated(&table)
    }

    /// Absolute blackbody spectral radiance B(λ, T) in W·m⁻²·sr⁻¹·nm⁻¹.
    pub fn blackbody(temperature_k: f32) -> Result<Self, InvalidSpectrum> {
        check_temperature(temperature_k)?;
        Ok(Spectrum::Blackbody {
            temperature_k,
            scale: 1.0,
        })
    }

    /// Blackbody normalised to 1 at its peak: B(λ, T) / B(λ_max, T), λ_max = b / T (Wien).
    pub fn blackbody_normalized(temperature_k: f32) -> Result<Self, InvalidSpectrum> {
        check_temperature(temperature_k)?;
        let peak = blackbody_peak_radiance(temperature_k as f64);
        let scale = (1.0 / peak) as f32;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(InvalidSpectrum::new(format!(
                "blackbody temperature {temperature_k} K is outside the range whose peak radiance f32 can represent"
            )));
        }
        Ok(Spectrum::Blackbody {
            temperature_k,
            scale,
        })
    }

    /// A reflectance from a linear RGB in `gamut`, each component in [0, 1]; values stay in
    /// [0, 1]. Uses the refined coefficients (`RgbAlbedoSpectrum::new`).
    pub fn rgb_albedo(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        RgbAlbedoSpectrum::new(gamut, rgb).map(Spectrum::RgbAlbedo)
    }

    /// An unbounded spectrum (scattering coefficients, …) from a linear RGB ≥ 0 in `gamut`.
    pub fn rgb_unbounded(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        RgbUnboundedSpectrum::new(gamut, rgb).map(Spectrum::RgbUnbounded)
    }

    /// An emission spectrum from a linear RGB ≥ 0 in `gamut`: RGB (1, 1, 1) is the gamut's
    /// white illuminant at luminance Y = 1.
    pub fn rgb_illuminant(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        RgbIlluminantSpectrum::new(gamut, rgb).map(Spectrum::RgbIlluminant)
    }

    /// This spectrum multiplied by `factor` (tables are copied once, here, not per evaluation).
    pub fn scaled(self, factor: f32) -> Self {
        match self {
            Spectrum::Constant(v) => Spectrum::Constant(v * factor),
            Spectrum::PiecewiseLinear(p) => Spectrum::PiecewiseLinear(p.scaled(factor)),
            Spectrum::Dense(d) => Spectrum::Dense(d.scaled(factor)),
            Spectrum::Blackbody {
                temperature_k,
                scale,
            } => Spectrum::Blackbody {
                temperature_k,
                scale: scale * factor,
            },
            // A scaled reflectance is no longer bounded by 1: same polynomial, with a scale.
            Spectrum::RgbAlbedo(a) => Spectrum::RgbUnbounded(RgbUnboundedSpectrum {
                scale: factor,
                polynomial: a.polynomial,
            }),
            Spectrum::RgbUnbounded(u) => Spectrum::RgbUnbounded(RgbUnboundedSpectrum {
                scale: u.scale * factor,
                ..u
            }),
            Spectrum::RgbIlluminant(i) => Spectrum::RgbIlluminant(i.scaled(factor)),
        }
    }

    /// Values at the four sampled wavelengths.
    #[inline]
    pub fn eval(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        let lambda_nm = wavelengths.lambda();
        match self {
            Spectrum::Constant(v) => SampledSpectrum::splat(*v),
            Spectrum::PiecewiseLinear(p) => p.eval4(lambda_nm),
            Spectrum::Dense(d) => d.eval4(lambda_nm),
            Spectrum::Blackbody {
                temperature_k,
                scale,
            } => blackbody_radiance_4(lambda_nm, *temperature_k, *scale),
            Spectrum::RgbAlbedo(a) => SampledSpectrum::new(a.eval4(lambda_nm)),
            Spectrum::RgbUnbounded(u) => SampledSpectrum::new(u.eval4(lambda_nm)),
            Spectrum::RgbIlluminant(i) => SampledSpectrum::new(i.eval4(lambda_nm)),
        }
    }

    /// `eval` for `N` sets of wavelengths, the same values: for RGB reflectances one loop
    /// over all `4N` wavelengths, which becomes vector code where the caller is compiled
    /// for it (the packet path tracer evaluates a batch of camera samples' reflectances at
    /// once); other kinds one `eval` per set.
    #[inline(always)]
    pub fn eval_many<const N: usize>(
        &self,
        wavelengths: &[SampledWavelengths; N],
    ) -> [SampledSpectrum; N] {
        match self {
            Spectrum::RgbAlbedo(a) => {
                let mut value = [[0.0f32; N_SPECTRUM_SAMPLES]; N];
                for (v, w) in value.iter_mut().zip(wavelengths) {
                    let lambda = w.lambda();
                    for i in 0..N_SPECTRUM_SAMPLES {
                        v[i] = a.polynomial.eval(lambda[i]);
                    }
                }
                value.map(SampledSpectrum::new)
            }
            _ => std::array::from_fn(|k| self.eval(&wavelengths[k])),
        }
    }

    /// Value at one wavelength in f64 (reference integrals, tests, colorimetry).
    pub fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        match self {
            Spectrum::Constant(v) => *v as f64,
            Spectrum::PiecewiseLinear(p) => p.eval_nm(wavelength_nm),
            Spectrum::Dense(d) => d.eval_nm(wavelength_nm),
            Spectrum::Blackbody {
                temperature_k,
                scale,
            } => *scale as f64 * blackbody_radiance(wavelength_nm, *temperature_k as f64),
            Spectrum::RgbAlbedo(a) => a.eval_nm(wavelength_nm),
            Spectrum::RgbUnbounded(u) => u.eval_nm(wavelength_nm),
            Spectrum::RgbIlluminant(i) => i.eval_nm(wavelength_nm),
        }
    }

    /// Samples the spectrum at every whole nanometre in 360..=830.
    pub fn to_dense(&self) -> DenseSpectrum {
        DenseSpectrum::from_fn(|wl| self.eval_nm(wl))
    }
}

fn check_temperature(temperature_k: f32) -> Result<(), InvalidSpectrum> {
    if temperature_k.is_finite() && temperature_k > 0.0 {
        Ok(())
    } else {
        Err(InvalidSpectrum::new(format!(
            "blackbody temperature must be a finite number of kelvin above 0, got {temperature_k}"
        )))
    }
}

/// Most samples of a piecewise-linear table (keeps every index exact in f32, see
/// `floor_index`).
pub const MAX_TABLE_SAMPLES: usize = 1 << 24;

/// ⌊x⌋ clamped to [0, max] (NaN → 0), for table indices. The clamp makes the float → int
/// conversion's own range and NaN checks (Rust's saturating `as`) redundant, so this uses
/// the bare truncation: 2–3× fewer instructions per lane.
#[inline(always)]
pub(crate) fn floor_index(x: f32, max: usize) -> usize {
    floor_index_and_value(x, max).0
}

/// `floor_index` and the same index as f32 (converted from i32: one instruction, where
/// `usize as f32` branches on the sign bit).
#[inline(always)]
pub(crate) fn floor_index_and_value(x: f32, max: usize) -> (usize, f32) {
    let m = max.min(MAX_TABLE_SAMPLES) as u32 as f32;
    // `x > 0.0` is false for NaN.
    let x = if x > 0.0 { x } else { 0.0 };
    let x = if x < m { x } else { m };
    // SAFETY: x is finite and in [0, 2²⁴], so truncating it to i32 is defined.
    let k = unsafe { x.to_int_unchecked::<i32>() };
    (k as usize, k as f32)
}

/// Converts table values to f32, rejecting NaN, ±∞ and values f32 cannot hold.
fn finite_f32_values(values: &[f64]) -> Result<Vec<f32>, InvalidSpectrum> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let v32 = v as f32;
            if v32.is_finite() {
                Ok(v32)
            } else {
                Err(InvalidSpectrum::new(format!(
                    "spectrum value {} (sample {}) is not a finite f32 number",
                    v,
                    i + 1
                )))
            }
        })
        .collect()
}

/// Piecewise-linear table at increasing wavelengths; zero outside [first, last].
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    wavelengths_nm: Arc<[f32]>,
    values: Arc<[f32]>,
    first_nm: f32,
    last_nm: f32,
    /// 1 / spacing in nm⁻¹ when the wavelengths are uniformly spaced, else 0.
    inv_step_per_nm: f32,
    /// Non-uniform tables: `segment_at_cell[c]` is a segment i ≤ n − 2 with
    /// w[i] ≤ every wavelength that maps to cell c of the `cell_nm`-wide cells over
    /// [first, last] (empty when uniform). Lookup = this entry + a forward step over the
    /// nodes inside the cell (none for tables spaced ≥ 1 nm, apart from the rare node
    /// within rounding distance of a cell start).
    segment_at_cell: Arc<[CellEntry]>,
    /// Non-uniform tables: per segment [w0, w1, v0, slope] (one 16-byte load per lane;
    /// v = v0 + (λ − w0)·slope, slope rounded once from f64). Empty when uniform.
    segments: Arc<[[f32; 4]]>,
    /// Uniform tables: per segment [v0, v1 − v0] (one 8-byte load per lane, the same
    /// arithmetic as values[i] + t·(values[i + 1] − values[i])). Empty otherwise.
    uniform_pairs: Arc<[[f32; 2]]>,
    /// Cells per nm (1 for tables up to 65,536 nm wide).
    cells_per_nm: f32,
    /// Every cell holds at most one segment start beyond its entry (cells are narrower
    /// than the closest node spacing), so lookup is one entry + one branch-free step.
    single_step: bool,
}

/// Width of the segment-index cells of non-uniform tables, in nm (widened for tables
/// wider than `MAX_SEGMENT_CELLS` nm).
const SEGMENT_CELL_NM: f64 = 1.0;
/// Most cells of a segment-index table.
const MAX_SEGMENT_CELLS: usize = 1 << 16;

/// Relative tolerance (in units of the spacing) under which a table counts as uniform.
const UNIFORM_SPACING_TOLERANCE: f64 = 1e-6;

impl PiecewiseLinear {
    /// Validates and stores the table: same non-zero length, finite strictly increasing
    /// wavelengths (also after rounding to f32), finite values.
    pub fn new(wavelengths_nm: &[f64], values: &[f64]) -> Result<Self, InvalidSpectrum> {
        if wavelengths_nm.is_empty() {
            return Err(InvalidSpectrum::new("spectrum table is empty"));
        }
        if wavelengths_nm.len() != values.len() {
            return Err(InvalidSpectrum::new(format!(
                "spectrum table has {} wavelengths but {} values",
                wavelengths_nm.len(),
                values.len()
            )));
        }
        if wavelengths_nm.len() > MAX_TABLE_SAMPLES {
            return Err(InvalidSpectrum::new(format!(
                "spectrum table has {} samples, more than the {MAX_TABLE_SAMPLES} supported",
                wavelengths_nm.len()
            )));
        }
        let wl32: Vec<f32> = wavelengths_nm.iter().map(|&w| w as f32).collect();
        if let Some(i) = wl32.iter().position(|w| !w.is_finite()) {
            return Err(InvalidSpectrum::new(format!(
                "wavelength {} nm (sample {}) is not finite",
                wavelengths_nm[i],
                i + 1
            )));
        }
        if let Some(i) = wl32.windows(2).position(|w| w[0] >= w[1]) {
            return Err(InvalidSpectrum::new(format!(
                "wavelengths must increase strictly: sample {} ({} nm) is not above sample {} ({} nm)",
                i + 2,
                wavelengths_nm[i + 1],
                i + 1,
                wavelengths_nm[i]
            )));
        }
        let values32 = finite_f32_values(values)?;
        let n = wavelengths_nm.len();
        let first = wavelengths_nm[0];
        let inv_step_per_nm = if n >= 2 {
            let step = (wavelengths_nm[n - 1] - first) / (n - 1) as f64;
            let uniform = wavelengths_nm.iter().enumerate().all(|(i, &w)| {
                (w - (first + i as f64 * step)).abs() <= UNIFORM_SPACING_TOLERANCE * step
            });
            if uniform {
                (1.0 / step) as f32
            } else {
                0.0
            }
        } else {
            0.0
        };
        let (segment_at_cell, cells_per_nm, single_step) = if inv_step_per_nm == 0.0 && n >= 2 {
            build_segment_index(&wl32)
        } else {
            (Vec::new(), 0.0, false)
        };
        let segments = if segment_at_cell.is_empty() {
            Vec::new()
        } else {
            build_segments(&wl32, &values32)
        };
        let uniform_pairs = if inv_step_per_nm > 0.0 {
            build_uniform_pairs(&values32)
        } else {
            Vec::new()
        };
        Ok(Self {
            uniform_pairs: uniform_pairs.into(),
            segments: segments.into(),
            segment_at_cell: segment_at_cell.into(),
            cells_per_nm,
            single_step,
            first_nm: wl32[0],
            last_nm: wl32[n - 1],
            wavelengths_nm: wl32.into(),
            values: values32.into(),
            inv_step_per_nm,
        })
    }

    /// True when evaluation indexes directly (uniform spacing).
    pub fn is_uniform(&self) -> bool {
        self.inv_step_per_nm > 0.0
    }

    pub fn wavelengths_nm(&self) -> &[f32] {
        &self.wavelengths_nm
    }

    pub fn values(&self) -> &[f32] {
        &self.values
    }

    fn scaled(&self, factor: f32) -> Self {
        let values: Vec<f32> = self.values.iter().map(|v| v * factor).collect();
        let segments = if self.segments.is_empty() {
            Vec::new()
        } else {
            build_segments(&self.wavelengths_nm, &values)
        };
        let uniform_pairs = if self.uniform_pairs.is_empty() {
            Vec::new()
        } else {
            build_uniform_pairs(&values)
        };
        Self {
            values: values.into(),
            segments: segments.into(),
            uniform_pairs: uniform_pairs.into(),
            ..self.clone()
        }
    }

    #[inline]
    fn eval4(&self, lambda_nm: [f32; N_SPECTRUM_SAMPLES]) -> SampledSpectrum {
        let values = &*self.values;
        let n = values.len();
        if n < 2 {
            // A single sample: defined only at its own wavelength (as `Tabulated`).
            return SampledSpectrum::new(lambda_nm.map(|wl| {
                if wl == self.first_nm {
                    values[0]
                } else {
                    0.0
                }
            }));
        }
        let (first, last) = (self.first_nm, self.last_nm);
        if self.is_uniform() {
            let inv_step = self.inv_step_per_nm;
            SampledSpectrum::new(lambda_nm.map(|wl| {
                let x = (wl - first) * inv_step;
                // Clamped index (NaN gives 0); lanes outside the table are zeroed below.
                let (i, i_f32) = floor_index_and_value(x, n - 2);
                let t = x - i_f32;
                let [v0, dv] = self.uniform_pairs[i];
                let v = v0 + t * dv;
                if wl >= first && wl <= last {
                    v
                } else {
                    0.0
                }
            }))
        } else {
            let mut out = [0.0f32; N_SPECTRUM_SAMPLES];
            // A per-table constant: the branch is always predicted.
            if self.single_step {
                for lane in 0..N_SPECTRUM_SAMPLES {
                    let wl = lambda_nm[lane];
                    let [w0, _, v0, slope] = self.segments[self.segment_single_step(wl)];
                    let v = v0 + (wl - w0) * slope;
                    out[lane] = if wl >= first && wl <= last { v } else { 0.0 };
                }
            } else {
                for lane in 0..N_SPECTRUM_SAMPLES {
                    let wl = lambda_nm[lane];
                    let [w0, _, v0, slope] = self.segment_data(wl);
                    let v = v0 + (wl - w0) * slope;
                    out[lane] = if wl >= first && wl <= last { v } else { 0.0 };
                }
            }
            SampledSpectrum::new(out)
        }
    }

    /// `segment_of` for tables whose cells hold at most one node (`single_step`): the
    /// entry plus one branch-free step, no loop.
    #[inline(always)]
    fn segment_single_step(&self, wl: f32) -> usize {
        let cells = &*self.segment_at_cell;
        let x = (wl - self.first_nm) * self.cells_per_nm;
        let entry = cells[floor_index(x, cells.len() - 1)];
        // next_nm is +∞ for the last segment, so this never steps past it.
        entry.segment as usize + (entry.next_nm <= wl) as usize
    }

    /// `segments[segment_of(wl)]`: [w0, w1, v0, slope] of the segment holding `wl`.
    #[inline(always)]
    fn segment_data(&self, wl: f32) -> [f32; 4] {
        self.segments[self.segment_of(wl)]
    }

    /// Non-uniform tables with n ≥ 2: the segment i ∈ [0, n − 2] holding `wl` — the last
    /// i ≤ n − 2 with w[i] ≤ wl, or 0 below the table (and for NaN). One cell lookup plus
    /// a forward step per node inside the cell.
    #[inline(always)]
    fn segment_of(&self, wl: f32) -> usize {
        let segments = &*self.segments;
        let cells = &*self.segment_at_cell;
        let last_cell = cells.len() - 1;
        let last_segment = segments.len() - 1;
        // Clamped cell index (NaN gives 0).
        let x = (wl - self.first_nm) * self.cells_per_nm;
        let cell = floor_index(x, last_cell);
        let entry = cells[cell];
        // Tables spaced ≥ 1 nm hold at most one node per cell: one branch-free step against
        // the node cached in the entry (a node inside the cell is common, ~spacing⁻¹ per
        // lane, so a branch would mispredict, and reading it from `segments` would add a
        // dependent load).
        let mut i = (entry.segment as usize + (entry.next_nm <= wl) as usize).min(last_segment);
        // More nodes per cell only in sub-nm clusters (w1 of segment i is w[i + 1]).
        while i < last_segment && segments[i][1] <= wl {
            i += 1;
        }
        i
    }

    fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        let values = &*self.values;
        let n = values.len();
        let (first, last) = (self.first_nm as f64, self.last_nm as f64);
        if !(wavelength_nm >= first && wavelength_nm <= last) {
            return 0.0;
        }
        if n < 2 {
            return values[0] as f64;
        }
        let (i, t) = if self.is_uniform() {
            let x = (wavelength_nm - first) * self.inv_step_per_nm as f64;
            let i = (x as usize).min(n - 2);
            (i + 1, x - i as f64)
        } else {
            let w = &*self.wavelengths_nm;
            let i = w
                .partition_point(|&x| x as f64 <= wavelength_nm)
                .clamp(1, n - 1);
            let (w0, w1) = (w[i - 1] as f64, w[i] as f64);
            (i, (wavelength_nm - w0) / (w1 - w0))
        };
        let (v0, v1) = (values[i - 1] as f64, values[i] as f64);
        v0 + t * (v1 - v0)
    }
}

/// [v0, v1 − v0] of every segment of a uniform table (n ≥ 2).
fn build_uniform_pairs(values: &[f32]) -> Vec<[f32; 2]> {
    values.windows(2).map(|v| [v[0], v[1] - v[0]]).collect()
}

/// [w0, w1, v0, slope] of every segment (n ≥ 2), slope = (v1 − v0)/(w1 − w0) in f64.
fn build_segments(wavelengths_nm: &[f32], values: &[f32]) -> Vec<[f32; 4]> {
    wavelengths_nm
        .windows(2)
        .zip(values.windows(2))
        .map(|(w, v)| {
            let slope = (v[1] as f64 - v[0] as f64) / (w[1] as f64 - w[0] as f64);
            [w[0], w[1], v[0], slope as f32]
        })
        .collect()
}

/// Segment-index table of a non-uniform piecewise-linear table (n ≥ 2): cells of
/// `SEGMENT_CELL_NM` (or wider, at most `MAX_SEGMENT_CELLS` cells) over [first, last]; entry
/// c is the last segment i ≤ n − 2 with w[i] ≤ (start of cell c) − margin, where the margin
/// exceeds the f32 rounding of the cell computation in `segment_of`, so the entry never
/// lies beyond the segment of any wavelength mapped to the cell. Returns the entries and
/// cells per nm.
fn build_segment_index(wavelengths_nm: &[f32]) -> (Vec<CellEntry>, f32, bool) {
    let n = wavelengths_nm.len();
    let (first, last) = (wavelengths_nm[0] as f64, wavelengths_nm[n - 1] as f64);
    let range = last - first;
    // Cells of 1 nm, narrower (down to half the closest spacing) where nodes are closer,
    // within a budget of cells, so that most tables need one step at most.
    let min_spacing = wavelengths_nm
        .windows(2)
        .map(|w| w[1] as f64 - w[0] as f64)
        .fold(f64::INFINITY, f64::min);
    let cell_budget = (4 * n)
        .max(range.ceil() as usize + 1)
        .min(MAX_SEGMENT_CELLS);
    let cell_nm = SEGMENT_CELL_NM
        .min(0.5 * min_spacing)
        .max(range / (cell_budget - 1) as f64)
        .max(range / (MAX_SEGMENT_CELLS - 1) as f64);
    let cells = (range / cell_nm).ceil() as usize + 1;
    let cells_per_nm = (1.0 / cell_nm) as f32;
    // f32 error of (wl − first)·cells_per_nm, in nm: the subtraction (a few ulp of the
    // largest wavelength) and the relative error of the product (a few f32 ε of x).
    let scale = first.abs().max(last.abs());
    let margin_nm = 8.0 * f32::EPSILON as f64 * (scale + cells as f64 * cell_nm);
    let entries = (0..cells)
        .map(|c| {
            let start = first + c as f64 * cell_nm - margin_nm;
            let i = wavelengths_nm
                .partition_point(|&w| w as f64 <= start)
                .saturating_sub(1)
                .min(n - 2);
            CellEntry {
                segment: i as u32,
                // The last segment never steps on (λ = last stays in it).
                next_nm: if i + 1 < n - 1 {
                    wavelengths_nm[i + 1]
                } else {
                    f32::INFINITY
                },
            }
        })
        .collect();
    // One step suffices iff no cell sees two segment starts (nodes 1..n − 2) in
    // (start − margin, end + margin].
    let single_step = (0..cells).all(|c| {
        let start = first + c as f64 * cell_nm - margin_nm;
        let end = first + (c + 1) as f64 * cell_nm + margin_nm;
        let starts = &wavelengths_nm[1..n - 1];
        let lo = starts.partition_point(|&w| w as f64 <= start);
        let hi = starts.partition_point(|&w| w as f64 <= end);
        hi - lo <= 1
    });
    (entries, cells_per_nm, single_step)
}

/// One cell of the segment index: a segment whose start lies at or below every wavelength
/// of the cell, and the wavelength where the next segment starts (+∞ for the last).
#[derive(Clone, Copy, Debug, PartialEq)]
struct CellEntry {
    segment: u32,
    next_nm: f32,
}

/// A spectrum on the 1 nm grid 360, 361, …, 830 nm in f32.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseTable {
    values: Arc<[f32; DENSE_SAMPLE_COUNT]>,
}

impl DenseTable {
    pub fn new(dense: &DenseSpectrum) -> Result<Self, InvalidSpectrum> {
        let converted = finite_f32_values(dense.values())?;
        let mut values = [0.0f32; DENSE_SAMPLE_COUNT];
        values.copy_from_slice(&converted);
        Ok(Self {
            values: Arc::new(values),
        })
    }

    /// Values at 360, 361, …, 830 nm.
    pub fn values(&self) -> &[f32; DENSE_SAMPLE_COUNT] {
        &self.values
    }

    fn scaled(&self, factor: f32) -> Self {
        Self {
            values: Arc::new(self.values.map(|v| v * factor)),
        }
    }

    #[inline]
    fn eval4(&self, lambda_nm: [f32; N_SPECTRUM_SAMPLES]) -> SampledSpectrum {
        let values = &*self.values;
        SampledSpectrum::new(lambda_nm.map(|wl| {
            let x = wl - LAMBDA_MIN_NM;
            // Clamped index (NaN gives 0); lanes outside 360–830 nm are zeroed below.
            let last_segment = DENSE_SAMPLE_COUNT - 2;
            let (i, i_f32) = floor_index_and_value(x, last_segment);
            let t = x - i_f32;
            let v = values[i] + t * (values[i + 1] - values[i]);
            if x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f32 {
                v
            } else {
                0.0
            }
        }))
    }

    fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        let x = wavelength_nm - LAMBDA_MIN_NM as f64;
        if !(x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f64) {
            return 0.0;
        }
        let i = (x as usize).min(DENSE_SAMPLE_COUNT - 2);
        let t = x - i as f64;
        let (v0, v1) = (self.values[i] as f64, self.values[i + 1] as f64);
        v0 + t * (v1 - v0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wavelengths(lambda_nm: [f32; 4]) -> SampledWavelengths {
        SampledWavelengths::new(lambda_nm, SampledSpectrum::splat(1.0))
    }

    fn all_kinds() -> Vec<(&'static str, Spectrum)> {
        let uniform = Spectrum::piecewise_linear(
            &[400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0],
            &[0.1, 0.5, 0.2, 0.9, 0.4, 0.3, 0.8],
        )
        .unwrap();
        let non_uniform = Spectrum::piecewise_linear(
            &[380.0, 381.5, 420.0, 555.25, 700.0, 780.0],
            &[1.0, 2.0, 0.5, 3.0, 0.25, 4.0],
        )
        .unwrap();
        vec![
            ("constant", Spectrum::constant(0.7)),
            ("uniform", uniform),
            ("non-uniform", non_uniform),
            (
                "dense",
                Spectrum::from_dense(&data::cmfs(data::Observer::Cie1931).y_bar).unwrap(),
            ),
            ("blackbody", Spectrum::blackbody(3000.0).unwrap()),
            (
                "blackbody normalised",
                Spectrum::blackbody_normalized(6500.0).unwrap(),
            ),
            ("F11", Spectrum::cie_illuminant("F11").unwrap()),
            ("D65", Spectrum::cie_illuminant("d65").unwrap()),
            (
                "rgb albedo",
                Spectrum::rgb_albedo(RgbGamut::Srgb, [0.8, 0.3, 0.1]).unwrap(),
            ),
            (
                "rgb albedo rec2020 saturated",
                Spectrum::rgb_albedo(RgbGamut::Rec2020, [0.1, 0.9, 0.05]).unwrap(),
            ),
            (
                "rgb unbounded",
                Spectrum::rgb_unbounded(RgbGamut::AcesCg, [3.0, 0.5, 1.25]).unwrap(),
            ),
            (
                "rgb illuminant",
                Spectrum::rgb_illuminant(RgbGamut::Srgb, [2.0, 1.0, 0.25]).unwrap(),
            ),
        ]
    }

    /// The batch form gives `eval`'s bits for every kind (RGB reflectances by their own
    /// loop, the rest through `eval`).
    #[test]
    fn eval_many_is_eval_per_set() {
        let sets: [SampledWavelengths; 5] =
            std::array::from_fn(|k| SampledWavelengths::sample_visible((k as f32 * 0.377).fract()));
        for (name, spectrum) in all_kinds() {
            let many = spectrum.eval_many(&sets);
            for (k, w) in sets.iter().enumerate() {
                assert_eq!(
                    many[k].to_array().map(f32::to_bits),
                    spectrum.eval(w).to_array().map(f32::to_bits),
                    "{name}, set {k}"
                );
            }
        }
    }

    #[test]
    fn eval_agrees_with_eval_nm_for_every_kind() {
        let mut lanes = Vec::new();
        // Nodes, in-between points, the range ends and points outside every table.
        for i in 0..=1880 {
            lanes.push(355.0 + i as f32 * 0.25);
        }
        lanes.extend([
            359.9,
            360.0,
            379.99,
            380.0,
            780.0,
            780.01,
            830.0,
            830.1,
            -5.0,
            f32::NAN,
        ]);
        while lanes.len() % 4 != 0 {
            lanes.push(500.0);
        }
        for (name, spectrum) in all_kinds() {
            let scale = (0..=470)
                .map(|i| spectrum.eval_nm(360.0 + i as f64).abs())
                .fold(0.0, f64::max);
            for chunk in lanes.chunks(4) {
                let lambda: [f32; 4] = chunk.try_into().unwrap();
                let got = spectrum.eval(&wavelengths(lambda));
                for lane in 0..4 {
                    let expected = spectrum.eval_nm(lambda[lane] as f64);
                    let got_lane = got[lane] as f64;
                    // The sigmoid kinds are defined at every wavelength: NaN in, NaN out.
                    if expected.is_nan() && got_lane.is_nan() {
                        continue;
                    }
                    // Saturated sigmoid polynomials have terms ~1e3 for an argument ~1, so
                    // the f32 argument carries ~1e-4 of rounding (f64 `eval_nm` does not).
                    let sigmoid_slack = if name.starts_with("rgb") {
                        1e-4 * scale
                    } else {
                        0.0
                    };
                    assert!(
                        (got_lane - expected).abs()
                            <= 2e-6 * scale + 1e-5 * expected.abs() + sigmoid_slack,
                        "{name} at {} nm: eval {got_lane}, eval_nm {expected}",
                        lambda[lane]
                    );
                }
            }
        }
    }

    #[test]
    fn clustered_non_uniform_tables_evaluate_exactly() {
        // Nodes crowded at both ends and sparse in the middle stress the segment index.
        let mut wavelengths_nm: Vec<f64> = (0..40).map(|i| 380.0 + 0.05 * i as f64).collect();
        wavelengths_nm.extend([450.0, 455.5, 600.0]);
        wavelengths_nm.extend((0..40).map(|i| 700.0 + 0.01 * i as f64));
        wavelengths_nm.push(780.0);
        let values: Vec<f64> = (0..wavelengths_nm.len())
            .map(|i| ((i * 7919) % 13) as f64)
            .collect();
        let s = Spectrum::piecewise_linear(&wavelengths_nm, &values).unwrap();
        let table = Tabulated::new(wavelengths_nm.clone(), values).unwrap();
        let mut probes: Vec<f32> = wavelengths_nm.iter().map(|&w| w as f32).collect();
        probes.extend((0..20_000).map(|i| 375.0 + 0.021 * i as f32));
        while !probes.len().is_multiple_of(4) {
            probes.push(600.0);
        }
        for chunk in probes.chunks(4) {
            let lambda: [f32; 4] = chunk.try_into().unwrap();
            let got = s.eval(&wavelengths(lambda));
            for lane in 0..4 {
                // Against the f64 evaluation of the same f32 nodes (segment search by
                // plain binary search); the f64 `Tabulated` agrees to f32 node rounding.
                let expected = s.eval_nm(lambda[lane] as f64);
                assert!((expected - table.eval(lambda[lane] as f64)).abs() < 0.1);
                assert!(
                    (got[lane] as f64 - expected).abs() < 1e-5,
                    "{} nm: {} vs {expected}",
                    lambda[lane],
                    got[lane]
                );
            }
        }
    }

    /// SplitMix64, uniform f64 in [0, 1).
    fn next_unit(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    #[test]
    fn segment_index_matches_binary_search_exactly_on_random_tables() {
        let mut state = 0x5e9_0001u64;
        let mut modes_seen = [0usize; 2];
        for table_no in 0..200 {
            // Random increasing wavelengths: gaps from 0.001 nm to 40 nm, some tables wide
            // (IOR data reach far into the infrared), some starting at negative or odd values.
            let n = 2 + (next_unit(&mut state) * 120.0) as usize;
            let mut w = 200.0 + next_unit(&mut state) * 400.0;
            let wide = table_no % 5 == 0;
            let mut wavelengths_nm = Vec::with_capacity(n);
            for _ in 0..n {
                wavelengths_nm.push(w);
                let u = next_unit(&mut state);
                // Odd tables: no sub-nm gaps (the single-step lookup); even: clusters.
                w += if u < 0.2 && table_no % 2 == 0 {
                    0.001 + u * 0.01
                } else if wide {
                    1.0 + u * 400.0
                } else {
                    0.7 + u * 40.0
                };
            }
            let values: Vec<f64> = (0..n).map(|_| next_unit(&mut state) * 10.0 - 2.0).collect();
            let Ok(Spectrum::PiecewiseLinear(p)) =
                Spectrum::piecewise_linear(&wavelengths_nm, &values)
            else {
                continue; // rounding to f32 merged two nodes
            };
            if p.is_uniform() {
                continue;
            }
            modes_seen[p.single_step as usize] += 1;
            let w32 = p.wavelengths_nm().to_vec();
            let (first, last) = (w32[0], w32[n - 1]);
            let mut probes: Vec<f32> = w32.clone();
            // Nodes, their f32 neighbours, random points, and points outside.
            for &x in &w32 {
                probes.push(f32::from_bits(x.to_bits() - 1));
                probes.push(f32::from_bits(x.to_bits() + 1));
            }
            for _ in 0..4000 {
                let u = next_unit(&mut state);
                probes.push((first as f64 - 5.0 + u * (last - first + 10.0) as f64) as f32);
            }
            probes.extend([f32::NAN, -1e30, 1e30, first - 1.0, last + 1.0]);
            while !probes.len().is_multiple_of(4) {
                probes.push(first);
            }
            let tabulated = Tabulated::new(wavelengths_nm.clone(), values.clone()).unwrap();
            let spectrum = Spectrum::PiecewiseLinear(p.clone());
            for chunk in probes.chunks(4) {
                let lambda: [f32; 4] = chunk.try_into().unwrap();
                let got = spectrum.eval(&wavelengths(lambda));
                for lane in 0..4 {
                    let wl = lambda[lane];
                    // Reference: binary search over the f32 nodes, same f32 arithmetic.
                    let i = w32.partition_point(|&x| x <= wl).clamp(1, n - 1) - 1;
                    if wl >= first && wl <= last {
                        assert_eq!(p.segment_of(wl), i, "table {table_no} at {wl} nm");
                        assert_eq!(p.segment_data(wl), p.segments[i]);
                        if p.single_step {
                            assert_eq!(p.segment_single_step(wl), i, "table {table_no} at {wl}");
                        }
                    }
                    let (w0, w1) = (w32[i], w32[i + 1]);
                    let vals = p.values();
                    let [sw0, sw1, v0, slope] = p.segments[i];
                    assert_eq!((sw0, sw1, v0), (w0, w1, vals[i]));
                    let v = v0 + (wl - w0) * slope;
                    let expected = if wl >= first && wl <= last { v } else { 0.0 };
                    assert_eq!(
                        got[lane].to_bits(),
                        expected.to_bits(),
                        "table {table_no} at {wl} nm: {} vs {expected}",
                        got[lane]
                    );
                    // And the f64 table agrees up to f32 rounding.
                    // (inside both the f32 and the f64 node ranges).
                    let inside_f64 =
                        wl as f64 >= wavelengths_nm[0] && wl as f64 <= wavelengths_nm[n - 1];
                    if wl >= first && wl <= last && inside_f64 {
                        let reference = tabulated.eval(wl as f64);
                        // Nodes rounded to f32 move by ≤ ½ ulp: the value by slope × that.
                        // (the f64 table may put λ in a neighbouring segment).
                        let slope = (i.saturating_sub(1)..(i + 2).min(n - 1))
                            .map(|k| ((vals[k + 1] - vals[k]) / (w32[k + 1] - w32[k])).abs())
                            .fold(0.0f32, f32::max) as f64;
                        let tol = slope * 2.0 * f32::EPSILON as f64 * wl.abs() as f64
                            + 1e-5 * (1.0 + reference.abs());
                        assert!(
                            (got[lane] as f64 - reference).abs() <= tol,
                            "table {table_no} at {wl} nm: {} vs Tabulated {reference}",
                            got[lane]
                        );
                    }
                }
            }
        }
        // Both lookups were exercised.
        assert!(modes_seen[0] > 20 && modes_seen[1] > 20, "{modes_seen:?}");
    }

    #[test]
    fn tables_match_their_source_and_vanish_outside() {
        let table = Tabulated::new(vec![400.0, 500.0, 700.0], vec![1.0, 3.0, 1.0]).unwrap();
        let s = Spectrum::from_tabulated(&table).unwrap();
        let Spectrum::PiecewiseLinear(p) = &s else {
            panic!("expected a piecewise-linear spectrum")
        };
        assert!(!p.is_uniform());
        for wl in [399.9, 400.0, 450.0, 600.0, 700.0, 700.1] {
            assert!((s.eval_nm(wl) - table.eval(wl)).abs() < 1e-6);
        }
        let uniform = Spectrum::piecewise_linear(&[400.0, 500.0, 600.0], &[1.0, 3.0, 1.0]).unwrap();
        let Spectrum::PiecewiseLinear(p) = &uniform else {
            panic!("expected a piecewise-linear spectrum")
        };
        assert!(p.is_uniform());
        let got = uniform.eval(&wavelengths([399.0, 450.0, 600.0, 601.0]));
        assert_eq!(got.values, [0.0, 2.0, 1.0, 0.0]);
        let single = Spectrum::piecewise_linear(&[500.0], &[2.0]).unwrap();
        assert_eq!(
            single.eval(&wavelengths([500.0, 501.0, 0.0, 499.0])).values,
            [2.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(single.eval_nm(500.0), 2.0);
    }

    #[test]
    fn named_illuminants_are_dense_copies_of_the_cie_tables() {
        let f11 = Spectrum::cie_illuminant("FL11").unwrap();
        assert!(matches!(f11, Spectrum::Dense(_)));
        let table = data::illuminant("F11").unwrap();
        for i in 0..=470 {
            let wl = 360.0 + i as f64;
            assert!((f11.eval_nm(wl) - table.eval(wl)).abs() < 1e-4 * table.eval(wl).max(1.0));
        }
        let err = Spectrum::cie_illuminant("D56").unwrap_err();
        assert!(
            err.message.contains("unknown CIE illuminant 'D56'"),
            "{err}"
        );
    }

    #[test]
    fn blackbody_kinds_follow_plancks_law() {
        let abs = Spectrum::blackbody(5000.0).unwrap();
        assert!((abs.eval_nm(500.0) / blackbody_radiance(500.0, 5000.0) - 1.0).abs() < 1e-12);
        let norm = Spectrum::blackbody_normalized(5000.0).unwrap();
        let peak_nm = crate::blackbody::wien_peak_wavelength_nm(5000.0);
        assert!((norm.eval_nm(peak_nm) - 1.0).abs() < 1e-6);
        assert!(Spectrum::blackbody(0.0).is_err());
        assert!(Spectrum::blackbody(-300.0).is_err());
        assert!(Spectrum::blackbody_normalized(f32::NAN).is_err());
    }

    #[test]
    fn scaling_multiplies_every_kind() {
        for (name, spectrum) in all_kinds() {
            let scaled = spectrum.clone().scaled(2.5);
            for wl in [365.0, 412.3, 555.0, 701.7, 829.0] {
                let (a, b) = (spectrum.eval_nm(wl), scaled.eval_nm(wl));
                assert!(
                    (b - 2.5 * a).abs() <= 1e-6 * b.abs().max(1e-30),
                    "{name} at {wl}: {a} {b}"
                );
            }
        }
    }

    #[test]
    fn invalid_tables_are_rejected_with_messages() {
        let e = Spectrum::piecewise_linear(&[], &[]).unwrap_err();
        assert!(e.message.contains("empty"));
        let e = Spectrum::piecewise_linear(&[400.0, 500.0], &[1.0]).unwrap_err();
        assert!(e.message.contains("2 wavelengths but 1 values"));
        let e = Spectrum::piecewise_linear(&[400.0, 400.0], &[1.0, 2.0]).unwrap_err();
        assert!(e.message.contains("increase strictly"), "{e}");
        let e = Spectrum::piecewise_linear(&[400.0, 400.000_000_01], &[1.0, 2.0]).unwrap_err();
        assert!(e.message.contains("increase strictly"), "{e}");
        let e = Spectrum::piecewise_linear(&[400.0, f64::NAN], &[1.0, 2.0]).unwrap_err();
        assert!(e.message.contains("not finite"), "{e}");
        let e = Spectrum::piecewise_linear(&[400.0, 500.0], &[1.0, f64::NAN]).unwrap_err();
        assert!(e.message.contains("sample 2"), "{e}");
        let e = Spectrum::piecewise_linear(&[400.0, 500.0], &[1e300, 1.0]).unwrap_err();
        assert!(e.message.contains("finite f32"), "{e}");
    }

    #[test]
    fn to_dense_samples_whole_nanometres() {
        let s = Spectrum::piecewise_linear(&[380.0, 780.0], &[0.0, 400.0]).unwrap();
        let d = s.to_dense();
        assert_eq!(d.values()[20], 0.0);
        assert!((d.values()[21] - 1.0).abs() < 1e-4);
        assert_eq!(d.values()[421], 0.0);
        assert_eq!(
            Spectrum::constant(3.0).to_dense(),
            DenseSpectrum::constant(3.0)
        );
    }
}
