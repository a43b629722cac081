//! The master-side driver (feature `driver`): one sans-IO core and thin shells over it.
//!
//! | layer | what | needs |
//! |---|---|---|
//! | [`DriverCore`] | every policy: frames out, telemetry in, requests (reads, verified reads, the settings sequences, turn cancel) with reply matching, retries and timeouts, the failsafe, the one-shot turn guard | nothing: bytes and the time come in as arguments |
//! | [`blocking::Driver`] | owns the UART and a [`Clock`]; blocking calls | `embedded-io` 0.7 `Read + Write + ReadReady` |
//! | [`asynch::Driver`] (feature `async`) | the same calls, `async`; awaits bytes or the next deadline, never busy-polls | `embedded-io-async` 0.7 `Read + Write` (no `ReadReady`) + `embedded-hal-async` `DelayNs` |
//! | [`Split`] | an RX half and a TX half as one UART, for either shell | the halves' traits |
//! | `nb::NbSerial` (feature `nb`) | adapts an `embedded-hal-nb` 1.0 serial port for the blocking driver | `serial::Read<u8> + serial::Write<u8>` |
//! | `io06::Io06` (feature `embedded-io-06`) | adapts an `embedded-io` 0.6 UART for the blocking driver | 0.6 `Read + Write + ReadReady` |
//! | `host` (feature `std`) | a serial port (`serialport` crate), a monotonic clock, [`Config::HOST`] | a PC or a Raspberry Pi |
//!
//! # Which HAL, which shell
//!
//! Checked against each HAL's manifest and source for the version named:
//!
//! | HAL | UART type | implements | use |
//! |---|---|---|---|
//! | embassy-stm32 0.6 | `BufferedUart` (or its `split()` halves) | embedded-io 0.7 and embedded-io-async 0.7, with `ReadReady` | [`asynch::Driver`] (halves through [`Split`]), or [`blocking::Driver`] |
//! | embassy-stm32 0.6 | `Uart<Async>` | only `Write` (embedded-io 0.7 and embedded-io-async 0.7) and embedded-hal-nb; no `Read` trait: its DMA `read` / `read_until_idle` are inherent methods, not cancel-safe | use `BufferedUart`, or `RingBufferedUartRx` for the receive side |
//! | embassy-stm32 0.6 | `RingBufferedUartRx` (`UartRx<Async>::into_ring_buffered`) | RX only: embedded-io-async 0.7 `Read` + `ReadReady`, embedded-hal-nb `Read`; `read` is cancel-safe (copies out of the DMA ring, awaits only the half/full or idle interrupt) | [`asynch::Driver`] through [`Split`] with a TX half whose write takes no byte when dropped (not `UartTx<Async>`'s DMA write), or the [`DriverCore`] fed slices (`mcu-example/boards/stm32-dma`) |
//! | embassy-rp 0.10 | `BufferedUart` | as embassy-stm32's | as embassy-stm32's |
//! | embassy-nrf 0.11 | `BufferedUarte` (and its halves) | embedded-io-async 0.7 `Read + Write + ReadReady` (and `BufRead`); no blocking embedded-io | [`asynch::Driver`] (`mcu-example/boards/nrf52840`) |
//! | rp2040-hal 0.12 | `UartPeripheral` | embedded-io 0.7 and embedded-hal-nb 1.0 | [`blocking::Driver`] directly, or through `NbSerial` |
//! | stm32f4xx-hal 0.23 | `Serial` | embedded-hal-nb 1.0; of embedded-io 0.6 only `Write` | `NbSerial` (not `Io06`: no 0.6 `Read`) |
//! | esp-hal 1.2 | `Uart` (`Blocking` or `Async`, and its `UartRx` / `UartTx` halves) | behind its `unstable` feature: embedded-io 0.7 (and 0.6) `Read + Write + ReadReady`; `Uart<Async>` also embedded-io-async 0.7 `Read + Write`, `read_async` / `write_async` documented cancel-safe; no embedded-hal-nb | [`blocking::Driver`] with esp-hal's `unstable` on (`mcu-example/boards/esp32c3`), or [`asynch::Driver`] on `Uart<Async>` under esp-rtos's embassy executor |
//!
//! # The safety model
//!
//! Every way the driver stops the chassis, or keeps it from doing what nobody asked, with its
//! bound and the test that proves it (in `host-tests/tests/` unless named otherwise). Times are
//! [`Config::DEFAULT`]'s (a microcontroller's UART); [`Config::HOST`] (a PC or a Raspberry Pi
//! behind a USB-UART) has a 200 ms failsafe and a 133 ms reply timeout.
//!
//! | what | what the driver does | bound | test |
//! |---|---|---|---|
//! | **the board goes silent while moving** (the failsafe) | sends STOP once no frame of any kind (telemetry or reply) has been heard for [`Config::failsafe_ms`], or for [`Config::settings_pause_ms`] after a settings frame until telemetry is back; judged only once every byte the UART holds is read, so a slow loop never stops a healthy robot | 100 ms of silence (200 on a host), plus the time to your next `poll` | `driver_in_use::bug2_a_silent_board_is_stopped_within_the_limit`, `driver_edges::case4_the_failsafe_stops_across_the_wrap` |
//! | **`stop()`** | queues STOP ahead of everything not yet begun; a frame a cut write left half sent is finished first (it must be: the board's parser holds its start); cancels an outstanding turn (reads the pending angle, sends the opposite) | at most 11 bytes before the STOP (1 ms at 115 200 bps) | `cancellation::a_half_sent_turn_then_stop_never_spins_the_board`, `driver_in_use::bug7_stop_cancels_a_pending_turn` |
//! | **a turn outstanding when the link dies** | the failsafe's STOP ends any translation; a stop frame does not end a turn on this board, and only the opposite angle cancels it, which needs the angle still pending: the driver keeps asking for it (in the background, a request you start goes first) and cancels what is left at the first reply. `stop()` with its replies lost returns [`CoreError::Unconfirmed`] and the guard holds | the chassis turns at most the angle it was told; it stops turning within a reply's round trip (and one retry) of the link coming back | `driver_edges::case6_a_turn_outstanding_when_the_link_dies_is_cancelled_at_the_first_reply` |
//! | **an async call cancelled** (a `select` with a timeout) | only whole frames reach the board, in order: the core owns a frame's bytes until the UART has taken the last one, and any later call finishes a cut frame before its own | the next call, `poll` included | `cancellation::every_async_call_cut_at_every_await_point_leaves_only_whole_frames_and_a_working_driver` (every call, every await point) |
//! | **a write cut by a transport error** | as a cancelled call: the rest of the frame stays in the core, the error is returned, the next call finishes the frame | the next call | `cancellation::every_blocking_call_cut_by_a_transport_error_after_every_byte_leaves_only_whole_frames` (every call, every byte) |
//! | **a turn sent twice** | refused: [`CoreError::TurnInProgress`] until the pending angle reads within [`Config::turn_done_deci_degrees`] of 0; a new driver (a new [`DriverCore`]) reads the pending angle before its first turn, so a turn an earlier program or driver left running is found | — | `driver::a_turn_in_a_periodic_loop_is_sent_once`, `driver_edges::case5_the_turn_guard_survives_release_and_a_new_driver` |
//! | **a late reply** | never answers a later read: an unanswered read leaves a ghost, a read of the same register waits until the ghost's reply has come or [`Config::late_reply_ms`] has passed, a late reply of another register is passed over; a timeout, or a late reply, makes later reads wait longer (at most [`Config::late_reply_ms`] more) | one failed read per slow board | `driver_edges::case3_a_board_slower_than_the_timeout_fails_one_read_not_every_read`, `driver_edges::case3_a_stale_zero_never_releases_the_turn_guard` |
//! | **the clock wraps or goes back** | time is the core's own, from the differences of the clock's low 32 bits: a `u32` millisecond counter that wraps after 49.7 days is one more millisecond; a clock that goes back stands still until it is past where it was | — | `driver_edges::case4_*`, unit tests in `driver/time.rs` |
//! | **the clock stands still** | a request gives up with [`CoreError::ClockStalled`] after [`blocking::STALL_POLLS`] polls ([`asynch::STALL_WAITS`](asynch) waits) that saw the clock stand still, whatever bytes arrive; a `poll` reads at most [`blocking::POLL_READS`] buffers | 1 000 000 polls (10 000 async waits) | `driver_edges::case2_*` |
//! | **the driver released, rebuilt or reconfigured** | [`blocking::Driver::release`] gives back the [`DriverCore`] (the turn guard, bytes read, a frame half sent); [`blocking::Driver::from_core`] goes on from it; [`blocking::Driver::set_config`] changes the limits in place | nothing lost | `driver_edges::case5_*` |
//! | **the driver dropped** | nothing: no I/O happens in `Drop`, and the 2020 board has no watchdog of its own, so the chassis keeps its last command. **Call `stop()` before you drop a driver that moved the chassis**; the `chassis` command does it on every signal | — | — |
//!
//! A [`Turn`](crate::Turn) is `Clone`: a clone is a second turn asked for on purpose, and the
//! driver refuses it while the first is outstanding (`driver_edges::case5_a_cloned_turn_is_refused_while_the_first_runs`).
//!
//! The wire-independent part of this policy (the frame slot, the failsafe, time, the stall
//! bounds) is written once, generic over the wire format (`driver/safety.rs`).
//!
//! # The failsafe, in one sentence
//!
//! While the driver has the chassis moving, it sends STOP once no frame from the board
//! (telemetry or reply) has been read for [`Config::failsafe_ms`] (100 ms; 200 ms with
//! [`Config::HOST`]), or, after a settings frame, for [`Config::settings_pause_ms`] (600 ms:
//! the board pauses telemetry while settings are made, A13) until its telemetry is back; a read
//! counts as a settings frame once the board has answered it (whole, or on the 2020 board
//! damaged on the line: bytes after the read that make no frame, then a quiet line; so a 2020
//! link dying in the middle of a frame while a read waits is stopped within the settings
//! pause), and a read left without any
//! answer ends the allowance (a paused board still answers reads: reads a silent board leaves
//! unanswered never hold the failsafe off, however often they are sent). It is
//! judged only after every byte the UART holds has been read, so a loop slower than the limit
//! is never stopped by its own slowness; such a loop stops a silent board at its first poll
//! that reads nothing.
//!
//! # The angle hazard, and how the driver takes it away
//!
//! The board **adds up** every angle it receives (a frame with the angle-mode bit): a control
//! loop that re-sends its last frame would spin the chassis without end. In the types: a
//! [`Turn`](crate::Turn) is not `Copy` and sending it consumes it; a
//! [`Velocity`](crate::Velocity) can never carry the angle-mode bit, however it was made (serde
//! included). In the driver: [`DriverCore::turn`] refuses a new turn while one is outstanding;
//! the guard is released when a read of the pending angle comes back within
//! [`Config::turn_done_deci_degrees`] of 0 (`turn_remaining()`), when `stop()` cancels the turn
//! (it reads the pending angle and sends the opposite turn), or by an explicit
//! [`DriverCore::abandon_turn`]. A loop that calls `turn_by(900)` every period turns the chassis
//! 90° once and gets [`CoreError::TurnInProgress`] until the turn is done.
//!
//! # Errors
//!
//! [`CoreError`] is what the logic refuses or finds wrong; [`Error`] adds the transport's.
//! **Every error leaves the driver usable**: a request cut short by a transport error, a stalled
//! clock or a dropped future ends with it ([`DriverCore::abort`]).
//!
//! # Feeding the core from an interrupt or a DMA buffer
//!
//! The core needs no shell: an RX interrupt (or a DMA half-transfer callback) hands it bytes
//! with the time, and the main loop takes frames to send. Bytes fed this way are stamped with
//! their arrival time, which makes rates and the failsafe exact.
//!
//! ```ignore
//! static CORE: Mutex<RefCell<DriverCore>> = Mutex::new(RefCell::new(DriverCore::new(Config::DEFAULT)));
//!
//! #[interrupt]
//! fn USART2() {
//!     let byte = uart_rx.read_byte();
//!     critical_section::with(|cs| {
//!         let mut core = CORE.borrow_ref_mut(cs);
//!         let (event, _) = core.receive(&[byte], now_ms());    // one byte: never a rest
//!         if let Some(Event::Telemetry(frame)) = event { LATEST.signal(frame) }
//!     });
//! }
//!
//! // Main loop, every few ms:
//! critical_section::with(|cs| {
//!     let mut core = CORE.borrow_ref_mut(cs);
//!     while core.tick(now_ms()).is_some() {}                      // quiet line, timeouts, failsafe
//!     // The core keeps each frame until the UART has taken its last byte.
//!     while let Some(bytes) = core.transmit(now_ms()) {
//!         let n = uart_tx.write(bytes)?;
//!         core.transmitted(n, now_ms());
//!     }
//! });
//! ```
//!
//! # Time
//!
//! Time is milliseconds from any origin, read from a [`Clock`] (the shells) or passed to each
//! [`DriverCore`] call. The core keeps its own monotonic time from the differences between
//! readings, taken on their low 32 bits: a `u64` clock runs as it is (the core's times equal its
//! readings), a `u32` tick counter may be handed over as it is (`|| millis() as u64`) and wrap,
//! and a clock that goes back makes time stand still until it is past where it was. Two
//! readings more than 24.8 days apart with no call in between are not supported.

