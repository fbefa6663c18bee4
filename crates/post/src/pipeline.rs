//! File-to-file entry points for the CLI (`prism tonemap`, `prism compare`), which stays a
//! thin wrapper: parse arguments, call these, print the serialisable report.
//!
//! `tonemap_file` order: read → exposure (× 2^EV) → white balance
//! ([`crate::colour::apply_white_balance`] with the `--cat` transform, Bradford by default;
//! for `--wb scene` the white comes from
//! the file's `illumination` layer, [`scene_white_of`]) → tone operator (or, for `--op all`,
//! the contact sheet of every operator) → gamut mapping into the target
//! ([`crate::colour::map_gamut`], fraction outside reported) → write. An EXR output holds
//! linear display values of the target in [0, 1]; a PNG is encoded with the target's
//! transfer function.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use prism_spectrum::AdaptationMethod;
use rayon::prelude::*;
use serde::Serialize;

use crate::auto_exposure::{auto_exposure_ev, exposure_ev_from_sums, log_luminance_sums};
use crate::colour::scene_illumination::ILLUMINATION_CHANNELS;
use crate::colour::{
    apply_with_source_white, estimate_source_white_xyz, illumination_white_xyz, map_gamut,
    GamutMethod, GamutTarget, SceneWhite, WhiteBalance, ILLUMINATION_LAYER,
};
use crate::metrics::strips::{compare_rows, strip_rows};
use crate::metrics::tmqi::{check_size, hdr_luminance_of, ldr_luminance_of, tmqi_owned, Tmqi};
use crate::metrics::{CompareOptions, Comparison, ErrorMaps};
use crate::report::compare_page::{compare_page, map_figures, CompareInput};
use crate::report::embed::ReportImageRows;
use crate::report::write_report;
use crate::sheet::{
    contact_sheet_from, contact_sheet_scored, score_tmqi, SheetFailure, SheetOptions, SheetScore,
    TileOrder, TileScore,
};
use crate::tonemap::{ToneOperator, ToneParams, ToneReport};
use prism_image::image::luminance_weights;
use prism_image::io::strips::RowSource;
use prism_image::io::{read_dimensions, read_image, write_image, ImageFormat};
use prism_image::Image;
use prism_image::{ImageError, Result};

/// `--op NAME` or `--op all` (contact sheet).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OperatorChoice {
    One(ToneOperator),
    /// Every operator of [`ToneOperator::ALL`] on one labelled contact sheet.
    All,
}

impl OperatorChoice {
    /// `all` or an operator name (errors list the valid names).
    pub fn parse(name: &str) -> Result<Self> {
        if name.trim().eq_ignore_ascii_case("all") {
            Ok(Self::All)
        } else {
            ToneOperator::from_name(name.trim()).map(Self::One)
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::One(op) => op.name(),
            Self::All => "all",
        }
    }
}

impl From<ToneOperator> for OperatorChoice {
    fn from(op: ToneOperator) -> Self {
        Self::One(op)
    }
}

/// Peak bytes per pixel of [`tonemap_file`] with one operator, beyond 4 bytes per stored
/// channel of the input as decoded: the operator's output (12) and a local operator's
/// luminance planes, or after the input is dropped the encoder's buffers. Measured on
/// 8192² float RGB EXRs (tools/measure_memory.py, docs/reliability.md: 24 in all for the
/// global operators, 28 for durand02); the memory check's estimate.
pub const TONEMAP_BYTES_PER_PIXEL: u64 = 32;

