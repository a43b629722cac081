//! What `chassis check` does the same on both firmware generations: the question before the
//! chassis moves, the failure's line (the progress line ended, what the stop after it did,
//! judged from what went out and came back, the checks not run, an ending's exit status). Each
//! generation's check is its bring-up from a PC: [`crate::v2020::check`], [`crate::v1::check`].

use crate::ending;
use crate::port::{Port, SharedClock};
use crate::stopping::{HostDriver, Spoken};
use chassis_bringup::link::Blocking;
use chassis_bringup::{Check, LinkError};
use chassis_protocol::driver::Error;
use std::io::{BufRead, IsTerminal, Write as _};
use std::time::Instant;

/// A check under way on either generation: the bring-up's link over the host driver, and what
/// its progress lines and its failure's line need. Each generation's check implements its
/// bring-up's link on it; `T` is what a check done keeps (what it measured, or whether it
/// passed).
pub struct Session<K, T> {
    /// The link over the host driver.
    pub inner: Blocking<Port, SharedClock, K>,
    /// When the check started.
    pub start: Instant,
    /// When the check under way started.
    pub step: Instant,
    /// Telemetry frames taken since the check under way started.
    pub frames: u32,
    /// The checks done.
    pub done: Vec<(Check, T)>,
    /// How the last stop went (`None`: none was sent).
    pub last_stop: Option<StopRecord>,
    /// The check under way.
    pub current: Option<Check>,
}

impl<K: Spoken, T> Session<K, T> {
    /// Asks before the chassis moves (`motion`: what it will do; not with `no_motion` or
    /// `yes`), then opens the board on `path` with `open`.
    pub fn open(
        path: &str,
        no_motion: bool,
        yes: bool,
        motion: &str,
        open: impl FnOnce(&str) -> Result<HostDriver<K>, String>,
    ) -> Result<Self, (String, u8)> {
        let failed = |e: String| (e, 1u8);
        if !no_motion && !yes && !confirm(path, motion).map_err(failed)? {
            return Err(failed("check cancelled: nothing was sent".into()));
        }
        let (uart, clock, core) = open(path).map_err(failed)?.release();
        let reader = clock.detached();
        Ok(Session {
            inner: Blocking::from_driver(HostDriver::from_core(uart, clock, core), reader),
            start: Instant::now(),
            step: Instant::now(),
            frames: 0,
            done: Vec::new(),
            last_stop: None,
            current: None,
        })
    }

    /// `Err` once the command must end: the bring-up fails its check and stops the chassis.
    pub fn go_on(&self) -> Result<(), LinkError> {
        match ending::ended() {
            Some(_) => Err(Error::Transport(embedded_io::ErrorKind::Interrupted)),
            None => Ok(()),
        }
    }

    /// The bring-up's stop (`stop`): never refused, never cut short (an ending is what a stop
    /// is for), and what it did kept for the failure's line.
    pub fn stop(
        &mut self,
        stop: impl FnOnce(&mut Blocking<Port, SharedClock, K>) -> Result<(), LinkError>,
    ) -> Result<(), LinkError> {
        let driver = self.inner.driver();
        driver.uart_mut().uninterrupted();
        let before = driver.uart().stops_sent();
        let result = stop(&mut self.inner);
        let driver = self.inner.driver();
        self.last_stop = Some(StopRecord {
            result,
            sent: driver.uart().stops_sent() > before,
            unheard: crate::stopping::unheard_after_stop(driver),
        });
        result
    }
}

/// The checks of `order` that would have run after `failed` (not those a `--no-motion` run
/// skips), by `name`: what a failed check's line lists as not run (both generations).
pub fn not_run<T>(
    order: impl IntoIterator<Item = Check>,
    failed: Check,
    done: &[(Check, T)],
    no_motion: bool,
    name: fn(Check) -> &'static str,
) -> Vec<&'static str> {
    order
        .into_iter()
        .filter(|c| !done.iter().any(|(d, _)| d == c) && *c != failed)
        .filter(|c| !no_motion || !c.moves())
        .map(name)
        .collect()
}

