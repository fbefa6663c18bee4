//! prism-cpu: which vector instruction sets (ISAs) Prism's fast paths may use.
//!
//! Three crates choose kernels at run time: prism-geometry's small-scene intersector (8
//! lanes), prism-render's packet tracer and film splat (8 or 16 lanes) and prism-post's
//! tone-mapping passes (loops compiled a second time for AVX2, AVX-512 register passes).
//! They share one definition of what each ISA needs and one process-wide choice, here, in
//! a crate without dependencies at the bottom of the workspace (prism-geometry, below
//! render and post, does not depend on prism-spectrum, and CPU detection is not spectral).
//!
//! - [`Isa`]: the ladder `scalar` < `avx2` < `avx512` and what each needs of the CPU.
//! - [`Simd`]: an ISA this CPU runs, the token every kernel entry point takes. It is made
//!   only after checking the CPU, so `simd.avx2()` true is what makes calling an
//!   `#[target_feature(enable = "avx2,fma")]` kernel sound.
//! - [`active`]: the process-wide choice, the widest ISA the CPU runs within the limit set
//!   by the environment variable [`ENV_VAR`] (`PRISM_SIMD=scalar|avx2|avx512`) or by
//!   [`set_limit`] (the CLI's `--simd`); [`choice`] says why.
//!
//! Entry points read [`active`] once on the calling thread (a tone-mapping call, a scene
//! build, a film tile) and pass the [`Simd`] down to the kernels on worker threads, so
//! tests run kernels at any ISA by passing it explicitly ([`each_isa`]), in parallel,
//! without touching the process-wide choice.
//!
//! The machine's other limits live here too: [`memory`] (the `--max-memory` budget and the
//! physical memory) and [`threads`] (the bound on `--threads`); and [`text_file`], how
//! every crate reads a user's text file, because this crate is the one below all others.
//! [`clock`] holds the CPU clocks that commands and benchmarks report time on.

pub mod clock;
pub mod memory;
pub mod text_file;
pub mod threads;

use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};

/// The environment variable that limits the fast paths' ISA: `scalar`, `avx2` or
/// `avx512` (the widest allowed). Unset or empty: no limit. Any other value is an error
/// the CLI reports at start ([`env_limit`]); the library ignores it ([`choice`] says so).
pub const ENV_VAR: &str = "PRISM_SIMD";

/// An instruction-set level of the fast paths, narrowest first (`Ord` follows the
/// ladder).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// The build's baseline (SSE2 on x86-64): the portable path.
    Scalar,
    /// AVX2 with FMA (and AVX), plus the bit instructions every AVX2 CPU has (BMI1, BMI2,
    /// LZCNT, POPCNT: x86-64-v3, which the BVH traversal's mask arithmetic uses): 8 f32
    /// lanes.
    Avx2,
    /// AVX-512 F, DQ, VL and BW, with everything `Avx2` needs: 16 f32 lanes.
    Avx512,
}

/// What [`Isa::parse`] accepts, for messages.
pub const VALID_VALUES: &str = "scalar, avx2 or avx512";

impl Isa {
    /// Every level, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Scalar, Isa::Avx2, Isa::Avx512];

    /// The name `PRISM_SIMD`, `--simd`, `--explain` and `--stats-json` use.
    pub const fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The level named `s` (ASCII case and surrounding spaces ignored), or `None`.
    pub fn parse(s: &str) -> Option<Isa> {
        let s = s.trim();
        Isa::ALL
            .into_iter()
            .find(|isa| isa.name().eq_ignore_ascii_case(s))
    }

