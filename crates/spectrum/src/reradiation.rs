//! Re-radiation (Donaldson) matrices for fluorescence: light absorbed at an excitation
//! wavelength λ_in is re-emitted at emission wavelengths λ_out (Donaldson 1954; Hullin et
//! al. 2010, "Fluorescent immersion range scanning", §3; Jung et al. 2019 for spectral
//! rendering with re-radiation).
//!
//! The matrix holds M(λ_in, λ_out): emitted spectral radiance per nm at λ_out per unit
//! incident at λ_in, on uniformly spaced excitation × emission grids, bilinear in between
//! and zero outside. ∫ M(λ_in, λ_out) dλ_out is the re-radiated fraction at λ_in and must not
//! exceed 1 for a physical (energy-conserving) material.
//!
//! Emission sampling draws λ_out proportionally to the bilinearly interpolated row
//! M(λ_in, ·), which is piecewise linear in λ_out: a segment is picked by its integral (the
//! row CDF at the nodes is linear in the row interpolation weight, so per-row cumulative
//! integrals are precomputed once) and the position inside it by inverting the CDF of a
//! linear density (a quadratic, solved in its cancellation-free form). Excitation sampling
//! (λ_in ∝ M(·, λ_out), for camera paths) is the same on per-column cumulative integrals.
//!
//! Measured matrices carry noise around zero; `from_dense_signed` keeps it. Evaluation and
//! `row_integral` keep the sign, while sampling draws ∝ the bilinear interpolation of |M| at
//! the nodes (≥ |M| and non-zero wherever M is), so M/pdf stays a valid, signed weight.

use std::fmt;

/// Why a re-radiation matrix could not be built.
#[derive(Debug, Clone, PartialEq)]
pub struct ReradiationError {
    pub message: String,
}

impl ReradiationError {
    fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }
}

impl fmt::Display for ReradiationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for ReradiationError {}

/// Uniformly spaced wavelengths start, start + step, …, start + (count − 1)·step, in nm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WavelengthGrid {
    start_nm: f32,
    step_nm: f32,
    count: usize,
}

impl WavelengthGrid {
    /// A grid with at least two finite, strictly increasing wavelengths.
    pub fn new(start_nm: f32, step_nm: f32, count: usize) -> Result<Self, ReradiationError> {
        if !(start_nm.is_finite() && step_nm.is_finite() && step_nm > 0.0) {
            return Err(ReradiationError::new(format!(
                "wavelength grid needs a finite start and a positive step, got start {start_nm} nm, step {step_nm} nm"
            )));
        }
        if count < 2 {
            return Err(ReradiationError::new(format!(
                "wavelength grid needs at least 2 wavelengths, got {count}"
            )));
        }
        Ok(Self {
            start_nm,
            step_nm,
            count,
        })
    }

    pub fn start_nm(&self) -> f32 {
        self.start_nm
    }

    pub fn step_nm(&self) -> f32 {
        self.step_nm
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// Wavelength of node `index` in nm.
    pub fn wavelength_nm(&self, index: usize) -> f32 {
        (self.start_nm as f64 + index as f64 * self.step_nm as f64) as f32
    }

    /// Last wavelength of the grid in nm.
    pub fn end_nm(&self) -> f32 {
        self.wavelength_nm(self.count - 1)
    }

    /// Segment index i ∈ [0, count − 2] and fraction t ∈ [0, 1] of `wavelength_nm`;
    /// `None` outside the grid (or NaN).
    #[inline]
    fn locate(&self, wavelength_nm: f32) -> Option<(usize, f64)> {
        let x = (wavelength_nm as f64 - self.start_nm as f64) / self.step_nm as f64;
        if !(x >= 0.0 && x <= (self.count - 1) as f64) {
            return None;
        }
        let i = (x as usize).min(self.count - 2);
        Some((i, x - i as f64))
    }
}

/// A Donaldson matrix: excitation × emission, row-major by excitation.
#[derive(Debug, Clone, PartialEq)]
pub struct ReradiationMatrix {
    excitation: WavelengthGrid,
    emission: WavelengthGrid,
    /// M at the nodes, `values[row * emission.count + column]`.
    values: Box<[f32]>,
    /// Per row, ∫ from the first emission node to node `column` of the row (trapezoids,
    /// exact for the piecewise-linear row), `cumulative[row * emission.count + column]`.
    cumulative: Box<[f64]>,
    /// |M| at the nodes: the sampling density is bilinear in these (equal to `values` for a
    /// non-negative matrix). For a signed matrix it bounds |M| from above and is non-zero
    /// wherever M is, so M/pdf is a valid signed weight.
    magnitudes: Box<[f32]>,
    /// As `cumulative`, of the magnitudes.
    magnitude_cumulative: Box<[f64]>,
    /// Per emission column, ∫ from the first excitation node to node `row` of the column's
    /// magnitudes, `column_cumulative[column * excitation.count + row]`: the per-column CDFs
    /// of `sample_excitation`.
    column_cumulative: Box<[f64]>,
    /// Per emission column, ∫ M dλ_in over the whole excitation grid (signed).
    column_totals: Box<[f64]>,
    /// Whether some node is negative (only `from_dense_signed` allows it).
    signed: bool,
}

impl ReradiationMatrix {
    /// From node values in row-major order (one row of `emission.count()` values per
    /// excitation wavelength). Entries must be finite and non-negative.
    pub fn from_dense(
        excitation: WavelengthGrid,
        emission: WavelengthGrid,
        values: Vec<f32>,
    ) -> Result<Self, ReradiationError> {
        Self::build(excitation, emission, values, false)
    }

