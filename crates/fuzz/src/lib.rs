//! Fuzzing Prism's input layer: one [`Target`] per parser or decoder a user can feed, a
//! deterministic [`mutate`] of seed inputs, and [`run`], a bounded mutation loop on the
//! stable toolchain (the test suite runs min(10⁴ inputs, 15 s) per target; the same
//! targets are cargo-fuzz targets in fuzz/fuzz_targets/ for coverage-guided runs).
//!
//! Each input must end in `Ok` or in an error whose text names the input file (every
//! message names the file, docs/reliability.md), and never panic; [`run`] also times each
//! input (a hang is an input slower than the limit). Allocation limits are checked by the
//! caller's global allocator (tests/fuzz_parsers.rs), which sees every allocation.

pub mod mutate;
pub mod runner;
pub mod target;

pub use runner::{check_one, run, Failure, Limits, Report};
pub use target::Target;
