//! The bounded mutation loop: seeds first (as they are), then mutated inputs until the
//! input count or the time budget runs out. Each input is written to the target's input
//! file and parsed; a panic, an error that does not name the file, or an input slower
//! than the per-input limit is a [`Failure`].

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::{Duration, Instant};

use rand::SeedableRng;

use crate::mutate::mutate;
use crate::target::Target;

/// How long the loop runs.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    pub max_inputs: u64,
    pub budget: Duration,
    /// An input that takes longer is a hang.
    pub per_input: Duration,
    pub seed: u64,
    /// Leave out seeds larger than this (a long run of an image decoder at the speed of
    /// its small seeds); `None`: every seed.
    pub max_seed_bytes: Option<usize>,
}

/// Why one input failed.
#[derive(Debug, Clone)]
pub struct Failure {
    pub input: Vec<u8>,
    pub reason: String,
}

/// What one target's run did.
#[derive(Debug, Clone)]
pub struct Report {
    pub target: Target,
    pub executions: u64,
    pub ok: u64,
    pub errors: u64,
    pub slowest: Duration,
    pub failures: Vec<Failure>,
    /// Seeds used, and seeds left out by `Limits::max_seed_bytes`.
    pub seeds_used: usize,
    pub seeds_left_out: usize,
}

/// Runs `target` on its seeds and on mutations of them, writing inputs into `dir`.
pub fn run(target: Target, root: &Path, dir: &Path, limits: &Limits) -> Report {
    let all_seeds = target.seeds(root);
    let seed_count = all_seeds.len();
    let seeds: Vec<Vec<u8>> = all_seeds
        .into_iter()
        .filter(|s| limits.max_seed_bytes.is_none_or(|most| s.len() <= most))
        .collect();
    let path = target.input_path(dir);
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(limits.seed);
    let mut report = Report {
        target,
        executions: 0,
        ok: 0,
        errors: 0,
        slowest: Duration::ZERO,
        failures: Vec::new(),
        seeds_used: seeds.len(),
        seeds_left_out: seed_count - seeds.len(),
    };
    if let Err(e) = target.prepare(root, dir) {
        report.failures.push(Failure {
            input: Vec::new(),
            reason: format!("cannot prepare the input directory: {e}"),
        });
        return report;
    }
    let start = Instant::now();
    while report.executions < limits.max_inputs && start.elapsed() < limits.budget {
        let k = report.executions as usize;
        let input = match seeds.get(k) {
            Some(seed) => seed.clone(),
            None if seeds.is_empty() => Vec::new(),
            None => {
                let seed = &seeds[rand::Rng::gen_range(&mut rng, 0..seeds.len())];
                let other = &seeds[rand::Rng::gen_range(&mut rng, 0..seeds.len())];
                mutate(&mut rng, seed, other)
            }
        };
        report.executions += 1;
        if let Err(e) = std::fs::write(&path, &input) {
            report.failures.push(Failure {
                input,
                reason: format!("cannot write the input file: {e}"),
            });
            break;
        }
        let began = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| target.parse(&path)));
        let took = began.elapsed();
        report.slowest = report.slowest.max(took);
        let reason = match outcome {
            Ok(Ok(())) => {
                report.ok += 1;
                None
            }
            Ok(Err(message)) => {
                report.errors += 1;
                (!message.contains(&file_name))
                    .then(|| format!("the error does not name the input file: {message}"))
            }
            Err(panic) => Some(format!(
                "panic: {}",
                panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("(no message)")
            )),
        };
        let reason = reason.or_else(|| {
            (took > limits.per_input)
                .then(|| format!("took {took:?} (limit {:?})", limits.per_input))
        });
        if let Some(reason) = reason {
            report.failures.push(Failure { input, reason });
        }
    }
    let _ = std::fs::remove_file(&path);
    report
}

/// One input as a cargo-fuzz target runs it: written into `dir`, parsed, and a panic for
/// an error that does not name the file (libFuzzer reports panics and slow inputs itself).
pub fn check_one(target: Target, data: &[u8], dir: &Path) {
    let path = target.input_path(dir);
    if let Some(parent) = path.parent() {
        if !parent.exists() {
            let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
            std::fs::create_dir_all(dir).expect("the fuzz directory");
            target
                .prepare(&root, dir)
                .expect("the fuzz directory's scenes");
            std::fs::create_dir_all(parent).expect("the fuzz directory");
        }
    }
    std::fs::write(&path, data).expect("the fuzz input file");
    if let Err(message) = target.parse(&path) {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        assert!(
            name.is_some_and(|n| message.contains(&n)),
            "the error does not name the input file: {message}"
        );
    }
}
