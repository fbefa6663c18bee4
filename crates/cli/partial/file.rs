//! Partial images: an EXR that is both a picture (R, G, B and the usual layers, the film
//! normalised so far) and the exact state of the film, so a render can continue from it
//! (`--resume`) and parts can be added (`prism merge`).
//!
//! The film's sums are exact 128-bit fixed-point integers (`prism_render::film::FixedSum`,
//! units of 2⁻⁶⁰). EXR has no 64-bit channel, and float32 pairs would keep only 48 bits, so
//! each sum is stored as four 32-bit words of its two's complement in `UINT` channels
//! `sums.<plane>.w3` (most significant) … `.w0`, which OpenEXR keeps bit for bit. Counts are `counts.<plane>`,
//! a per-pixel plan's sample counts `counts.plan`. The header (text attributes) holds the
//! render's identity (`identity.rs`), the sample range, the ranges done, whether the
//! range is complete, the work items done (for resuming) and the time spent.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::UVec2;
use prism_image::io::exr::ExrWriteOptions;
use prism_image::io::raw_exr::{read_raw_channels, write_exr_with_raw};
use prism_render::film::{CountPlane, FilmSums, FixedSum, SumPlane};
use prism_render::{AovSelection, FilmImage, SpectralBins};

use super::range::{format_ranges, parse_range, parse_ranges, SampleRange};

/// The format `prism:partial` names: 2 since the sums are fixed point.
pub const FORMAT_VERSION: &str = "2";

/// Header attributes.
pub const VERSION: &str = "prism:partial";
pub const RANGE: &str = "prism:samples";
pub const RANGES_DONE: &str = "prism:ranges_done";
pub const COMPLETE: &str = "prism:complete";
pub const ITEMS_DONE: &str = "prism:items_done";
pub const WALL_TIME: &str = "prism:wall_time_s";
pub const AOVS: &str = "prism:film.aovs";
pub const BINS: &str = "prism:film.spectral_bins";
pub const LIGHT_PATHS: &str = "prism:film.light_paths";

/// What a partial file says about itself.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialHeader {
    /// `prism:identity` and its fields.
    pub identity_hash: String,
    pub identity: Vec<(String, String)>,
    /// The range this file's samples were taken from (a merge: the span of its parts).
    pub range: SampleRange,
    /// The ranges whose samples the file holds in full, sorted.
    pub ranges_done: Vec<SampleRange>,
    /// Every sample of `range` is in the file.
    pub complete: bool,
    /// Work items of the render pass in the film (what a resume continues from).
    pub items_done: usize,
    /// Seconds spent on the samples held, over every run that contributed.
    pub wall_time_s: f64,
}

/// A partial file read back.
pub struct PartialFile {
    pub path: PathBuf,
    pub header: PartialHeader,
    pub sums: FilmSums,
    /// Per-pixel samples of the whole render (`--plan predicted`), row-major.
    pub plan: Option<Vec<u32>>,
    /// The predictor's layers (`bandwidth.*`, `plan.*`): the same in every part, as every
    /// process computes the same plan.
    pub plan_layers: Vec<prism_render::AovPlane>,
}

/// `<stem>.partial.exr` beside `output` (`long.exr` → `long.partial.exr`).
pub fn checkpoint_path(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    output.with_file_name(format!("{stem}.partial.exr"))
}

fn aov_names(sel: AovSelection) -> String {
    let mut names = Vec::new();
    for (on, name) in [
        (sel.depth, "depth"),
        (sel.normal, "normal"),
        (sel.albedo, "albedo"),
        (sel.illumination, "illumination"),
        (sel.variance, "variance"),
    ] {
        if on {
            names.push(name);
        }
    }
    names.join(",")
}

fn parse_aovs(path: &Path, s: &str) -> Result<AovSelection, String> {
    let mut sel = AovSelection::NONE;
    for name in s.split(',').filter(|t| !t.is_empty()) {
        match name {
            "depth" => sel.depth = true,
            "normal" => sel.normal = true,
            "albedo" => sel.albedo = true,
            "illumination" => sel.illumination = true,
            "variance" => sel.variance = true,
            other => {
                return Err(format!(
                    "{}: header {AOVS}: unknown AOV `{other}` (expected depth, normal, albedo, \
                     illumination, variance)",
                    path.display()
                ))
            }
        }
    }
    Ok(sel)
}

