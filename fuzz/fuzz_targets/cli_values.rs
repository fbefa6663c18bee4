#![no_main]
//! cargo-fuzz target: cli_values (prism_fuzz::Target::CliValues).

use libfuzzer_sys::fuzz_target;
use prism_fuzz::{check_one, Target};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-{}", std::process::id()));
    check_one(Target::CliValues, data, &dir);
});