/// What the check's last stop did: its result, whether the stop frame went out whole, and why
/// the board is not known to have heard it (`None`: its frames were arriving).
#[derive(Clone, Debug)]
pub struct StopRecord {
    /// The stop's result.
    pub result: Result<(), LinkError>,
    /// The stop frame was written whole.
    pub sent: bool,
    /// Why the board is not known to have heard it.
    pub unheard: Option<String>,
}

/// What the stop after a failure did, as the end of the failure's line, from what was sent
/// and what came back: "the chassis was stopped" only when the stop went out and the board's
/// frames were arriving. `forced`: v1.0.0's forced stop; `why` words a driver error.
pub fn stopped_words(
    last_stop: Option<StopRecord>,
    no_motion: bool,
    forced: bool,
    why: impl FnOnce(LinkError) -> String,
) -> String {
    let (stop, how) = if forced {
        ("forced stop", " (forced stop)")
    } else {
        ("stop", "")
    };
    let Some(last) = last_stop.filter(|_| !no_motion) else {
        return if no_motion {
            String::new()
        } else {
            "; nothing had moved".into()
        };
    };
    match (last.sent, last.result, last.unheard) {
        (false, result, _) => format!(
            "; the {stop} could not be sent ({}): the chassis may still be moving, cut its power",
            result
                .err()
                .map_or_else(|| "nothing was written".into(), why)
        ),
        (true, Err(e), _) => format!("; the {stop} was sent but not confirmed: {}", why(e)),
        (true, Ok(()), Some(unheard)) => {
            format!("; the {stop} was sent but not confirmed: {unheard}")
        }
        (true, Ok(()), None) => format!("; the chassis was stopped{how}"),
    }
}

/// A failed check, on either generation.
pub struct Ending {
    /// The failed check's name.
    pub check: &'static str,
    /// A check was under way (its progress line waits for its end).
    pub under_way: bool,
    /// The checks that would have run after it.
    pub not_run: Vec<&'static str>,
    /// What the stop after the failure did ([`stopped_words`]).
    pub stopped: String,
    /// Why it failed, in words.
    pub why: String,
    /// The failed check's exit status.
    pub code: u8,
}

/// Ends the progress line of the check under way and gives the failure's line and exit status:
/// a signal's (128 + its number) if one ended the check, else the check's.
pub fn ending(end: Ending) -> (String, u8) {
    let interrupted = ending::ended();
    if end.under_way {
        say!(
            "{}",
            if interrupted.is_some() {
                "interrupted"
            } else {
                "FAILED"
            }
        );
    }
    let tail = if end.not_run.is_empty() {
        String::new()
    } else {
        format!("; not run: {}", end.not_run.join(", "))
    };
    let stopped = end.stopped;
    match interrupted {
        Some(why) => (
            format!(
                "{} during the {} check{stopped}{tail}",
                why.words(),
                end.check
            ),
            why.exit_status(),
        ),
        None => (
            format!("FAIL: {}: {}{stopped}{tail}", end.check, end.why),
            end.code,
        ),
    }
}

/// Asks before the chassis moves (`motion`: what it will do): `Ok(true)` to go on.
pub fn confirm(path: &str, motion: &str) -> Result<bool, String> {
    let stdin = std::io::stdin();
    if !stdin.is_terminal() {
        return Err(format!(
            "{motion}. Nobody is at a terminal to agree: add --yes to go ahead, or --no-motion to check the link, the registers and the battery only"
        ));
    }
    tell_partial!("chassis check on {path}: {motion}.\nGo ahead? [y/N] ");
    let _ = std::io::stderr().flush();
    let mut answer = String::new();
    stdin
        .lock()
        .read_line(&mut answer)
        .map_err(|e| format!("standard input: {e}"))?;
    Ok(matches!(answer.trim(), "y" | "Y" | "yes" | "Yes"))
}
