//! `prism compare A B [--json]`: error metrics of image A against the reference B.

use std::path::PathBuf;

use clap::Args;
use prism_post::metrics::Comparison;
use prism_post::pipeline::compare_files;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test (EXR, HDR or PNG).
    pub test: PathBuf,
    /// The reference image (same size); relMSE, PSNR peak and ΔE2000 white come from it.
    pub reference: PathBuf,
    /// Print one JSON object (mse, rmse, relmse, psnr_db, ssim, delta_e2000_mean,
    /// delta_e2000_p95, per_channel) instead of a table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub simd: crate::simd::SimdArgs,
}

fn print_table(c: &Comparison) {
    let row3 = |name: &str, v: [f64; 3]| {
        println!("{name:<18}{:>14.6e}{:>14.6e}{:>14.6e}", v[0], v[1], v[2]);
    };
    println!("{:<18}{} × {} px", "size", c.width, c.height);
    println!("{:<18}{:>14.6e}", "MSE", c.mse);
    println!("{:<18}{:>14.6e}", "RMSE", c.rmse);
    println!("{:<18}{:>14.6e}", "relMSE", c.relmse);
    println!("{:<18}{:>14.3} dB", "PSNR", c.psnr_db);
    match c.ssim {
        Some(s) => println!("{:<18}{s:>14.6}", "SSIM"),
        None => println!("{:<18}{:>14}", "SSIM", "n/a (< 11×11)"),
    }
    println!("{:<18}{:>14.4}", "ΔE2000 mean", c.delta_e2000_mean);
    println!("{:<18}{:>14.4}", "ΔE2000 p95", c.delta_e2000_p95);
    println!("{:<18}{:>14}{:>14}{:>14}", "per channel", "R", "G", "B");
    row3("  MSE", c.per_channel.mse);
    row3("  RMSE", c.per_channel.rmse);
    row3("  relMSE", c.per_channel.relmse);
    row3("  PSNR (dB)", c.per_channel.psnr_db);
    if c.non_finite_pixels > 0 {
        println!("{:<18}{:>14}", "non-finite pixels", c.non_finite_pixels);
    }
}

pub fn run(args: &CompareArgs) -> Result<(), String> {
    args.simd.apply()?;
    let comparison = compare_files(&args.test, &args.reference).map_err(|e| e.to_string())?;
    if args.json {
        let text = serde_json::to_string_pretty(&comparison).map_err(|e| e.to_string())?;
        println!("{text}");
    } else {
        print_table(&comparison);
    }
    Ok(())
}