#[cfg(feature = "async")]
#[cfg_attr(docsrs, doc(cfg(feature = "async")))]
pub mod asynch;
pub mod blocking;
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub mod host;
#[cfg(feature = "embedded-io-06")]
#[cfg_attr(docsrs, doc(cfg(feature = "embedded-io-06")))]
pub mod io06;
mod latest;
#[cfg(feature = "nb")]
#[cfg_attr(docsrs, doc(cfg(feature = "nb")))]
pub mod nb;
mod pump;
mod safety;
mod split;
mod time;
pub mod v1;
mod v2020;

pub use crate::registers::{BatteryRange, Readable, Snapshot, reg};
pub use latest::{Stamped, StreamInfo};
pub use split::Split;
pub use v2020::{DriverCore, Event, Outcome, Outgoing, Request, TurnState};

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

/// What a shell ([`blocking::Driver`], [`asynch::Driver`]) needs of a driver core: the pump
/// (bytes out whole, bytes in, time judged) and the request in progress. One shell serves each
/// firmware generation: [`DriverCore`] speaks the 2020 firmware (`FF FE` frames),
/// [`v1::DriverCore`] v1.0.0 (`7B … BCC 7D`). What a generation can do (a turn by an angle, a
/// register read) is in the methods of its own core and of `Driver<_, _, ItsCore>`: a call that
/// means nothing to a generation does not compile for it.
///
/// Sealed: the two cores are the crate's.
pub trait Core: sealed::Sealed {
    /// Something the core saw on the line (a telemetry frame, a reply nobody waited for).
    type Event;
    /// A request that needs replies.
    type Request;
    /// How a request ended.
    type Outcome;