/// Options of `prism tonemap` (CLI defaults in [`Default`]: `--wb none`, `--gamut clip`,
/// `--target srgb`, `--exposure 0`).
#[derive(Debug, Clone)]
pub struct TonemapOptions {
    pub operator: OperatorChoice,
    /// `--param key=value` (checked against the operator's `ParamSpec`s).
    pub params: BTreeMap<String, f64>,
    /// `--wb METHOD`.
    pub wb: WhiteBalance,
    /// `--cat bradford|cat16|cat02|von-kries`: the chromatic adaptation transform white
    /// balance uses (`AdaptationMethod::None` would make white balance a no-op: the CLI
    /// does not offer it).
    pub cat: AdaptationMethod,
    /// `--gamut METHOD`.
    pub gamut: GamutMethod,
    /// `--target srgb|p3|rec2020`: output primaries and, for PNG, transfer function.
    pub target: GamutTarget,
    /// `--exposure EV`: input × 2^EV before white balance.
    pub exposure_ev: f64,
    /// `--exposure auto`: `exposure_ev` is replaced by the EV that maps the log-average
    /// luminance to middle grey ([`auto_exposure_ev`]); the report gives the EV used.
    pub auto_exposure: bool,
    /// No `--exposure` was given: a photometric image (one with `prism:cd_m2_per_unit`)
    /// tone-mapped by an operator that is not absolute gets the auto exposure, as renders
    /// in cd/m² are otherwise black (an explicit `--exposure 0` keeps the scale).
    pub auto_exposure_if_photometric: bool,
    /// `--luminance-scale CD_M2`: cd/m² per unit, overriding `prism:cd_m2_per_unit`.
    pub luminance_scale_cd_m2: Option<f64>,
    /// `--score tmqi`: score the output (each tile of a sheet) against the HDR input as the
    /// operators see it (after exposure and white balance).
    pub score: Option<SheetScore>,
    /// `--sort score`: the sheet's tiles best first.
    pub order: TileOrder,
}

impl Default for TonemapOptions {
    fn default() -> Self {
        Self {
            operator: OperatorChoice::One(ToneOperator::Reinhard02),
            params: BTreeMap::new(),
            wb: WhiteBalance::None,
            cat: AdaptationMethod::Bradford,
            gamut: GamutMethod::Clip,
            target: GamutTarget::Srgb,
            exposure_ev: 0.0,
            auto_exposure: false,
            auto_exposure_if_photometric: false,
            luminance_scale_cd_m2: None,
            score: None,
            order: TileOrder::Catalogue,
        }
    }
}

/// Wall-clock milliseconds of each stage.
#[derive(Debug, Clone, Default, Serialize)]
pub struct TonemapTimings {
    pub read_ms: f64,
    pub exposure_white_balance_ms: f64,
    pub tone_ms: f64,
    pub gamut_ms: f64,
    pub write_ms: f64,
    pub total_ms: f64,
}

/// What `prism tonemap --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct TonemapFileReport {
    pub input: String,
    pub output: String,
    /// Output size (the sheet's for `--op all`).
    pub width: usize,
    pub height: usize,
    /// `NAME` or `all`.
    pub operator: &'static str,
    pub params: BTreeMap<String, f64>,
    /// The exposure applied (computed when `auto_exposure`).
    pub exposure_ev: f64,
    pub auto_exposure: bool,
    /// The auto exposure was chosen because the image is photometric and no exposure was
    /// given (`TonemapOptions::auto_exposure_if_photometric`).
    pub auto_exposure_photometric: bool,
    pub luminance_scale_cd_m2: Option<f64>,
    pub white_balance: String,
    /// The chromatic adaptation transform of the white balance (`--cat`).
    pub chromatic_adaptation: &'static str,
    /// Estimated scene white (CIE 1931 xy) when white balance ran.
    pub white_balance_source_xy: Option<[f64; 2]>,
    pub gamut_method: &'static str,
    pub target: &'static str,
    /// One report per operator that ran (one, or every operator of the sheet).
    pub tone: Vec<ToneReport>,
    /// Sheet operators that produced no tile (e.g. absolute ones without a scale).
    pub failures: Vec<SheetFailure>,
    /// Input pixels with a NaN/∞ component (reported, mapped as black).
    pub non_finite_pixels: u64,
    /// `--score`: which score, and one entry per scored operator in the sheet's tile order.
    pub score: Option<SheetScore>,
    pub scores: Vec<TileScore>,
    /// Finite input pixels that the exposure scale 2^EV made infinite (mapped as black).
    pub exposure_overflow_pixels: u64,
    /// Fraction of pixels outside the target gamut before gamut mapping.
    pub gamut_fraction_outside: f64,
    pub timings: TonemapTimings,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Tone-maps `input` into `output` (formats from the extensions); see the module text for
/// the order of stages. Errors name the file or the option at fault; nothing panics on
/// user input.
pub fn tonemap_file(
    input: &Path,
    output: &Path,
    options: &TonemapOptions,
) -> Result<TonemapFileReport> {
    let start = Instant::now();
    let t = Instant::now();
    let image = read_image(input)?;
    let read_ms = ms(t);
    let reread = || read_image(input);
    let (out, mut report) = tonemap_image_from(image, input, options, Some(&reread))?;
    let t = Instant::now();
    write_image(output, &out)?;
    report.output = output.display().to_string();
    report.timings.read_ms = read_ms;
    report.timings.write_ms = ms(t);
    report.timings.total_ms = ms(start);
    Ok(report)
}

