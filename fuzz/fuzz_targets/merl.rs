#![no_main]
//! cargo-fuzz target: merl (prism_fuzz::Target::Merl).

use libfuzzer_sys::fuzz_target;
use prism_fuzz::{check_one, Target};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-{}", std::process::id()));
    check_one(Target::Merl, data, &dir);
});
