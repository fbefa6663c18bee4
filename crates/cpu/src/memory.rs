//! How much memory a command may use: the `--max-memory SIZE` limit (default 75 % of the
//! physical memory) and the check a command makes with its estimate before it allocates.
//!
//! Commands estimate what they need from sizes known before the work (a film's resolution
//! and layers, an image file's header) and call [`MemoryBudget::check`]; a refusal names
//! the work, the estimate and the limit, so a user can lower the size or raise
//! `--max-memory`. Any code that allocates in proportion to its input (the film, images,
//! metrics, later photon maps) asks the same budget.

use std::fmt;

/// Share of the physical memory a command may use when `--max-memory` is not given.
pub const DEFAULT_FRACTION_OF_PHYSICAL: f64 = 0.75;

/// Where a budget's limit came from (what a refusal tells the user to change).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimitOrigin {
    /// `--max-memory` (or a caller's explicit limit).
    Given,
    /// [`DEFAULT_FRACTION_OF_PHYSICAL`] of this many bytes of physical memory.
    DefaultOfPhysical { physical_bytes: u64 },
    /// The physical memory could not be read (not Linux): no limit.
    Unlimited,
}

/// The memory a command may use, bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    pub limit_bytes: u64,
    pub origin: LimitOrigin,
}

/// A refused estimate: what would have been allocated and the limit it exceeds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverBudget {
    pub what: String,
    pub estimate_bytes: u64,
    pub budget: MemoryBudget,
}

impl fmt::Display for OverBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} needs about {}, more than the memory limit of {}",
            self.what,
            format_bytes(self.estimate_bytes),
            format_bytes(self.budget.limit_bytes)
        )?;
        match self.budget.origin {
            LimitOrigin::Given => write!(f, " set by --max-memory"),
            LimitOrigin::DefaultOfPhysical { physical_bytes } => write!(
                f,
                " ({:.0} % of the {} of physical memory; raise it with --max-memory SIZE, \
                 e.g. --max-memory 64G)",
                100.0 * DEFAULT_FRACTION_OF_PHYSICAL,
                format_bytes(physical_bytes)
            ),
            LimitOrigin::Unlimited => Ok(()),
        }
    }
}

impl MemoryBudget {
    /// [`DEFAULT_FRACTION_OF_PHYSICAL`] of [`physical_memory_bytes`], or no limit where it
    /// cannot be read.
    pub fn machine_default() -> Self {
        match physical_memory_bytes() {
            Some(physical_bytes) => Self {
                limit_bytes: (physical_bytes as f64 * DEFAULT_FRACTION_OF_PHYSICAL) as u64,
                origin: LimitOrigin::DefaultOfPhysical { physical_bytes },
            },
            None => Self {
                limit_bytes: u64::MAX,
                origin: LimitOrigin::Unlimited,
            },
        }
    }

    /// A budget of `limit_bytes` given by the user.
    pub fn given(limit_bytes: u64) -> Self {
        Self {
            limit_bytes,
            origin: LimitOrigin::Given,
        }
    }

    /// Refuses `estimate_bytes` above the limit; `what` names the work ("rendering
    /// 640×480 px with 3 spectral bins").
    pub fn check(&self, what: &str, estimate_bytes: u64) -> Result<(), OverBudget> {
        if estimate_bytes <= self.limit_bytes {
            Ok(())
        } else {
            Err(OverBudget {
                what: what.to_string(),
                estimate_bytes,
                budget: *self,
            })
        }
    }
}

/// The memory this process can have: the smaller of `MemTotal` in /proc/meminfo and a
/// cgroup v2 limit (`memory.max` of the process's cgroup, as in a container). `None` where
/// neither can be read.
pub fn physical_memory_bytes() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| meminfo_total_bytes(&text));
    let cgroup = cgroup_limit_bytes();
    match (total, cgroup) {
        (Some(t), Some(c)) => Some(t.min(c)),
        (Some(t), None) => Some(t),
        (None, c) => c,
    }
}