    /// Changes the limits, keeping everything the core knows.
    fn set_config(&mut self, config: Config);
    /// Starts a request ([`CoreError::Busy`] while another runs).
    fn start(&mut self, request: Self::Request) -> Result<(), CoreError>;
    /// Queues the stop frame ahead of everything not yet begun.
    fn stop(&mut self);
    /// Ends the request in progress, as if it had never started.
    fn abort(&mut self);
    /// Whether a request the user started is in progress.
    fn busy_for_user(&self) -> bool;
    /// The request's end, if it has ended ([`CoreError::ClockStalled`] after `limit` calls in
    /// a row that saw the clock stand still).
    fn settle(&mut self, now_ms: u64, limit: u32) -> Option<Result<Self::Outcome, CoreError>>;
    /// The bytes to write now: the rest of the frame going out, else the next frame.
    fn transmit(&mut self, now_ms: u64) -> Option<&[u8]>;
    /// The UART took `n` of the bytes [`transmit`](Core::transmit) gave.
    fn transmitted(&mut self, n: usize, now_ms: u64);
    /// Where a shell reads the UART into.
    fn rx_space(&mut self) -> &mut [u8];
    /// `n` bytes were read into [`rx_space`](Core::rx_space).
    fn rx_filled(&mut self, n: usize);
    /// Feeds the bytes read until one completes an event.
    fn drain(&mut self, now_ms: u64) -> Option<Self::Event>;
    /// Judges time (reply timeouts, the failsafe); call once every byte the UART holds is in.
    fn tick(&mut self, now_ms: u64) -> Option<Self::Event>;
    /// How long until [`tick`](Core::tick) may have something to do, in ms.
    fn wait_ms(&self, now_ms: u64) -> Option<u64>;
}

