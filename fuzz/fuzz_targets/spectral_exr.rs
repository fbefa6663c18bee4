#![no_main]
//! cargo-fuzz target: spectral_exr (prism_fuzz::Target::SpectralExr).

use libfuzzer_sys::fuzz_target;
use prism_fuzz::{check_one, Target};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-{}", std::process::id()));
    check_one(Target::SpectralExr, data, &dir);
});
