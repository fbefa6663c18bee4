//! `prism tonemap`: white balance, tone operator, gamut mapping and encoding of an HDR image
//! (any EXR/HDR, not only Prism's), or a labelled contact sheet of every operator.

use std::path::{Path, PathBuf};

use clap::Args;
use prism_cpu::memory::MemoryBudget;
use prism_image::io::read_dimensions;
use prism_post::colour::{GamutMethod, GamutTarget, WhiteBalance};
use prism_post::pipeline::{
    tonemap_file, OperatorChoice, TonemapFileReport, TonemapOptions, TONEMAP_BYTES_PER_PIXEL,
};
use prism_post::sheet::{SheetScore, TileOrder};
use prism_post::tonemap::ToneOperator;

#[derive(Args, Debug)]
pub struct TonemapArgs {
    /// HDR input: OpenEXR (RGB or spectral) or Radiance .hdr.
    #[arg(required_unless_present = "list")]
    pub input: Option<PathBuf>,
    /// Output: .png (encoded with the target's transfer function) or .exr (linear display
    /// values in [0, 1], after gamut mapping).
    #[arg(short = 'o', long = "output", required_unless_present = "list")]
    pub output: Option<PathBuf>,
    /// Tone operator name (see --list), or `all` for a contact sheet of every operator.
    #[arg(long = "op", required_unless_present = "list")]
    pub op: Option<String>,
    /// Operator parameter override, repeatable: --param key=0.18 --param l_white=4.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// White balance: none, grey-world, white-patch, white-patch:PERCENTILE,
    /// illuminant:NAME (or a bare CIE name such as A), cct:KELVIN, or scene (the white of
    /// the light in the scene, from the `illumination` layer `prism render` writes).
    #[arg(long, default_value = "none")]
    pub wb: String,
    /// Chromatic adaptation transform of the white balance: bradford, cat16, cat02 or
    /// von-kries.
    #[arg(long, value_enum, default_value = "bradford")]
    pub cat: CatArg,
    /// Gamut mapping: clip, local-lch, local-oklab, global, aces-rgc.
    #[arg(long, default_value = "clip")]
    pub gamut: String,
    /// Output primaries: srgb, p3 or rec2020.
    #[arg(long, default_value = "srgb")]
    pub target: String,
    /// Exposure in stops applied first (input × 2^EV), or `auto`: the EV that maps the
    /// log-average luminance to middle grey 0.18 (for absolute renders with the
    /// operators that are not scale invariant: linear, aces, agx, …).
    /// Left out: 0, except for an image with `prism:cd_m2_per_unit` (a render in cd/m²)
    /// and an operator that is not absolute, which gets `auto` (said on one line).
    #[arg(long, allow_hyphen_values = true, value_name = "EV|auto")]
    pub exposure: Option<String>,
    /// cd/m² per unit of the input, for the absolute operators when the file has no
    /// `prism:cd_m2_per_unit` header (overrides it when it has).
    #[arg(long, value_name = "CD_M2")]
    pub luminance_scale: Option<f64>,
    /// Score the output against the input it was made from: `tmqi` (Yeganeh & Wang 2013:
    /// structural fidelity S, naturalness N). With `--op all` each tile is scored at full
    /// resolution and its score printed under it. Needs an image of at least 176×176 px.
    #[arg(long, value_enum)]
    pub score: Option<ScoreArg>,
    /// Tile order of `--op all`: `catalogue` (the `--list` order) or `score` (best first,
    /// unscored tiles last; needs `--score`).
    #[arg(long, value_enum, default_value = "catalogue")]
    pub sort: SortArg,
    /// List every operator with its parameters, defaults and reference.
    #[arg(long)]
    pub list: bool,
    /// Allow -o to be the input file itself (replaced once the result is complete).
    #[arg(long)]
    pub overwrite: bool,
    /// Print the report (or the --list catalogue) as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub simd: crate::simd::SimdArgs,
}

fn print_list(json: bool) -> Result<(), String> {
    let catalogue = ToneOperator::catalogue();
    if json {
        let text = serde_json::to_string_pretty(&catalogue).map_err(|e| e.to_string())?;
        println!("{text}");
        return Ok(());
    }
    for info in catalogue {
        let absolute = if info.absolute {
            "  [needs absolute luminance: prism:cd_m2_per_unit or --luminance-scale]"
        } else {
            ""
        };
        println!("{}{absolute}", info.name);
        println!("    {}", info.reference);
        for p in info.params {
            let default = p
                .default
                .map(|d| format!("{d}"))
                .unwrap_or_else(|| "from the image".to_string());
            println!(
                "    --param {}=…   default {default}, range [{}, {}]: {}",
                p.name, p.min, p.max, p.doc
            );
        }
    }
    Ok(())
}

