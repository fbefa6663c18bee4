//! Every parser and decoder a user can feed, fuzzed on every test run (issue 24): for each
//! target of `prism_fuzz`, its seeds and then mutated inputs, min(10⁴ inputs, 15 s) (set
//! `PRISM_FUZZ_INPUTS` and `PRISM_FUZZ_SECONDS` for long runs). Each input must parse or
//! fail with an error naming the file; no panic, no input slower than 5 s, and no single
//! allocation above 1 GiB (this binary's global allocator refuses it, naming the size, and
//! the process aborts: a test failure that cannot be missed).

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::time::Duration;

use prism_fuzz::{run, Limits, Target};

/// The largest single allocation a parser may make on any input.
const ALLOCATION_LIMIT_BYTES: usize = 1 << 30;

struct Limited;

// SAFETY: forwards to the system allocator; only refuses (null) above the limit.
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > ALLOCATION_LIMIT_BYTES {
            eprintln!(
                "fuzz: a parser asked for {} bytes in one allocation (limit {ALLOCATION_LIMIT_BYTES})",
                layout.size()
            );
            return std::ptr::null_mut();
        }
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > ALLOCATION_LIMIT_BYTES {
            eprintln!(
                "fuzz: a parser asked for {} zeroed bytes in one allocation (limit {ALLOCATION_LIMIT_BYTES})",
                layout.size()
            );
            return std::ptr::null_mut();
        }
        System.alloc_zeroed(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > ALLOCATION_LIMIT_BYTES {
            eprintln!("fuzz: a parser grew an allocation to {new_size} bytes (limit {ALLOCATION_LIMIT_BYTES})");
            return std::ptr::null_mut();
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Limited = Limited;

fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn fuzz(target: Target) {
    let limits = Limits {
        max_inputs: env_or("PRISM_FUZZ_INPUTS", 10_000),
        budget: Duration::from_secs(env_or("PRISM_FUZZ_SECONDS", 15)),
        per_input: Duration::from_secs(5),
        seed: 0x5eed ^ target as u64,
        max_seed_bytes: std::env::var("PRISM_FUZZ_MAX_SEED_BYTES")
            .ok()
            .and_then(|v| v.parse().ok()),
    };
    // What a user's --max-memory does for decoders: files declaring more are refused.
    prism_image::io::exr::set_exr_decode_limit_bytes(ALLOCATION_LIMIT_BYTES as u64 / 4);
    // Each input is a file: in memory where the system has a RAM file system.
    let shm = Path::new("/dev/shm");
    let dir = if shm.is_dir() {
        tempfile::tempdir_in(shm)
    } else {
        tempfile::tempdir()
    }
    .unwrap();
    // Panics are caught and reported per input; the default hook would print each one.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let report = run(
        target,
        Path::new(env!("CARGO_MANIFEST_DIR")),
        dir.path(),
        &limits,
    );
    std::panic::set_hook(hook);
    eprintln!(
        "fuzz {}: {} executions ({} parsed, {} refused), slowest {:?}, {} failures ({} seeds, \
         {} left out by size)",
        target.name(),
        report.executions,
        report.ok,
        report.errors,
        report.slowest,
        report.failures.len(),
        report.seeds_used,
        report.seeds_left_out
    );
    assert!(
        report.executions >= 100,
        "{}: too few inputs ran",
        target.name()
    );
    if let Some(first) = report.failures.first() {
        let shown: String =
            String::from_utf8_lossy(&first.input[..first.input.len().min(200)]).into();
        panic!(
            "{}: {} of {} inputs failed; first: {} (input starts {shown:?})",
            target.name(),
            report.failures.len(),
            report.executions,
            first.reason
        );
    }
}

#[test]
fn scene_json() {
    fuzz(Target::SceneJson);
}
#[test]
fn scene_build() {
    fuzz(Target::SceneBuild);
}
#[test]
fn spectrum_csv() {
    fuzz(Target::SpectrumCsv);
}
#[test]
fn bfc() {
    fuzz(Target::Bfc);
}
#[test]
fn ies() {
    fuzz(Target::Ies);
}
#[test]
fn ldt() {
    fuzz(Target::Ldt);
}
#[test]
fn obj() {
    fuzz(Target::Obj);
}
#[test]
fn ply() {
    fuzz(Target::Ply);
}
#[test]
fn merl() {
    fuzz(Target::Merl);
}
#[test]
fn vol() {
    fuzz(Target::Vol);
}
#[test]
fn exr() {
    fuzz(Target::Exr);
}
#[test]
fn spectral_exr() {
    fuzz(Target::SpectralExr);
}
#[test]
fn rgbe() {
    fuzz(Target::Rgbe);
}
#[test]
fn png() {
    fuzz(Target::Png);
}
#[test]
fn cli_values() {
    fuzz(Target::CliValues);
}