/// Header text attributes of a partial file (beside the identity's).
pub fn header_attributes(header: &PartialHeader, sums: &FilmSums) -> Vec<(String, String)> {
    let mut out = vec![
        (VERSION.to_string(), FORMAT_VERSION.to_string()),
        (RANGE.to_string(), header.range.to_string()),
        (RANGES_DONE.to_string(), format_ranges(&header.ranges_done)),
        (COMPLETE.to_string(), header.complete.to_string()),
        (ITEMS_DONE.to_string(), header.items_done.to_string()),
        (WALL_TIME.to_string(), format!("{}", header.wall_time_s)),
        (AOVS.to_string(), aov_names(sums.aov_selection)),
        (
            BINS.to_string(),
            sums.spectral_bins.map_or(0, |b| b.count()).to_string(),
        ),
        (
            LIGHT_PATHS.to_string(),
            sums.light_paths
                .map_or_else(|| "none".to_string(), |n| n.to_string()),
        ),
    ];
    out.push((
        super::identity::HASH_ATTRIBUTE.to_string(),
        header.identity_hash.clone(),
    ));
    let prefix = super::identity::HASH_ATTRIBUTE;
    out.extend(
        header
            .identity
            .iter()
            .map(|(k, v)| (format!("{prefix}.{k}"), v.clone())),
    );
    out
}

/// The raw channels of `sums` and a plan.
pub fn raw_channels(sums: &FilmSums, plan: Option<&[u32]>) -> Vec<(String, Vec<u32>)> {
    let mut raw = Vec::new();
    for SumPlane { name, values } in &sums.sums {
        for word in (0..4).rev() {
            raw.push((
                format!("sums.{name}.w{word}"),
                values
                    .iter()
                    .map(|v| (v.to_bits() as u128 >> (32 * word)) as u32)
                    .collect(),
            ));
        }
    }
    for CountPlane { name, values } in &sums.counts {
        raw.push((format!("counts.{name}"), values.clone()));
    }
    if let Some(plan) = plan {
        raw.push(("counts.plan".to_string(), plan.to_vec()));
    }
    raw
}

/// Writes `image` (the film normalised) with the sums and header, atomically.
pub fn write_partial(
    path: &Path,
    image: &FilmImage,
    header: &PartialHeader,
    sums: &FilmSums,
    plan: Option<&[u32]>,
) -> Result<(), String> {
    let mut picture = crate::render::to_image(image)?;
    picture.metadata.extend(header_attributes(header, sums));
    let raw = raw_channels(sums, plan);
    let spectral = image
        .spectral
        .as_ref()
        .map(|s| (s.centres_nm.as_slice(), s.planes.as_slice()));
    write_exr_with_raw(path, &picture, spectral, raw, &ExrWriteOptions::default())
        .map_err(|e| format!("cannot write the partial image {}: {e}", path.display()))
}