    /// As `from_dense`, but entries may be negative (measured matrices carry noise around
    /// zero): evaluation and the integrals keep the sign, sampling draws ∝ |M| at the nodes.
    pub fn from_dense_signed(
        excitation: WavelengthGrid,
        emission: WavelengthGrid,
        values: Vec<f32>,
    ) -> Result<Self, ReradiationError> {
        Self::build(excitation, emission, values, true)
    }

    fn build(
        excitation: WavelengthGrid,
        emission: WavelengthGrid,
        values: Vec<f32>,
        allow_negative: bool,
    ) -> Result<Self, ReradiationError> {
        let expected = excitation.count * emission.count;
        if values.len() != expected {
            return Err(ReradiationError::new(format!(
                "re-radiation matrix has {} entries, expected {} excitation rows × {} emission columns = {expected}",
                values.len(),
                excitation.count,
                emission.count
            )));
        }
        for (index, &v) in values.iter().enumerate() {
            if !(v.is_finite() && (allow_negative || v >= 0.0)) {
                let (row, column) = (index / emission.count, index % emission.count);
                let rule = if allow_negative {
                    "finite"
                } else {
                    "finite and non-negative"
                };
                return Err(ReradiationError::new(format!(
                    "re-radiation matrix entry at excitation row {} ({} nm), emission column {} ({} nm) is {v}: entries must be {rule}",
                    row + 1,
                    excitation.wavelength_nm(row),
                    column + 1,
                    emission.wavelength_nm(column)
                )));
            }
        }
        let signed = values.iter().any(|&v| v < 0.0);
        let magnitudes: Box<[f32]> = values.iter().map(|v| v.abs()).collect();
        let cumulative = row_cumulative(&values, emission);
        let magnitude_cumulative = if signed {
            row_cumulative(&magnitudes, emission)
        } else {
            cumulative.clone()
        };
        let transpose = |table: &[f32]| -> Vec<f32> {
            (0..emission.count)
                .flat_map(|column| {
                    (0..excitation.count).map(move |row| table[row * emission.count + column])
                })
                .collect()
        };
        let column_cumulative = row_cumulative(&transpose(&magnitudes), excitation);
        let column_totals = row_cumulative(&transpose(&values), excitation)
            .chunks_exact(excitation.count)
            .map(|c| c[excitation.count - 1])
            .collect();
        Ok(Self {
            excitation,
            emission,
            values: values.into_boxed_slice(),
            cumulative,
            magnitudes,
            magnitude_cumulative,
            column_cumulative,
            column_totals,
            signed,
        })
    }

    /// Whether some entry is negative (a signed matrix from `from_dense_signed`).
    pub fn is_signed(&self) -> bool {
        self.signed
    }

    /// From rows as any parser produces them: exactly `excitation.count()` rows of
    /// `emission.count()` values each.
    pub fn from_rows<R: AsRef<[f32]>>(
        excitation: WavelengthGrid,
        emission: WavelengthGrid,
        rows: impl IntoIterator<Item = R>,
    ) -> Result<Self, ReradiationError> {
        let mut values = Vec::with_capacity(excitation.count * emission.count);
        let mut row_count = 0;
        for row in rows {
            let row = row.as_ref();
            row_count += 1;
            if row_count > excitation.count {
                return Err(ReradiationError::new(format!(
                    "re-radiation matrix has more than the {} excitation rows of its grid",
                    excitation.count
                )));
            }
            if row.len() != emission.count {
                return Err(ReradiationError::new(format!(
                    "re-radiation matrix excitation row {row_count} ({} nm) has {} values, expected {} (one per emission wavelength)",
                    excitation.wavelength_nm(row_count - 1),
                    row.len(),
                    emission.count
                )));
            }
            values.extend_from_slice(row);
        }
        if row_count != excitation.count {
            return Err(ReradiationError::new(format!(
                "re-radiation matrix has {row_count} excitation rows, expected {}",
                excitation.count
            )));
        }
        Self::from_dense(excitation, emission, values)
    }

    /// Evaluates `f(λ_in_nm, λ_out_nm)` at every node.
    pub fn from_fn(
        excitation: WavelengthGrid,
        emission: WavelengthGrid,
        mut f: impl FnMut(f32, f32) -> f32,
    ) -> Result<Self, ReradiationError> {
        let mut values = Vec::with_capacity(excitation.count * emission.count);
        for row in 0..excitation.count {
            for column in 0..emission.count {
                values.push(f(
                    excitation.wavelength_nm(row),
                    emission.wavelength_nm(column),
                ));
            }
        }
        Self::from_dense(excitation, emission, values)
    }

    pub fn excitation(&self) -> &WavelengthGrid {
        &self.excitation
    }

    pub fn emission(&self) -> &WavelengthGrid {
        &self.emission
    }