/// `MemTotal:  131596284 kB` → bytes.
fn meminfo_total_bytes(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The cgroup v2 `memory.max` of this process (`None` when unlimited or unreadable).
fn cgroup_limit_bytes() -> Option<u64> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    // cgroup v2: a single line `0::/path`.
    let path = cgroup.lines().find_map(|l| l.strip_prefix("0::"))?;
    let file = format!("/sys/fs/cgroup{}/memory.max", path.trim_end_matches('/'));
    std::fs::read_to_string(file).ok()?.trim().parse().ok()
}

/// `512M`, `8G`, `1.5GiB`, `100000` (bytes): a size with an optional binary suffix (K, M,
/// G, T = 2¹⁰, 2²⁰, 2³⁰, 2⁴⁰ bytes, with or without `B`/`iB`; case ignored). Errors say
/// what was expected.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let s = text.trim();
    let digits_end = s
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(s.len());
    let (number, suffix) = s.split_at(digits_end);
    let expected =
        || format!("`{text}`: expected a size such as 512M, 8G or 1.5T (bytes without a suffix)");
    let value: f64 = number.parse().map_err(|_| expected())?;
    let unit: u64 = match suffix.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        _ => return Err(expected()),
    };
    let bytes = value * unit as f64;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "`{text}`: expected a size of at least 1 byte and below 16 EiB"
        ));
    }
    Ok(bytes as u64)
}

/// Bytes with a binary unit and three significant digits: `37.3 GiB`.
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else if value >= 100.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else if value >= 10.0 {
        format!("{value:.1} {}", UNITS[unit])
    } else {
        format!("{value:.2} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_suffixes() {
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("8gib"), Ok(8 << 30));
        assert_eq!(parse_size("1.5T"), Ok(3 << 39));
        assert_eq!(parse_size("100000"), Ok(100000));
        assert_eq!(parse_size(" 2k "), Ok(2048));
        for bad in ["", "G", "8X", "-1G", "0", "1e3", "99999999999T"] {
            let e = parse_size(bad).unwrap_err();
            assert!(e.contains(&format!("`{bad}`")), "{e}");
        }
    }

    #[test]
    fn meminfo_is_read_in_kib() {
        let text = "MemTotal:       16384 kB\nMemFree:  12 kB\n";
        assert_eq!(meminfo_total_bytes(text), Some(16384 * 1024));
        assert_eq!(meminfo_total_bytes("MemFree: 1 kB"), None);
    }

    #[test]
    fn the_default_is_three_quarters_of_physical_memory() {
        let budget = MemoryBudget::machine_default();
        match budget.origin {
            LimitOrigin::DefaultOfPhysical { physical_bytes } => {
                assert!(physical_bytes > 0);
                assert_eq!(budget.limit_bytes, (physical_bytes as f64 * 0.75) as u64);
            }
            LimitOrigin::Unlimited => assert_eq!(budget.limit_bytes, u64::MAX),
            LimitOrigin::Given => panic!("the default is not a given limit"),
        }
    }

    #[test]
    fn a_refusal_names_the_work_the_estimate_and_the_option() {
        let budget = MemoryBudget::given(1 << 30);
        assert!(budget.check("small", 1 << 30).is_ok());
        let e = budget.check("rendering 9×9 px", (1 << 30) + 1).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("rendering 9×9 px"), "{text}");
        assert!(text.contains("1.00 GiB"), "{text}");
        assert!(text.contains("--max-memory"), "{text}");
        let default = MemoryBudget {
            limit_bytes: 3 << 30,
            origin: LimitOrigin::DefaultOfPhysical {
                physical_bytes: 4 << 30,
            },
        };
        let text = default.check("x", 40 << 30).unwrap_err().to_string();
        assert!(text.contains("40.0 GiB") && text.contains("75 %"), "{text}");
        assert!(
            text.contains("4.00 GiB") && text.contains("--max-memory"),
            "{text}"
        );
    }

    #[test]
    fn bytes_format_with_three_digits() {
        assert_eq!(format_bytes(512), "512 bytes");
        assert_eq!(format_bytes(1536), "1.50 KiB");
        assert_eq!(format_bytes(40 << 30), "40.0 GiB");
        assert_eq!(format_bytes(300 << 40), "300 TiB");
    }
}
