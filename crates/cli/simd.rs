//! The vector instruction set of the subcommands that run fast paths (render, converge,
//! tonemap, compare): `PRISM_SIMD` checked at start, and the hidden `--simd scalar|avx2|avx512` (the widest ISA the fast
//! paths may use, over `PRISM_SIMD`; for tests and comparisons, so not in `--help`).

use clap::Args;
use prism_cpu::Isa;

#[derive(Args, Debug, Clone, Default)]
pub struct SimdArgs {
    /// The widest vector instruction set the fast paths may use: scalar, avx2 or avx512
    /// (over PRISM_SIMD; an ISA the CPU lacks falls back to the widest it has).
    #[arg(long = "simd", value_name = "ISA", hide = true, value_parser = parse_isa)]
    pub simd: Option<Isa>,
}

fn parse_isa(s: &str) -> Result<Isa, String> {
    Isa::parse(s).ok_or_else(|| format!("expected {}", prism_cpu::VALID_VALUES))
}

impl SimdArgs {
    /// Refuses an invalid `PRISM_SIMD`, sets `--simd` as the process-wide limit, and warns
    /// when the CPU lacks what was asked for. Call before any work starts (scenes built and
    /// tone maps begun read the choice once).
    pub fn apply(&self) -> Result<(), String> {
        let env = prism_cpu::env_limit()?;
        if let Some(isa) = self.simd {
            prism_cpu::set_limit(isa);
        }
        if let Some(asked) = self.simd.or(env) {
            let choice = prism_cpu::choice();
            if choice.simd.isa() < asked {
                eprintln!("warning: simd: {choice}");
            }
        }
        Ok(())
    }
}
