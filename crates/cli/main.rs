//! The `prism` command: spectral rendering, colorimetry and tone reproduction.

mod atomic_write;
mod bispectral;
mod cache_dir;
mod color;
mod compare;
mod converge;
mod daylight_factor;
mod falsecolour;
mod import;
mod merge;
mod merl_export;
mod partial;
mod plan_args;
mod predictor_time;
mod progress;
mod render;
mod sensors;
mod simd;
mod tile_brdf;
mod tonemap;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use prism_cpu::memory::MemoryBudget;

#[derive(Parser)]
#[command(
    name = "prism",
    version,
    about = "Prism: a spectral, predictive renderer with a tone-reproduction toolkit"
)]
struct Cli {
    /// Memory a command may use, e.g. 512M or 8G (default: 75 % of the physical memory):
    /// `render`, `converge`, `compare`, `tonemap` and `tile-brdf` estimate what they need
    /// before they allocate and refuse above it (docs/reliability.md).
    #[arg(long = "max-memory", global = true, value_name = "SIZE", value_parser = prism_cpu::memory::parse_size)]
    max_memory: Option<u64>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Colorimetry of a spectrum: XYZ, xy, CCT/Duv, CIELAB and sRGB, as colour-science computes them;
    /// of a fluorescent sample (--bispectral): reflected and total colour, βT, CIE whiteness.
    Color(color::ColorArgs),
    /// Error metrics of an image against a reference: MSE, RMSE, relMSE, PSNR, SSIM, ΔE2000.
    Compare(compare::CompareArgs),
    /// Error against time for each method: progressive renders, RMSE/relMSE/ΔE2000 at
    /// checkpoints, a log–log chart (PNG/SVG) with fitted slopes, JSON (docs/converge.md).
    Converge(converge::ConvergeArgs),
    /// Translate a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene into Prism's JSON, listing what
    /// is not imported exactly (docs/import.md).
    Import(import::ImportArgs),
    /// Add the partial images of disjoint sample ranges of one render (`render --samples`)
    /// into the image of their union, weighted by sample counts (docs/scale-out.md).
    Merge(merge::MergeArgs),
    /// Write a material of a scene file as a MERL BRDF table (90×90×180 half/difference angles).
    MerlExport(merl_export::MerlExportArgs),
    /// Render a scene file to an EXR or PNG image (docs/rendering.md).
    Render(render::RenderArgs),
    /// The BRDF/BTDF pyramid of a scene's periodic tile (`tiles`), by path tracing the
    /// repeated tile; cached in --cache-dir; prints a JSON summary (docs/radiosity.md).
    TileBrdf(tile_brdf::TileBrdfArgs),
    /// Tone-map an HDR image (EXR/HDR): white balance, tone operator, gamut mapping, encoding.
    Tonemap(tonemap::TonemapArgs),
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`prism tonemap --list | head`)
    // would panic; the default action ends the process quietly like other Unix tools.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let budget = match cli.max_memory {
        Some(bytes) => MemoryBudget::given(bytes),
        None => MemoryBudget::machine_default(),
    };
    // Decoders refuse files whose headers declare more than the limit.
    prism_image::io::exr::set_exr_decode_limit_bytes(budget.limit_bytes);
    let done = |r: Result<(), String>| r.map(|()| ExitCode::SUCCESS);
    let result = match cli.command {
        Command::Color(args) => done(color::run(&args)),
        Command::Compare(args) => done(compare::run(&args, &budget)),
        Command::Converge(args) => done(converge::run(&args, &budget)),
        Command::Import(args) => done(import::run(&args)),
        Command::Merge(args) => merge::run(&args),
        Command::MerlExport(args) => done(merl_export::run(&args)),
        // Non-zero without an error when a signal stopped it (the work is saved).
        Command::Render(args) => render::run(&args, &budget),
        Command::TileBrdf(args) => done(tile_brdf::run(&args, &budget)),
        Command::Tonemap(args) => done(tonemap::run(&args, &budget)),
    };
    match result {
        Ok(code) => code,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