/// The stages of [`tonemap_file`] between reading and writing, on an image in memory (the
/// Python package's `prism.tonemap`): returns the display image (linear values of the
/// target in [0, 1]) and the report, whose `output` is empty and whose read and write
/// times are 0. `input` names the image in messages and in the report.
pub fn tonemap_image(
    image: Image,
    input: &Path,
    options: &TonemapOptions,
) -> Result<(Image, TonemapFileReport)> {
    tonemap_image_from(image, input, options, None)
}

/// [`tonemap_image`] with a way to read the input again: the contact sheet (`--op all`)
/// then gives each operator a fresh copy (exposed and white-balanced as the first) instead
/// of keeping the input beside each output (docs/reliability.md).
pub fn tonemap_image_from(
    mut image: Image,
    input: &Path,
    options: &TonemapOptions,
    reread: Option<&dyn Fn() -> Result<Image>>,
) -> Result<(Image, TonemapFileReport)> {
    let start = Instant::now();
    let t = Instant::now();
    if !options.exposure_ev.is_finite() {
        return Err(ImageError::invalid(format!(
            "--exposure {}: expected a finite number of stops",
            options.exposure_ev
        )));
    }
    let photometric_auto = options.auto_exposure_if_photometric
        && !options.auto_exposure
        && image.cd_m2_per_unit.is_some()
        && match options.operator {
            OperatorChoice::One(op) => !op.info().absolute,
            // The sheet holds absolute operators, which read the scale themselves.
            OperatorChoice::All => false,
        };
    let auto_exposure = options.auto_exposure || photometric_auto;
    let non_finite_input = image
        .pixels()
        .par_iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count() as u64;
    let exposure_ev = if auto_exposure {
        auto_exposure_ev(&image).ok_or_else(|| {
            ImageError::format(
                input,
                "--exposure auto: no pixel has a positive finite luminance (black image)",
            )
        })?
    } else {
        options.exposure_ev
    };
    // The scale of a non-zero exposure (0 stops leaves the pixels untouched).
    let exposure_factor = (exposure_ev != 0.0).then(|| 2f64.powf(exposure_ev) as f32);
    let mut exposure_overflow_pixels = 0;
    if let Some(factor) = exposure_factor {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(ImageError::invalid(format!(
                "--exposure {exposure_ev}: the scale 2^{exposure_ev} is outside the range of \
                 32-bit floats; expected an exposure between -149 and 127 stops"
            )));
        }
        exposure_overflow_pixels = expose(&mut image, factor);
    }
    let space = image.color_space.clone();
    let source_white = match &options.wb {
        WhiteBalance::None => None,
        WhiteBalance::Scene => Some(scene_white_of(&image, input)?),
        method => Some(
            estimate_source_white_xyz(image.pixels(), &space, method)
                .map_err(|e| ImageError::format(input, e.to_string()))?,
        ),
    };
    let wb_source_xy = source_white.map(|white| {
        apply_with_source_white(image.pixels_mut(), &space, &options.wb, white, options.cat)
            .source_white_xy
    });
    // The contact sheet's fresh copies of the input, prepared as `image` was.
    let prepared_again = |read: &dyn Fn() -> Result<Image>| -> Result<Image> {
        let mut again = read()?;
        if let Some(factor) = exposure_factor {
            expose(&mut again, factor);
        }
        if let Some(white) = source_white {
            let space = again.color_space.clone();
            apply_with_source_white(again.pixels_mut(), &space, &options.wb, white, options.cat);
        }
        Ok(again)
    };
    let exposure_white_balance_ms = ms(t);

    let params = ToneParams {
        exposure_ev: 0.0,
        luminance_scale_cd_m2: options.luminance_scale_cd_m2,
        values: options.params.clone(),
    };
    let in_file = |e: ImageError| match e {
        ImageError::Invalid(m) => ImageError::format(input, m),
        other => other,
    };
    let t = Instant::now();
    let sheet_options = SheetOptions {
        target: options.target,
        gamut: options.gamut,
        score: options.score,
        order: options.order,
    };
    // The input is not read after the operator: one operator maps it in place (no second
    // image), and otherwise its memory goes back before the gamut mapping and the
    // encoder's buffers are allocated (docs/reliability.md).
    let (mut out, tone, failures, sheet_outside, scores) = match (options.operator, options.score) {
        (OperatorChoice::One(op), None) => {
            let result = op.apply_in_place(image, &params).map_err(in_file)?;
            (
                result.image,
                vec![result.report],
                Vec::new(),
                None,
                Vec::new(),
            )
        }
        (OperatorChoice::One(op), Some(SheetScore::Tmqi)) => {
            check_size(image.width(), image.height()).map_err(in_file)?;
            let result = op.apply(&image, &params).map_err(in_file)?;
            let scores = vec![TileScore {
                operator: op.name(),
                tmqi: score_tmqi(&result.image, &image, &sheet_options).map_err(in_file)?,
            }];
            drop(image);
            (result.image, vec![result.report], Vec::new(), None, scores)
        }
        (OperatorChoice::All, _) => {
            let sheet = match reread {
                Some(read) => contact_sheet_from(
                    image,
                    || prepared_again(read),
                    &ToneOperator::ALL,
                    &params,
                    &sheet_options,
                ),
                None => contact_sheet_scored(&image, &ToneOperator::ALL, &params, &sheet_options),
            }
            .map_err(in_file)?;
            (
                sheet.image,
                sheet.reports,
                sheet.failures,
                Some(sheet.gamut_fraction_outside),
                sheet.scores,
            )
        }
    };
    let tone_ms = ms(t);

    let t = Instant::now();
    let out_space = out.color_space.clone();
    let gamut = map_gamut(out.pixels_mut(), &out_space, options.target, options.gamut);
    out.color_space = options.target.space();
    let gamut_ms = ms(t);

    let report = TonemapFileReport {
        input: input.display().to_string(),
        output: String::new(),
        width: out.width(),
        height: out.height(),
        operator: options.operator.name(),
        params: options.params.clone(),
        exposure_ev,
        auto_exposure,
        auto_exposure_photometric: photometric_auto,
        luminance_scale_cd_m2: options.luminance_scale_cd_m2,
        white_balance: options.wb.name(),
        chromatic_adaptation: options.cat.name(),
        white_balance_source_xy: wb_source_xy,
        gamut_method: options.gamut.name(),
        target: options.target.name(),
        non_finite_pixels: non_finite_input,
        exposure_overflow_pixels,
        tone,
        score: options.score,
        scores,
        failures,
        gamut_fraction_outside: sheet_outside.unwrap_or(gamut.fraction_outside),
        timings: TonemapTimings {
            read_ms: 0.0,
            exposure_white_balance_ms,
            tone_ms,
            gamut_ms,
            write_ms: 0.0,
            total_ms: ms(start),
        },
    };
    Ok((out, report))
}

