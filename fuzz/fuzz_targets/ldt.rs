#![no_main]
//! cargo-fuzz target: ldt (prism_fuzz::Target::Ldt).

use libfuzzer_sys::fuzz_target;
use prism_fuzz::{check_one, Target};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-{}", std::process::id()));
    check_one(Target::Ldt, data, &dir);
});
