//! The reference a local-bandwidth estimate is checked against: the power spectrum of a
//! square window of an image (mean removed, Hann-windowed, discrete Fourier transform) and
//! the radius that holds a given share of its energy (95 % in the predictor's tests, as
//! Bagher et al. 2013 define a signal's bandwidth).

use std::f64::consts::TAU;

/// One frequency bin of a window's spectrum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectrumBin {
    /// |f| in cycles per sample (per texel or pixel); at most √2 · ½.
    pub radius_cycles: f64,
    /// |DFT|² of the windowed values (units² of the input).
    pub power: f64,
}

/// The 2-D Hann window's weight at (i, j) of a `side`×`side` window (cells centred).
pub fn hann_weight(i: usize, j: usize, side: usize) -> f64 {
    let hann = |k: usize| 0.5 - 0.5 * (TAU * (k as f64 + 0.5) / side as f64).cos();
    hann(i) * hann(j)
}

/// The power spectrum of the `side`×`side` window of `values` (row-major, `width` per row)
/// whose top-left cell is `origin`: the window's mean is subtracted (so the DC bin holds
/// only what the window leaks into it), the Hann window applied, then a separable DFT. The
/// bins come in the same order for every window of one side, so two spectra (a reference
/// and its noise) subtract bin by bin.
pub fn hann_power_spectrum(
    values: &[f64],
    width: usize,
    origin: (usize, usize),
    side: usize,
) -> Vec<SpectrumBin> {
    let (x0, y0) = origin;
    let at = |i: usize, j: usize| values[(y0 + j) * width + x0 + i];
    let mean = (0..side)
        .flat_map(|j| (0..side).map(move |i| (i, j)))
        .map(|(i, j)| at(i, j))
        .sum::<f64>()
        / (side * side) as f64;
    let windowed: Vec<f64> = (0..side)
        .flat_map(|j| (0..side).map(move |i| (i, j)))
        .map(|(i, j)| (at(i, j) - mean) * hann_weight(i, j, side))
        .collect();
    let twiddle = |k: usize, n: usize| {
        let a = -TAU * ((k * n) % side) as f64 / side as f64;
        (a.cos(), a.sin())
    };
    // Rows first: rows[j][k] = Σ_i w[j][i]·e^{−2πi·ki/side}.
    let mut rows = vec![(0.0, 0.0); side * side];
    for j in 0..side {
        for k in 0..side {
            let (mut re, mut im) = (0.0, 0.0);
            for i in 0..side {
                let (c, s) = twiddle(k, i);
                re += windowed[j * side + i] * c;
                im += windowed[j * side + i] * s;
            }
            rows[j * side + k] = (re, im);
        }
    }
    let signed = |k: usize| {
        if k <= side / 2 {
            k as f64
        } else {
            k as f64 - side as f64
        }
    };
    let mut bins = Vec::with_capacity(side * side);
    for l in 0..side {
        for k in 0..side {
            let (mut re, mut im) = (0.0, 0.0);
            for j in 0..side {
                let (c, s) = twiddle(l, j);
                let (r, q) = rows[j * side + k];
                re += r * c - q * s;
                im += r * s + q * c;
            }
            bins.push(SpectrumBin {
                radius_cycles: signed(k).hypot(signed(l)) / side as f64,
                power: re * re + im * im,
            });
        }
    }
    bins
}

/// The smallest radius (cycles per sample) whose bins at or inside it hold `fraction` of the
/// total power. Bins may be negative (a reference's spectrum minus its noise's, which is
/// unbiased but not positive bin by bin); `None` when the total is not positive.
pub fn energy_radius(bins: &[SpectrumBin], fraction: f64) -> Option<f64> {
    let total: f64 = bins.iter().map(|b| b.power).sum();
    if total <= 0.0 {
        return None;
    }
    let mut sorted = bins.to_vec();
    sorted.sort_by(|a, b| a.radius_cycles.total_cmp(&b.radius_cycles));
    let mut acc = 0.0;
    for bin in &sorted {
        acc += bin.power;
        if acc >= fraction * total {
            return Some(bin.radius_cycles);
        }
    }
    sorted.last().map(|b| b.radius_cycles)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sinusoid(width: usize, fx: f64, fy: f64) -> Vec<f64> {
        (0..width * width)
            .map(|n| (TAU * (fx * (n % width) as f64 + fy * (n / width) as f64)).sin())
            .collect()
    }

    #[test]
    fn a_sinusoids_energy_sits_at_its_frequency() {
        // On a bin (k/32 cycles) the Hann window spreads energy to the two neighbours only.
        for (fx, fy) in [
            (4.0 / 32.0, 0.0),
            (3.0 / 32.0, 4.0 / 32.0),
            (0.0, 10.0 / 32.0),
        ] {
            let v = sinusoid(64, fx, fy);
            let radius = energy_radius(&hann_power_spectrum(&v, 64, (16, 8), 32), 0.95).unwrap();
            let f = f64::hypot(fx, fy);
            assert!(
                radius >= f - 1e-9 && radius <= f + 1.5 / 32.0,
                "({fx}, {fy}): {radius}"
            );
        }
    }

    #[test]
    fn a_constant_window_has_no_energy() {
        let v = vec![3.0; 64 * 64];
        assert_eq!(
            energy_radius(&hann_power_spectrum(&v, 64, (0, 0), 32), 0.95),
            None
        );
    }

    #[test]
    fn parseval_holds_for_the_windowed_values() {
        let v: Vec<f64> = (0..32 * 32).map(|n| ((n * 7919) % 101) as f64).collect();
        let bins = hann_power_spectrum(&v, 32, (0, 0), 32);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let energy: f64 = (0..32 * 32)
            .map(|n| ((v[n] - mean) * hann_weight(n % 32, n / 32, 32)).powi(2))
            .sum();
        let spectrum: f64 = bins.iter().map(|b| b.power).sum::<f64>() / (32.0 * 32.0);
        assert!(
            (spectrum - energy).abs() < 1e-9 * energy,
            "{spectrum} {energy}"
        );
    }
}
