//! A fluorescent dye as a Donaldson matrix, from its absorption and emission spectra, its
//! quantum yield Φ and its peak absorptance (Lakowicz, "Principles of Fluorescence
//! Spectroscopy", 3rd ed., §1.2–1.4: a photon absorbed at λ_in is re-emitted with
//! probability Φ, with the emission spectrum's shape whatever λ_in was — Kasha's rule):
//!
//! M(λ_in, λ_out) = a(λ_in)·Φ·(λ_in/λ_out)·e(λ_out) / ∫e dλ        (e in photon counts)
//! M(λ_in, λ_out) = a(λ_in)·Φ·λ_in·e_E(λ_out) / ∫λ·e_E(λ) dλ      (e_E in energy)
//!
//! a is the absorption spectrum scaled so its largest node is `peak_absorptance`; λ_in/λ_out
//! turns a photon ratio into an energy ratio. Both forms are one: e = λ·e_E up to a constant.
//! The matrix is stored at grid nodes and interpolated bilinearly, so the normalisation is
//! taken over the stored (piecewise-linear) emission: ∫ M(λ_in, λ_out)·λ_out/λ_in dλ_out =
//! a(λ_in)·Φ holds exactly at the excitation nodes (photons are conserved up to the yield),
//! and ∫ M dλ_out = a·Φ·λ_in/λ̄ ≤ a·Φ when the emission lies above λ_in (Stokes shift).

use crate::reradiation::{ReradiationError, ReradiationMatrix, WavelengthGrid};

/// Whether an emission spectrum counts photons or energy per nm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EmissionUnits {
    /// Photon counts per nm (what most fluorimeters report).
    Photons,
    /// Radiant energy per nm.
    Energy,
}

/// A dye's matrix and the absorptance it was built from.
#[derive(Debug, Clone, PartialEq)]
pub struct Dye {
    matrix: ReradiationMatrix,
    /// a at the excitation nodes (scaled to the peak absorptance).
    absorptance: Box<[f64]>,
}

impl Dye {
    /// Samples `absorption(λ_nm)` on the `excitation` grid and `emission(λ_nm)` on the
    /// `emission_grid` (both any non-negative shape), and builds M. Errors for a yield or peak
    /// outside [0, 1], negative or non-finite spectra, spectra without mass, and a matrix
    /// that would re-radiate more energy than it absorbs (emission below the excitation).
    pub fn new(
        absorption: impl Fn(f64) -> f64,
        emission: impl Fn(f64) -> f64,
        units: EmissionUnits,
        quantum_yield: f64,
        peak_absorptance: f64,
        excitation: WavelengthGrid,
        emission_grid: WavelengthGrid,
    ) -> Result<Self, ReradiationError> {
        let err = |m: String| Err(ReradiationError { message: m });
        if !(0.0..=1.0).contains(&quantum_yield) {
            return err(format!(
                "dye quantum yield is {quantum_yield}, expected a fraction in [0, 1]"
            ));
        }
        if !(0.0..=1.0).contains(&peak_absorptance) {
            return err(format!(
                "dye peak absorptance is {peak_absorptance}, expected a fraction in [0, 1]"
            ));
        }
        let shape = |f: &dyn Fn(f64) -> f64,
                     grid: &WavelengthGrid,
                     what: &str|
         -> Result<Vec<f64>, ReradiationError> {
            let mut values = Vec::with_capacity(grid.count());
            for k in 0..grid.count() {
                let nm = grid.wavelength_nm(k) as f64;
                let v = f(nm);
                if !(v.is_finite() && v >= 0.0) {
                    return Err(ReradiationError {
                        message: format!(
                            "dye {what} is {v} at {nm} nm: expected finite and non-negative"
                        ),
                    });
                }
                values.push(v);
            }
            if values.iter().all(|&v| v == 0.0) {
                return Err(ReradiationError {
                    message: format!(
                        "dye {what} is zero over {}–{} nm",
                        grid.start_nm(),
                        grid.end_nm()
                    ),
                });
            }
            Ok(values)
        };
        let absorption = shape(&absorption, &excitation, "absorption")?;
        let emitted = shape(&emission, &emission_grid, "emission")?;
        let peak = absorption.iter().copied().fold(0.0, f64::max);
        let absorptance: Box<[f64]> = absorption
            .iter()
            .map(|v| v / peak * peak_absorptance)
            .collect();
        // n(λ_out) ∝ photons per nm per λ_out, so that M = a·Φ·λ_in·n(λ_out)/∫n·λ: e/λ for a
        // photon spectrum, e_E itself for an energy spectrum.
        let n: Vec<f64> = match units {
            EmissionUnits::Photons => emitted
                .iter()
                .enumerate()
                .map(|(k, e)| e / emission_grid.wavelength_nm(k) as f64)
                .collect(),
            EmissionUnits::Energy => emitted,
        };
        // ∫ n(λ)·λ dλ of the piecewise-linear n: quadratic per segment, so Simpson is exact.
        let step = emission_grid.step_nm() as f64;
        let normaliser: f64 = (1..n.len())
            .map(|k| {
                let (l0, l1) = (
                    emission_grid.wavelength_nm(k - 1) as f64,
                    emission_grid.wavelength_nm(k) as f64,
                );
                let (n0, n1) = (n[k - 1], n[k]);
                step / 6.0 * (n0 * l0 + 2.0 * (n0 + n1) * (l0 + l1) / 2.0 + n1 * l1)
            })
            .sum();
        let mut values = Vec::with_capacity(excitation.count() * emission_grid.count());
        for (row, a) in absorptance.iter().enumerate() {
            let scale = a * quantum_yield * excitation.wavelength_nm(row) as f64 / normaliser;
            values.extend(n.iter().map(|v| (scale * v) as f32));
        }
        let matrix = ReradiationMatrix::from_dense(excitation, emission_grid, values)?;
        matrix
            .check_energy_conservation(1e-4)
            .map_err(|e| ReradiationError {
                message: format!(
                    "{} (the dye's emission lies below its excitation there: anti-Stokes)",
                    e.message
                ),
            })?;
        Ok(Self {
            matrix,
            absorptance,
        })
    }