/// Scales `image` by `factor` (an exposure); returns the pixels that were finite before
/// and are not after (overflow).
fn expose(image: &mut Image, factor: f32) -> u64 {
    image
        .pixels_mut()
        .par_iter_mut()
        .map(|p| {
            let finite = p.iter().all(|c| c.is_finite());
            *p = p.map(|c| c * factor);
            u64::from(finite && !p.iter().all(|c| c.is_finite()))
        })
        .sum()
}

/// The scene white for `--wb scene`: the luminance-weighted mean chromaticity of the
/// `illumination.X/Y/Z` layer of `image` (read from `path`, which errors name).
pub fn scene_white_of(image: &Image, path: &Path) -> Result<SceneWhite> {
    let missing = |found: String| {
        ImageError::format(
            path,
            format!(
                "`--wb scene` needs the `{ILLUMINATION_LAYER}` layer (channels \
                 {ILLUMINATION_LAYER}.X, {ILLUMINATION_LAYER}.Y, {ILLUMINATION_LAYER}.Z), \
                 {found}; `prism render` writes it into its EXR outputs"
            ),
        )
    };
    let Some(layer) = image.layer(ILLUMINATION_LAYER) else {
        let names: Vec<&str> = image.layers().iter().map(|l| l.name.as_str()).collect();
        return Err(missing(if names.is_empty() {
            "and this file has no layers".to_string()
        } else {
            format!("which this file lacks (its layers: {})", names.join(", "))
        }));
    };
    let position = |c: &str| layer.channels.iter().position(|x| x == c);
    let [Some(x), Some(y), Some(z)] = ILLUMINATION_CHANNELS.map(position) else {
        return Err(missing(format!(
            "but this file's layer has channels {}",
            layer.channels.join(", ")
        )));
    };
    let k = layer.channels.len();
    let xyz: Vec<[f32; 3]> = layer
        .samples
        .chunks_exact(k)
        .map(|p| [p[x], p[y], p[z]])
        .collect();
    illumination_white_xyz(&xyz).map_err(|e| ImageError::format(path, e.to_string()))
}

