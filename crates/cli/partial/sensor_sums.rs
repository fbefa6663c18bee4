//! The sensors' share of a sample-range part: `<part stem>.sensors.partial.json` beside
//! the partial EXR, holding each point's replicate sums (the exact fixed-point integers as 32 hex digits,
//! two's complement)
//! and counts, which `prism merge` adds into `<output stem>.sensors.json/.csv` with the
//! mean and standard error of the whole measurement (docs/scale-out.md).

use std::path::{Path, PathBuf};

use prism_render::sensor::{PointSums, ReplicateStats, SensorSums};
use serde_json::{json, Value};

/// `<stem>.sensors.partial.json` beside `image`.
pub fn sidecar_path(image: &Path) -> PathBuf {
    let stem = image
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    image.with_file_name(format!("{stem}.sensors.partial.json"))
}

pub fn to_json(identity_hash: &str, range: &str, sensors: &[SensorSums]) -> Value {
    let hex =
        |v: &prism_render::film::FixedSum| Value::String(format!("{:032x}", v.to_bits() as u128));
    json!({
        "prism_partial_sensors": 1,
        "identity": identity_hash,
        "samples": range,
        "sensors": sensors.iter().map(|s| json!({
            "name": s.name,
            "grid_resolution": s.grid_resolution,
            "points": s.points.iter().map(|p| json!({
                "position_m": p.position_m,
                "normal": p.normal,
                "sums": p.replicates.sums().iter().map(hex).collect::<Vec<_>>(),
                "counts": p.replicates.counts(),
            })).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    })
}

/// Reads a sidecar; errors name the file and the JSON path.
pub fn read(path: &Path) -> Result<(String, Vec<SensorSums>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let value: Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let bad = |at: &str, what: &str| format!("{}: {at}: expected {what}", path.display());
    let identity = value["identity"]
        .as_str()
        .ok_or_else(|| bad("identity", "the render's identity hash"))?
        .to_string();
    let mut sensors = Vec::new();
    for (i, s) in value["sensors"]
        .as_array()
        .ok_or_else(|| bad("sensors", "an array"))?
        .iter()
        .enumerate()
    {
        let at = format!("sensors[{i}]");
        let name = s["name"]
            .as_str()
            .ok_or_else(|| bad(&format!("{at}.name"), "a string"))?
            .to_string();
        let grid_resolution = match &s["grid_resolution"] {
            Value::Null => None,
            v => Some(
                serde_json::from_value::<[u32; 2]>(v.clone())
                    .map_err(|_| bad(&format!("{at}.grid_resolution"), "[nu, nv]"))?,
            ),
        };
        let mut points = Vec::new();
        for (k, p) in s["points"]
            .as_array()
            .ok_or_else(|| bad(&format!("{at}.points"), "an array"))?
            .iter()
            .enumerate()
        {
            let at = format!("{at}.points[{k}]");
            let triple = |key: &str| {
                serde_json::from_value::<[f64; 3]>(p[key].clone())
                    .map_err(|_| bad(&format!("{at}.{key}"), "three numbers"))
            };
            let sums = p["sums"]
                .as_array()
                .ok_or_else(|| bad(&format!("{at}.sums"), "an array of hex fixed-point sums"))?
                .iter()
                .map(|h| {
                    h.as_str()
                        .filter(|h| h.len() == 32)
                        .and_then(|h| u128::from_str_radix(h, 16).ok())
                        .map(|bits| prism_render::film::FixedSum::from_bits(bits as i128))
                        .ok_or_else(|| bad(&format!("{at}.sums"), "32 hex digits per sum"))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let counts = serde_json::from_value::<Vec<u64>>(p["counts"].clone())
                .map_err(|_| bad(&format!("{at}.counts"), "an array of counts"))?;
            let replicates = ReplicateStats::from_parts(sums, counts)
                .ok_or_else(|| bad(&at, "as many sums as counts"))?;
            points.push(PointSums {
                position_m: triple("position_m")?,
                normal: triple("normal")?,
                replicates,
            });
        }
        sensors.push(SensorSums {
            name,
            grid_resolution,
            points,
        });
    }
    Ok((identity, sensors))
}
