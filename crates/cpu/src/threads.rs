//! The bound on worker-thread counts a user may ask for (`--threads N`): at most
//! [`MAX_THREADS_PER_CPU`] per logical CPU. More threads than that only add scheduling
//! and stack memory (each rayon worker reserves its stack), and 10⁵ of them ran the
//! machine out of threads before any work was done.

/// Threads per logical CPU a command accepts.
pub const MAX_THREADS_PER_CPU: usize = 4;

/// Logical CPUs this process may run on (1 where unknown).
pub fn logical_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The most worker threads a command accepts on this machine.
pub fn max_threads() -> usize {
    MAX_THREADS_PER_CPU * logical_cpus()
}

/// `--threads N`: a whole number from 1 to [`max_threads`]; the error says the range and
/// why (clap reports it as a usage error).
pub fn parse_thread_count(text: &str) -> Result<usize, String> {
    let max = max_threads();
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}`: expected a whole number of threads from 1 to {max}"))?;
    check_thread_count(text, n, max)
}

fn check_thread_count(text: &str, n: usize, max: usize) -> Result<usize, String> {
    if n == 0 {
        return Err(format!(
            "`{text}`: expected at least 1 thread (at most {max})"
        ));
    }
    if n > max {
        return Err(format!(
            "`{text}`: at most {max} threads ({MAX_THREADS_PER_CPU} per logical CPU, {} here)",
            max / MAX_THREADS_PER_CPU
        ));
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_counts_are_bounded_by_four_per_cpu() {
        assert_eq!(check_thread_count("1", 1, 8), Ok(1));
        assert_eq!(check_thread_count("8", 8, 8), Ok(8));
        assert!(check_thread_count("9", 9, 8)
            .unwrap_err()
            .contains("at most 8"));
        assert!(check_thread_count("0", 0, 8)
            .unwrap_err()
            .contains("at least 1"));
        assert!(parse_thread_count("100000").is_err() || max_threads() >= 100000);
        assert!(parse_thread_count("many")
            .unwrap_err()
            .contains("whole number"));
        assert_eq!(parse_thread_count("1"), Ok(1));
    }
}