/// Compares the image at `test` with the reference at `reference`; mismatched sizes are an
/// error naming both files.
pub fn compare_files(test: &Path, reference: &Path) -> Result<Comparison> {
    compare_files_with(test, reference, &CompareOptions::default()).map(|(c, _)| c)
}

/// TMQI of the tone-mapped image at `ldr` (PNG) against its HDR source at `hdr` (EXR or
/// Radiance HDR); any other pairing is an error naming the files.
pub fn tmqi_files(ldr: &Path, hdr: &Path) -> Result<Tmqi> {
    let (ldr_format, hdr_format) = (ImageFormat::from_path(ldr)?, ImageFormat::from_path(hdr)?);
    let ldr_ok = match ldr_format {
        ImageFormat::Png => true,
        ImageFormat::Exr | ImageFormat::Hdr => false,
    };
    let hdr_ok = match hdr_format {
        ImageFormat::Exr | ImageFormat::Hdr => true,
        ImageFormat::Png => false,
    };
    if !(ldr_ok && hdr_ok) {
        return Err(ImageError::invalid(format!(
            "--tmqi compares a tone-mapped LDR image (PNG) with its HDR source (EXR or HDR): \
             got {} and {}",
            ldr.display(),
            hdr.display()
        )));
    }
    // The tone-mapped image is decoded into its luminance (8 bytes per pixel) and
    // dropped, then the HDR source is read in bands into its own: the two images never
    // exist whole at once.
    let source_size = read_dimensions(hdr)?;
    let (w, h) = (source_size.width, source_size.height);
    let image = read_image(ldr)?;
    check_sizes((ldr, (image.width(), image.height())), (hdr, (w, h)))?;
    check_size(w, h)?;
    let ldr_y = ldr_luminance_of(image.pixels(), &image.color_space);
    drop(image);
    let source = RowSource::open(hdr)?;
    let mut hdr_y = Vec::with_capacity(w * h);
    source.for_each_band(strip_rows(w), |rows| {
        hdr_y.extend(hdr_luminance_of(rows, source.color_space()));
        Ok(())
    })?;
    drop(source);
    tmqi_owned(ldr_y, hdr_y, w, h)
}

/// [`compare_files`] with a choice of metrics, and the maps asked for. The images are read
/// in strips where their format allows (`metrics::strips`: the whole-image numbers, in
/// bounded memory).
pub fn compare_files_with(
    test: &Path,
    reference: &Path,
    options: &CompareOptions,
) -> Result<(Comparison, ErrorMaps)> {
    let (a, b) = open_pair(test, reference)?;
    compare_rows(&a, &b, options, strip_rows(b.width()))
}

/// Row sources of `test` and `reference`; an error naming both when their sizes differ.
fn open_pair(test: &Path, reference: &Path) -> Result<(RowSource, RowSource)> {
    let a = RowSource::open(test)?;
    let b = RowSource::open(reference)?;
    check_sizes(
        (test, (a.width(), a.height())),
        (reference, (b.width(), b.height())),
    )?;
    Ok((a, b))
}

/// An error naming both files when their sizes differ.
fn check_sizes(
    (test, a): (&Path, (usize, usize)),
    (reference, b): (&Path, (usize, usize)),
) -> Result<()> {
    if a != b {
        return Err(ImageError::invalid(format!(
            "{} is {}×{} but {} is {}×{}: compare needs equal sizes",
            test.display(),
            a.0,
            a.1,
            reference.display(),
            b.0,
            b.1
        )));
    }
    Ok(())
}

