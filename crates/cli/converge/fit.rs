//! Power-law fits of error against time: least squares of log10(error) on log10(time).
//! For an unbiased Monte Carlo estimator at a constant cost per sample, RMSE ∝ t^−½ and
//! relMSE ∝ t^−1 (variance ∝ 1/N); a flatter slope means bias (the error stops falling) or
//! a cost per sample that grows.

use serde_json::{json, Value};

/// A fitted line log10(y) = intercept + slope · log10(x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination of the log–log line.
    pub r2: f64,
    /// Points used (those with x > 0 and y > 0, finite).
    pub points: usize,
}

impl PowerFit {
    /// The fit of `(x, y)` pairs; `None` with fewer than two usable points or when every x
    /// is equal.
    pub fn new(points: impl IntoIterator<Item = (f64, f64)>) -> Option<Self> {
        let logs: Vec<(f64, f64)> = points
            .into_iter()
            .filter(|&(x, y)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite())
            .map(|(x, y)| (x.log10(), y.log10()))
            .collect();
        let n = logs.len() as f64;
        if logs.len() < 2 {
            return None;
        }
        let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
        let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let syy: f64 = logs.iter().map(|p| (p.1 - my).powi(2)).sum();
        if sxx <= 0.0 {
            return None;
        }
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let r2 = if syy > 0.0 {
            (sxy * sxy) / (sxx * syy)
        } else {
            1.0
        };
        Some(Self {
            slope,
            intercept,
            r2,
            points: logs.len(),
        })
    }

    /// The fitted y at x.
    pub fn at(&self, x: f64) -> f64 {
        10f64.powf(self.intercept + self.slope * x.log10())
    }

    pub fn to_json(fit: Option<&Self>) -> Value {
        match fit {
            Some(f) => json!({"slope": f.slope, "intercept_log10": f.intercept, "r2": f.r2,
                              "points": f.points}),
            None => Value::Null,
        }
    }
}

/// The first x at which y falls to `target`, interpolated log–log between the checkpoints
/// around the crossing; `None` if y never gets there. Points are in increasing x.
pub fn first_crossing(points: &[(f64, f64)], target: f64) -> Option<f64> {
    let mut previous: Option<(f64, f64)> = None;
    for &(x, y) in points {
        if y <= target {
            return Some(match previous {
                Some((x0, y0)) if y0 > target && x0 > 0.0 && y > 0.0 => {
                    let f = (target.ln() - y0.ln()) / (y.ln() - y0.ln());
                    (x0.ln() + f * (x.ln() - x0.ln())).exp()
                }
                _ => x,
            });
        }
        previous = Some((x, y));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exact_power_law_gives_its_exponent() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|k| {
                let t = 0.01 * 2f64.powi(k);
                (t, 3.0 * t.powf(-0.5))
            })
            .collect();
        let fit = PowerFit::new(pts.iter().copied()).unwrap();
        assert!((fit.slope + 0.5).abs() < 1e-12);
        assert!((fit.at(1.0) - 3.0).abs() < 1e-9);
        assert!((fit.r2 - 1.0).abs() < 1e-12);
        assert_eq!(fit.points, 10);
    }

    #[test]
    fn degenerate_inputs_give_no_fit() {
        assert!(PowerFit::new([(1.0, 1.0)]).is_none());
        assert!(PowerFit::new([(1.0, 1.0), (1.0, 2.0)]).is_none());
        assert!(PowerFit::new([(1.0, 0.0), (2.0, f64::NAN)]).is_none());
    }

    #[test]
    fn crossing_is_interpolated_log_log() {
        // y = 1/x: crosses 0.1 at x = 10, between the checkpoints 4 and 16.
        let pts = [(1.0, 1.0), (4.0, 0.25), (16.0, 0.0625)];
        assert!((first_crossing(&pts, 0.1).unwrap() - 10.0).abs() < 1e-9);
        assert_eq!(first_crossing(&pts, 2.0), Some(1.0));
        assert_eq!(first_crossing(&pts, 0.01), None);
    }
}