    /// Node value at (excitation row, emission column).
    pub fn node(&self, row: usize, column: usize) -> f32 {
        self.values[row * self.emission.count + column]
    }

    #[inline]
    fn node_f64(&self, row: usize, column: usize) -> f64 {
        self.values[row * self.emission.count + column] as f64
    }

    #[inline]
    fn cumulative_at(&self, row: usize, s: f64, column: usize) -> f64 {
        let n = self.emission.count;
        (1.0 - s) * self.cumulative[row * n + column] + s * self.cumulative[(row + 1) * n + column]
    }

    /// Row `row` interpolated with weight `s` towards row + 1, at emission node `column`.
    #[inline]
    fn row_node(&self, row: usize, s: f64, column: usize) -> f64 {
        (1.0 - s) * self.node_f64(row, column) + s * self.node_f64(row + 1, column)
    }

    /// M(λ_in, λ_out) in nm⁻¹, bilinear between nodes, zero outside either grid.
    pub fn eval(&self, excitation_nm: f32, emission_nm: f32) -> f32 {
        self.eval_f64(excitation_nm, emission_nm) as f32
    }

    fn eval_f64(&self, excitation_nm: f32, emission_nm: f32) -> f64 {
        let (Some((row, s)), Some((column, t))) = (
            self.excitation.locate(excitation_nm),
            self.emission.locate(emission_nm),
        ) else {
            return 0.0;
        };
        let a = self.row_node(row, s, column);
        let b = self.row_node(row, s, column + 1);
        a + t * (b - a)
    }

    /// ∫ M(λ_in, λ_out) dλ_out: the fraction of light absorbed at λ_in that is re-radiated
    /// (zero outside the excitation grid).
    pub fn row_integral(&self, excitation_nm: f32) -> f32 {
        self.row_integral_f64(excitation_nm) as f32
    }

    fn row_integral_f64(&self, excitation_nm: f32) -> f64 {
        match self.excitation.locate(excitation_nm) {
            Some((row, s)) => self.cumulative_at(row, s, self.emission.count - 1),
            None => 0.0,
        }
    }

    /// The excitation wavelength (nm) with the largest re-radiated fraction, and that
    /// fraction. The fraction is linear between excitation nodes, so its maximum is at a node.
    pub fn max_row_integral(&self) -> (f32, f32) {
        let last = self.emission.count - 1;
        (0..self.excitation.count)
            .map(|row| {
                (
                    self.excitation.wavelength_nm(row),
                    self.cumulative[row * self.emission.count + last] as f32,
                )
            })
            .fold((self.excitation.start_nm, f32::NEG_INFINITY), |best, x| {
                if x.1 > best.1 {
                    x
                } else {
                    best
                }
            })
    }

    /// Ok when no excitation wavelength re-radiates more than it absorbs (row integrals
    /// ≤ 1 + `tolerance`); otherwise an error naming the worst row.
    pub fn check_energy_conservation(&self, tolerance: f32) -> Result<(), ReradiationError> {
        let (excitation_nm, fraction) = self.max_row_integral();
        if fraction <= 1.0 + tolerance {
            Ok(())
        } else {
            Err(ReradiationError::new(format!(
                "re-radiation matrix emits {fraction} times the absorbed energy at excitation {excitation_nm} nm: a physical matrix re-radiates at most 1"
            )))
        }
    }

    /// True when `check_energy_conservation(1e-4)` passes.
    pub fn is_energy_conserving(&self) -> bool {
        self.check_energy_conservation(1e-4).is_ok()
    }

    /// ∫ |M|(λ_in, λ_out) dλ_out with |M| bilinear in the node magnitudes: the row's
    /// sampling mass (equal to `row_integral` for a non-negative matrix).
    pub fn row_magnitude_integral(&self, excitation_nm: f32) -> f32 {
        self.row_magnitude_integral_f64(excitation_nm) as f32
    }

    fn row_magnitude_integral_f64(&self, excitation_nm: f32) -> f64 {
        match self.excitation.locate(excitation_nm) {
            Some((row, s)) => self.magnitude_cumulative_at(row, s, self.emission.count - 1),
            None => 0.0,
        }
    }

    #[inline]
    fn magnitude_cumulative_at(&self, row: usize, s: f64, column: usize) -> f64 {
        let n = self.emission.count;
        (1.0 - s) * self.magnitude_cumulative[row * n + column]
            + s * self.magnitude_cumulative[(row + 1) * n + column]
    }

    /// The sampling density's unnormalised value: bilinear in the node magnitudes.
    fn eval_magnitude_f64(&self, excitation_nm: f32, emission_nm: f32) -> f64 {
        let (Some((row, s)), Some((column, t))) = (
            self.excitation.locate(excitation_nm),
            self.emission.locate(emission_nm),
        ) else {
            return 0.0;
        };
        let n = self.emission.count;
        let node = |c: usize| {
            (1.0 - s) * self.magnitudes[row * n + c] as f64
                + s * self.magnitudes[(row + 1) * n + c] as f64
        };
        let (a, b) = (node(column), node(column + 1));
        a + t * (b - a)
    }

