//! A model of the board (feature `sim`): registers, kinematics, the telemetry clock, replies and
//! fault injection, with no I/O and no clock of its own. `no_std`, allocation-free: a master can
//! be tested against it on the host, and it can run on a spare MCU as a fake chassis.
//!
//! ```
//! use chassis_protocol::sim::{Board, SimConfig};
//! use chassis_protocol::{DownlinkParser, Register, Setting, Downlink};
//!
//! let mut board = Board::new(SimConfig::default());
//! board.receive(&Setting::Read(Register::MotorVoltage).encode());
//! let mut parser = DownlinkParser::new();
//! let mut buf = [0u8; 64];
//! let mut reply = None;
//! for ms in 0..100 {
//!     board.advance(ms);
//!     let n = board.transmit(&mut buf);
//!     let mut frames: Vec<Downlink> = parser.frames(&buf[..n]).collect();
//!     if n == 0 {
//!         // A quiet millisecond: the telemetry is paused while settings are made.
//!         frames.extend(core::iter::from_fn(|| parser.idle()));
//!     }
//!     for frame in frames {
//!         if let Downlink::Reply(r) = frame { reply = Some(r); }
//!     }
//! }
//! assert_eq!(reply.map(|r| r.value), Some(1_200)); // 12.00 V, the factory default
//! ```
//!
//! Each firmware generation's board is a module with the same parts ([`v2020`], re-exported
//! here, and [`v1`]):
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | the `Board`: commands in, time on, the configuration (`SimConfig`) |
//! | `registers.rs` | the settings it keeps, factory defaults (2020: live and stored registers, actions, calibration) |
//! | `motion.rs` | what it was told, wheel speeds, encoders, gyro, turns, yaw, battery drain |
//! | `telemetry.rs` | the telemetry clock and frames |
//!
//! What both boards share is written once beside them:
//!
//! | file | what |
//! |---|---|
//! | `line.rs` | the line to the master: pacing at 115 200 bps, its buffer, [`Faults`] |
//! | `pose.rs` | the chassis's true pose, integrated every ms (each board's `pose`) |
//! | `adapters.rs` | (feature `driver`) in-memory UART, clock and delay on shared simulated time |
//! | `serve.rs` | (feature `std`) a board in real time on an OS byte stream |
//!
//! Both boards implement [`Simulated`], which is all the adapters and `serve` need of them.
//!
//! # Behaviour, and the decisions where the spec is silent
//!
//! * **Registers** have a live copy and a stored copy. [`Action::Store`](crate::Action::Store) copies live to stored,
//!   except system-mode bit 3 (gyro compensation), which the spec says is not stored;
//!   [`Action::LoadStored`](crate::Action::LoadStored) and [`Action::LoadDefaults`](crate::Action::LoadDefaults) copy back.
//! * **Gyro calibration** takes 30 s (10 s to settle, 20 s still) once compensation is switched
//!   on, by action, system-mode write or a write of 0xFFFF to the calibration register. While it
//!   runs, the calibration register reads 0xFFFF; then it reads the calibrated value.
//! * **Angle mode accumulates**, exactly as the spec warns: every frame with the angle bit adds
//!   its angle to the pending turn; the chassis turns at 90°/s until the pending angle is 0.
//!   [`Board::total_turn_commanded`] tells a test what was asked in all.
//! * **Downlink pauses while settings are made** (A6): every settings frame stops it, and it
//!   resumes [`SimConfig::resume_after_ms`] (100 ms by default: a parameter, since the vendor
//!   does not say, A13) after the last one. Counts carry on from
//!   where they stopped (they count frames sent).
//! * Replies go out [`SimConfig::reply_delay_ms`] after the read arrives.
//! * Downlink: IMU at 100 Hz, encoders at 25 Hz, battery at 1 Hz, each with its rolling count;
//!   simple kinematics for omni, mecanum and differential chassis move the encoders and gyro Z;
//!   the battery drains.
//! * **Axes** (decision A14 of `docs/protocol-2020.md`): X to the right, Y forward, Z
//!   counter-clockwise, for every drive type, and a positive angle turns counter-clockwise.
//!   The raw velocity units are wheel ticks per second; the chassis's geometry is in
//!   [`SimConfig`] (1 000 ticks/m, half wheelbase 0.10 m, half track 0.12 m by default: 1 m/s
//!   is 1 000 raw, 1 rad/s is 220 on a mecanum chassis). An angle turn moves the wheels too.
//! * **Encoders** are running totals per wheel, wrapping at 16 bits.
//! * **The true pose** ([`Board::pose`], and [`v1::Board::pose`]): where the body motion the
//!   wheels make has taken the chassis since power-up, REP-103 axes, integrated every ms in
//!   f64 by the board's own code, for an odometry to be measured against; `serve_observed`
//!   (feature `std`) hands the board to a callback every N ms of board time to log it. A
//!   chassis without encoders (open-loop differential) does not move in the model.