/// Reads a partial file; errors name the file and what is missing or malformed.
pub fn read_partial(path: &Path) -> Result<PartialFile, String> {
    let mut file = read_raw_channels(path).map_err(|e| e.to_string())?;
    let text = &file.text;
    let get = |key: &str| -> Result<&String, String> {
        text.get(key).ok_or_else(|| {
            format!(
                "{}: not a partial image of `prism render` (no header attribute {key}; \
                 expected a file written with --samples or --checkpoint-every)",
                path.display()
            )
        })
    };
    let version = get(VERSION)?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "{}: partial image version {version}; this prism reads version {FORMAT_VERSION} \
             (version 1 held f64 sums, which do not merge exactly: render the part again)",
            path.display()
        ));
    }
    let bad = |key: &str, e: String| format!("{}: header {key}: {e}", path.display());
    let range = parse_range(get(RANGE)?).map_err(|e| bad(RANGE, e))?;
    let mut ranges_done = parse_ranges(get(RANGES_DONE)?).map_err(|e| bad(RANGES_DONE, e))?;
    ranges_done.sort();
    let complete = match get(COMPLETE)?.as_str() {
        "true" => true,
        "false" => false,
        other => return Err(bad(COMPLETE, format!("`{other}`: expected true or false"))),
    };
    let items_done = get(ITEMS_DONE)?
        .parse::<usize>()
        .map_err(|e| bad(ITEMS_DONE, e.to_string()))?;
    let wall_time_s = get(WALL_TIME)?
        .parse::<f64>()
        .map_err(|e| bad(WALL_TIME, e.to_string()))?;
    let aov_selection = parse_aovs(path, get(AOVS)?)?;
    let bins = get(BINS)?
        .parse::<u32>()
        .map_err(|e| bad(BINS, e.to_string()))?;
    let spectral_bins = if bins == 0 {
        None
    } else {
        Some(SpectralBins::new(bins).map_err(|e| bad(BINS, e.to_string()))?)
    };
    let light_paths = match get(LIGHT_PATHS)?.as_str() {
        "none" => None,
        n => Some(
            n.parse::<u64>()
                .map_err(|e| bad(LIGHT_PATHS, e.to_string()))?,
        ),
    };
    let identity_hash = get(super::identity::HASH_ATTRIBUTE)?.clone();
    let identity = super::identity::RenderIdentity::from_attributes(text);
    let resolution = UVec2::new(file.width as u32, file.height as u32);
    let (sums, plan) = sums_from_raw(
        path,
        resolution,
        aov_selection,
        spectral_bins,
        light_paths,
        // Taken: each plane's words are freed as its sums are made (a 4K part's words and
        // sums are 2.3 GB each).
        std::mem::take(&mut file.raw),
    )?;
    Ok(PartialFile {
        path: path.to_path_buf(),
        header: PartialHeader {
            identity_hash,
            identity,
            range,
            ranges_done,
            complete,
            items_done,
            wall_time_s,
        },
        sums,
        plan,
        plan_layers: file
            .floats
            .iter()
            .filter(|(k, _)| k.starts_with("bandwidth.") || k.starts_with("plan."))
            .map(|(k, v)| prism_render::AovPlane {
                name: k.clone(),
                values: v.clone(),
            })
            .collect(),
    })
}

fn sums_from_raw(
    path: &Path,
    resolution: UVec2,
    aov_selection: AovSelection,
    spectral_bins: Option<SpectralBins>,
    light_paths: Option<u64>,
    mut raw: BTreeMap<String, Vec<u32>>,
) -> Result<(FilmSums, Option<Vec<u32>>), String> {
    // The planes a film of this configuration has, in its order.
    let template =
        prism_render::Film::new(resolution, prism_render::Filter::default(), aov_selection)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    let template = match spectral_bins {
        Some(b) => template.with_bins(b),
        None => template,
    };
    let mut layout = template.sums();
    if light_paths.is_some() {
        let mut with_light = template;
        let _ = with_light.light_splats();
        layout = with_light.sums();
    }
    let mut channel = |name: String| -> Result<Vec<u32>, String> {
        raw.remove(&name).ok_or_else(|| {
            format!(
                "{}: the channel {name} is missing (expected the sums of a film with AOVs \
                 [{}] and {} spectral bins)",
                path.display(),
                aov_names(aov_selection),
                spectral_bins.map_or(0, |b| b.count())
            )
        })
    };
    let mut sums = Vec::new();
    for plane in &layout.sums {
        let words = (0..4)
            .map(|w| channel(format!("sums.{}.w{w}", plane.name)))
            .collect::<Result<Vec<_>, _>>()?;
        sums.push(SumPlane {
            name: plane.name.clone(),
            values: (0..words[0].len())
                .map(|i| {
                    let bits = words.iter().enumerate().fold(0u128, |b, (w, plane)| {
                        b | (u128::from(plane[i]) << (32 * w))
                    });
                    FixedSum::from_bits(bits as i128)
                })
                .collect(),
        });
    }
    let mut counts = Vec::new();
    for plane in &layout.counts {
        counts.push(CountPlane {
            name: plane.name.clone(),
            values: channel(format!("counts.{}", plane.name))?,
        });
    }
    let sums = FilmSums {
        resolution,
        aov_selection,
        spectral_bins,
        sums,
        counts,
        light_paths,
    };
    sums.check()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((sums, raw.remove("counts.plan")))
}
