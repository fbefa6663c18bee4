//! Sensor readings beside the image: `<image stem>.sensors.json` (every point with its
//! standard error, per sensor the uniformity ratios) and `<image stem>.sensors.csv` (one row
//! per point), both written atomically (temporary sibling, then rename). docs/lighting.md.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use prism_render::sensor::{SensorReading, SensorStats};
use serde_json::json;

/// `dir/stem.sensors.json` and `dir/stem.sensors.csv` for the image `output`.
pub fn sensor_paths(output: &Path) -> (PathBuf, PathBuf) {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    (
        output.with_file_name(format!("{stem}.sensors.json")),
        output.with_file_name(format!("{stem}.sensors.csv")),
    )
}

/// The JSON document of the readings.
pub fn readings_json(
    scene: &Path,
    readings: &[SensorReading],
    stats: &SensorStats,
    wall_time_s: f64,
) -> serde_json::Value {
    let sensors: Vec<serde_json::Value> = readings
        .iter()
        .map(|r| {
            let u = r.uniformity();
            let points: Vec<serde_json::Value> = r
                .points
                .iter()
                .map(|p| {
                    json!({
                        "position_m": p.position_m,
                        "normal": p.normal,
                        "illuminance_lx": p.illuminance_lx,
                        "std_error_lx": p.std_error_lx,
                        "samples": p.samples,
                    })
                })
                .collect();
            json!({
                "name": r.name,
                "grid_resolution": r.grid_resolution,
                "uniformity": {
                    "min_lx": u.min_lx,
                    "max_lx": u.max_lx,
                    "average_lx": u.average_lx,
                    "min_over_average": u.min_over_average,
                    "min_over_max": u.min_over_max,
                },
                "points": points,
            })
        })
        .collect();
    json!({
        "scene": scene.display().to_string(),
        "quantity": "illuminance",
        "unit": "lx",
        // lx of an irradiance of 1 W·m⁻²·nm⁻¹ at every wavelength (683.002 lm/W × ∫ȳ dλ),
        // to compare with renderers that report flat-spectrum irradiance.
        "lx_per_flat_irradiance": prism_render::film::xyz::cd_m2_per_unit(),
        "wall_time_s": wall_time_s,
        "samples": stats.samples,
        "rays_traced": stats.rays_traced,
        "non_finite_contributions": stats.non_finite_contributions,
        "sensors": sensors,
    })
}

/// One CSV row per point: sensor, index, grid column and row (empty for point lists),
/// position, normal, illuminance, standard error, samples.
pub fn readings_csv(readings: &[SensorReading]) -> String {
    let mut s =
        String::from("sensor,index,i,j,x_m,y_m,z_m,nx,ny,nz,illuminance_lx,std_error_lx,samples\n");
    for r in readings {
        // Names are free text: quote them (CSV doubles inner quotes).
        let name = format!("\"{}\"", r.name.replace('"', "\"\""));
        for (k, p) in r.points.iter().enumerate() {
            let (i, j) = match r.grid_resolution {
                Some([nu, _]) => ((k % nu as usize).to_string(), (k / nu as usize).to_string()),
                None => (String::new(), String::new()),
            };
            let [x, y, z] = p.position_m;
            let [nx, ny, nz] = p.normal;
            let _ = writeln!(
                s,
                "{name},{k},{i},{j},{x},{y},{z},{nx},{ny},{nz},{},{},{}",
                p.illuminance_lx, p.std_error_lx, p.samples
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_render::sensor::PointReading;

    #[test]
    fn csv_has_one_row_per_point_and_grid_indices() {
        let p = PointReading {
            position_m: [1.0, 2.0, 3.0],
            normal: [0.0, 1.0, 0.0],
            illuminance_lx: 500.0,
            std_error_lx: 2.5,
            samples: 64,
        };
        let readings = vec![
            SensorReading {
                name: "work \"plane\"".into(),
                grid_resolution: Some([2, 1]),
                points: vec![p, p],
            },
            SensorReading {
                name: "desk".into(),
                grid_resolution: None,
                points: vec![p],
            },
        ];
        let csv = readings_csv(&readings);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(
            lines[2],
            "\"work \"\"plane\"\"\",1,1,0,1,2,3,0,1,0,500,2.5,64"
        );
        assert_eq!(lines[3], "\"desk\",0,,,1,2,3,0,1,0,500,2.5,64");
        let j = readings_json(Path::new("s.json"), &readings, &SensorStats::default(), 1.0);
        assert_eq!(j["sensors"][0]["uniformity"]["min_over_average"], 1.0);
        assert_eq!(
            sensor_paths(Path::new("out/room.exr")).1,
            PathBuf::from("out/room.sensors.csv")
        );
    }
}