    pub fn matrix(&self) -> &ReradiationMatrix {
        &self.matrix
    }

    /// a(λ): linear between the excitation nodes, 0 outside the excitation grid.
    pub fn absorptance(&self, wavelength_nm: f64) -> f64 {
        let grid = self.matrix.excitation();
        let x = (wavelength_nm - grid.start_nm() as f64) / grid.step_nm() as f64;
        if !(x >= 0.0 && x <= (grid.count() - 1) as f64) {
            return 0.0;
        }
        let i = (x as usize).min(grid.count() - 2);
        let t = x - i as f64;
        self.absorptance[i] + t * (self.absorptance[i + 1] - self.absorptance[i])
    }

    /// R(λ) = 1 − a(λ): the reflectance when the scene gives none (what the dye does not
    /// absorb is reflected).
    pub fn default_reflectance(&self, wavelength_nm: f64) -> f64 {
        1.0 - self.absorptance(wavelength_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gaussian(centre_nm: f64, width_nm: f64) -> impl Fn(f64) -> f64 {
        move |l| (-(l - centre_nm).powi(2) / (2.0 * width_nm * width_nm)).exp()
    }

    /// Excitation 300–600 nm, emission 360–830 nm, 5 nm steps.
    fn grids() -> (WavelengthGrid, WavelengthGrid) {
        (
            WavelengthGrid::new(300.0, 5.0, 61).unwrap(),
            WavelengthGrid::new(360.0, 5.0, 95).unwrap(),
        )
    }

    /// A Stokes-shifted dye: absorption peak 440 nm, emission peak 530 nm.
    fn dye(units: EmissionUnits, quantum_yield: f64) -> Dye {
        let (ex, em) = grids();
        Dye::new(
            gaussian(440.0, 25.0),
            gaussian(530.0, 30.0),
            units,
            quantum_yield,
            0.8,
            ex,
            em,
        )
        .unwrap()
    }

    /// Simpson over the emission range on 0.5 nm steps: 10 per 5 nm node segment, so every
    /// Simpson pair lies inside a segment and is exact for the quadratic M(λi, ·)·λo.
    fn integrate_emission(f: impl Fn(f64) -> f64) -> f64 {
        prism_testkit::quadrature::simpson(360.0, 830.0, 940, f)
    }

    #[test]
    fn photons_are_conserved_up_to_the_quantum_yield() {
        for units in [EmissionUnits::Photons, EmissionUnits::Energy] {
            let d = dye(units, 0.9);
            let m = d.matrix();
            for row in (0..61).step_by(4) {
                let l_in = m.excitation().wavelength_nm(row) as f64;
                let photons = integrate_emission(|l_out| {
                    m.eval(l_in as f32, l_out as f32) as f64 * l_out / l_in
                });
                let expected = d.absorptance(l_in) * 0.9;
                assert!(
                    (photons - expected).abs() <= 1e-5 * expected.max(1e-3),
                    "{units:?} {l_in} nm: ∫M·λo/λi = {photons}, a·Φ = {expected}"
                );
            }
            // The peak absorptance is reached at the absorption peak.
            assert!((d.absorptance(440.0) - 0.8).abs() < 1e-12);
        }
    }

    #[test]
    fn a_stokes_shifted_dye_conserves_energy() {
        let d = dye(EmissionUnits::Photons, 1.0);
        let m = d.matrix();
        for row in 0..61 {
            let l_in = m.excitation().wavelength_nm(row);
            let energy = integrate_emission(|l_out| m.eval(l_in, l_out as f32) as f64);
            assert!(energy <= 1.0, "{l_in} nm: ∫M dλo = {energy}");
            assert!((energy - m.row_integral(l_in) as f64).abs() < 1e-5);
            // Energy is lost to the Stokes shift where the dye absorbs.
            let a = d.absorptance(l_in as f64);
            if a > 0.05 {
                assert!(energy < a, "{l_in} nm: {energy} ≥ a = {a}");
            }
        }
        assert!(m.is_energy_conserving());
    }

    #[test]
    fn energy_and_photon_spectra_give_the_same_matrix() {
        // e = λ·e_E: the same emission in photons and in energy.
        let (ex, em) = grids();
        let energy = gaussian(530.0, 30.0);
        let from_energy = Dye::new(
            gaussian(440.0, 25.0),
            &energy,
            EmissionUnits::Energy,
            0.7,
            0.5,
            ex,
            em,
        )
        .unwrap();
        let from_photons = Dye::new(
            gaussian(440.0, 25.0),
            |l| 3.0 * l * energy(l),
            EmissionUnits::Photons,
            0.7,
            0.5,
            ex,
            em,
        )
        .unwrap();
        for row in 0..61 {
            for column in 0..95 {
                let (a, b) = (
                    from_energy.matrix().node(row, column),
                    from_photons.matrix().node(row, column),
                );
                assert!((a - b).abs() <= 1e-6 * a.abs() + 1e-12, "{a} vs {b}");
            }
        }
        // Treating the energy spectrum as photons shifts it blue: a different matrix.
        let wrong = Dye::new(
            gaussian(440.0, 25.0),
            &energy,
            EmissionUnits::Photons,
            0.7,
            0.5,
            ex,
            em,
        )
        .unwrap();
        // At 600 nm (column 48), well above the mean emission wavelength, by about 530/600.
        let ratio = wrong.matrix().node(28, 48) / from_energy.matrix().node(28, 48);
        assert!((ratio - 0.88).abs() < 0.02, "{ratio}");
    }

    #[test]
    fn reflectance_defaults_to_one_minus_absorptance() {
        let d = dye(EmissionUnits::Photons, 0.9);
        assert!((d.default_reflectance(440.0) - 0.2).abs() < 1e-12);
        assert!((d.default_reflectance(442.5) - (1.0 - d.absorptance(442.5))).abs() < 1e-15);
        let between = 0.5 * (d.absorptance(440.0) + d.absorptance(445.0));
        assert!((d.absorptance(442.5) - between).abs() < 1e-12);
        assert_eq!(d.default_reflectance(700.0), 1.0);
        assert_eq!(d.absorptance(299.0), 0.0);
        // Without fluorescence the matrix is zero.
        let dark = dye(EmissionUnits::Photons, 0.0);
        assert_eq!(dark.matrix().max_row_integral().1, 0.0);
    }

    #[test]
    fn bad_dyes_are_rejected() {
        let (ex, em) = grids();
        let make = |abs: &dyn Fn(f64) -> f64, emi: &dyn Fn(f64) -> f64, q: f64, p: f64| {
            Dye::new(abs, emi, EmissionUnits::Photons, q, p, ex, em)
                .unwrap_err()
                .message
        };
        let a = gaussian(440.0, 25.0);
        let e = gaussian(530.0, 30.0);
        assert!(make(&a, &e, 1.1, 0.8).contains("quantum yield is 1.1"));
        assert!(make(&a, &e, 0.9, -0.1).contains("peak absorptance is -0.1"));
        assert!(make(&|_| 0.0, &e, 0.9, 0.8).contains("absorption is zero over 300–600 nm"));
        assert!(
            make(&a, &|l: f64| if l > 500.0 { -1.0 } else { 0.0 }, 0.9, 0.8)
                .contains("emission is -1 at 505 nm")
        );
        assert!(make(&a, &|_| f64::NAN, 0.9, 0.8).contains("emission is NaN at 360 nm"));
        // Anti-Stokes: absorbs at 580 nm, emits at 400 nm, every photon re-emitted.
        let message = make(&gaussian(580.0, 10.0), &gaussian(400.0, 10.0), 1.0, 1.0);
        assert!(message.contains("at excitation 580 nm"), "{message}");
        assert!(message.contains("anti-Stokes"), "{message}");
    }
}