    /// What this CPU lacks for this level, e.g. "AVX-512 BW" or "AVX2 and FMA"; `None`
    /// when it runs it (always for `Scalar`).
    pub fn missing(self) -> Option<String> {
        let cpu = Features::detect();
        let mut lacks: Vec<&'static str> = Vec::new();
        if !cpu.x86_64 {
            return (self != Isa::Scalar).then(|| "x86-64 vector extensions".to_string());
        }
        if self >= Isa::Avx2 {
            for (has, name) in [
                (cpu.avx, "AVX"),
                (cpu.avx2, "AVX2"),
                (cpu.fma, "FMA"),
                (cpu.bmi1, "BMI1"),
                (cpu.bmi2, "BMI2"),
                (cpu.lzcnt, "LZCNT"),
                (cpu.popcnt, "POPCNT"),
            ] {
                if !has {
                    lacks.push(name);
                }
            }
        }
        let mut avx512: Vec<&'static str> = Vec::new();
        if self == Isa::Avx512 {
            for (has, name) in [
                (cpu.avx512f, "F"),
                (cpu.avx512dq, "DQ"),
                (cpu.avx512vl, "VL"),
                (cpu.avx512bw, "BW"),
            ] {
                if !has {
                    avx512.push(name);
                }
            }
        }
        let mut parts: Vec<String> = lacks.into_iter().map(String::from).collect();
        if !avx512.is_empty() {
            parts.push(format!("AVX-512 {}", avx512.join("/")));
        }
        match parts.len() {
            0 => None,
            1 => parts.pop(),
            n => Some(format!(
                "{} and {}",
                parts[..n - 1].join(", "),
                parts[n - 1]
            )),
        }
    }

    /// The widest level this CPU runs.
    pub fn detected() -> Isa {
        Isa::ALL
            .into_iter()
            .rev()
            .find(|isa| isa.missing().is_none())
            .unwrap_or(Isa::Scalar)
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The CPU features the levels need, detected once (the standard library caches each
/// query after the first; `is_x86_feature_detected!` also checks that the OS saves the
/// wider registers).
#[derive(Clone, Copy, Debug)]
struct Features {
    x86_64: bool,
    avx: bool,
    avx2: bool,
    fma: bool,
    bmi1: bool,
    bmi2: bool,
    lzcnt: bool,
    popcnt: bool,
    avx512f: bool,
    avx512dq: bool,
    avx512vl: bool,
    avx512bw: bool,
}

impl Features {
    #[cfg(target_arch = "x86_64")]
    fn detect() -> Features {
        use std::arch::is_x86_feature_detected as has;
        Features {
            x86_64: true,
            avx: has!("avx"),
            avx2: has!("avx2"),
            fma: has!("fma"),
            bmi1: has!("bmi1"),
            bmi2: has!("bmi2"),
            lzcnt: has!("lzcnt"),
            popcnt: has!("popcnt"),
            avx512f: has!("avx512f"),
            avx512dq: has!("avx512dq"),
            avx512vl: has!("avx512vl"),
            avx512bw: has!("avx512bw"),
        }
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn detect() -> Features {
        Features {
            x86_64: false,
            avx: false,
            avx2: false,
            fma: false,
            bmi1: false,
            bmi2: false,
            lzcnt: false,
            popcnt: false,
            avx512f: false,
            avx512dq: false,
            avx512vl: false,
            avx512bw: false,
        }
    }
}

/// An ISA this CPU runs: what kernel entry points take. Only [`Simd::new`] (which checks
/// the CPU), [`Simd::SCALAR`], [`Simd::detected`], [`active`] and [`each_isa`] make one,
/// so a kernel may call `#[target_feature]` code for the level it says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Simd(Isa);

impl Simd {
    /// The portable path, on every CPU.
    pub const SCALAR: Simd = Simd(Isa::Scalar);

    /// `isa` if this CPU runs it.
    pub fn new(isa: Isa) -> Option<Simd> {
        isa.missing().is_none().then_some(Simd(isa))
    }

    /// The widest level this CPU runs, ignoring any limit.
    pub fn detected() -> Simd {
        Simd(Isa::detected())
    }

    pub fn isa(self) -> Isa {
        self.0
    }

    /// AVX, AVX2 and FMA kernels may run (`#[target_feature(enable = "avx2,fma")]`), and
    /// with them the x86-64-v3 bit instructions (`bmi1,bmi2,lzcnt,popcnt`).
    #[inline(always)]
    pub fn avx2(self) -> bool {
        self.0 >= Isa::Avx2
    }

    /// AVX-512 F/DQ/VL/BW kernels may run (and everything [`Self::avx2`] allows).
    #[inline(always)]
    pub fn avx512(self) -> bool {
        self.0 == Isa::Avx512
    }
}

impl fmt::Display for Simd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0.name())
    }
}

/// The process-wide choice and why it was made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Choice {
    pub simd: Simd,
    /// E.g. "CPU has AVX-512 F/DQ/VL/BW", "PRISM_SIMD=scalar", "--simd avx512; the CPU
    /// lacks AVX-512 BW".
    pub reason: String,
}

