//! The baseline the predictor must beat: variance-driven adaptive sampling as Cycles does it
//! (kernel/film/adaptive_sampling.h, after Dammertz et al. 2010, "A hierarchical automatic
//! stopping condition for Monte Carlo global illumination"). The film keeps a second image A
//! of half the samples; |I − A| estimates the error of the full image I. After the first
//! 4 spp every pass spends a uniform pass's samples in proportion to that error.

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::stochastic_rounding::round_stochastic;

/// The image mean (per channel, averaged over R, G, B) the error is measured at, so that its
/// √I / I switch at 1 means the same in every scene whatever the exposure.
pub const REFERENCE_MEAN: f64 = 0.18;

/// Per-pixel error e_p = Σ_c |I_c − A_c| / (10⁻⁴ + g(ΣI_c)), g(x) = √x up to 1 and x above
/// (Cycles divides by √I alone; above 1 the relative error is the better measure, since
/// highlights would otherwise draw samples ∝ their brightness), with I and A scaled so that
/// I's mean is [`REFERENCE_MEAN`]; then max-dilated over 3×3 pixels (noise next to a noisy
/// pixel is likely, and the dilation stops isolated pixels from starving their neighbours).
pub fn adaptive_error(
    resolution: UVec2,
    full_rgb: &[[f32; 3]],
    half_rgb: &[[f32; 3]],
) -> Result<Vec<f32>, BandwidthError> {
    let n = pixel_count("adaptive error", resolution)?;
    check_lengths(
        resolution,
        n,
        &[
            ("adaptive error full image", full_rgb.len()),
            ("adaptive error half image", half_rgb.len()),
        ],
    )?;
    let mean = full_rgb
        .iter()
        .map(|p| p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / n as f64;
    let scale = if mean > 0.0 && mean.is_finite() {
        REFERENCE_MEAN / mean
    } else {
        1.0
    };
    let raw: Vec<f32> = full_rgb
        .iter()
        .zip(half_rgb)
        .map(|(i, a)| {
            let difference: f64 = (0..3)
                .map(|c| (f64::from(i[c]) - f64::from(a[c])).abs() * scale)
                .sum();
            let intensity: f64 = i.iter().map(|&c| f64::from(c).max(0.0) * scale).sum();
            let normaliser = if intensity <= 1.0 {
                intensity.sqrt()
            } else {
                intensity
            };
            let e = difference / (1e-4 + normaliser);
            if e.is_finite() {
                e as f32
            } else {
                0.0
            }
        })
        .collect();
    Ok(dilate_max_3x3(resolution, &raw))
}

fn dilate_max_3x3(resolution: UVec2, values: &[f32]) -> Vec<f32> {
    let (w, h) = (resolution.x as i64, resolution.y as i64);
    let mut out = vec![0.0f32; values.len()];
    for y in 0..h {
        for x in 0..w {
            let mut m = 0.0f32;
            for yy in (y - 1).max(0)..=(y + 1).min(h - 1) {
                for xx in (x - 1).max(0)..=(x + 1).min(w - 1) {
                    m = m.max(values[(yy * w + xx) as usize]);
                }
            }
            out[(y * w + x) as usize] = m;
        }
    }
    out
}

/// One adaptive pass: `pass_total` camera samples (a uniform pass's) spread ∝ e_p, rounded
/// stochastically per pixel with (seed, pass). All-zero error spreads them uniformly.
pub fn adaptive_pass_counts(errors: &[f32], pass_total: u64, seed: u64, pass: u32) -> Vec<u32> {
    let sum: f64 = errors.iter().map(|&e| f64::from(e.max(0.0))).sum();
    let n = errors.len().max(1) as f64;
    let pass_seed = seed ^ (u64::from(pass) << 40);
    errors
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            let share = if sum > 0.0 {
                f64::from(e.max(0.0)) / sum
            } else {
                1.0 / n
            };
            round_stochastic(share * pass_total as f64, pass_seed, i as u64)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_is_the_relative_half_difference_and_spreads_to_neighbours() {
        let r = UVec2::new(5, 5);
        let mut full = vec![[0.18f32; 3]; 25];
        let mut half = full.clone();
        half[12] = [0.28, 0.18, 0.18]; // centre differs by 0.1 in R
        full[0] = [0.18; 3];
        let e = adaptive_error(r, &full, &half).unwrap();
        let expected = 0.1 / (1e-4 + (0.54f64).sqrt());
        for (i, v) in e.iter().enumerate() {
            let (x, y) = (i % 5, i / 5);
            let near = x.abs_diff(2) <= 1 && y.abs_diff(2) <= 1;
            if near {
                assert!((f64::from(*v) - expected).abs() < 1e-5, "{i}: {v}");
            } else {
                assert_eq!(*v, 0.0, "{i}");
            }
        }
    }

    #[test]
    fn error_ignores_exposure_and_goes_relative_above_one() {
        let r = UVec2::new(2, 1);
        let e1 = adaptive_error(r, &[[1.0; 3], [1.0; 3]], &[[1.1, 1.0, 1.0], [1.0; 3]]).unwrap();
        let e2 =
            adaptive_error(r, &[[50.0; 3], [50.0; 3]], &[[55.0, 50.0, 50.0], [50.0; 3]]).unwrap();
        assert!((e1[0] - e2[0]).abs() < 1e-5 * e1[0]);
        // A pixel 10× the mean: intensity 5.4 > 1, so the error divides by I itself.
        let e = adaptive_error(r, &[[1.8; 3], [0.0; 3]], &[[1.9, 1.8, 1.8], [0.0; 3]]).unwrap();
        let scale = 0.18 / 0.9;
        let expected = 0.1 * scale / (1e-4 + 5.4 * scale);
        assert!(
            (f64::from(e[0]) - expected).abs() < 1e-5,
            "{} vs {expected}",
            e[0]
        );
        assert!(adaptive_error(r, &[[1.0; 3]], &[[1.0; 3]; 2]).is_err());
    }

    #[test]
    fn passes_spend_the_uniform_total_in_proportion_to_the_error() {
        let errors = vec![0.0, 1.0, 3.0, 0.0];
        let total: u64 = (0..1000)
            .map(|pass| adaptive_pass_counts(&errors, 40, 1, pass))
            .map(|c| {
                assert_eq!(c[0] + c[3], 0);
                assert!((c[2] as i64 - 30).abs() <= 1 && (c[1] as i64 - 10).abs() <= 1);
                c.iter().map(|&n| u64::from(n)).sum::<u64>()
            })
            .sum();
        assert_eq!(total, 40_000, "10 and 30 are exact shares");
        assert_eq!(adaptive_pass_counts(&[0.0; 4], 8, 1, 0), [2, 2, 2, 2]);
    }
}
