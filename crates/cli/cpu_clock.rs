//! CPU clocks of this process and of the calling thread (`clock_gettime`), for the
//! commands that report CPU time (`prism converge --clock cpu`, the predictor's time in
//! `prism render --stats-json`). `None` where the platform has no such clock.

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
