//! Shared by the end-to-end tests that run the `prism` binary: each test crate declares
//! `mod support;` and uses what it needs.
#![allow(dead_code)]

pub mod html_report;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `prism` binary with `args` from the repository root.
pub fn prism(args: &[&str]) -> Output {
    prism_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// The `prism` binary as a command whose default cache directory (converge's references,
/// the predictor's BSDF tables; `$XDG_CACHE_HOME/prism`) lies in cargo's temporary
/// directory for tests, not in the user's home.
pub fn prism_command() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_prism"));
    command.env(
        "XDG_CACHE_HOME",
        Path::new(env!("CARGO_TARGET_TMPDIR")).join("xdg-cache"),
    );
    command
}

/// Runs the `prism` binary with `args` from `dir`.
pub fn prism_in(dir: &Path, args: &[&str]) -> Output {
    prism_command()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("prism runs")
}

/// Runs the `prism` binary with `args` from the repository root with `PRISM_SIMD` set to
/// `simd` (`None`: unset, whatever the test process has).
pub fn prism_simd(simd: Option<&str>, args: &[&str]) -> Output {
    let mut command = prism_command();
    command
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .env_remove("PRISM_SIMD");
    if let Some(value) = simd {
        command.env("PRISM_SIMD", value);
    }
    command.output().expect("prism runs")
}

/// The standard error of a finished run, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A UTF-8 path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Width and height of a PNG file from its IHDR chunk (PNG spec §11.2.2: the signature,
/// then IHDR's length, type, and big-endian width and height), so tests can check the size
/// of what was written without decoding it.
pub fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.len() >= 24 && bytes.starts_with(b"\x89PNG\r\n\x1a\n") && &bytes[12..16] == b"IHDR",
        "{} is not a PNG",
        path.display()
    );
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}
