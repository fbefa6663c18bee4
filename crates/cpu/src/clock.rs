//! CPU clocks of this process and of the calling thread (`clock_gettime`), for the
//! commands that report CPU time (`prism converge --clock cpu`, the predictor's time in
//! `prism render --stats-json`) and the benchmarks in tools/; and the machine's load, which
//! their JSON records beside the times. `None` where the platform has no such clock.

#[cfg(unix)]
fn cpu_clock_s(clock: libc::clockid_t) -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant.
    let rc = unsafe { libc::clock_gettime(clock, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// CPU time of the whole process (all threads), s.
pub fn process_cpu_s() -> Option<f64> {
    #[cfg(unix)]
    {
        cpu_clock_s(libc::CLOCK_PROCESS_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// CPU time of the calling thread, s.
pub fn thread_cpu_s() -> Option<f64> {
    #[cfg(unix)]
    {
        cpu_clock_s(libc::CLOCK_THREAD_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The 1-minute load average (`/proc/loadavg`; `None` where there is none): timings on a
/// busy machine read differently.
pub fn load_average_1m() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    #[test]
    fn the_clocks_advance_and_the_load_reads_on_linux() {
        let (p0, t0) = (process_cpu_s().unwrap(), thread_cpu_s().unwrap());
        // Spin until this thread's clock moves (its resolution is far below a second).
        let mut x = 0u64;
        while thread_cpu_s().unwrap() <= t0 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        assert!(process_cpu_s().unwrap() > p0);
        let load = load_average_1m().expect("/proc/loadavg");
        assert!(load.is_finite() && load >= 0.0, "{load}");
    }
}
