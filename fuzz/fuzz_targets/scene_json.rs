#![no_main]
//! cargo-fuzz target: scene_json (prism_fuzz::Target::SceneJson).

use libfuzzer_sys::fuzz_target;
use prism_fuzz::{check_one, Target};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-{}", std::process::id()));
    check_one(Target::SceneJson, data, &dir);
});
