//! What `chassis check` does the same on both firmware generations: the question before the
//! chassis moves, the bring-up's link over the host driver with a progress line per check
//! ([`Session`]), the failure's line (the progress line ended, what the stop after it did,
//! judged from what went out and came back, the checks not run, an ending's exit status). Each
//! generation's check is its bring-up from a PC: [`crate::v2020::check`], [`crate::v1::check`];
//! what its progress lines say of it is its [`Steps`].

use crate::ending;
use crate::port::{Port, SharedClock};
use crate::stopping::{HostDriver, Spoken, core_words};
use chassis_bringup::link::{Blocking, Common};
use chassis_bringup::{Check, Failure, LinkError, Note, Skip, Timing};
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::Heard;
use std::io::{BufRead, IsTerminal, Write as _};
use std::time::Instant;

/// What a generation's check says of itself in its progress lines and its verdict,
/// implemented on its driver core: its checks, their names, what a check passed measured, why
/// one was skipped, what the verdict says of its bring-up's report.
pub trait Steps: Spoken + Sized {
    /// What the generation's bring-up reports when every check passed.
    type Report;
    /// What the verdict's pass line says after the time taken.
    const PASS_NOTE: &'static str;
    /// The generation's checks, in the order its bring-up runs them.
    fn checks() -> impl Iterator<Item = Check>;
    /// A check's name.
    fn name(check: Check) -> &'static str;
    /// Whether `event` is a telemetry frame (counted in [`Session::frames`]).
    fn telemetry(event: &Self::Event) -> bool;
    /// What `check`, just passed in `seconds`, measured, for its progress line.
    fn detail(session: &Session<Self>, check: Check, seconds: f64) -> String;
    /// Why a check was skipped, in words.
    fn skipped(why: Skip) -> &'static str;
    /// What a passed check found, for its line of the verdict (`said`: what its progress line
    /// said).
    fn found(check: Check, said: &str, report: &Self::Report) -> String;
    /// What the link lost or refused, for the verdict's last line.
    fn counted(report: &Self::Report) -> String;
}

/// A check under way on either generation: the bring-up's link over the host driver, and what
/// its progress lines and its failure's line need. Each generation's check implements its
/// bring-up's link on it.
pub struct Session<K> {
    /// The link over the host driver.
    pub inner: Blocking<Port, SharedClock, K>,
    /// When the check started.
    pub start: Instant,
    /// When the check under way started.
    pub step: Instant,
    /// Telemetry frames taken since the check under way started.
    pub frames: u32,
    /// The checks done, each with what it measured (`None`: skipped).
    pub done: Vec<(Check, Option<String>)>,
    /// How the last stop went (`None`: none was sent).
    pub last_stop: Option<StopRecord>,
    /// The check under way.
    pub current: Option<Check>,
}

impl<K: Steps> Session<K> {
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

    /// How the check ended, once its bring-up gave `result`: the verdict on one screen
    /// ([`verdict`]), or the failure's line and exit status ([`Session::failed`]; `why` words
    /// the reason, told what came from the board).
    pub fn conclude<W>(
        &mut self,
        result: Result<K::Report, Failure<W>>,
        no_motion: bool,
        path: &str,
        why: impl FnOnce(W, Heard) -> String,
    ) -> Result<(), (String, u8)> {
        let seconds = self.start.elapsed().as_secs_f64();
        match result {
            Ok(report) => {
                say!(
                    "\n{}",
                    verdict::<K>(&report, &self.done, !no_motion, seconds)
                );
                Ok(())
            }
            Err(Failure { check, why: reason }) => {
                Err(self.failed(check, no_motion, path, |heard| why(reason, heard)))
            }
        }
    }

    /// The failure's line and exit status once `check` failed: why (`why` words it, told what
    /// came from the board), what the stop after it did, the checks not run.
    fn failed(
        &mut self,
        check: Check,
        no_motion: bool,
        path: &str,
        why: impl FnOnce(Heard) -> String,
    ) -> (String, u8) {
        let now = self.now_ms();
        let heard = Common::core(self).heard_at(now);
        let stopped = stopped_words::<K>(self.last_stop.take(), no_motion, |e| {
            driver_words(e, heard, path)
        });
        ending(Ending {
            check: K::name(check),
            under_way: self.current.is_some(),
            not_run: not_run::<K>(check, &self.done, no_motion),
            stopped,
            why: why(heard),
            code: u8::try_from(check.exit_code()).unwrap_or(1),
        })
    }
}

