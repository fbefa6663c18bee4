//! Illuminance sensors (the `sensors` section): single points, lists of points and grids
//! over a plane, each point with a receiving orientation (its normal) and a sampling rule
//! (a fixed number of samples, or run until a requested standard error). Render measures
//! E = ∫ L cos θ dω in lux at each point (docs/lighting.md).

use glam::DVec3;

use crate::reader::{Obj, Result, V};
use crate::schema::schema;

/// One entry of `sensors`: a named group of measuring points.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// `name` from the file, else `sensors[i]`; unique within the scene.
    pub name: String,
    pub kind: SensorKind,
    pub sampling: SensorSampling,
}

/// Where the points are and which way they face.
#[derive(Debug, Clone, PartialEq)]
pub enum SensorKind {
    /// Explicit points (`point` or `points`), each with a unit normal.
    Points {
        positions_m: Vec<[f64; 3]>,
        normals: Vec<[f64; 3]>,
    },
    /// `resolution[0] × resolution[1]` points at the centres of the cells of the
    /// parallelogram `origin_m + s·u_m + t·v_m`, s, t ∈ [0, 1]; row-major with `u` fastest.
    Grid {
        origin_m: [f64; 3],
        u_m: [f64; 3],
        v_m: [f64; 3],
        resolution: [u32; 2],
        /// Unit normal of every point (default +Y: horizontal illuminance).
        normal: [f64; 3],
    },
}

/// How many samples each point takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SensorSampling {
    /// Exactly this many samples per point.
    Fixed { samples: u32 },
    /// Samples in batches until the standard error of the mean is at most
    /// max(`relative_error` · mean, `absolute_error_lx`), with at least `min_samples` and at
    /// most `max_samples`.
    Adaptive {
        relative_error: f64,
        absolute_error_lx: f64,
        min_samples: u32,
        max_samples: u32,
    },
}