#[cfg(feature = "driver")]
mod adapters;
mod line;
mod pose;
#[cfg(feature = "std")]
mod serve;
pub mod v1;
pub mod v2020;

#[cfg(feature = "async")]
pub use adapters::SimDelay;
#[cfg(feature = "driver")]
pub use adapters::{SimClock, SimUart};
pub use line::{Faults, OUT_CAPACITY};
#[cfg(feature = "std")]
pub use serve::{serve, serve_observed, write_pose};
pub use v2020::{Board, FACTORY, Motion, SimConfig};

/// A simulated board's end of the wire: the line (pacing, faults), the parser of what the
/// master sends, and the board's time.
#[derive(Clone, Debug)]
struct Port<P> {
    line: line::Line,
    uplink: P,
    now_ms: u64,
}

impl<P> Port<P> {
    /// A port at time 0, its line's faults drawn from `seed`.
    fn new(seed: u64, uplink: P) -> Self {
        Port {
            line: line::Line::new(seed),
            uplink,
            now_ms: 0,
        }
    }
}

/// The wire side every simulated board has, in one text: faults, bytes in (each command the
/// board's uplink parser finds goes to its `execute`), time (a millisecond at a time, through
/// its `step_one_ms`), bytes out, and [`Simulated`]. Used in each board's module, on a `Board`
/// with a field `port` ([`Port`]).
macro_rules! wire_side {
    () => {
        impl Board {
            /// Sets the faults to inject from now on.
            pub fn set_faults(&mut self, faults: $crate::sim::Faults) {
                self.port.line.faults = faults;
            }

            /// Bytes from the master, taken at the board's current time.
            pub fn receive(&mut self, bytes: &[u8]) {
                let mut rest = bytes;
                loop {
                    let (command, later) =
                        $crate::stream::Parser::push_slice(&mut self.port.uplink, rest);
                    rest = later;
                    match command {
                        Some(command) => self.execute(command),
                        None => break,
                    }
                }
            }

            /// Moves the board's time forward to `now_ms` (ms since power-up): what the
            /// chassis does, replies and telemetry fall due. Time never goes back.
            pub fn advance(&mut self, now_ms: u64) {
                while self.port.now_ms < now_ms {
                    self.port.now_ms = self.port.now_ms.saturating_add(1);
                    self.step_one_ms();
                }
            }

            /// Copies bytes for the master into `buf`, with the faults applied; returns how
            /// many.
            pub fn transmit(&mut self, buf: &mut [u8]) -> usize {
                self.port.line.transmit(self.port.now_ms, buf)
            }

            /// Whether a byte for the master has crossed the wire by now (what a UART's "data
            /// ready" says).
            #[must_use]
            pub fn byte_arrived(&self) -> bool {
                self.port.line.byte_arrived(self.port.now_ms)
            }

            /// The board's time in ms.
            #[must_use]
            pub const fn now_ms(&self) -> u64 {
                self.port.now_ms
            }
        }

        impl $crate::sim::Simulated for Board {
            fn receive(&mut self, bytes: &[u8]) {
                Board::receive(self, bytes);
            }
            fn advance(&mut self, now_ms: u64) {
                Board::advance(self, now_ms);
            }
            fn transmit(&mut self, buf: &mut [u8]) -> usize {
                Board::transmit(self, buf)
            }
            fn byte_arrived(&self) -> bool {
                Board::byte_arrived(self)
            }
            fn now_ms(&self) -> u64 {
                Board::now_ms(self)
            }
            fn pose(&self) -> Option<(f64, f64, f64)> {
                Some(Board::pose(self))
            }
        }
    };
}
use wire_side;

/// What the adapters ([`SimUart`], with feature `driver`) and [`serve`] (feature `std`) need
/// of a simulated board: both generations, [`Board`] (2020) and [`v1::Board`] (v1.0.0),
/// implement it (each method is the board's own, of the same name).
pub trait Simulated {
    /// Bytes from the master, taken at the board's current time.
    fn receive(&mut self, bytes: &[u8]);
    /// Moves the board's time forward to `now_ms` (ms since power-up); time never goes back.
    fn advance(&mut self, now_ms: u64);
    /// Copies bytes for the master that have crossed the wire by now into `buf`; how many.
    fn transmit(&mut self, buf: &mut [u8]) -> usize;
    /// Whether a byte for the master has crossed the wire by now.
    fn byte_arrived(&self) -> bool;
    /// The board's time in ms.
    fn now_ms(&self) -> u64;
    /// Where the chassis truly is, if the board tracks it: x, y (m) and yaw (rad, in
    /// (-π, π]) since power-up, REP-103 axes (x forward, y left, yaw counter-clockwise). Both
    /// boards do (their own `pose`); a wrapper that does not pass it on gives `None`.
    fn pose(&self) -> Option<(f64, f64, f64)> {
        None
    }
}