/// The bring-up's link calls every generation makes, over the host driver: an ending turned
/// into an error at the next call (the bring-up then stops the chassis itself), the stop kept
/// for the failure's line, a progress line per check.
impl<K: Steps> Common for Session<K> {
    type Core = K;
    type Event = K::Event;
    fn now_ms(&mut self) -> u64 {
        self.inner.now_ms()
    }
    fn core(&self) -> &K {
        Common::core(&self.inner)
    }
    fn poll(&mut self) -> Result<Option<K::Event>, LinkError> {
        self.go_on()?;
        let event = self.inner.poll()?;
        if event.as_ref().is_some_and(K::telemetry) {
            self.frames = self.frames.saturating_add(1);
        }
        Ok(event)
    }
    fn stop(&mut self) -> Result<(), LinkError> {
        Session::stop(self, Common::stop)
    }
    fn note(&mut self, note: Note) {
        let index = |c: Check| K::checks().position(|x| x == c).unwrap_or(0) + 1;
        let count = K::checks().count();
        let mut out = std::io::stdout().lock();
        match note {
            Note::Start(check) => {
                self.step = Instant::now();
                self.frames = 0;
                self.current = Some(check);
                let _ = write!(out, "[{}/{count}] {:<13}", index(check), K::name(check));
            }
            Note::Passed(check) => {
                let seconds = self.step.elapsed().as_secs_f64();
                let detail = K::detail(self, check, seconds);
                let _ = writeln!(out, "ok    {seconds:>4.1} s  {detail}");
                self.done.push((check, Some(detail)));
                self.current = None;
            }
            Note::Skipped(check, why) => {
                let _ = writeln!(
                    out,
                    "[{}/{count}] {:<13}skipped ({})",
                    index(check),
                    K::name(check),
                    K::skipped(why)
                );
                self.done.push((check, None));
            }
        }
        let _ = out.flush();
    }
}

/// A driver error that failed a check, in words, told by what came from the board on `port`.
pub fn driver_words(e: LinkError, heard: Heard, port: &str) -> String {
    match e {
        Error::Transport(embedded_io::ErrorKind::Interrupted) => "interrupted".into(),
        Error::Core(e) => core_words(e, heard, port),
        Error::Transport(kind) => format!(
            "the serial port failed ({kind:?}): was the adapter unplugged, or the board's power cut?"
        ),
        e => format!("the driver failed: {e:?}"),
    }
}

/// The checks of `K` that would have run after `failed` (not those a `--no-motion` run
/// skips), by name: what a failed check's line lists as not run.
fn not_run<K: Steps>(
    failed: Check,
    done: &[(Check, Option<String>)],
    no_motion: bool,
) -> Vec<&'static str> {
    K::checks()
        .filter(|c| !done.iter().any(|(d, _)| d == c) && *c != failed)
        .filter(|c| !no_motion || !c.moves())
        .map(K::name)
        .collect()
}

/// The plan's timing on either generation: the bring-up's own, the checks that move the
/// chassis run or not.
pub const fn timing(no_motion: bool) -> Timing {
    Timing {
        motion: !no_motion,
        ..Timing::DEFAULT
    }
}

/// The verdict of a passed check on `K`, from its bring-up's `report`: the pass line, a line
/// per check done, then what the link lost or refused and what became of the chassis
/// (`motion`: it was let move).
fn verdict<K: Steps>(
    report: &K::Report,
    done: &[(Check, Option<String>)],
    motion: bool,
    seconds: f64,
) -> String {
    let passed = done.iter().filter(|(_, s)| s.is_some()).count();
    let skipped = done.len() - passed;
    let mut lines = vec![format!(
        "PASS: {passed} checks passed{} in {seconds:.1} s{}",
        if skipped > 0 {
            format!(", {skipped} skipped")
        } else {
            String::new()
        },
        K::PASS_NOTE
    )];
    for (check, state) in done {
        let detail = match state {
            None => "skipped".to_string(),
            Some(said) => K::found(*check, said, report),
        };
        lines.push(format!("  {:<13} {detail}", K::name(*check)));
    }
    lines.push(format!(
        "  {}; {}",
        K::counted(report),
        if motion {
            format!("the chassis is stopped{}", K::STOPPED_HOW)
        } else {
            "nothing moved, nothing was written".into()
        }
    ));
    lines.join("\n")
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
/// frames were arriving. `K` names the stop (v1.0.0's is the forced stop); `why` words a
/// driver error.
fn stopped_words<K: Spoken>(
    last_stop: Option<StopRecord>,
    no_motion: bool,
    why: impl FnOnce(LinkError) -> String,
) -> String {
    let (stop, how) = (K::STOP, K::STOPPED_HOW);
    let Some(last) = last_stop.filter(|_| !no_motion) else {
        return if no_motion {
            String::new()
        } else {
            "; nothing had moved".into()
        };
    };
    match (last.sent, last.result, last.unheard) {
        (false, result, _) => format!(
            "; {stop} could not be sent ({}): the chassis may still be moving, cut its power",
            result
                .err()
                .map_or_else(|| "nothing was written".into(), why)
        ),
        (true, Err(e), _) => format!("; {stop} was sent but not confirmed: {}", why(e)),
        (true, Ok(()), Some(unheard)) => {
            format!("; {stop} was sent but not confirmed: {unheard}")
        }
        (true, Ok(()), None) => format!("; the chassis was stopped{how}"),
    }
}

/// A failed check, on either generation.
struct Ending {
    /// The failed check's name.
    check: &'static str,
    /// A check was under way (its progress line waits for its end).
    under_way: bool,
    /// The checks that would have run after it.
    not_run: Vec<&'static str>,
    /// What the stop after the failure did ([`stopped_words`]).
    stopped: String,
    /// Why it failed, in words.
    why: String,
    /// The failed check's exit status.
    code: u8,
}

/// Ends the progress line of the check under way and gives the failure's line and exit status:
/// a signal's (128 + its number) if one ended the check, else the check's.
fn ending(end: Ending) -> (String, u8) {
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