impl SensorKind {
    /// Number of measuring points.
    pub fn len(&self) -> usize {
        match self {
            SensorKind::Points { positions_m, .. } => positions_m.len(),
            SensorKind::Grid { resolution, .. } => resolution[0] as usize * resolution[1] as usize,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Position (metres) and unit normal of point `i` (< `len()`).
    pub fn point(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        match self {
            SensorKind::Points {
                positions_m,
                normals,
            } => (positions_m[i], normals[i]),
            SensorKind::Grid {
                origin_m,
                u_m,
                v_m,
                resolution,
                normal,
            } => {
                let nu = resolution[0] as usize;
                let (iu, iv) = (i % nu, i / nu);
                let s = (iu as f64 + 0.5) / f64::from(resolution[0]);
                let t = (iv as f64 + 0.5) / f64::from(resolution[1]);
                let p = DVec3::from(*origin_m) + DVec3::from(*u_m) * s + DVec3::from(*v_m) * t;
                (p.to_array(), *normal)
            }
        }
    }
}

pub const SENSOR_TYPES: [&str; 3] = ["point", "points", "grid"];

/// Default samples per point when a sensor gives no sampling rule.
pub const DEFAULT_SENSOR_SAMPLES: u32 = 256;
/// Default cap of an adaptive sensor.
pub const DEFAULT_MAX_SENSOR_SAMPLES: u32 = 1 << 22;
/// Default floor of an adaptive sensor (the variance estimate needs some samples).
pub const DEFAULT_MIN_SENSOR_SAMPLES: u32 = 64;
/// Most points in one scene's sensors (a 2000 × 2000 grid).
pub const MAX_SENSOR_POINTS: usize = 4_000_000;

fn unit(v: &V) -> Result<[f64; 3]> {
    let d = DVec3::from(v.numbers::<3>()?);
    if d.length() <= 1e-12 {
        return Err(v.err("expected a non-zero direction"));
    }
    Ok(d.normalize().to_array())
}

fn sampling(o: &Obj) -> Result<SensorSampling> {
    let adaptive = o.get("relative_error").is_some() || o.get("absolute_error_lx").is_some();
    if let (Some(s), true) = (o.get("samples"), adaptive) {
        return Err(s.err(
            "give either `samples` (a fixed count) or `relative_error`/`absolute_error_lx` \
             (run to a standard error), not both",
        ));
    }
    if !adaptive {
        for key in ["min_samples", "max_samples"] {
            if let Some(v) = o.get(key) {
                return Err(v.err(format!(
                    "`{key}` only applies with `relative_error` or `absolute_error_lx`"
                )));
            }
        }
        return Ok(SensorSampling::Fixed {
            samples: o.u32_or("samples", 1, DEFAULT_SENSOR_SAMPLES)?,
        });
    }
    let relative_error = match o.get("relative_error") {
        None => 0.0,
        Some(v) => {
            let x = v.f64()?;
            if !(x > 0.0 && x < 1.0) {
                return Err(v.err(format!(
                    "expected a relative standard error in (0, 1), e.g. 0.01 for 1 %, found {x}"
                )));
            }
            x
        }
    };
    let absolute_error_lx = match o.get("absolute_error_lx") {
        None => 0.0,
        Some(v) => v.positive()?,
    };
    let min_samples = o.u32_or("min_samples", 2, DEFAULT_MIN_SENSOR_SAMPLES)?;
    let max_samples = o.u32_or(
        "max_samples",
        2,
        DEFAULT_MAX_SENSOR_SAMPLES.max(min_samples),
    )?;
    if max_samples < min_samples {
        let v = o.get("max_samples").unwrap_or_else(|| o.v.clone());
        return Err(v.err(format!(
            "expected `max_samples` ≥ `min_samples` ({min_samples}), found {max_samples}"
        )));
    }
    Ok(SensorSampling::Adaptive {
        relative_error,
        absolute_error_lx,
        min_samples,
        max_samples,
    })
}

fn parse_sensor(v: &V, index: usize) -> Result<Sensor> {
    let kind_name = v.tag("sensor", &SENSOR_TYPES, None)?;
    let (o, kind) = match kind_name {
        "point" => {
            let o = v.object(schema!("sensors[]<point>"))?;
            let position_m = o.req("position_m", "[x, y, z] in metres")?.numbers::<3>()?;
            let normal = o.get("normal").map_or(Ok([0.0, 1.0, 0.0]), |n| unit(&n))?;
            (
                o,
                SensorKind::Points {
                    positions_m: vec![position_m],
                    normals: vec![normal],
                },
            )
        }
        "points" => {
            let o = v.object(schema!("sensors[]<points>"))?;
            let list = o.req("positions_m", "an array of [x, y, z] in metres")?;
            let items = list.array()?;
            if items.is_empty() {
                return Err(list.err("expected at least one point, found an empty array"));
            }
            let positions_m = items
                .iter()
                .map(|p| p.numbers::<3>())
                .collect::<Result<Vec<_>>>()?;
            let normals = match o.at_most_one(&["normal", "normals"])? {
                None => vec![[0.0, 1.0, 0.0]; positions_m.len()],
                Some(("normal", n)) => vec![unit(&n)?; positions_m.len()],
                Some((_, ns)) => {
                    let items = ns.array()?;
                    if items.len() != positions_m.len() {
                        return Err(ns.err(format!(
                            "expected one normal per point ({}), found {}",
                            positions_m.len(),
                            items.len()
                        )));
                    }
                    items.iter().map(unit).collect::<Result<Vec<_>>>()?
                }
            };
            (
                o,
                SensorKind::Points {
                    positions_m,
                    normals,
                },
            )
        }
        _ => {
            let o = v.object(schema!("sensors[]<grid>"))?;
            let origin_m = o
                .req("origin_m", "the grid's corner [x, y, z] in metres")?
                .numbers::<3>()?;
            let u_v = o.req("u_m", "the first edge of the grid [x, y, z] in metres")?;
            let v_v = o.req("v_m", "the second edge of the grid [x, y, z] in metres")?;
            let (u_m, v_m) = (u_v.numbers::<3>()?, v_v.numbers::<3>()?);
            for (e, val) in [(&u_v, u_m), (&v_v, v_m)] {
                if DVec3::from(val).length() <= 0.0 {
                    return Err(e.err("expected a non-zero edge vector"));
                }
            }
            if DVec3::from(u_m).cross(DVec3::from(v_m)).length()
                <= 1e-9 * DVec3::from(u_m).length() * DVec3::from(v_m).length()
            {
                return Err(v_v.err("expected `v_m` not parallel to `u_m` (the grid is a line)"));
            }
            let r = o.req("resolution", "[points along u_m, points along v_m]")?;
            let items = r.array()?;
            if items.len() != 2 {
                return Err(r.err(format!(
                    "expected [points along u_m, points along v_m], found {} numbers",
                    items.len()
                )));
            }
            let resolution = [items[0].u32_at_least(1)?, items[1].u32_at_least(1)?];
            if resolution[0] as usize * resolution[1] as usize > MAX_SENSOR_POINTS {
                return Err(r.err(format!(
                    "a grid of {} × {} points is more than {MAX_SENSOR_POINTS}",
                    resolution[0], resolution[1]
                )));
            }
            let normal = o.get("normal").map_or(Ok([0.0, 1.0, 0.0]), |n| unit(&n))?;
            (
                o,
                SensorKind::Grid {
                    origin_m,
                    u_m,
                    v_m,
                    resolution,
                    normal,
                },
            )
        }
    };
    let name = match o.get("name") {
        None => format!("sensors[{index}]"),
        Some(n) => {
            let s = n.str()?;
            if s.is_empty() {
                return Err(n.err("expected a non-empty name"));
            }
            s.to_string()
        }
    };
    Ok(Sensor {
        name,
        kind,
        sampling: sampling(&o)?,
    })
}

pub(crate) fn parse_sensors(v: &V) -> Result<Vec<Sensor>> {
    let mut sensors: Vec<Sensor> = Vec::new();
    let mut total = 0usize;
    for (i, item) in v.array()?.iter().enumerate() {
        let sensor = parse_sensor(item, i)?;
        if sensors.iter().any(|s| s.name == sensor.name) {
            let at = item.member("name").unwrap_or_else(|| item.clone());
            return Err(at.err(format!(
                "sensor name `{}` is used twice; names must be unique",
                sensor.name
            )));
        }
        total += sensor.kind.len();
        if total > MAX_SENSOR_POINTS {
            return Err(item.err(format!(
                "the sensors have more than {MAX_SENSOR_POINTS} points in all"
            )));
        }
        sensors.push(sensor);
    }
    Ok(sensors)
}

#[cfg(test)]
mod tests {
    use crate::parse_scene_str;

    use super::*;

    fn sensors(json: &str) -> std::result::Result<Vec<Sensor>, String> {
        parse_scene_str(&format!("{{\"sensors\": {json}}}"), "scene.json")
            .map(|s| s.sensors)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn points_grids_and_sampling_rules_parse() {
        let s = sensors(
            r#"[{"type": "point", "name": "desk", "position_m": [1, 0.8, 2]},
                {"type": "points", "positions_m": [[0, 1, 0], [1, 1, 0]], "normals": [[1, 0, 0], [0, 0, 2]],
                 "relative_error": 0.01, "max_samples": 100000},
                {"type": "grid", "name": "wp", "origin_m": [0, 0.85, 0], "u_m": [4, 0, 0], "v_m": [0, 0, 2],
                 "resolution": [4, 2], "normal": [0, 0, -1], "samples": 16}]"#,
        )
        .unwrap();
        assert_eq!(s[0].name, "desk");
        assert_eq!(s[0].kind.point(0), ([1.0, 0.8, 2.0], [0.0, 1.0, 0.0]));
        assert_eq!(
            s[0].sampling,
            SensorSampling::Fixed {
                samples: DEFAULT_SENSOR_SAMPLES
            }
        );
        assert_eq!(s[1].name, "sensors[1]");
        assert_eq!(s[1].kind.point(1).1, [0.0, 0.0, 1.0]);
        assert_eq!(
            s[1].sampling,
            SensorSampling::Adaptive {
                relative_error: 0.01,
                absolute_error_lx: 0.0,
                min_samples: DEFAULT_MIN_SENSOR_SAMPLES,
                max_samples: 100_000
            }
        );
        assert_eq!(s[2].kind.len(), 8);
        // Cell centres, u fastest.
        assert_eq!(s[2].kind.point(0).0, [0.5, 0.85, 0.5]);
        assert_eq!(s[2].kind.point(5).0, [1.5, 0.85, 1.5]);
        assert_eq!(s[2].kind.point(5).1, [0.0, 0.0, -1.0]);
    }

    #[test]
    fn mistakes_are_errors_with_their_place() {
        for (json, expected) in [
            (
                r#"[{"type": "point"}]"#,
                "sensors[0]: missing field `position_m`",
            ),
            (
                r#"[{"type": "point", "position_m": [0, 0, 0], "normal": [0, 0, 0]}]"#,
                "sensors[0].normal: expected a non-zero direction",
            ),
            (
                r#"[{"type": "grid", "origin_m": [0, 0, 0], "u_m": [1, 0, 0], "v_m": [2, 0, 0], "resolution": [2, 2]}]"#,
                "sensors[0].v_m: expected `v_m` not parallel",
            ),
            (
                r#"[{"type": "grid", "origin_m": [0, 0, 0], "u_m": [1, 0, 0], "v_m": [0, 0, 1], "resolution": [0, 2]}]"#,
                "sensors[0].resolution[0]: expected a whole number ≥ 1, found 0",
            ),
            (
                r#"[{"type": "point", "position_m": [0, 0, 0], "samples": 4, "relative_error": 0.1}]"#,
                "sensors[0].samples: give either `samples`",
            ),
            (
                r#"[{"type": "point", "position_m": [0, 0, 0], "relative_error": 2}]"#,
                "sensors[0].relative_error: expected a relative standard error in (0, 1)",
            ),
            (
                r#"[{"type": "point", "position_m": [0, 0, 0], "max_samples": 9}]"#,
                "sensors[0].max_samples: `max_samples` only applies",
            ),
            (
                r#"[{"type": "points", "positions_m": [[0, 0, 0]], "normals": []}]"#,
                "sensors[0].normals: expected one normal per point (1), found 0",
            ),
            (
                r#"[{"type": "point", "name": "a", "position_m": [0, 0, 0]}, {"type": "point", "name": "a", "position_m": [0, 0, 0]}]"#,
                "sensors[1].name: sensor name `a` is used twice",
            ),
            (
                r#"[{"type": "pointz", "position_m": [0, 0, 0]}]"#,
                "sensors[0].type: unknown sensor type `pointz`",
            ),
        ] {
            let e = sensors(json).unwrap_err();
            assert!(e.contains(expected), "{json}\n→ {e}\nexpected {expected}");
        }
    }
}
