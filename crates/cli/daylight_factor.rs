//! The daylight factor beside the sensor readings: when the scene has one daylight sky
//! (`cie_sky`, `perez_sky`, `preetham_sky`), every point also gets
//! DF = 100 · E / E_out % with E_out the sky's unobstructed horizontal illuminance (sky only:
//! no sun disk, no ground; CIE's definition under the overcast sky, reported for any daylight
//! sky), in the JSON (`daylight` at the top, `daylight_factor_percent` and its standard error
//! per point, the average/minimum/maximum per sensor) and as two more CSV columns.
//! docs/daylight.md.

use prism_render::sensor::SensorReading;
use serde_json::{json, Value};

/// Adds the daylight factor to the JSON document of `readings_json`.
pub fn add_to_json(value: &mut Value, readings: &[SensorReading], outdoor_lx: f64) {
    let df = |e: f64| 100.0 * e / outdoor_lx;
    value["daylight"] = json!({
        "outdoor_horizontal_illuminance_lx": outdoor_lx,
        "definition": "daylight_factor_percent = 100 · illuminance_lx / outdoor_horizontal_illuminance_lx \
                       (the sky alone on an unobstructed horizontal plane: no sun, no ground)",
    });
    let Some(sensors) = value["sensors"].as_array_mut() else {
        return;
    };
    for (s, r) in sensors.iter_mut().zip(readings) {
        let u = r.uniformity();
        s["daylight_factor_percent"] = json!({
            "average": df(u.average_lx),
            "min": df(u.min_lx),
            "max": df(u.max_lx),
        });
        if let Some(points) = s["points"].as_array_mut() {
            for (p, reading) in points.iter_mut().zip(&r.points) {
                p["daylight_factor_percent"] = json!(df(reading.illuminance_lx));
                p["daylight_factor_std_error_percent"] = json!(df(reading.std_error_lx));
            }
        }
    }
}

/// `csv` (one header line, then one row per point in `readings` order) with the columns
/// `daylight_factor_percent,daylight_factor_std_error_percent` appended.
pub fn add_to_csv(csv: &str, readings: &[SensorReading], outdoor_lx: f64) -> String {
    let mut values = readings.iter().flat_map(|r| r.points.iter());
    let mut out = String::with_capacity(csv.len() + 64 * readings.len());
    for (k, line) in csv.lines().enumerate() {
        out.push_str(line);
        if k == 0 {
            out.push_str(",daylight_factor_percent,daylight_factor_std_error_percent");
        } else if let Some(p) = values.next() {
            out.push_str(&format!(
                ",{},{}",
                100.0 * p.illuminance_lx / outdoor_lx,
                100.0 * p.std_error_lx / outdoor_lx
            ));
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_render::sensor::{PointReading, SensorStats};
    use std::path::Path;

    #[test]
    fn daylight_factor_is_added_to_json_and_csv() {
        let p = |e: f64| PointReading {
            position_m: [0.0, 0.0, 0.0],
            normal: [0.0, 1.0, 0.0],
            illuminance_lx: e,
            std_error_lx: 0.1 * e,
            samples: 10,
        };
        let readings = vec![SensorReading {
            name: "floor".into(),
            grid_resolution: None,
            points: vec![p(200.0), p(50.0)],
        }];
        let mut v = crate::sensors::readings_json(
            Path::new("s.json"),
            &readings,
            &SensorStats::default(),
            1.0,
        );
        add_to_json(&mut v, &readings, 10_000.0);
        assert_eq!(v["daylight"]["outdoor_horizontal_illuminance_lx"], 10_000.0);
        assert_eq!(v["sensors"][0]["points"][0]["daylight_factor_percent"], 2.0);
        assert_eq!(v["sensors"][0]["daylight_factor_percent"]["min"], 0.5);
        let csv = add_to_csv(
            &crate::sensors::readings_csv(&readings),
            &readings,
            10_000.0,
        );
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines[0].ends_with(",daylight_factor_percent,daylight_factor_std_error_percent"));
        assert!(lines[1].ends_with(",2,0.2"), "{}", lines[1]);
        assert!(lines[2].ends_with(",0.5,0.05"), "{}", lines[2]);
    }
}
