//! Ctrl-C and SIGTERM during a render: the first asks the render to stop (no new work
//! item starts; those in flight finish and the film so far is written as a checkpoint and
//! as the output, marked partial); a second ends the process at once, removing the
//! temporary file of a write in progress so that only whole files are ever left (the last
//! checkpoint stays as it was).
//!
//! signal-hook registers the handlers: it chains with handlers already installed, and its
//! `low_level::register` takes a closure, so the second signal can remove files by paths
//! prepared in advance — with `unlink(2)` and `_exit(2)` only, which are
//! async-signal-safe (ctrlc's one handler per process and its thread could not do this).

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::OnceLock;

static STOP: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicI32 = AtomicI32::new(0);
/// The temporary files this process may be writing (set before the handlers).
static TEMP_FILES: OnceLock<Vec<CString>> = OnceLock::new();

/// Set by the first signal.
pub fn stop_flag() -> &'static AtomicBool {
    &STOP
}

/// The signal that stopped the render, if one did.
pub fn received() -> Option<i32> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// The signal's name for messages.
pub fn name(signal: i32) -> &'static str {
    match signal {
        libc::SIGINT => "SIGINT (Ctrl-C)",
        libc::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// Installs the handlers for SIGINT and SIGTERM; `temp_files` are the temporary siblings
/// of every file the render may write (`prism_image::io::temp_sibling`).
pub fn install(temp_files: &[PathBuf]) -> Result<(), String> {
    let paths: Vec<CString> = temp_files
        .iter()
        .filter_map(|p| CString::new(p.as_os_str().as_bytes()).ok())
        .collect();
    let _ = TEMP_FILES.set(paths);
    for signal in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: the handler only touches atomics, reads the prepared paths and calls
        // unlink(2) and _exit(2), which are async-signal-safe.
        unsafe { signal_hook::low_level::register(signal, move || on_signal(signal)) }
            .map_err(|e| format!("cannot handle {}: {e}", name(signal)))?;
    }
    Ok(())
}

fn on_signal(signal: i32) {
    if STOP.swap(true, Ordering::SeqCst) {
        if let Some(files) = TEMP_FILES.get() {
            for f in files {
                // SAFETY: a NUL-terminated path that lives for the whole process.
                unsafe {
                    libc::unlink(f.as_ptr());
                }
            }
        }
        signal_hook::low_level::exit(128 + signal);
    }
    SIGNAL.store(signal, Ordering::SeqCst);
}