/// The accessors both shells ([`blocking::Driver`], [`asynch::Driver`]) have, in one text: the
/// configuration, the UART and the core. Used inside each shell's `impl` block (fields `uart`
/// and `core`, type parameters `U` and `K`).
macro_rules! shell_accessors {
    () => {
        /// Changes the configuration, keeping everything the driver knows.
        pub fn set_config(&mut self, config: $crate::driver::Config) {
            self.core.set_config(config);
        }

        /// The UART (to inspect it; the driver keeps it).
        pub const fn uart(&self) -> &U {
            &self.uart
        }

        /// The UART, mutably (for a test double's controls; do not read from or write to it
        /// behind the driver's back).
        pub fn uart_mut(&mut self) -> &mut U {
            &mut self.uart
        }

        /// The sans-IO core: latest telemetry, stream rates, parser counters, link state.
        pub const fn core(&self) -> &K {
            &self.core
        }

        /// The sans-IO core, mutably: [`DriverCore::abandon_turn`](crate::driver::DriverCore::abandon_turn),
        /// [`DriverCore::abort`](crate::driver::DriverCore::abort).
        pub fn core_mut(&mut self) -> &mut K {
            &mut self.core
        }
    };
}
use shell_accessors;

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::DriverCore {}
    impl Sealed for super::v1::DriverCore {}
}