impl fmt::Display for Choice {
    /// `avx2 (--simd avx2)`: the form of `prism render --explain`'s line.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.simd, self.reason)
    }
}

/// No limit set by [`set_limit`] / no cached choice.
const UNSET: u8 = u8::MAX;
/// The limit [`set_limit`] stored (an `Isa as u8`), or UNSET.
static FLAG_LIMIT: AtomicU8 = AtomicU8::new(UNSET);
/// The cached `active()` (an `Isa as u8`), or UNSET.
static ACTIVE: AtomicU8 = AtomicU8::new(UNSET);

fn isa_of(v: u8) -> Option<Isa> {
    Isa::ALL.into_iter().find(|isa| *isa as u8 == v)
}

/// The limit in [`ENV_VAR`]: `Ok(None)` when unset or empty, `Err` with a message naming
/// the variable and the valid values for anything else (the CLI refuses to start with
/// it; the library treats it as unset).
pub fn env_limit() -> Result<Option<Isa>, String> {
    let Some(raw) = std::env::var_os(ENV_VAR) else {
        return Ok(None);
    };
    let text = raw.to_string_lossy();
    if text.trim().is_empty() {
        return Ok(None);
    }
    Isa::parse(&text).map(Some).ok_or_else(|| {
        format!(
            "{ENV_VAR}={text}: expected {VALID_VALUES} (the widest vector instruction set \
             the fast paths may use)"
        )
    })
}

/// Sets the process-wide limit (the CLI's `--simd`), over [`ENV_VAR`]. Call it before
/// work starts: scenes built and tone maps begun earlier keep the ISA they read.
pub fn set_limit(isa: Isa) {
    FLAG_LIMIT.store(isa as u8, Ordering::SeqCst);
    ACTIVE.store(UNSET, Ordering::SeqCst);
}

/// The process-wide choice: the widest ISA this CPU runs within the limit (`--simd` via
/// [`set_limit`], else [`ENV_VAR`]), with the reason; an ISA the CPU lacks falls back to
/// the widest it has, and the reason names what is missing.
pub fn choice() -> Choice {
    let best = Isa::detected();
    let env = env_limit();
    let flag = isa_of(FLAG_LIMIT.load(Ordering::SeqCst));
    let (request, mut reason) = match (flag, &env) {
        (Some(f), Ok(Some(e))) if *e != f => {
            (Some(f), format!("--simd {f}; {ENV_VAR}={e} overridden"))
        }
        (Some(f), _) => (Some(f), format!("--simd {f}")),
        (None, Ok(Some(e))) => (Some(*e), format!("{ENV_VAR}={e}")),
        (None, _) => (None, String::new()),
    };
    let isa = match request {
        Some(r) if r <= best => r,
        Some(r) => {
            if let Some(lacks) = r.missing() {
                reason += &format!("; the CPU lacks {lacks}");
            }
            best
        }
        None => {
            reason = match (best, Isa::Avx512.missing()) {
                (Isa::Avx512, _) => "CPU has AVX-512 F/DQ/VL/BW".into(),
                (Isa::Avx2, Some(lacks)) => format!("CPU has AVX2 and FMA but lacks {lacks}"),
                (_, _) => match Isa::Avx2.missing() {
                    Some(lacks) => format!("the CPU lacks {lacks}"),
                    None => "CPU has AVX2 and FMA".into(),
                },
            };
            best
        }
    };
    if flag.is_none() {
        if let Err(message) = &env {
            reason += &format!("; ignored {message}");
        }
    }
    Choice {
        simd: Simd(isa),
        reason,
    }
}

