//! Tabulated spectra: arbitrary strictly increasing wavelengths (piecewise linear, zero
//! outside the table) and the dense 1 nm grid over 360–830 nm that colorimetry integrates on.

use crate::constants::{DENSE_SAMPLE_COUNT, LAMBDA_MIN_NM};

/// A spectrum given at strictly increasing wavelengths, linear between them and zero outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Tabulated {
    wavelengths_nm: Vec<f64>,
    values: Vec<f64>,
}

impl Tabulated {
    /// Builds a table; `None` when the lengths differ, it is empty, or wavelengths are not
    /// strictly increasing and finite (callers that read user files report those earlier).
    pub fn new(wavelengths_nm: Vec<f64>, values: Vec<f64>) -> Option<Self> {
        let ok = !wavelengths_nm.is_empty()
            && wavelengths_nm.len() == values.len()
            && wavelengths_nm.iter().all(|w| w.is_finite())
            && wavelengths_nm.windows(2).all(|w| w[0] < w[1]);
        ok.then_some(Self {
            wavelengths_nm,
            values,
        })
    }

    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Linear interpolation; zero outside [first, last] wavelength.
    pub fn eval(&self, wavelength_nm: f64) -> f64 {
        let w = &self.wavelengths_nm;
        let last = w.len() - 1;
        if !(wavelength_nm >= w[0] && wavelength_nm <= w[last]) {
            return 0.0;
        }
        if last == 0 {
            return self.values[0];
        }
        // Index of the first sample strictly above λ, clamped so [i-1, i] is a valid segment.
        let i = w.partition_point(|&x| x <= wavelength_nm).clamp(1, last);
        let t = (wavelength_nm - w[i - 1]) / (w[i] - w[i - 1]);
        self.values[i - 1] + t * (self.values[i] - self.values[i - 1])
    }

    /// Resamples onto the 1 nm grid over 360–830 nm (linear, zero outside the table).
    pub fn to_dense(&self) -> DenseSpectrum {
        DenseSpectrum::from_fn(|wl| self.eval(wl))
    }

    /// Multiplies every value by `factor`.
    pub fn scaled(mut self, factor: f64) -> Self {
        self.values.iter_mut().for_each(|v| *v *= factor);
        self
    }
}

/// A spectrum on the 1 nm grid 360, 361, …, 830 nm (471 samples), the grid of the CIE
/// observers; colorimetric integrals are sums over it with Δλ = 1 nm.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseSpectrum {
    values: Box<[f64; DENSE_SAMPLE_COUNT]>,
}

impl DenseSpectrum {
    /// Samples `f(wavelength_nm)` at every integer nanometre in 360..=830.
    pub fn from_fn(mut f: impl FnMut(f64) -> f64) -> Self {
        let mut values = Box::new([0.0; DENSE_SAMPLE_COUNT]);
        for (i, v) in values.iter_mut().enumerate() {
            *v = f(LAMBDA_MIN_NM as f64 + i as f64);
        }
        Self { values }
    }

    pub fn constant(value: f64) -> Self {
        Self::from_fn(|_| value)
    }

    /// Values at 360, 361, …, 830 nm.
    pub fn values(&self) -> &[f64; DENSE_SAMPLE_COUNT] {
        &self.values
    }

    /// Wavelength of sample `index` in nm.
    pub fn wavelength_nm(index: usize) -> f64 {
        LAMBDA_MIN_NM as f64 + index as f64
    }

    /// Linear interpolation between the 1 nm samples; zero outside 360–830 nm.
    pub fn eval(&self, wavelength_nm: f64) -> f64 {
        let x = wavelength_nm - LAMBDA_MIN_NM as f64;
        if !(x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f64) {
            return 0.0;
        }
        let i = (x as usize).min(DENSE_SAMPLE_COUNT - 2);
        let t = x - i as f64;
        self.values[i] + t * (self.values[i + 1] - self.values[i])
    }

    /// Σ self(λ)·other(λ)·Δλ over the grid, Δλ = 1 nm.
    pub fn inner_product(&self, other: &DenseSpectrum) -> f64 {
        self.values
            .iter()
            .zip(other.values.iter())
            .map(|(a, b)| a * b)
            .sum()
    }

    /// Pointwise product.
    pub fn product(&self, other: &DenseSpectrum) -> DenseSpectrum {
        DenseSpectrum::from_fn(|wl| {
            let i = (wl - LAMBDA_MIN_NM as f64) as usize;
            self.values[i] * other.values[i]
        })
    }

    pub fn scaled(&self, factor: f64) -> DenseSpectrum {
        let mut out = self.clone();
        out.values.iter_mut().for_each(|v| *v *= factor);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tabulated_interpolates_linearly_and_is_zero_outside() {
        let t = Tabulated::new(vec![400.0, 500.0, 700.0], vec![1.0, 3.0, 1.0]).unwrap();
        assert_eq!(t.eval(399.9), 0.0);
        assert_eq!(t.eval(400.0), 1.0);
        assert_eq!(t.eval(450.0), 2.0);
        assert_eq!(t.eval(600.0), 2.0);
        assert_eq!(t.eval(700.0), 1.0);
        assert_eq!(t.eval(700.1), 0.0);
        assert_eq!(t.eval(f64::NAN), 0.0);
    }

    #[test]
    fn tabulated_rejects_non_increasing_wavelengths() {
        assert!(Tabulated::new(vec![400.0, 400.0], vec![1.0, 1.0]).is_none());
        assert!(Tabulated::new(vec![500.0, 400.0], vec![1.0, 1.0]).is_none());
        assert!(Tabulated::new(vec![], vec![]).is_none());
    }

    #[test]
    fn dense_grid_matches_the_table_at_integer_wavelengths() {
        let t = Tabulated::new(vec![380.0, 780.0], vec![0.0, 400.0]).unwrap();
        let d = t.to_dense();
        assert_eq!(d.values()[0], 0.0); // 360 nm, outside
        assert_eq!(d.values()[20], 0.0); // 380 nm
        assert_eq!(d.values()[21], 1.0); // 381 nm
        assert_eq!(d.values()[420], 400.0); // 780 nm
        assert_eq!(d.values()[421], 0.0); // 781 nm, outside
        assert!((d.eval(380.5) - 0.5).abs() < 1e-12);
    }
}