/// How the driver talks to the board, and its policies' limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Config {
    /// Line speed in bits per second (the board's is 115 200).
    pub baud: u32,
    /// How long the board may take to answer a read, beyond the bytes' time on the wire, in ms.
    pub board_latency_ms: u32,
    /// While moving, the board silent (no frame of any kind) for longer than this: the driver
    /// sends stop (100 ms; 200 ms with [`Config::HOST`]).
    pub failsafe_ms: u32,
    /// After a settings frame the board pauses its telemetry (A13: at least up to 500 ms); the
    /// failsafe allows it this long to speak again (after a read, once the board answered it;
    /// until a read goes unanswered).
    pub settings_pause_ms: u32,
    /// A line quiet for this long marks a frame boundary ([`crate::DownlinkParser::quiet`]). It
    /// must be longer than any gap *inside* a frame: 2 ms on a UART peripheral, more behind a
    /// USB-UART adapter, which delivers bytes in bursts.
    pub idle_ms: u32,
    /// A pending angle within this many 0.1° of 0 ends a turn (a board may leave a remainder).
    pub turn_done_deci_degrees: u16,
    /// Reads sent at most by a verified read ([`Request::ReadVerified`]).
    pub read_tries: u8,
    /// How long after a read's timeout its reply may still come, in ms. Until it has come, or
    /// this has passed, a read of the same register is not sent (the two replies could not be
    /// told apart), and a late reply makes later reads wait longer (at most this much more).
    pub late_reply_ms: u32,
}

impl Config {
    /// A UART peripheral on a microcontroller: the board's line, 50 ms of board latency, a
    /// 100 ms failsafe (ten IMU periods), 600 ms allowed for a settings pause, 2 ms idle.
    pub const DEFAULT: Config = Config {
        baud: 115_200,
        board_latency_ms: 50,
        failsafe_ms: 100,
        settings_pause_ms: 600,
        idle_ms: 2,
        turn_done_deci_degrees: 5,
        read_tries: 4,
        late_reply_ms: 150,
    };

    /// A PC or a Raspberry Pi behind a USB-UART adapter: the adapter hands bytes over in bursts
    /// every 1 to 16 ms (its latency timer), both ways, and the OS adds its own scheduling. So a
    /// quiet line is 40 ms (no burst gap inside a frame is mistaken for one), replies get 40 ms
    /// more, the failsafe is 200 ms, and a late reply is awaited 300 ms more.
    pub const HOST: Config = Config {
        board_latency_ms: 90,
        failsafe_ms: 200,
        idle_ms: 40,
        late_reply_ms: 300,
        ..Config::DEFAULT
    };

    /// How long to wait for a reply: the request (10 bytes), a telemetry frame that may be on
    /// the wire first (15) and the reply (6), at 10 bits a byte, rounded up; the board's
    /// latency; and [`idle_ms`](Config::idle_ms), since a reply alone on a quiet line is
    /// proved by the quiet. 55 ms with [`Config::DEFAULT`], 133 ms with [`Config::HOST`]. A
    /// board found slower waits longer ([`DriverCore::reply_timeout_ms`]).
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
            .saturating_add(self.idle_ms)
    }
}

impl Default for Config {
    fn default() -> Self {
        Config::DEFAULT
    }
}

