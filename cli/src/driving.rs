//! What moving the chassis does the same on both firmware generations: the pump between sends
//! ([`poll_for`]), a velocity held for a while ([`drive_for`]), the stop on the way out and the
//! line that says how the command ended ([`stop_after`]), the progress bar.

use crate::ending;
use crate::stopping::{self, HostDriver, Spoken, Stopped};
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::SerialError;
use std::time::{Duration, Instant};

/// Polls the driver for `ms`, or until the command must end.
pub fn poll_for<K: Spoken>(driver: &mut HostDriver<K>, ms: u64) -> Result<(), String> {
    let until = Instant::now() + Duration::from_millis(ms);
    while Instant::now() < until && ending::ended().is_none() {
        match driver.poll() {
            Ok(Some(_)) => {}
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            // An ending that came during the poll cut its read short (the port's waits look at
            // it): that is the ending, not a link error, and the caller says what of its work
            // the ending left (a turn's angle, a calibration's time), as when the ending comes
            // between two polls.
            Err(_) if ending::ended().is_some() => break,
            Err(e) => return Err(stopping::explain(driver, e)),
        }
    }
    Ok(())
}

/// A progress bar on stderr (drawn only on a terminal).
pub fn progress(len: u64, template: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr_with_hz(10),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}

/// `--for`: 0..=600 s (-0 is 0).
pub fn drive_seconds(seconds: f64) -> Result<f64, String> {
    if !(0.0..=600.0).contains(&seconds) {
        return Err(format!("--for: {seconds} s is out of range (0..=600)"));
    }
    Ok(seconds + 0.0)
}

/// `chassis drive` on either generation, once the port is open: `send` (the velocity) re-sent
/// every 50 ms for `seconds`, a progress bar on a terminal, then the stop. Cut short by any
/// ending or by the driver's failsafe (`failsafe`: what it did, in words). The line to print.
pub fn drive_for<K: Spoken>(
    driver: &mut HostDriver<K>,
    seconds: f64,
    mut send: impl FnMut(&mut HostDriver<K>) -> Result<(), Error<SerialError>>,
    failsafe: &str,
) -> Result<String, String> {
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(seconds);
    let bar = progress(
        (seconds * 10.0).round() as u64,
        "driving {bar:30} {msg} (Ctrl-C stops)",
    );
    let mut next = Instant::now();
    let ended = loop {
        if Instant::now() >= end {
            break Ok(format!("drove {seconds} s, stopped{}", K::STOPPED_HOW));
        }
        if let Some(end) = ending::ended() {
            break Err(end.words());
        }
        if Instant::now() >= next {
            if let Err(e) = send(driver) {
                break Err(stopping::explain(driver, e));
            }
            next += Duration::from_millis(50);
        }
        if let Err(e) = poll_for(driver, 5) {
            break Err(e);
        }
        if driver.core().failsafe_stops() > 0 {
            break Err(stopping::failsafe_words(driver, failsafe));
        }
        let done = start.elapsed().as_secs_f64().min(seconds);
        bar.set_position((done * 10.0) as u64);
        bar.set_message(format!("{done:.1}/{seconds} s"));
    };
    bar.finish_and_clear();
    stop_after(driver, ended)
}

/// Stops the chassis (on the 2020 firmware cancelling a turn) and says how the command ended:
/// `ended` is what happened (`Ok`: a line for stdout); the ending that cut it short comes
/// first.
pub fn stop_after<K: Spoken>(
    driver: &mut HostDriver<K>,
    ended: Result<String, String>,
) -> Result<String, String> {
    let stopped = stopping::stop(driver);
    let words = stopped.words::<K>();
    if let Some(end) = ending::ended() {
        let end = end.words();
        // A wait the ending cut short says only the ending's words: not said twice.
        return Err(match ended {
            Err(detail) if !detail.contains(&end) => format!("{end}: {detail}; {words}"),
            _ => format!("{end}: {words}"),
        });
    }
    match (ended, stopped) {
        (Ok(line), Stopped::Confirmed) => Ok(line),
        (Ok(line), _) => Err(format!("{line}, but {words}")),
        (Err(e), _) => Err(format!("{e}; {words}")),
    }
}