    /// Draws λ_out with density ∝ M(λ_in, ·) (∝ |M| at the nodes, bilinear, for a signed
    /// matrix) from `u` ∈ [0, 1). Returns the wavelength in nm and its density in nm⁻¹, or
    /// `None` when λ_in is outside the excitation grid or nothing is re-radiated there.
    pub fn sample_emission(&self, excitation_nm: f32, u: f32) -> Option<(f32, f32)> {
        let (row, s) = self.excitation.locate(excitation_nm)?;
        let n = self.emission.count;
        let node = |c: usize| {
            (1.0 - s) * self.magnitudes[row * n + c] as f64
                + s * self.magnitudes[(row + 1) * n + c] as f64
        };
        sample_piecewise_linear(
            &self.emission,
            node,
            |c| self.magnitude_cumulative_at(row, s, c),
            u,
        )
    }

    /// Density of `sample_emission` at λ_out given λ_in, in nm⁻¹.
    pub fn pdf_emission(&self, excitation_nm: f32, emission_nm: f32) -> f32 {
        let total = self.row_magnitude_integral_f64(excitation_nm);
        if total > 0.0 {
            (self.eval_magnitude_f64(excitation_nm, emission_nm) / total) as f32
        } else {
            0.0
        }
    }
}

impl ReradiationMatrix {
    /// c(λ_out) = ∫ M(λ_in, λ_out) dλ_in: how much an emission wavelength gathers from all
    /// excitations (zero outside the emission grid).
    pub fn column_integral(&self, emission_nm: f32) -> f32 {
        match self.emission.locate(emission_nm) {
            Some((column, t)) => {
                ((1.0 - t) * self.column_totals[column] + t * self.column_totals[column + 1]) as f32
            }
            None => 0.0,
        }
    }

    /// ∫ |M|(λ_in, λ_out) dλ_in with |M| bilinear in the node magnitudes: the column's
    /// sampling mass (equal to `column_integral` for a non-negative matrix).
    pub fn column_magnitude_integral(&self, emission_nm: f32) -> f32 {
        self.column_magnitude_integral_f64(emission_nm) as f32
    }

    fn column_magnitude_integral_f64(&self, emission_nm: f32) -> f64 {
        match self.emission.locate(emission_nm) {
            Some((column, t)) => self.column_cumulative_at(column, t, self.excitation.count - 1),
            None => 0.0,
        }
    }

    #[inline]
    fn column_cumulative_at(&self, column: usize, t: f64, row: usize) -> f64 {
        let n = self.excitation.count;
        (1.0 - t) * self.column_cumulative[column * n + row]
            + t * self.column_cumulative[(column + 1) * n + row]
    }

    /// Draws λ_in with density ∝ M(·, λ_out) (∝ |M| at the nodes, bilinear, for a signed
    /// matrix) from `u` ∈ [0, 1): for camera paths, which meet the emission wavelength first
    /// and ask which excitation fed it. Returns the wavelength in nm and its density in
    /// nm⁻¹, or `None` when λ_out is outside the emission grid or nothing re-radiates there.
    pub fn sample_excitation(&self, emission_nm: f32, u: f32) -> Option<(f32, f32)> {
        let (column, t) = self.emission.locate(emission_nm)?;
        let m = self.emission.count;
        let node = |row: usize| {
            (1.0 - t) * self.magnitudes[row * m + column] as f64
                + t * self.magnitudes[row * m + column + 1] as f64
        };
        sample_piecewise_linear(
            &self.excitation,
            node,
            |row| self.column_cumulative_at(column, t, row),
            u,
        )
    }

