//! SIGINT (Ctrl-C), SIGTERM and SIGHUP (a closed terminal or ssh session) as a flag: a command
//! that moves the chassis, or watches it, checks the flag in its loop, stops the chassis
//! (cancelling a turn) and exits with 128 + the signal's number. SIGKILL cannot be caught:
//! then the driver's failsafe is gone with the process, and only the board's own watchdog (if
//! any) stops the chassis.

use std::sync::Arc;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

static CAUGHT: OnceLock<Arc<AtomicUsize>> = OnceLock::new();

#[cfg(unix)]
const SIGNALS: [(i32, &str); 3] = [
    (signal_hook::consts::SIGINT, "SIGINT"),
    (signal_hook::consts::SIGTERM, "SIGTERM"),
    (signal_hook::consts::SIGHUP, "SIGHUP"),
];
#[cfg(not(unix))]
const SIGNALS: [(i32, &str); 2] = [
    (signal_hook::consts::SIGINT, "SIGINT"),
    (signal_hook::consts::SIGTERM, "SIGTERM"),
];

/// From now on, the signals only set the flag (once per process; later calls do nothing).
pub fn install() -> Result<(), String> {
    if CAUGHT.get().is_some() {
        return Ok(());
    }
    let flag = Arc::new(AtomicUsize::new(0));
    for (signal, name) in SIGNALS {
        let value = usize::try_from(signal).unwrap_or(usize::MAX);
        signal_hook::flag::register_usize(signal, Arc::clone(&flag), value)
            .map_err(|e| format!("cannot handle {name}: {e}"))?;
    }
    let _ = CAUGHT.set(flag);
    Ok(())
}

/// The signal caught, if any.
pub fn caught() -> Option<i32> {
    let value = CAUGHT.get()?.load(Ordering::SeqCst);
    if value == 0 {
        None
    } else {
        i32::try_from(value).ok()
    }
}

/// A signal's name ("SIGINT").
pub fn name(signal: i32) -> &'static str {
    SIGNALS
        .iter()
        .find(|(s, _)| *s == signal)
        .map_or("a signal", |(_, n)| n)
}

/// The process's exit status after `signal`: 128 + its number, as a shell reports a process
/// the signal ended.
pub fn exit_status(signal: i32) -> u8 {
    u8::try_from(128 + signal).unwrap_or(1)
}
