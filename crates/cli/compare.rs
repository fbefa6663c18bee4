//! `prism compare A B [--json] [--ppd X] [--error-map OUT.png]`: error metrics of image A
//! against the reference B, FLIP included; `prism compare LDR.png HDR.exr --tmqi`: TMQI of
//! a tone-mapped image against its HDR source (docs/post.md).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use prism_cpu::memory::MemoryBudget;
use prism_image::io::strips::RowSource;
use prism_image::io::{read_dimensions, write_image, ImageDimensions, ImageFormat};
use prism_post::metrics::flip::DEFAULT_PPD;
use prism_post::metrics::strips::strip_compare_bytes;
use prism_post::metrics::tmqi::{Tmqi, TMQI_BYTES_PER_PIXEL};
use prism_post::metrics::{CompareOptions, Comparison, FlipMaps};
use prism_post::pipeline::{compare_files_report, compare_files_with, tmqi_files};

/// Which FLIP map `--error-map` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ErrorMapKind {
    Ldr,
    Hdr,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test (EXR, HDR or PNG).
    pub test: PathBuf,
    /// The reference image (same size); relMSE, PSNR peak, ΔE2000 white and HDR-FLIP's
    /// exposure range come from it.
    pub reference: PathBuf,
    /// Print one JSON object (mse, rmse, relmse, psnr_db, ssim, delta_e2000_mean,
    /// delta_e2000_p95, per_channel, ldr_flip_mean, ldr_flip_p95, hdr_flip_mean,
    /// hdr_flip_p95, …) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// FLIP's viewing condition in pixels per degree (default: flip-evaluator's, a 0.7 m
    /// wide 3840-pixel display at 0.7 m, 67.02).
    #[arg(long, default_value_t = DEFAULT_PPD, allow_negative_numbers = true)]
    pub ppd: f64,
    /// Write the FLIP error map in magma with a legend (PNG).
    #[arg(long, value_name = "OUT.png")]
    pub error_map: Option<PathBuf>,
    /// The map `--error-map` writes: default HDR-FLIP when either input is EXR or HDR,
    /// LDR-FLIP for two PNGs.
    #[arg(long, value_enum, requires = "error_map")]
    pub error_map_kind: Option<ErrorMapKind>,
    /// Write a self-contained HTML page (images embedded, no network): A and B in a
    /// viewer that flips, splits and zooms (with an exposure control for EXR/HDR), the
    /// FLIP and ΔE2000 maps with legends, and the metric table.
    #[arg(long, value_name = "OUT.html")]
    pub report: Option<PathBuf>,
    /// TMQI (Yeganeh & Wang 2013) of A, a tone-mapped PNG, against B, its HDR source (EXR
    /// or HDR), instead of the error metrics: tmqi, tmqi_structural_fidelity,
    /// tmqi_naturalness.
    #[arg(long, conflicts_with_all = ["error_map", "error_map_kind", "report"])]
    pub tmqi: bool,
    #[command(flatten)]
    pub simd: crate::simd::SimdArgs,
}

/// PSNR with three decimals, or ±∞ (identical images; a black reference).
fn psnr_text(db: f64) -> String {
    if db == f64::INFINITY {
        "+∞".to_string()
    } else if db == f64::NEG_INFINITY {
        "−∞".to_string()
    } else {
        format!("{db:.3}")
    }
}