    /// Density of `sample_excitation` at λ_in given λ_out, in nm⁻¹.
    pub fn pdf_excitation(&self, emission_nm: f32, excitation_nm: f32) -> f32 {
        let total = self.column_magnitude_integral_f64(emission_nm);
        if total > 0.0 {
            (self.eval_magnitude_f64(excitation_nm, emission_nm) / total) as f32
        } else {
            0.0
        }
    }
}

/// Per row of a row-major `grid`-wide table, ∫ from the first node to each node
/// (trapezoids, exact for the piecewise-linear row).
fn row_cumulative(values: &[f32], grid: WavelengthGrid) -> Box<[f64]> {
    let step = grid.step_nm as f64;
    let mut cumulative = vec![0.0f64; values.len()];
    for (row_values, row_cumulative) in values
        .chunks_exact(grid.count)
        .zip(cumulative.chunks_exact_mut(grid.count))
    {
        let mut sum = 0.0;
        for column in 1..grid.count {
            sum += 0.5 * step * (row_values[column - 1] as f64 + row_values[column] as f64);
            row_cumulative[column] = sum;
        }
    }
    cumulative.into_boxed_slice()
}

/// Draws x on `grid` with density ∝ the piecewise-linear function with node values
/// `node(k)` ≥ 0 and cumulative integrals `cumulative(k)` (from node 0 to node k), from
/// `u` ∈ [0, 1): the segment by binary search on the cumulative integrals, the position
/// inside by inverting the linear density's CDF. Returns x in nm and its density in nm⁻¹;
/// `None` when the function has no mass.
fn sample_piecewise_linear(
    grid: &WavelengthGrid,
    node: impl Fn(usize) -> f64,
    cumulative: impl Fn(usize) -> f64,
    u: f32,
) -> Option<(f32, f32)> {
    let n = grid.count;
    let total = cumulative(n - 1);
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    // Keep the target strictly below the total so the chosen segment has mass.
    let target = (u.clamp(0.0, 1.0) as f64 * total).min(total * (1.0 - f64::EPSILON));
    // Binary search for the first node whose cumulative integral exceeds the target
    // (node n − 1 does, its integral being the total); the segment ends there.
    let (mut low, mut high) = (1, n - 1);
    while low < high {
        let mid = (low + high) / 2;
        if cumulative(mid) > target {
            high = mid;
        } else {
            low = mid + 1;
        }
    }
    let segment = low - 1;
    let step = grid.step_nm as f64;
    let a = node(segment);
    let b = node(segment + 1);
    // Solve step·(a x + (b − a) x²/2) = d for x ∈ [0, 1]: x = 2d' / (a + √(a² + 2(b − a)d'))
    // with d' = d / step, stable for every sign of b − a.
    let d = (target - cumulative(segment)) / step;
    let denominator = a + (a * a + 2.0 * (b - a) * d).max(0.0).sqrt();
    let x = if denominator > 0.0 {
        (2.0 * d / denominator).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let wavelength_nm = grid.start_nm as f64 + (segment as f64 + x) * step;
    let pdf = (a + x * (b - a)) / total;
    Some((wavelength_nm as f32, pdf as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_testkit::chi2::{chi2_p_value, sidak, SplitMix64};

    /// A small fluorescent-like matrix: excitation 300–500 nm (5 rows), emission 400–780 nm
    /// (20 columns), Stokes-shifted Gaussian-ish emission with exact zeros below λ_in and in
    /// one gap, rows scaled so the re-radiated fraction stays below 1.
    fn test_matrix() -> ReradiationMatrix {
        let excitation = WavelengthGrid::new(300.0, 50.0, 5).unwrap();
        let emission = WavelengthGrid::new(400.0, 20.0, 20).unwrap();
        ReradiationMatrix::from_fn(excitation, emission, |l_in, l_out| {
            if l_out < l_in + 40.0 || (600.0..=640.0).contains(&l_out) {
                return 0.0;
            }
            let peak = l_in + 120.0;
            0.004 * (-(l_out - peak).powi(2) / (2.0 * 60.0f32.powi(2))).exp()
        })
        .unwrap()
    }

    /// Pearson's statistic of `histogram` against `expected` counts (bins expecting nothing
    /// must be empty) and its p-value.
    fn pearson(histogram: &[u64], expected: &[f64]) -> (f64, usize, f64) {
        let (mut chi2, mut bins) = (0.0, 0usize);
        for (bin, (&observed, &expected)) in histogram.iter().zip(expected).enumerate() {
            if expected < 1e-9 {
                assert_eq!(observed, 0, "samples in empty bin {bin}");
                continue;
            }
            chi2 += (observed as f64 - expected).powi(2) / expected;
            bins += 1;
        }
        let dof = bins - 1;
        (chi2, dof, chi2_p_value(chi2, dof))
    }

    use prism_testkit::quadrature::simpson;

    #[test]
    fn eval_matches_the_grid_at_nodes_and_is_zero_outside() {
        let m = test_matrix();
        for row in 0..5 {
            for column in 0..20 {
                let (l_in, l_out) = (
                    m.excitation().wavelength_nm(row),
                    m.emission().wavelength_nm(column),
                );
                assert_eq!(m.eval(l_in, l_out), m.node(row, column));
            }
        }
        // Bilinear in between.
        let mid = m.eval(325.0, 530.0);
        let corners = (m.node(0, 6) + m.node(0, 7) + m.node(1, 6) + m.node(1, 7)) / 4.0;
        assert!((mid - corners).abs() < 1e-9);
        assert_eq!(m.eval(299.0, 500.0), 0.0);
        assert_eq!(m.eval(400.0, 399.0), 0.0);
        assert_eq!(m.eval(400.0, 781.0), 0.0);
        assert_eq!(m.eval(f32::NAN, 500.0), 0.0);
        assert_eq!(m.sample_emission(501.0, 0.5), None);
    }

    #[test]
    fn pdf_integrates_to_one_and_row_integral_is_the_fraction() {
        let m = test_matrix();
        for l_in in [300.0f32, 312.5, 375.0, 433.3, 500.0] {
            // Simpson on 0.05 nm steps (exact per linear piece since 20 nm is a multiple).
            let n = 7600;
            let h = 380.0 / n as f64;
            let (mut pdf_sum, mut m_sum) = (0.0, 0.0);
            for i in 0..=n {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let l_out = (400.0 + i as f64 * h) as f32;
                pdf_sum += w * m.pdf_emission(l_in, l_out) as f64;
                m_sum += w * m.eval(l_in, l_out) as f64;
            }
            let (pdf_integral, m_integral) = (pdf_sum * h / 3.0, m_sum * h / 3.0);
            assert!(
                (pdf_integral - 1.0).abs() < 1e-5,
                "{l_in} nm: ∫pdf = {pdf_integral}"
            );
            assert!((m_integral / m.row_integral(l_in) as f64 - 1.0).abs() < 1e-5);
        }
        let (_, fraction) = m.max_row_integral();
        assert!(fraction > 0.1 && fraction < 1.0, "{fraction}");
        assert!(m.is_energy_conserving());
    }

    #[test]
    fn sampled_emission_matches_its_pdf_chi_square() {
        let m = test_matrix();
        let samples = 1_000_000;
        // 4 nm bins over 400–780 nm: aligned with the 20 nm nodes, so the pdf is linear in
        // each bin and the expected count is exact by the midpoint rule.
        const BINS: usize = 95;
        for (l_in, seed) in [(300.0f32, 1u64), (362.5, 2), (480.0, 3)] {
            let mut rng = SplitMix64(seed);
            let mut histogram = [0u64; BINS];
            for _ in 0..samples {
                let (l_out, pdf) = m.sample_emission(l_in, rng.next_f32()).unwrap();
                assert!((400.0..=780.0).contains(&l_out));
                let expected_pdf = m.pdf_emission(l_in, l_out);
                // The returned wavelength is rounded to f32 (ulp 6e-5 nm near 600 nm), so
                // where the pdf falls steeply to zero the absolute term dominates.
                assert!(
                    (pdf - expected_pdf).abs() <= 1e-4 * expected_pdf + 1e-7,
                    "pdf {pdf} vs {expected_pdf} at {l_out} nm"
                );
                assert!(pdf > 0.0, "sampled a zero-density wavelength {l_out} nm");
                histogram[(((l_out - 400.0) / 4.0) as usize).min(BINS - 1)] += 1;
            }
            let expected: Vec<f64> = (0..BINS)
                .map(|bin| {
                    let mid = 400.0 + 4.0 * bin as f32 + 2.0;
                    m.pdf_emission(l_in, mid) as f64 * 4.0 * samples as f64
                })
                .collect();
            let (chi2, dof, p) = pearson(&histogram, &expected);
            assert!(
                p >= sidak(0.01, 3),
                "{l_in} nm: χ² = {chi2} ({dof} dof), p = {p}"
            );
        }
    }

    #[test]
    fn sampled_excitation_matches_its_pdf_chi_square() {
        let m = test_matrix();
        let samples = 1_000_000;
        // 2.5 nm bins over 300–500 nm: aligned with the 50 nm excitation nodes, so the pdf
        // is linear in each bin and the midpoint rule gives the expected count exactly.
        const BINS: usize = 80;
        let cases = [(460.0f32, 1u64), (517.0, 2), (700.0, 3), (780.0, 4)];
        for (l_out, seed) in cases {
            let mut rng = SplitMix64(seed);
            let mut histogram = [0u64; BINS];
            for _ in 0..samples {
                let (l_in, pdf) = m.sample_excitation(l_out, rng.next_f32()).unwrap();
                assert!((300.0..=500.0).contains(&l_in));
                let expected_pdf = m.pdf_excitation(l_out, l_in);
                assert!(
                    (pdf - expected_pdf).abs() <= 1e-4 * expected_pdf + 1e-7,
                    "pdf {pdf} vs {expected_pdf} at {l_in} nm"
                );
                assert!(pdf > 0.0, "sampled a zero-density wavelength {l_in} nm");
                histogram[(((l_in - 300.0) / 2.5) as usize).min(BINS - 1)] += 1;
            }
            let expected: Vec<f64> = (0..BINS)
                .map(|bin| {
                    let mid = 300.0 + 2.5 * bin as f32 + 1.25;
                    m.pdf_excitation(l_out, mid) as f64 * 2.5 * samples as f64
                })
                .collect();
            let (chi2, dof, p) = pearson(&histogram, &expected);
            assert!(
                p >= sidak(0.01, cases.len()),
                "{l_out} nm: χ² = {chi2} ({dof} dof), p = {p}"
            );
        }
        // A wrong pdf fails: the histogram of 517 nm against the column at 460 nm.
        let mut rng = SplitMix64(9);
        let mut histogram = [0u64; BINS];
        for _ in 0..samples {
            let (l_in, _) = m.sample_excitation(517.0, rng.next_f32()).unwrap();
            histogram[(((l_in - 300.0) / 2.5) as usize).min(BINS - 1)] += 1;
        }
        let expected: Vec<f64> = (0..BINS)
            .map(|bin| {
                let mid = 300.0 + 2.5 * bin as f32 + 1.25;
                m.pdf_excitation(460.0, mid) as f64 * 2.5 * samples as f64
            })
            .collect();
        let chi2: f64 = histogram
            .iter()
            .zip(&expected)
            .filter(|(_, &e)| e > 0.0)
            .map(|(&o, &e)| (o as f64 - e).powi(2) / e)
            .sum();
        assert!(chi2 > 1e4, "{chi2}");
    }

    #[test]
    fn excitation_pdf_integrates_to_one_and_column_integral_is_the_gathered_fraction() {
        let m = test_matrix();
        // λ_out on nodes, between nodes, at the grid's ends.
        for l_out in [400.0f32, 433.3, 517.0, 560.0, 700.0, 780.0] {
            // 0.25 nm Simpson steps: 200 per 50 nm segment, exact for the linear pieces.
            let pdf_integral = simpson(300.0, 500.0, 800, |l| {
                m.pdf_excitation(l_out, l as f32) as f64
            });
            let m_integral = simpson(300.0, 500.0, 800, |l| m.eval(l as f32, l_out) as f64);
            assert!(
                (pdf_integral - 1.0).abs() < 1e-5,
                "{l_out} nm: ∫pdf = {pdf_integral}"
            );
            assert!(
                (m_integral / m.column_integral(l_out) as f64 - 1.0).abs() < 1e-5,
                "{l_out} nm: {m_integral} vs {}",
                m.column_integral(l_out)
            );
            assert_eq!(m.column_integral(l_out), m.column_magnitude_integral(l_out));
        }
        // The gap at 600–640 nm gathers nothing; outside the emission grid is empty too.
        assert_eq!(m.column_integral(620.0), 0.0);
        assert_eq!(m.sample_excitation(620.0, 0.5), None);
        assert_eq!(m.pdf_excitation(620.0, 400.0), 0.0);
        assert_eq!(m.sample_excitation(399.0, 0.5), None);
        assert_eq!(m.sample_excitation(f32::NAN, 0.5), None);
    }

    /// A signed variant of `test_matrix`: noise of ±0.0004 on every node.
    fn signed_test_matrix() -> ReradiationMatrix {
        let m = test_matrix();
        let mut values = Vec::new();
        for row in 0..5 {
            for column in 0..20 {
                let noise = if (row + column) % 3 == 0 { -4e-4 } else { 4e-4 };
                values.push(m.node(row, column) + noise);
            }
        }
        ReradiationMatrix::from_dense_signed(*m.excitation(), *m.emission(), values).unwrap()
    }

    /// Row and column estimators of ∫∫ f(λi) M(λi, λo) g(λo) dλi dλo against quadrature,
    /// each within 4 standard errors (issue 21's test 1).
    fn check_row_and_column_estimators(m: &ReradiationMatrix) {
        let f = |l: f64| 1.0 + 0.5 * (l / 37.0).sin();
        let g = |l: f64| 0.5 + (l - 400.0) / 380.0;
        let (ex_lo, ex_hi, em_lo, em_hi) = (300.0, 500.0, 400.0, 780.0);
        // Nested Simpson on steps that divide the node spacings (50 and 20 nm).
        let exact = simpson(ex_lo, ex_hi, 400, |li| {
            f(li)
                * simpson(em_lo, em_hi, 380, |lo| {
                    m.eval(li as f32, lo as f32) as f64 * g(lo)
                })
        });
        let n = 400_000;
        let estimate = |mut draw: Box<dyn FnMut(&mut SplitMix64) -> f64>, seed: u64| {
            let mut rng = SplitMix64(seed);
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..n {
                let x = draw(&mut rng);
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / n as f64;
            let standard_error = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            (mean, standard_error)
        };
        // Row: λi uniform, λo ∝ M(λi, ·).
        let row = estimate(
            Box::new(|rng: &mut SplitMix64| {
                let li = ex_lo + (ex_hi - ex_lo) * rng.next_f32() as f64;
                match m.sample_emission(li as f32, rng.next_f32()) {
                    Some((lo, pdf)) => {
                        f(li) * m.eval(li as f32, lo) as f64 * g(lo as f64) * (ex_hi - ex_lo)
                            / pdf as f64
                    }
                    None => 0.0,
                }
            }),
            11,
        );
        // Column: λo uniform, λi ∝ M(·, λo).
        let column = estimate(
            Box::new(|rng: &mut SplitMix64| {
                let lo = em_lo + (em_hi - em_lo) * rng.next_f32() as f64;
                match m.sample_excitation(lo as f32, rng.next_f32()) {
                    Some((li, pdf)) => {
                        f(li as f64) * m.eval(li, lo as f32) as f64 * g(lo) * (em_hi - em_lo)
                            / pdf as f64
                    }
                    None => 0.0,
                }
            }),
            12,
        );
        for (name, (mean, standard_error)) in [("row", row), ("column", column)] {
            assert!(
                (mean - exact).abs() <= 4.0 * standard_error + 1e-6 * exact.abs(),
                "{name}: {mean} ± {standard_error} vs quadrature {exact}"
            );
        }
    }

    #[test]
    fn row_and_column_estimators_agree_with_quadrature() {
        check_row_and_column_estimators(&test_matrix());
    }

    #[test]
    fn signed_matrices_sample_columns_by_magnitude() {
        let m = signed_test_matrix();
        assert!(m.is_signed());
        check_row_and_column_estimators(&m);
        // The column pdf is the magnitude's: it integrates to 1 and never vanishes where M
        // does not.
        for l_out in [400.0f32, 517.0, 620.0] {
            let pdf_integral = simpson(300.0, 500.0, 800, |l| {
                m.pdf_excitation(l_out, l as f32) as f64
            });
            assert!((pdf_integral - 1.0).abs() < 1e-5, "{pdf_integral}");
            assert!(m.column_magnitude_integral(l_out) > m.column_integral(l_out).abs());
        }
        let mut rng = SplitMix64(5);
        for _ in 0..10_000 {
            let (_, pdf) = m.sample_excitation(620.0, rng.next_f32()).unwrap();
            assert!(pdf > 0.0);
        }
    }

    #[test]
    fn invalid_entries_and_shapes_are_rejected() {
        let excitation = WavelengthGrid::new(300.0, 50.0, 2).unwrap();
        let emission = WavelengthGrid::new(400.0, 10.0, 3).unwrap();
        let e = ReradiationMatrix::from_dense(
            excitation,
            emission,
            vec![0.0, 0.1, 0.0, 0.0, -0.5, 0.0],
        )
        .unwrap_err();
        assert!(
            e.message
                .contains("excitation row 2 (350 nm), emission column 2 (410 nm) is -0.5"),
            "{e}"
        );
        let e = ReradiationMatrix::from_dense(
            excitation,
            emission,
            vec![f32::NAN, 0.1, 0.0, 0.0, 0.5, 0.0],
        )
        .unwrap_err();
        assert!(
            e.message
                .contains("excitation row 1 (300 nm), emission column 1 (400 nm) is NaN"),
            "{e}"
        );
        let e = ReradiationMatrix::from_dense(excitation, emission, vec![0.0; 5]).unwrap_err();
        assert!(e.message.contains("5 entries"), "{e}");
        let e =
            ReradiationMatrix::from_rows(excitation, emission, [[0.0f32; 3].as_slice(), &[0.0; 2]])
                .unwrap_err();
        assert!(e.message.contains("row 2 (350 nm) has 2 values"), "{e}");
        let e = ReradiationMatrix::from_rows(excitation, emission, [[0.0f32; 3]]).unwrap_err();
        assert!(e.message.contains("1 excitation rows, expected 2"), "{e}");
        let e = ReradiationMatrix::from_rows(excitation, emission, [[0.0f32; 3]; 3]).unwrap_err();
        assert!(e.message.contains("more than"), "{e}");
        assert!(WavelengthGrid::new(300.0, 0.0, 4).is_err());
        assert!(WavelengthGrid::new(300.0, 10.0, 1).is_err());
        assert!(WavelengthGrid::new(f32::NAN, 10.0, 4).is_err());
        let ok = ReradiationMatrix::from_rows(
            excitation,
            emission,
            [[0.0f32, 0.2, 0.0], [0.0, 0.0, 0.0]],
        )
        .unwrap();
        assert_eq!(ok.eval(300.0, 410.0), 0.2);
        // A zero row samples nothing.
        assert_eq!(ok.sample_emission(350.0, 0.5), None);
        assert_eq!(ok.pdf_emission(350.0, 410.0), 0.0);
    }

    #[test]
    fn signed_matrices_keep_the_sign_and_sample_the_magnitude() {
        let excitation = WavelengthGrid::new(300.0, 50.0, 2).unwrap();
        let emission = WavelengthGrid::new(400.0, 10.0, 3).unwrap();
        let values = vec![0.02f32, -0.01, 0.03, 0.0, 0.0, 0.0];
        assert!(ReradiationMatrix::from_dense(excitation, emission, values.clone()).is_err());
        let m = ReradiationMatrix::from_dense_signed(excitation, emission, values).unwrap();
        assert!(m.is_signed());
        assert_eq!(m.eval(300.0, 410.0), -0.01);
        // Signed: 10 nm × (0.005 + 0.01) = 0.15; magnitudes: 10 nm × (0.015 + 0.02) = 0.35.
        assert!((m.row_integral(300.0) - 0.15).abs() < 1e-7);
        assert!((m.row_magnitude_integral(300.0) - 0.35).abs() < 1e-7);
        assert!((m.pdf_emission(300.0, 410.0) - 0.01 / 0.35).abs() < 1e-6);
        assert!((m.pdf_emission(300.0, 405.0) - 0.015 / 0.35).abs() < 1e-6);
        // Every draw has positive density, and the signed weights M/pdf average to ∫M.
        let mut rng = SplitMix64(7);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let (l_out, pdf) = m.sample_emission(300.0, rng.next_f32()).unwrap();
            assert!(pdf > 0.0);
            sum += m.eval(300.0, l_out) as f64 / pdf as f64;
        }
        assert!((sum / n as f64 - 0.15).abs() < 3e-3, "{}", sum / n as f64);
        let e = ReradiationMatrix::from_dense_signed(
            excitation,
            emission,
            vec![f32::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
        .unwrap_err();
        assert!(e.message.contains("must be finite"), "{e}");
    }

    #[test]
    fn energy_violations_are_reported_with_the_row() {
        let excitation = WavelengthGrid::new(300.0, 50.0, 2).unwrap();
        let emission = WavelengthGrid::new(400.0, 10.0, 3).unwrap();
        // Row 1 integrates to 2 segments × 10 nm × 0.005 = 0.1, row 2 to 2 × 10 nm × 0.1 = 2.
        let m = ReradiationMatrix::from_rows(
            excitation,
            emission,
            [[0.0f32, 0.01, 0.0], [0.1, 0.1, 0.1]],
        )
        .unwrap();
        assert!((m.row_integral(300.0) - 0.1).abs() < 1e-7);
        assert!((m.row_integral(350.0) - 2.0).abs() < 1e-6);
        assert!((m.row_integral(325.0) - 1.05).abs() < 1e-6);
        assert!(!m.is_energy_conserving());
        let e = m.check_energy_conservation(0.0).unwrap_err();
        assert!(e.message.contains("350 nm"), "{e}");
    }
}
