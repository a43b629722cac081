//! The master-side driver (feature `driver`): one sans-IO core and thin shells over it.
//!
//! | layer | what | needs |
//! |---|---|---|
//! | [`DriverCore`] | all the logic: frames out, telemetry in, reply matching, timeouts, the failsafe, one-shot turns | nothing: bytes and the time come in as arguments |
//! | [`blocking::Driver`] | owns the UART and a [`Clock`]; blocking calls | `embedded-io` 0.7 `Read + Write + ReadReady` |
//! | `nb::NbSerial` (feature `nb`) | adapts an `embedded-hal-nb` 1.0 serial port for `blocking::Driver` | `serial::Read<u8> + serial::Write<u8>` |
//! | `io06::Io06` (feature `embedded-io-06`) | adapts an `embedded-io` 0.6 UART for `blocking::Driver` | 0.6 `Read + Write + ReadReady` |
//! | `asynch::Driver` (feature `async`) | the same calls, `async` | `embedded-io-async` 0.7 + `embedded-hal-async` `DelayNs` |
//!
//! # The angle hazard, and how the driver takes it away
//!
//! The board **adds up** every angle it receives (a frame with the angle-mode bit): a control
//! loop that re-sends its last frame would spin the chassis without end. The driver never stores
//! or re-sends an angle frame, and [`DriverCore::turn`] refuses a new turn while one is still
//! outstanding: it is released only when a read of the pending angle (2D) comes back 0
//! ([`blocking::Driver::turn_remaining`]), or by an explicit [`DriverCore::abandon_turn`]. A loop
//! that calls `turn_by(900)` every period therefore turns the chassis 90° once, and gets
//! [`Error::TurnInProgress`] until the turn is done.
//!
//! # Time
//!
//! Time is milliseconds from any origin, as a `u64`; it must not go back. The blocking shell
//! reads it from a [`Clock`].

#[cfg(feature = "async")]
pub mod asynch;
pub mod blocking;
#[cfg(feature = "embedded-io-06")]
pub mod io06;
#[cfg(feature = "nb")]
pub mod nb;
mod sans_io;

pub use crate::registers::Settings;
pub use sans_io::{DriverCore, Event, RxBuffer, Stamped, StreamInfo};

use crate::command::Register;
use core::fmt;

/// A source of milliseconds for the blocking shell (a HAL timer, `std::time::Instant`, a test
/// clock). Any `FnMut() -> u64` is one.
pub trait Clock {
    /// Milliseconds since any fixed origin; never goes back.
    fn now_ms(&mut self) -> u64;
}

impl<F: FnMut() -> u64> Clock for F {
    fn now_ms(&mut self) -> u64 {
        self()
    }
}

/// How the driver talks to the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Line speed in bits per second (the board's is 115 200).
    pub baud: u32,
    /// How long the board may take to answer a read, beyond the bytes' time on the wire, in ms.
    pub board_latency_ms: u32,
    /// Telemetry silent for longer than this while the chassis is moving: the driver sends stop.
    pub failsafe_ms: u32,
    /// A line quiet for this long marks a frame boundary ([`crate::DownlinkParser::idle`]).
    pub idle_ms: u32,
}

impl Config {
    /// The board's line, 50 ms of board latency, a 100 ms failsafe (ten IMU periods), 2 ms idle.
    pub const DEFAULT: Config = Config {
        baud: 115_200,
        board_latency_ms: 50,
        failsafe_ms: 100,
        idle_ms: 2,
    };

    /// How long to wait for a reply: the request (10 bytes), a telemetry frame that may be on
    /// the wire first (15), and the reply (6), at 10 bits a byte, rounded up, plus the board's
    /// latency. 53 ms with [`Config::DEFAULT`].
    #[must_use]
    pub const fn reply_timeout_ms(&self) -> u32 {
        const BITS: u64 = (10 + 15 + 6) * 10;
        let baud = if self.baud == 0 { 1 } else { self.baud as u64 };
        let wire = (BITS * 1_000).div_ceil(baud);
        let wire = if wire > u32::MAX as u64 {
            u32::MAX
        } else {
            wire as u32
        };
        wire.saturating_add(self.board_latency_ms)
    }
}

impl Default for Config {
    fn default() -> Self {
        Config::DEFAULT
    }
}

/// What can go wrong talking to the board; `E` is the transport's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// The UART failed.
    Transport(E),
    /// No reply to a read of this register within [`Config::reply_timeout_ms`].
    Timeout(Register),
    /// A reply came for another register than the one read (its code is here).
    WrongReply {
        /// The register read.
        expected: Register,
        /// The code of the reply that came.
        got: u8,
    },
    /// A read is already waiting for its reply.
    Busy,
    /// A turn is still outstanding: the board adds angles up, so a second one is refused until
    /// the pending angle reads 0 (see the module docs).
    TurnInProgress,
    /// The UART accepted no bytes (a write returned 0).
    WriteZero,
    /// Replies to reads of this register disagreed (bytes changed on the line).
    Unconfirmed(Register),
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Transport(e)
    }
}

impl<E: fmt::Debug> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Transport(e) => write!(f, "UART error: {e:?}"),
            Error::Timeout(r) => write!(f, "no reply to a read of {r:?} in time"),
            Error::WrongReply { expected, got } => {
                write!(f, "reply code {got:#04x} while waiting for {expected:?}")
            }
            Error::Busy => f.write_str("a read is already waiting for its reply"),
            Error::TurnInProgress => f.write_str("a turn is still outstanding"),
            Error::WriteZero => f.write_str("the UART accepted no bytes"),
            Error::Unconfirmed(r) => write!(f, "replies to reads of {r:?} disagreed"),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for Error<E> {}