/// [`compare_files_with`] (FLIP and the ΔE2000 map always computed) that also writes the
/// HTML report of the comparison to `report` (report/compare_page.rs), atomically. EXR and
/// HDR inputs are shown scene-referred (with an exposure control), PNGs as they are. EXRs
/// are read in strips for the metrics and again for the page, whose images are compressed
/// band by band: what stays whole is the maps and the compressed PNGs.
pub fn compare_files_report(
    test: &Path,
    reference: &Path,
    options: &CompareOptions,
    report: &Path,
) -> Result<(Comparison, ErrorMaps)> {
    let (a, b) = open_pair(test, reference)?;
    let options = CompareOptions {
        flip_ppd: Some(
            options
                .flip_ppd
                .unwrap_or(crate::metrics::flip::DEFAULT_PPD),
        ),
        delta_e2000_map: true,
        ..*options
    };
    let band = strip_rows(b.width());
    let (comparison, maps) = compare_rows(&a, &b, &options, band)?;
    let scene_referred = |path: &Path| match ImageFormat::from_path(path) {
        Ok(ImageFormat::Exr | ImageFormat::Hdr) => true,
        Ok(ImageFormat::Png) | Err(_) => false,
    };
    let hdr = scene_referred(test) || scene_referred(reference);
    let figures = map_figures(&maps, comparison.width, comparison.height, hdr)?;
    let label = |path: &Path| {
        path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    };
    // Each input is read once more, band by band, into its compressed image; the
    // reference's bands also give the exposure the viewer starts at (where `--exposure
    // auto` would put it).
    let weights = luminance_weights(b.color_space());
    let (mut sum_ln, mut count) = (0.0, 0);
    let mut input = |path: &Path, source: &RowSource, meter: bool| -> Result<CompareInput> {
        let scene = scene_referred(path);
        let (w, h) = (source.width(), source.height());
        let mut rows = if scene {
            ReportImageRows::radiance(w, h)?
        } else {
            ReportImageRows::display(w, h)?
        };
        source.for_each_band(band, |pixels| {
            if meter {
                let (s, n) = log_luminance_sums(pixels, weights);
                sum_ln += s;
                count += n;
            }
            rows.push(pixels, source.color_space())
        })?;
        Ok(CompareInput {
            label: label(path),
            image: rows.finish()?,
            scene_referred: scene,
        })
    };
    let test_input = input(test, &a, false)?;
    let reference_input = input(reference, &b, hdr)?;
    let reference_exposure_ev = if hdr {
        exposure_ev_from_sums(sum_ln, count)
    } else {
        None
    };
    drop((a, b));
    let page = compare_page(
        test_input,
        reference_input,
        reference_exposure_ev,
        &comparison,
        figures,
    );
    write_report(report, &page)?;
    Ok((comparison, maps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::rgb_space::RgbColorSpace;

    /// A contact sheet whose operators each get a fresh copy of the input, exposed and
    /// white-balanced again (`prism tonemap` reads the file again), is bit for bit the sheet
    /// of one prepared image kept in memory, TMQI scores included.
    #[test]
    fn a_sheet_from_fresh_copies_is_the_sheet_of_the_kept_image() {
        let (w, h) = (200, 180);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                [
                    0.2 + 3.0 * x * y,
                    0.5 + (7.0 * x).sin().abs(),
                    0.1 + 10.0 * y * y,
                ]
            })
            .collect();
        let image = Image::new(w, h, pixels, RgbColorSpace::srgb()).unwrap();
        let options = TonemapOptions {
            operator: OperatorChoice::All,
            wb: WhiteBalance::GreyWorld,
            exposure_ev: 1.5,
            luminance_scale_cd_m2: Some(100.0),
            score: Some(SheetScore::Tmqi),
            ..TonemapOptions::default()
        };
        let path = Path::new("memory.exr");
        let (kept, kept_report) = tonemap_image(image.clone(), path, &options).unwrap();
        let reads = std::cell::Cell::new(0);
        let read = || {
            reads.set(reads.get() + 1);
            Ok(image.clone())
        };
        let (fresh, fresh_report) =
            tonemap_image_from(image.clone(), path, &options, Some(&read)).unwrap();
        assert_eq!(reads.get(), ToneOperator::ALL.len() - 1);
        assert_eq!(fresh.pixels(), kept.pixels());
        assert_eq!(fresh_report.scores, kept_report.scores);
        assert_eq!(fresh_report.scores.len(), ToneOperator::ALL.len());
        assert!(fresh_report.failures.is_empty());
    }
}
