//! Stopping the chassis on a command's way out, and saying only what is known of it: what went
//! out (the port counts the stop frames it wrote whole) and what came back (the board's frames).
//! "The chassis was stopped" is said only when the stop went out and the board's frames were
//! arriving; a stop whose write failed is never said to have been sent.

use crate::port::{Port, SharedClock};
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::host::{Heard, SerialError, words_heard};
use chassis_protocol::driver::{Core, DriverCore, Error, TurnState, v1};

/// What the CLI needs of a generation's driver core to say what a stop did.
pub trait Spoken: Core {
    /// The stop frame's name: "the stop", "the forced stop".
    const STOP: &'static str;
    /// The firmware's name: "2020", "v1.0.0".
    const FIRMWARE: &'static str;
    /// How a drive's end says the chassis was stopped, after "stopped": "", " (forced stop)".
    const STOPPED_HOW: &'static str;
    /// Times the driver's failsafe has stopped the chassis.
    fn failsafe_stops(&self) -> u32;
    /// What has come from the board, judged at `now_ms`.
    fn heard_at(&self, now_ms: u64) -> Heard;
    /// A turn the board may still have pending (a cancellation not confirmed).
    fn turn_unsettled(&self) -> bool {
        false
    }
}

impl Spoken for DriverCore {
    const STOP: &'static str = "the stop";
    const FIRMWARE: &'static str = "2020";
    const STOPPED_HOW: &'static str = "";
    fn failsafe_stops(&self) -> u32 {
        DriverCore::failsafe_stops(self)
    }
    fn heard_at(&self, now_ms: u64) -> Heard {
        self.heard(now_ms)
    }
    fn turn_unsettled(&self) -> bool {
        // `Unknown` is a turn nobody sent here: it is no reason to speak of one.
        matches!(self.turn_state(), TurnState::Turning { .. })
    }
}

impl Spoken for v1::DriverCore {
    const STOP: &'static str = "the forced stop";
    const FIRMWARE: &'static str = "v1.0.0";
    const STOPPED_HOW: &'static str = " (forced stop)";
    fn failsafe_stops(&self) -> u32 {
        v1::DriverCore::failsafe_stops(self)
    }
    fn heard_at(&self, now_ms: u64) -> Heard {
        self.heard(now_ms)
    }
}

/// A host driver of either generation over the CLI's port.
pub type HostDriver<K> = Driver<Port, SharedClock, K>;

/// A driver error as one line, in the CLI's words. "Is it powered?" only when nothing at all
/// came from the board.
pub fn explain<K: Spoken>(driver: &HostDriver<K>, e: Error<SerialError>) -> String {
    let port = driver.uart().name();
    match e {
        Error::Core(e) => words_heard(e, driver.core().heard_at(driver.uart().now_ms()), port),
        Error::Transport(e) => format!("serial port {port}: {}", e.0),
        other => other.to_string(),
    }
}

/// What a stop did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Stopped {
    /// The stop went out whole and the board's frames were arriving (a turn's cancellation
    /// confirmed).
    Confirmed,
    /// The stop went out whole; why that is all that is known.
    Unconfirmed(String),
    /// No stop went out: why.
    NotSent(String),
}

impl Stopped {
    /// Whether the chassis is known to have been stopped.
    pub fn confirmed(&self) -> bool {
        *self == Stopped::Confirmed
    }

    /// What the stop did, for a person: "the chassis was stopped", "the stop was sent but not
    /// confirmed: …", "the stop could not be sent (…): …".
    pub fn words<K: Spoken>(&self) -> String {
        match self {
            Stopped::Confirmed => "the chassis was stopped".into(),
            Stopped::Unconfirmed(why) => format!("{} was sent but not confirmed: {why}", K::STOP),
            Stopped::NotSent(why) => format!(
                "{} could not be sent ({why}): the chassis may still be moving; run `chassis stop` once the port is back",
                K::STOP
            ),
        }
    }
}

