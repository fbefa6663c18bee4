//! `prism render --false-colour luminance|illuminance`: false-colour PNGs with a legend
//! beside the image — `<stem>.luminance.falsecolour.png` from the film's luminance (cd/m²),
//! `<stem>.<sensor>.falsecolour.png` for every grid sensor's illuminance (lx). docs/lighting.md.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use prism_image::io::write_image;
use prism_post::falsecolour::{false_colour, FalseColourOptions, FalseColourScale, Palette};
use prism_render::sensor::SensorReading;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FalseColourQuantity {
    /// The image's luminance in cd/m².
    Luminance,
    /// Every grid sensor's illuminance in lx.
    Illuminance,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ScaleArg {
    Linear,
    Log,
}

/// The ramp's options checked before rendering: a log scale needs a minimum above 0.
pub fn check_options(scale: ScaleArg, range: Option<(f64, f64)>) -> Result<(), String> {
    match (scale, range) {
        (ScaleArg::Log, Some((min, max))) if min <= 0.0 => Err(format!(
            "--false-colour-range {min}:{max} with --false-colour-scale log: expected a \
             minimum > 0 (a log scale has no 0), e.g. {}:{max}",
            max / 1000.0
        )),
        (ScaleArg::Log | ScaleArg::Linear, _) => Ok(()),
    }
}

fn options(
    scale: ScaleArg,
    range: Option<(f64, f64)>,
    unit: &str,
    cell_px: usize,
) -> FalseColourOptions {
    FalseColourOptions {
        scale: match scale {
            ScaleArg::Linear => FalseColourScale::Linear,
            ScaleArg::Log => FalseColourScale::Log,
        },
        range,
        unit: unit.into(),
        cell_px,
        palette: Palette::Lighting,
    }
}

fn sibling(output: &Path, middle: &str) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    output.with_file_name(format!("{stem}.{middle}.falsecolour.png"))
}

/// A name as a file-name part: letters, digits, '-' and '_' kept, the rest '_' (sensor
/// names here, tile names in `tile_brdf`).
pub(crate) fn file_name_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The luminance image (cd/m², row-major, top row first) in false colour.
pub fn write_luminance(
    output: &Path,
    luminance: &[f32],
    (w, h): (usize, usize),
    scale: ScaleArg,
    range: Option<(f64, f64)>,
) -> Result<PathBuf, String> {
    let img = false_colour(luminance, w, h, &options(scale, range, "cd/m2", 1))
        .map_err(|e| format!("false colour of the luminance: {e}"))?;
    let path = sibling(output, "luminance");
    write_image(&path, &img).map_err(|e| e.to_string())?;
    Ok(path)
}

/// Every grid sensor's illuminance in false colour (row j = 0, the first row along `v_m`,
/// at the top).
pub fn write_illuminance(
    output: &Path,
    readings: &[SensorReading],
    scale: ScaleArg,
    range: Option<(f64, f64)>,
) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    for r in readings {
        let Some([nu, nv]) = r.grid_resolution else {
            continue;
        };
        let values: Vec<f32> = r.points.iter().map(|p| p.illuminance_lx as f32).collect();
        let cell = (400 / nu.max(nv) as usize).max(1);
        let img = false_colour(
            &values,
            nu as usize,
            nv as usize,
            &options(scale, range, "lx", cell),
        )
        .map_err(|e| format!("false colour of sensor `{}`: {e}", r.name))?;
        let path = sibling(output, &file_name_part(&r.name));
        write_image(&path, &img).map_err(|e| e.to_string())?;
        written.push(path);
    }
    if written.is_empty() {
        return Err("--false-colour illuminance: the scene has no `grid` sensor".into());
    }
    Ok(written)
}
