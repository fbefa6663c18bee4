//! Progress of `prism render` on stderr: a bar with ETA on a terminal (`--progress auto`),
//! or for log files of farm jobs a plain line every N seconds (`--progress plain`):
//! samples done, per cent, elapsed time and ETA.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::render::ProgressArg;

/// A running progress report.
pub struct Progress {
    bar: ProgressBar,
    done: Arc<AtomicU64>,
    finished: Arc<AtomicBool>,
    printer: Option<JoinHandle<()>>,
}

fn bar(total: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{elapsed_precise} [{bar:40}] {percent:>3}% {per_sec} samples, ETA {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// One plain progress line.
pub fn plain_line(label: &str, done: u64, total: u64, elapsed: Duration) -> String {
    let fraction = if total > 0 {
        done as f64 / total as f64
    } else {
        1.0
    };
    let elapsed_s = elapsed.as_secs_f64();
    let eta = if fraction > 0.0 {
        format!("{:.0} s", elapsed_s * (1.0 - fraction) / fraction)
    } else {
        "unknown".to_string()
    };
    format!(
        "{label}: {:.1} % ({done} of {total} samples), {elapsed_s:.0} s elapsed, ETA {eta}",
        100.0 * fraction
    )
}

impl Progress {
    /// Starts reporting `total` samples as `mode` asks; `label` starts plain lines.
    pub fn start(mode: ProgressArg, every: Duration, total: u64, label: &str) -> Self {
        let done = Arc::new(AtomicU64::new(0));
        let finished = Arc::new(AtomicBool::new(false));
        let (bar, printer) = match mode {
            ProgressArg::Auto => (bar(total), None),
            ProgressArg::None => (ProgressBar::hidden(), None),
            ProgressArg::Plain => {
                let (done, finished) = (Arc::clone(&done), Arc::clone(&finished));
                let label = label.to_string();
                let printer = std::thread::spawn(move || {
                    let start = Instant::now();
                    let mut next = every;
                    // Short sleeps so that the end of the render is not delayed by `every`.
                    while !finished.load(Ordering::Relaxed) {
                        std::thread::sleep(Duration::from_millis(50));
                        if start.elapsed() >= next {
                            next += every;
                            eprintln!(
                                "{}",
                                plain_line(
                                    &label,
                                    done.load(Ordering::Relaxed),
                                    total,
                                    start.elapsed()
                                )
                            );
                        }
                    }
                });
                (ProgressBar::hidden(), Some(printer))
            }
        };
        Self {
            bar,
            done,
            finished,
            printer,
        }
    }

    pub fn inc(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
        self.bar.inc(n);
    }

    pub fn finish(mut self) {
        self.finished.store(true, Ordering::Relaxed);
        if let Some(p) = self.printer.take() {
            let _ = p.join();
        }
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_lines_say_share_counts_and_eta() {
        let line = plain_line("scene.json", 250, 1000, Duration::from_secs(10));
        assert_eq!(
            line,
            "scene.json: 25.0 % (250 of 1000 samples), 10 s elapsed, ETA 30 s"
        );
        assert!(plain_line("s", 0, 10, Duration::from_secs(1)).ends_with("ETA unknown"));
    }
}