fn print_table(c: &Comparison) {
    let row3 = |name: &str, v: [f64; 3]| {
        println!("{name:<18}{:>14.6e}{:>14.6e}{:>14.6e}", v[0], v[1], v[2]);
    };
    println!("{:<18}{} × {} px", "size", c.width, c.height);
    println!("{:<18}{:>14.6e}", "MSE", c.mse);
    println!("{:<18}{:>14.6e}", "RMSE", c.rmse);
    println!("{:<18}{:>14.6e}", "relMSE", c.relmse);
    println!("{:<18}{:>14} dB", "PSNR", psnr_text(c.psnr_db));
    match c.ssim {
        Some(s) => println!("{:<18}{s:>14.6}", "SSIM"),
        None => println!("{:<18}{:>14}", "SSIM", "n/a (< 11×11)"),
    }
    println!("{:<18}{:>14.4}", "ΔE2000 mean", c.delta_e2000_mean);
    println!("{:<18}{:>14.4}", "ΔE2000 p95", c.delta_e2000_p95);
    if let Some(f) = &c.flip {
        println!("{:<18}{:>14.6}", "LDR-FLIP mean", f.ldr_flip_mean);
        println!("{:<18}{:>14.6}", "LDR-FLIP p95", f.ldr_flip_p95);
        println!("{:<18}{:>14.6}", "HDR-FLIP mean", f.hdr_flip_mean);
        println!("{:<18}{:>14.6}", "HDR-FLIP p95", f.hdr_flip_p95);
        let e = &f.hdr_flip_exposures;
        println!(
            "{:<18}{:>14}",
            "HDR-FLIP stops",
            format!("{:.2} … {:.2} ({})", e.start_stops, e.stop_stops, e.count)
        );
        println!("{:<18}{:>14.2}", "FLIP px/degree", f.flip_ppd);
        if f.hdr_flip_negative_samples > 0 {
            println!(
                "{:<18}{:>14}",
                "negative samples", f.hdr_flip_negative_samples
            );
        }
    }
    println!("{:<18}{:>14}{:>14}{:>14}", "per channel", "R", "G", "B");
    row3("  MSE", c.per_channel.mse);
    row3("  RMSE", c.per_channel.rmse);
    row3("  relMSE", c.per_channel.relmse);
    let p = c.per_channel.psnr_db.map(psnr_text);
    println!("{:<18}{:>14}{:>14}{:>14}", "  PSNR (dB)", p[0], p[1], p[2]);
    if let Some(note) = c.psnr_note {
        println!("{:<18}{note}", "");
    }
    if c.non_finite_pixels > 0 {
        println!("{:<18}{:>14}", "non-finite pixels", c.non_finite_pixels);
    }
}

fn is_hdr(path: &Path) -> bool {
    match ImageFormat::from_path(path) {
        Ok(ImageFormat::Exr | ImageFormat::Hdr) => true,
        Ok(ImageFormat::Png) | Err(_) => false,
    }
}

fn write_error_map(args: &CompareArgs, out: &Path, maps: &FlipMaps) -> Result<(), String> {
    let kind = args
        .error_map_kind
        .unwrap_or(if is_hdr(&args.test) || is_hdr(&args.reference) {
            ErrorMapKind::Hdr
        } else {
            ErrorMapKind::Ldr
        });
    let (map, title) = match kind {
        ErrorMapKind::Ldr => (&maps.ldr, "LDR-FLIP"),
        ErrorMapKind::Hdr => (&maps.hdr, "HDR-FLIP"),
    };
    let image = map.to_image(title).map_err(|e| e.to_string())?;
    // write_image writes a temporary sibling and renames it (atomic).
    write_image(out, &image).map_err(|e| e.to_string())
}

/// `--report` must name an `.html` file in an existing directory: checked before the
/// comparison runs.
pub fn check_report_path(path: &Path) -> Result<(), String> {
    let html = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
    if !html {
        return Err(format!(
            "--report {}: expected an .html file name",
            path.display()
        ));
    }
    crate::atomic_write::check_parent("--report", path)
}

fn print_tmqi(t: &Tmqi) {
    println!("{:<26}{:>10.6}", "TMQI", t.tmqi);
    println!(
        "{:<26}{:>10.6}",
        "structural fidelity S", t.tmqi_structural_fidelity
    );
    println!("{:<26}{:>10.6}", "naturalness N", t.tmqi_naturalness);
    let s = t.tmqi_structural_per_scale;
    println!(
        "{:<26}{:.4} {:.4} {:.4} {:.4} {:.4}",
        "S per scale (fine→coarse)", s[0], s[1], s[2], s[3], s[4]
    );
}

/// Bytes per pixel `--report` holds beyond the strip comparison's working set
/// (`strip_compare_bytes`): the ΔE2000 map (4), the PNGs of A and B (RGBE: at most 4 each)
/// and of the three false-colour maps (at most 3 each), and one image's data URI as the
/// page is written (4/3 of its PNG).
const REPORT_BYTES_PER_PIXEL: u64 = 4 + 8 + 9 + 6;