/// What the driver's logic can refuse or find wrong: no transport in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CoreError {
    /// No reply to a read of this register within [`Config::reply_timeout_ms`].
    Timeout(Register),
    /// A reply came for another register than the one read (its code is here).
    WrongReply {
        /// The register read.
        expected: Register,
        /// The code of the reply that came.
        got: u8,
    },
    /// A reply's value cannot be this register's (a 16-bit register with its high half set):
    /// a damaged reply.
    Invalid {
        /// The register read.
        register: Register,
        /// The value that came.
        value: u32,
    },
    /// Replies to reads of this register disagreed, or none came, in [`Config::read_tries`]
    /// reads.
    Unconfirmed(Register),
    /// A request is already in progress.
    Busy,
    /// A turn is still outstanding: the board adds angles up, so a second one is refused until
    /// the pending angle reads (nearly) 0, or the turn is cancelled.
    TurnInProgress,
    /// The request was ended by [`DriverCore::stop`] (which cancels a turn first).
    Aborted,
    /// The clock stood still while a request waited: time never came to end the wait.
    ClockStalled,
    /// A frame is still to go out (the rest of one a cut write left, a stop, a request's
    /// frame): write out what [`DriverCore::transmit`] gives first. The shells always do.
    FramePending,
    /// Whether the board still has a turn pending is not known (a new driver has not read the
    /// pending angle yet): read it first. The shells do it before the first turn.
    TurnStateUnknown,
    /// v1.0.0: no reply to this readback in [`Config::read_tries`] requests.
    NoReadback(crate::v1::Readback),
    /// v1.0.0: the readback after a settings write does not carry what was written (the
    /// board did not take it, or keeps other values).
    ReadbackDiffers(crate::v1::Readback),
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::Timeout(r) => write!(f, "no reply to a read of {r:?} in time"),
            CoreError::WrongReply { expected, got } => {
                write!(f, "reply code {got:#04x} while waiting for {expected:?}")
            }
            CoreError::Invalid { register, value } => {
                write!(f, "reply value {value:#010x} cannot be {register:?}'s")
            }
            CoreError::Unconfirmed(r) => write!(f, "replies to reads of {r:?} did not agree"),
            CoreError::Busy => f.write_str("a request is already in progress"),
            CoreError::TurnInProgress => f.write_str("a turn is still outstanding"),
            CoreError::Aborted => f.write_str("the request was ended by a stop"),
            CoreError::ClockStalled => f.write_str("the clock stood still while waiting"),
            CoreError::FramePending => f.write_str("a frame is still being sent"),
            CoreError::TurnStateUnknown => {
                f.write_str("whether a turn is pending is not known: read the pending angle first")
            }
            CoreError::NoReadback(r) => write!(f, "no reply to the readback {r:?}"),
            CoreError::ReadbackDiffers(r) => {
                write!(f, "the readback {r:?} does not show what was written")
            }
        }
    }
}

impl core::error::Error for CoreError {}

/// What can go wrong talking to the board through a shell; `E` is the transport's error.
/// Every one leaves the driver usable: no request stays in progress after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error<E> {
    /// The UART failed (an overrun, a framing error…: see the transport's error).
    Transport(E),
    /// The UART accepted no bytes (a write returned 0).
    WriteZero,
    /// The driver's logic refused or found something wrong.
    Core(CoreError),
}

impl<E> From<CoreError> for Error<E> {
    fn from(e: CoreError) -> Self {
        Error::Core(e)
    }
}

impl<E> Error<E> {
    /// The core's error, if this is one.
    #[must_use]
    pub const fn core(&self) -> Option<CoreError> {
        match self {
            Error::Core(e) => Some(*e),
            _ => None,
        }
    }

    /// The same error with the transport's error mapped by `f`: e.g. to its
    /// `embedded_io::ErrorKind`, so that code shared by several HALs sees one error type.
    pub fn map_transport<F>(self, f: impl FnOnce(E) -> F) -> Error<F> {
        match self {
            Error::Transport(e) => Error::Transport(f(e)),
            Error::WriteZero => Error::WriteZero,
            Error::Core(e) => Error::Core(e),
        }
    }
}

impl<E: fmt::Debug> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Transport(e) => write!(f, "UART error: {e:?}"),
            Error::WriteZero => f.write_str("the UART accepted no bytes"),
            Error::Core(e) => fmt::Display::fmt(e, f),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for Error<E> {}
