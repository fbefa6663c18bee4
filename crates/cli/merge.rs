//! `prism merge PART.exr… -o OUT.exr`: the parts of one render (`prism render --samples`,
//! one sample range each, possibly from different machines) added into the image of
//! their union. Each part holds its film's exact sums (crates/cli/partial/file.rs), so the
//! merged pixel is Σ sums / Σ weights over the parts: the image weighted by sample
//! counts, AOVs, spectral bins, light-path splats and the luminance layer included.
//!
//! Refused (status 1): parts of different renders (their identity hashes differ; the
//! message names the fields), overlapping ranges (a file given twice included), an
//! interrupted checkpoint. Ranges of [0, spp) no part covers are a warning. The parts are
//! read one at a time (headers first, to order them), so memory holds two films whatever
//! their number; the sums are added in range order.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::Args;
use prism_render::Film;

use crate::partial::file::{header_attributes, read_partial, PartialHeader, COMPLETE};
use crate::partial::identity::HASH_ATTRIBUTE;
use crate::partial::range::{format_ranges, missing_ranges, parse_range, SampleRange};

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Partial images written by `prism render --samples A..B` (or by earlier merges
    /// written as `*.partial.exr`).
    #[arg(required = true, num_args = 1..)]
    pub parts: Vec<PathBuf>,
    /// The merged image (.exr). A name ending in `.partial.exr` keeps the sums too, so it
    /// can be merged again (a merge tree).
    #[arg(short = 'o', long = "output", required = true)]
    pub output: PathBuf,
}

/// What the header says of one part, read without its pixels.
struct PartInfo {
    path: PathBuf,
    hash: String,
    spp: Option<u32>,
    ranges: Vec<SampleRange>,
    complete: bool,
}

fn part_info(path: &Path) -> Result<PartInfo, String> {
    let text = prism_image::io::raw_exr::read_text_attributes(path).map_err(|e| e.to_string())?;
    let get = |key: &str| {
        text.get(key).ok_or_else(|| {
            format!(
                "{}: not a partial image of `prism render` (no header attribute {key}; \
                 expected a file written with --samples)",
                path.display()
            )
        })
    };
    let hash = get(HASH_ATTRIBUTE)?.clone();
    let ranges = crate::partial::range::parse_ranges(get(crate::partial::file::RANGES_DONE)?)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let range = parse_range(get(crate::partial::file::RANGE)?)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let complete = get(COMPLETE)? == "true";
    let spp = text
        .get(&format!("{HASH_ATTRIBUTE}.spp"))
        .and_then(|s| s.parse().ok());
    Ok(PartInfo {
        path: path.to_path_buf(),
        hash,
        spp,
        ranges: if complete { ranges } else { vec![range] },
        complete,
    })
}