/// Bytes a comparison of the two files will need, from their headers. `--tmqi` holds the
/// tone-mapped PNG as decoded, the HDR source only where it does not stream, and the
/// luminance planes; `--report` the strip comparison's working set, its maps and the
/// page's compressed images ([`REPORT_BYTES_PER_PIXEL`]); the metrics alone read EXRs in strips
/// (`strip_compare_bytes`), an input of another format decoded whole, and
/// `--error-map` adds its false-colour image and encoder (24 bytes per pixel).
fn check_memory(args: &CompareArgs, budget: &MemoryBudget) -> Result<(), String> {
    let header = |p: &Path| read_dimensions(p).map_err(|e| e.to_string());
    let (test, reference) = (header(&args.test)?, header(&args.reference)?);
    let decoded = |d: &ImageDimensions| d.pixels().saturating_mul(4 * d.channels as u64);
    let per_pixel = |bytes: u64| reference.pixels().saturating_mul(bytes);
    let whole = |path: &Path, d: &ImageDimensions| {
        if RowSource::streams(path) {
            0
        } else {
            decoded(d)
        }
    };
    let map = if args.error_map.is_some() { 24 } else { 0 };
    let estimate = if args.tmqi {
        // The HDR source's luminance is read in bands (tmqi_files), the PNG decoded
        // whole; then two f64 luminance planes and the next scale's (a quarter each).
        decoded(&test)
            .saturating_add(whole(&args.reference, &reference))
            .saturating_add(per_pixel(TMQI_BYTES_PER_PIXEL))
    } else if args.report.is_some() {
        whole(&args.test, &test)
            .saturating_add(whole(&args.reference, &reference))
            .saturating_add(per_pixel(REPORT_BYTES_PER_PIXEL + map))
            .saturating_add(strip_compare_bytes(reference.width, reference.height))
    } else {
        whole(&args.test, &test)
            .saturating_add(whole(&args.reference, &reference))
            .saturating_add(per_pixel(map))
            .saturating_add(strip_compare_bytes(reference.width, reference.height))
    };
    budget
        .check(
            &format!(
                "comparing {} with {} ({}×{} px)",
                args.test.display(),
                args.reference.display(),
                reference.width,
                reference.height
            ),
            estimate,
        )
        .map_err(|e| e.to_string())
}

pub fn run(args: &CompareArgs, budget: &MemoryBudget) -> Result<(), String> {
    args.simd.apply()?;
    if let Some(map) = &args.error_map {
        // Checked before the metrics run, which take long on large images.
        crate::atomic_write::check_parent("--error-map", map)?;
        ImageFormat::from_path(map).map_err(|e| format!("--error-map: {e}"))?;
    }
    check_memory(args, budget)?;
    if args.tmqi {
        let t = tmqi_files(&args.test, &args.reference).map_err(|e| e.to_string())?;
        if args.json {
            println!(
                "{}",
                serde_json::to_string_pretty(&t).map_err(|e| e.to_string())?
            );
        } else {
            print_tmqi(&t);
        }
        return Ok(());
    }
    let options = CompareOptions {
        flip_ppd: Some(args.ppd),
        ..CompareOptions::default()
    };
    if let Some(report) = &args.report {
        check_report_path(report)?;
    }
    let (comparison, maps) = match &args.report {
        Some(report) => compare_files_report(&args.test, &args.reference, &options, report),
        None => compare_files_with(&args.test, &args.reference, &options),
    }
    .map_err(|e| e.to_string())?;
    if let (Some(out), Some(maps)) = (&args.error_map, &maps.flip) {
        write_error_map(args, out, maps)?;
    }
    if let Some(report) = &args.report {
        eprintln!("wrote {}", report.display());
    }
    if args.json {
        let text = serde_json::to_string_pretty(&comparison).map_err(|e| e.to_string())?;
        println!("{text}");
    } else {
        print_table(&comparison);
    }
    Ok(())
}