/// [`choice`]'s ISA, cached after the first call (and after each [`set_limit`]).
#[inline]
pub fn active() -> Simd {
    match isa_of(ACTIVE.load(Ordering::Relaxed)) {
        Some(isa) => Simd(isa),
        None => {
            let simd = choice().simd;
            ACTIVE.store(simd.0 as u8, Ordering::Relaxed);
            simd
        }
    }
}

/// The ISAs a test that compares kernels runs: every one this CPU runs within the
/// process limit ([`active`]), narrowest first (`scalar` always). For each other it
/// writes the missing feature (or the limit) to stderr, past the test harness's output
/// capture, so that a comparison run on a narrower machine says what it did not check.
pub fn each_isa() -> Vec<Simd> {
    let limit = active();
    let mut run = Vec::new();
    for isa in Isa::ALL {
        if isa <= limit.isa() {
            run.push(Simd(isa));
            continue;
        }
        let why = match isa.missing() {
            Some(lacks) => format!("the CPU lacks {lacks}"),
            None => choice().reason,
        };
        let test = std::thread::current()
            .name()
            .unwrap_or("this test")
            .to_string();
        // Written to the stderr handle, not with eprintln!: the harness captures only the
        // print macros.
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "{test}: {isa} kernels skipped: {why}");
    }
    run
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_order_follows_the_ladder() {
        for isa in Isa::ALL {
            assert_eq!(Isa::parse(isa.name()), Some(isa));
            assert_eq!(
                Isa::parse(&format!(" {} ", isa.name().to_uppercase())),
                Some(isa)
            );
        }
        assert_eq!(Isa::parse("avx"), None);
        assert_eq!(Isa::parse("sse2"), None);
        assert!(Isa::Scalar < Isa::Avx2 && Isa::Avx2 < Isa::Avx512);
    }

    #[test]
    fn detection_is_consistent() {
        // Scalar always runs; a level runs exactly when nothing is missing, and the
        // detected level is the widest such.
        assert_eq!(Isa::Scalar.missing(), None);
        assert_eq!(Simd::new(Isa::Scalar), Some(Simd::SCALAR));
        let best = Isa::detected();
        for isa in Isa::ALL {
            assert_eq!(Simd::new(isa).is_some(), isa <= best, "{isa}");
            assert_eq!(isa.missing().is_none(), isa <= best, "{isa}");
        }
        // AVX-512 needs everything AVX2 needs.
        if Isa::Avx2.missing().is_some() {
            assert!(Isa::Avx512.missing().is_some());
        }
        let simd = Simd::detected();
        assert_eq!(simd.avx2(), best >= Isa::Avx2);
        assert_eq!(simd.avx512(), best == Isa::Avx512);
        assert!(!Simd::SCALAR.avx2() && !Simd::SCALAR.avx512());
    }

    #[test]
    fn the_choice_stays_within_the_cpu_and_the_limit() {
        // Whatever PRISM_SIMD says in this process (CI runs the tests with it set), the
        // choice runs on this CPU, stays within a valid limit and says why.
        let c = choice();
        assert!(c.simd.isa() <= Isa::detected());
        if let Ok(Some(limit)) = env_limit() {
            assert!(c.simd.isa() <= limit);
            assert!(
                c.reason.starts_with(&format!("{ENV_VAR}={limit}")),
                "{}",
                c.reason
            );
        }
        assert!(!c.reason.is_empty());
        assert_eq!(active(), c.simd);
        assert_eq!(each_isa().last(), Some(&c.simd));
        assert_eq!(each_isa()[0], Simd::SCALAR);
        assert_eq!(
            format!("{c}"),
            format!("{} ({})", c.simd.isa().name(), c.reason)
        );
    }
}
