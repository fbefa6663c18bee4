//! The `ratios` block of `prism converge --json`: each method against the first one, on
//! the run's clock, with log–log interpolation between checkpoints (error curves are
//! straight lines there).
//! - `time_to_relmse`: for each target, the time each method first reaches it and the
//!   speed-up (first method's time ÷ this method's; > 1: this one is faster);
//! - `relmse_at_equal_time`: at each of the first method's checkpoints that lies inside
//!   this method's time range, both relMSEs and their ratio (first ÷ this; > 1: this one
//!   has the lower error at equal time).

use serde_json::{json, Value};

use super::fit::first_crossing;

/// relMSE levels whose crossing times are compared (1e-2 is the target).
pub const RELMSE_TARGETS: [f64; 3] = [1e-1, 1e-2, 1e-3];

/// log y at log x, interpolated between the two points around x (increasing x); `None`
/// outside the points' range or where a value is not positive.
pub fn interpolate_log_log(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let upper = points.iter().position(|&(px, _)| px >= x)?;
    let (x1, y1) = points[upper];
    if x1 == x {
        return Some(y1);
    }
    let (x0, y0) = *points.get(upper.checked_sub(1)?)?;
    if x0 <= 0.0 || y0 <= 0.0 || y1 <= 0.0 {
        return None;
    }
    let f = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
    Some((y0.ln() + f * (y1.ln() - y0.ln())).exp())
}

/// The block for one method (`this`) against the first (`against`); both series are
/// (time on the run's clock, relMSE) at the checkpoints, in increasing time.
pub fn ratios(against_label: &str, against: &[(f64, f64)], this: &[(f64, f64)]) -> Value {
    let time_to: Vec<Value> = RELMSE_TARGETS
        .iter()
        .map(|&target| {
            let (a, t) = (
                first_crossing(against, target),
                first_crossing(this, target),
            );
            json!({
                "relmse": target,
                "against_s": a,
                "this_s": t,
                "speedup": match (a, t) {
                    (Some(a), Some(t)) if t > 0.0 => Some(a / t),
                    _ => None,
                },
            })
        })
        .collect();
    let at_equal_time: Vec<Value> = against
        .iter()
        .filter_map(|&(time_s, relmse_against)| {
            let relmse_this = interpolate_log_log(this, time_s)?;
            Some(json!({
                "time_s": time_s,
                "against": relmse_against,
                "this": relmse_this,
                "ratio": relmse_against / relmse_this,
            }))
        })
        .collect();
    json!({
        "against": against_label,
        "time_to_relmse": time_to,
        "relmse_at_equal_time": at_equal_time,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two exact power laws e = c·t^−1: the ratios are the constants' ratio everywhere.
    #[test]
    fn power_laws_give_constant_ratios() {
        let series = |c: f64| -> Vec<(f64, f64)> {
            (0..8)
                .map(|k| {
                    let t = 0.1 * 2f64.powi(k);
                    (t, c / t)
                })
                .collect()
        };
        let (slow, fast) = (series(0.02), series(0.005));
        let block = ratios("path", &slow, &fast);
        assert_eq!(block["against"], "path");
        // relMSE 1e-2 at t = 2 (slow) and 0.5 (fast): 4× sooner.
        let row = &block["time_to_relmse"][1];
        assert!(
            (row["speedup"].as_f64().unwrap() - 4.0).abs() < 1e-9,
            "{row}"
        );
        assert!(
            block["time_to_relmse"][2]["speedup"].is_null(),
            "1e-3 never reached"
        );
        let equal = block["relmse_at_equal_time"].as_array().unwrap();
        assert_eq!(equal.len(), 8);
        for r in equal {
            assert!((r["ratio"].as_f64().unwrap() - 4.0).abs() < 1e-9, "{r}");
        }
        // Between checkpoints: log–log interpolation is exact on a power law.
        let y = interpolate_log_log(&fast, 0.3).unwrap();
        assert!((y - 0.005 / 0.3).abs() < 1e-12);
        assert_eq!(
            interpolate_log_log(&fast, 0.05),
            None,
            "before the first point"
        );
        assert_eq!(
            interpolate_log_log(&fast, 100.0),
            None,
            "after the last point"
        );
    }
}