/// Stops the chassis (on the 2020 firmware cancelling a turn), the port's waits no longer cut
/// short by the command's ending: what the stop did, from what was sent and what came back.
pub fn stop<K: Spoken>(driver: &mut HostDriver<K>) -> Stopped {
    driver.uart_mut().uninterrupted();
    let before = driver.uart().stops_sent();
    let result = driver.stop();
    let sent = driver.uart().stops_sent() > before;
    match result {
        Err(e) if !sent => Stopped::NotSent(explain(driver, e)),
        Err(e) => Stopped::Unconfirmed(format!("{}{}", explain(driver, e), pending_turn(driver))),
        Ok(()) if !sent => Stopped::NotSent("nothing was written".into()),
        Ok(()) if driver.core().turn_unsettled() => {
            Stopped::Unconfirmed(pending_turn(driver).trim_start_matches("; ").into())
        }
        Ok(()) => match unheard_after_stop(driver) {
            None => Stopped::Confirmed,
            Some(why) => Stopped::Unconfirmed(why),
        },
    }
}

/// How long a stop waits for the board's first frame when none has come yet (a driver opened
/// a moment ago: v1.0.0 sends a frame every 39-47 ms, the 2020 board every 10 ms).
const FIRST_FRAME: std::time::Duration = std::time::Duration::from_millis(150);

/// Waits up to [`FIRST_FRAME`] for the board's first frame when none has come yet (nothing,
/// or the tail of a frame the port opened in the middle of), so that a stop right after the
/// port opened is judged by what the board sends.
fn await_first_frame<K: Spoken>(driver: &mut HostDriver<K>) {
    let until = std::time::Instant::now() + FIRST_FRAME;
    while matches!(
        driver.core().heard_at(driver.uart().now_ms()),
        Heard::Nothing | Heard::NoFrame
    ) && std::time::Instant::now() < until
    {
        if driver.poll().is_err() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}

/// After a stop went out: why the board is not known to have heard it (`None`: its frames
/// are arriving), waiting up to 150 ms for the first one when none came yet.
pub fn unheard_after_stop<K: Spoken>(driver: &mut HostDriver<K>) -> Option<String> {
    await_first_frame(driver);
    unheard(driver)
}

/// Why the board is not known to have heard: `None` when its frames are arriving.
pub fn unheard<K: Spoken>(driver: &HostDriver<K>) -> Option<String> {
    let port = driver.uart().name();
    match driver.core().heard_at(driver.uart().now_ms()) {
        Heard::Frames => None,
        Heard::Quiet => Some(format!(
            "the board on {port} went quiet (no frame within the failsafe time)"
        )),
        Heard::NoFrame => Some(format!(
            "bytes came from {port}, but no frame of the {} firmware (the other firmware? `chassis detect` tells)",
            K::FIRMWARE
        )),
        Heard::Nothing => Some(format!("nothing came from the board on {port}")),
    }
}

/// "; the board may still have the turn pending: …" when a cancellation was not confirmed.
fn pending_turn<K: Spoken>(driver: &HostDriver<K>) -> String {
    if driver.core().turn_unsettled() {
        "; the board may still have the turn pending: run `chassis stop` once it answers again"
            .into()
    } else {
        String::new()
    }
}

/// Why the driver's failsafe stopped the chassis (`did`: what it did), from what came from the
/// board: nothing at all, bytes of another firmware, or frames that stopped.
pub fn failsafe_words<K: Spoken>(driver: &HostDriver<K>, did: &str) -> String {
    let heard = unheard(driver).unwrap_or_else(|| "the board's frames stopped for a while".into());
    let hint = if driver.core().heard_at(driver.uart().now_ms()) == Heard::Nothing {
        " (is it powered, TX wired to RX and RX to TX, at 115200 bps?)"
    } else {
        ""
    };
    format!("{heard}{hint}: the driver's failsafe {did}")
}

/// The driver's logic error `e` in the CLI's words, told by what came from the board on
/// `port`. Shared by every command and `chassis check` (and the Python package).
pub fn core_words(e: chassis_protocol::driver::CoreError, heard: Heard, port: &str) -> String {
    words_heard(e, heard, port)
}