/// The status lines, on standard error like every command's (standard output is for data:
/// `--json`, tables).
fn print_summary(report: &TonemapFileReport) {
    if report.auto_exposure_photometric {
        eprintln!(
            "exposure auto: {:+.2} EV (the image is photometric, prism:cd_m2_per_unit, and no \
             --exposure was given; --exposure 0 keeps its scale)",
            report.exposure_ev
        );
    } else if report.auto_exposure {
        eprintln!(
            "exposure auto: {:+.2} EV (log-average luminance → 0.18)",
            report.exposure_ev
        );
    }
    eprintln!(
        "wrote {} ({}×{}, {}, {} → {}, {:.2} % of pixels outside the gamut before mapping)",
        report.output,
        report.width,
        report.height,
        report.operator,
        report.gamut_method,
        report.target,
        100.0 * report.gamut_fraction_outside
    );
    if report.exposure_overflow_pixels > 0 {
        eprintln!(
            "note: {} pixels overflowed to ∞ when scaled by 2^{:.2} (the exposure) and were \
             mapped to black; lower --exposure",
            report.exposure_overflow_pixels, report.exposure_ev
        );
    }
    if report.non_finite_pixels > 0 {
        eprintln!(
            "note: {} input pixels had NaN/∞ components (mapped to black)",
            report.non_finite_pixels
        );
    }
    for failure in &report.failures {
        eprintln!("note: no tile for {}: {}", failure.operator, failure.error);
    }
    if !report.scores.is_empty() {
        println!("{:<20}{:>8}{:>8}{:>8}", "operator", "TMQI", "S", "N");
        for score in &report.scores {
            println!(
                "{:<20}{:>8.4}{:>8.4}{:>8.4}",
                score.operator,
                score.tmqi.tmqi,
                score.tmqi.tmqi_structural_fidelity,
                score.tmqi.tmqi_naturalness
            );
        }
    }
}

/// The scores `--score` offers.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ScoreArg {
    Tmqi,
}

impl From<ScoreArg> for SheetScore {
    fn from(arg: ScoreArg) -> Self {
        match arg {
            ScoreArg::Tmqi => Self::Tmqi,
        }
    }
}

/// The tile orders `--sort` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SortArg {
    Catalogue,
    Score,
}

/// The adaptation transforms `--cat` offers (all but the identity, which would switch
/// white balance off: `--wb none` says that).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum CatArg {
    Bradford,
    Cat16,
    Cat02,
    VonKries,
}

impl From<CatArg> for prism_spectrum::AdaptationMethod {
    fn from(arg: CatArg) -> Self {
        match arg {
            CatArg::Bradford => Self::Bradford,
            CatArg::Cat16 => Self::Cat16,
            CatArg::Cat02 => Self::Cat02,
            CatArg::VonKries => Self::VonKries,
        }
    }
}

/// Bytes tone-mapping `input` will need, from its header (see `TONEMAP_BYTES_PER_PIXEL`;
/// a contact sheet holds a tile per operator at most the input's size in all).
fn check_memory(input: &Path, budget: &MemoryBudget) -> Result<(), String> {
    let d = read_dimensions(input).map_err(|e| e.to_string())?;
    let estimate = d
        .pixels()
        .saturating_mul(4 * d.channels as u64 + TONEMAP_BYTES_PER_PIXEL);
    budget
        .check(
            &format!(
                "tone-mapping {} ({}×{} px, {} channels)",
                input.display(),
                d.width,
                d.height,
                d.channels
            ),
            estimate,
        )
        .map_err(|e| e.to_string())
}

pub fn run(args: &TonemapArgs, budget: &MemoryBudget) -> Result<(), String> {
    if args.list {
        return print_list(args.json);
    }
    args.simd.apply()?;
    let (input, output, op) = match (&args.input, &args.output, &args.op) {
        (Some(i), Some(o), Some(op)) => (i, o, op),
        _ => return Err("tonemap needs IN, -o OUT and --op NAME (or --list)".to_string()),
    };
    let (exposure_ev, auto_exposure) = match &args.exposure {
        Some(text) => prism_args::tone_values::parse_exposure(text)?,
        None => (0.0, false),
    };
    if !args.overwrite && prism_image::io::same_file(input, output) {
        return Err(format!(
            "-o {}: it is the input file; give another output, or --overwrite to replace the \
             input once the result is complete",
            output.display()
        ));
    }
    crate::atomic_write::check_parent("-o", output)?;
    prism_image::io::ImageFormat::from_path(output).map_err(|e| e.to_string())?;
    check_memory(input, budget)?;
    let order = match (args.sort, args.score) {
        (SortArg::Catalogue, _) => TileOrder::Catalogue,
        (SortArg::Score, Some(_)) => TileOrder::ScoreDescending,
        (SortArg::Score, None) => {
            return Err("--sort score needs a score: add --score tmqi".to_string())
        }
    };
    let options = TonemapOptions {
        operator: OperatorChoice::parse(op).map_err(|e| format!("--op {op}: {e}"))?,
        params: prism_args::tone_values::parse_params(&args.params)?,
        wb: WhiteBalance::parse(&args.wb).map_err(|e| e.to_string())?,
        cat: args.cat.into(),
        gamut: GamutMethod::parse(&args.gamut).map_err(|e| e.to_string())?,
        target: GamutTarget::parse(&args.target).map_err(|e| e.to_string())?,
        exposure_ev,
        auto_exposure,
        auto_exposure_if_photometric: args.exposure.is_none(),
        luminance_scale_cd_m2: args.luminance_scale,
        score: args.score.map(SheetScore::from),
        order,
    };
    let report = tonemap_file(input, output, &options).map_err(|e| e.to_string())?;
    if args.json {
        let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
        println!("{text}");
    } else {
        print_summary(&report);
    }
    Ok(())
}