pub fn run(args: &MergeArgs) -> Result<ExitCode, String> {
    if !matches!(
        prism_image::io::ImageFormat::from_path(&args.output),
        Ok(prism_image::io::ImageFormat::Exr)
    ) {
        return Err(format!(
            "-o {}: the merged image is an EXR (it keeps every layer); expected a .exr name",
            args.output.display()
        ));
    }
    let start = Instant::now();
    let mut infos = Vec::new();
    for path in &args.parts {
        infos.push(part_info(path)?);
    }
    if let Some(p) = infos.iter().find(|p| !p.complete) {
        return Err(format!(
            "{}: an interrupted render (its range {} is not complete); finish it with \
             `prism render … --resume {}` before merging",
            p.path.display(),
            format_ranges(&p.ranges),
            p.path.display()
        ));
    }
    // Same render: the first part's identity is the reference.
    let first = &infos[0];
    if let Some(p) = infos.iter().find(|p| p.hash != first.hash) {
        let a = read_partial(&first.path)?;
        let b = read_partial(&p.path)?;
        let differences = crate::partial::identity::field_differences(
            &a.header.identity,
            &b.header.identity,
            "in the first",
            "in the second",
        )
        .join("; ");
        return Err(format!(
            "{} and {} are parts of different renders (identity {} and {}); {}",
            first.path.display(),
            p.path.display(),
            first.hash,
            p.hash,
            differences
                .replace(" in the file, ", " in the second, ")
                .replace(" now", " in the first")
        ));
    }
    // Disjoint ranges, in order.
    let mut ranges: Vec<(SampleRange, usize)> = infos
        .iter()
        .enumerate()
        .flat_map(|(i, p)| p.ranges.iter().map(move |r| (*r, i)))
        .collect();
    ranges.sort();
    for w in ranges.windows(2) {
        let ((a, i), (b, j)) = (w[0], w[1]);
        if a.overlaps(b) {
            let same = if infos[i].path == infos[j].path {
                " (the same file given twice)".to_string()
            } else {
                String::new()
            };
            return Err(format!(
                "{} (samples {a}) and {} (samples {b}) overlap{same}: each sample may be \
                 counted once; expected disjoint ranges",
                infos[i].path.display(),
                infos[j].path.display()
            ));
        }
    }
    let done: Vec<SampleRange> = ranges.iter().map(|(r, _)| *r).collect();
    let spp = first
        .spp
        .unwrap_or_else(|| done.last().map_or(0, |r| r.end));
    let missing = missing_ranges(&done, spp);
    if !missing.is_empty() {
        eprintln!(
            "warning: no part holds the samples {} of the {spp}-sample render; the image \
             has {} of {spp} samples per pixel (uniform plan)",
            format_ranges(&missing),
            done.iter().map(|r| r.len()).sum::<u32>()
        );
    }
    // Parts in the order of their first range: the sums are added in sample order.
    let mut order: Vec<usize> = Vec::new();
    for (_, i) in &ranges {
        if !order.contains(i) {
            order.push(*i);
        }
    }
    let mut total: Option<(
        prism_render::film::FilmSums,
        PartialHeader,
        Option<Vec<u32>>,
    )> = None;
    let mut plan_layers = Vec::new();
    let mut wall_time_s = 0.0;
    for &i in &order {
        let part = read_partial(&infos[i].path)?;
        wall_time_s += part.header.wall_time_s;
        match &mut total {
            None => {
                plan_layers = part.plan_layers;
                total = Some((part.sums, part.header, part.plan));
            }
            Some((sums, _, plan)) => {
                if *plan != part.plan {
                    return Err(format!(
                        "{}: its per-pixel sample plan differs from {}'s (same options, \
                         different plan: were they rendered by different versions?)",
                        part.path.display(),
                        first.path.display()
                    ));
                }
                sums.add(&part.sums)
                    .map_err(|e| format!("{}: {e}", part.path.display()))?;
            }
        }
    }
    let Some((sums, mut header, plan)) = total else {
        return Err("no parts to merge".into());
    };
    header.range = SampleRange {
        start: done.first().map_or(0, |r| r.start),
        end: done.last().map_or(0, |r| r.end),
    };
    header.ranges_done = done.clone();
    header.complete = missing.iter().all(|m| !header.range.overlaps(*m));
    header.items_done = 0;
    header.wall_time_s = wall_time_s;
    let film = Film::from_sums(&sums).map_err(|e| e.to_string())?;
    let mut image = film.finish();
    image.aovs.extend(plan_layers);
    let keep_sums = args
        .output
        .file_name()
        .is_some_and(|n| n.to_string_lossy().ends_with(".partial.exr"));
    if keep_sums {
        crate::partial::file::write_partial(&args.output, &image, &header, &sums, plan.as_deref())?;
    } else {
        let mut picture = crate::render::to_image(&image)?;
        let mut attributes = header_attributes(&header, &sums);
        // The plain image is not a partial file: it cannot be resumed or merged again.
        attributes.retain(|(k, _)| k != crate::partial::file::VERSION);
        attributes.push((COMPLETE.to_string(), missing.is_empty().to_string()));
        picture.metadata.extend(attributes);
        match &image.spectral {
            Some(bins) => prism_image::io::spectral_exr::write_exr_with_spectral_bands(
                &args.output,
                &picture,
                &bins.centres_nm,
                &bins.planes,
                &prism_image::io::exr::ExrWriteOptions::default(),
            ),
            None => prism_image::io::write_image(&args.output, &picture),
        }
        .map_err(|e| e.to_string())?;
    }
    let paths: Vec<&Path> = order.iter().map(|&i| infos[i].path.as_path()).collect();
    merge_sensors(&paths, &first.hash, &args.output, wall_time_s)?;
    eprintln!(
        "wrote {} ({} parts, samples {}, {:.2} s)",
        args.output.display(),
        order.len(),
        format_ranges(&done),
        start.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

/// The parts' sensor sums (`partial::sensor_sums`), when they have them: added in range
/// order into the readings of the whole measurement, `<output stem>.sensors.json/.csv`.
fn merge_sensors(
    parts: &[&Path],
    identity: &str,
    output: &Path,
    wall_time_s: f64,
) -> Result<(), String> {
    use crate::partial::sensor_sums::{read, sidecar_path};
    let sidecars: Vec<PathBuf> = parts.iter().map(|p| sidecar_path(p)).collect();
    let present = sidecars.iter().filter(|p| p.exists()).count();
    if present == 0 {
        return Ok(());
    }
    if present < sidecars.len() {
        let missing: Vec<String> = sidecars
            .iter()
            .filter(|p| !p.exists())
            .map(|p| p.display().to_string())
            .collect();
        eprintln!(
            "warning: the sensors are not merged: {} of {} parts have sensor sums ({} \
             missing)",
            present,
            sidecars.len(),
            missing.join(", ")
        );
        return Ok(());
    }
    let mut total: Option<Vec<prism_render::sensor::SensorSums>> = None;
    for path in &sidecars {
        let (hash, sums) = read(path)?;
        if hash != identity {
            return Err(format!(
                "{}: sensor sums of another render (identity {hash}, the parts' {identity})",
                path.display()
            ));
        }
        match &mut total {
            None => total = Some(sums),
            Some(total) => {
                if total.len() != sums.len() {
                    return Err(format!(
                        "{}: {} sensors; the first part has {}",
                        path.display(),
                        sums.len(),
                        total.len()
                    ));
                }
                for (a, b) in total.iter_mut().zip(&sums) {
                    a.add(b).map_err(|e| format!("{}: {e}", path.display()))?;
                }
            }
        }
    }
    let readings: Vec<prism_render::sensor::SensorReading> = total
        .unwrap_or_default()
        .iter()
        .map(|s| s.reading())
        .collect();
    let stats = prism_render::sensor::SensorStats {
        samples: readings
            .iter()
            .flat_map(|r| r.points.iter().map(|p| p.samples))
            .sum(),
        ..Default::default()
    };
    let (json_path, csv_path) = crate::sensors::sensor_paths(output);
    let value = crate::sensors::readings_json(parts[0], &readings, &stats, wall_time_s);
    let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())? + "\n";
    crate::atomic_write::write_atomic(&json_path, text.as_bytes(), "sensor readings")?;
    crate::atomic_write::write_atomic(
        &csv_path,
        crate::sensors::readings_csv(&readings).as_bytes(),
        "sensor readings",
    )?;
    eprintln!("wrote {} and {}", json_path.display(), csv_path.display());
    Ok(())
}
