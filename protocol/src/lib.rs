//! Frames and streaming parsers for the chassis motor-controller board's UART protocol.
//!
//! `no_std`, no allocation, no `unsafe`, no panic on any input. The same crate runs on the
//! microcontroller that drives the chassis, on a Linux host behind a USB-UART adapter, in the
//! board simulator and under the fuzzer.
//!
//! ```
//! use chassis_protocol::{DownlinkParser, Imu, Downlink, Turn, Velocity};
//!
//! // Master → board: fixed-size frames, built without a parser.
//! let drive: [u8; 10] = Velocity::new(0, 300, 0).encode();
//! assert_eq!(drive, [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x01, 0x2C, 0x00, 0x00, 0x00]);
//! let turn: [u8; 10] = Turn::by_deci_degrees(900).encode(); // once: the board adds it up
//! assert_eq!(turn[9], 0b0001_0000);
//!
//! // Board → master: a byte stream in, typed frames out. The line was quiet before (as it is
//! // when the board powers up, and between its bursts): the next byte starts a frame.
//! let mut parser = DownlinkParser::new();
//! assert_eq!(parser.quiet(5), None);
//! let mut wire = Vec::new();
//! for seq in 0..3 {
//!     wire.extend_from_slice(&Imu { accel: [0, 0, 16_384], gyro: [0, 0, -6], seq }.encode());
//! }
//! let frames: Vec<Downlink> = parser.frames(&wire).collect();
//! assert_eq!(frames.len(), 3);
//! assert!(matches!(frames[2], Downlink::Imu(Imu { seq: 2, .. })));
//! ```
//!
//! The driver (feature `driver`) owns a UART and a clock; here the simulated board (feature
//! `sim`) behind an in-memory UART, on simulated time:
//!
//! ```
//! # #[cfg(not(all(feature = "driver", feature = "sim")))]
//! # fn main() {}
//! # #[cfg(all(feature = "driver", feature = "sim"))]
//! # fn main() -> Result<(), chassis_protocol::driver::Error<core::convert::Infallible>> {
//! use chassis_protocol::driver::{Config, blocking::Driver, reg};
//! use chassis_protocol::sim::{Board, SimClock, SimConfig, SimUart};
//! use chassis_protocol::Velocity;
//! use core::cell::Cell;
//!
//! let time = Cell::new(0);
//! let mut driver = Driver::new(SimUart::new(Board::new(SimConfig::default()), &time), SimClock(&time), Config::DEFAULT);
//! driver.set_velocity(Velocity::new(0, 300, 0))?;    // safe to repeat every period
//! let volts: u16 = driver.read(reg::MotorVoltage)?;  // typed: 12.00 V
//! assert_eq!(volts, 1_200);
//! driver.turn_by(900)?;                               // 90°, sent once: a second is refused
//! driver.stop()?;                                     // stops, and cancels the turn
//! # Ok(())
//! # }
//! ```
//!
//! On a PC or a Raspberry Pi (feature `std`), the same driver over a serial port:
//!
//! ```no_run
//! # #[cfg(feature = "std")] {
//! let mut driver = chassis_protocol::driver::host::open("/dev/ttyUSB0")?;
//! driver.set_velocity(chassis_protocol::Velocity::new(0, 300, 0))?;
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The board's newer firmware, v1.0.0, has its own frames ([`v1`]); [`detect`] tells the two
//! apart from what a board sends.
//!
//! ```
//! use chassis_protocol::v1::{BodyVelocity, Command, Readback};
//!
//! let forward = Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode(); // 0.3 m/s
//! assert_eq!((forward[0], forward[13]), (0x7B, 0x7D));
//! let read = Command::Readback(Readback::Geometry).encode();
//! assert_eq!(read[12], 0x7B ^ 0x34); // the BCC
//! ```
//!
//! # Map
//!
//! | module | what |
//! |---|---|
//! | [`command`] | master → board: [`Velocity`], [`Turn`], [`Motors`], [`Setting`] ([`Action`], [`Write`], [`Register`] reads), [`SystemMode`] |
//! | [`telemetry`] | board → master: [`Imu`], [`Encoders`], [`Battery`], [`Reply`] |
//! | [`parse`] | [`DownlinkParser`] (board → master), [`UplinkParser`] (master → board), their counters |
//! | [`registers`] | [`Snapshot`]: a snapshot of every readable register |
//! | [`units`] | conversions where the spec states the unit |
//! | `driver` (feature) | the master-side driver: sans-IO core, blocking / `nb` / async shells |
//! | `sim` (feature) | the board simulator |
//! | [`v1`] | the v1.0.0 firmware's `7B … BCC 7D` frames and their parsers |
//! | [`detect`] | which firmware a board runs, from what it sends (with `driver`: on a UART, with harmless probes) |
//!
//! There is no checksum in this protocol, and a gyro at rest writes false headers into every
//! other IMU payload: how the board → master parser resynchronises, and the trade-off it makes
//! between latency and false frames, is documented in [`parse::downlink`].
//!
//! Each frame type has `LEN`, `encode() -> [u8; LEN]` and `decode(&[u8]) -> Result<_, Error>`;
//! every decoded frame encodes back to the same bytes (reserved bits and unknown codes are kept).
//! Signed values are signed in the API; magnitudes and direction bits exist only on the wire.
//! Units are in the names (`centivolts`, `deci_degrees`, `centi_percent`).
//!
//! # The spec, and where it is ambiguous
//!
//! The protocol is the vendor's (Traditional Chinese) document, restated with every frame, every
//! ambiguity and the decision taken on it (A1–A13) in the repository's `docs/protocol-2020.md`
//! (v1.0.0's, V1–V13: `docs/protocol-v1.md`). The decisions are noted where they apply: A1 on
//! [`DriveType`], A2 and A3 in [`command::motion`], A5 in [`telemetry::encoders`], A7 in
//! [`parse::downlink`].
//!
//! # Features
//!
//! * `defmt`: `defmt::Format` for every public type.
//! * `serde`: `Serialize` / `Deserialize` for the typed frames and counters.
//! * `std`: links `std`; `driver::host`, a serial-port transport (the `serialport` crate), a
//!   monotonic clock and host defaults for a PC or a Raspberry Pi; `sim::serve` (the simulator
//!   in real time on an OS byte stream).
//! * `arbitrary`: `arbitrary::Arbitrary` for the frames, for fuzzing (values `decode` can return).
//! * `driver`: the master-side driver, module `driver` (sans-IO core, blocking shell over
//!   embedded-io 0.7); `nb`, `async`, `embedded-io-06`: its other shells and adapters.
//! * `sim`: the board simulator, module `sim` (both generations); with `driver`, also an
//!   in-memory UART to it. Pulls in `heapless`.
//!
//! What each pulls in: `driver` embedded-io 0.7; `async` embedded-io-async 0.7,
//! embedded-hal-async 1 and embassy-futures; `nb` embedded-hal-nb 1; `embedded-io-06`
//! embedded-io 0.6; `std` serialport (no libudev); `defmt` defmt 1; `serde` serde (no std);
//! `arbitrary` arbitrary 1. With no feature: no dependency at all.

#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]
#![cfg_attr(docsrs, feature(doc_cfg))]
#![cfg_attr(
    not(test),
    warn(
        clippy::indexing_slicing,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::arithmetic_side_effects,
        clippy::unreachable,
        clippy::todo
    )
)]

#[cfg(feature = "arbitrary")]
mod arbitrary;
mod bytes;
mod codes;
pub mod detect;
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
pub mod driver;
mod error;
#[cfg(feature = "sim")]
#[cfg_attr(docsrs, doc(cfg(feature = "sim")))]
pub mod sim;
pub mod stream;
pub mod units;
pub mod v1;
pub mod v2020;
mod wire;

pub use bytes::FrameBytes;
pub use command::{
    Action, Command, CommandBytes, DriveType, MotorLoop, Motors, Register, Setting, SystemMode,
    Turn, Velocity, VelocityReading, Write,
};
pub use error::Error;
pub use parse::{DownlinkParser, DownlinkStats, Lock, UplinkParser, UplinkStats};
pub use registers::Snapshot;
pub use telemetry::{Battery, Downlink, DownlinkBytes, Encoders, Imu, Kind, Reply, Stream};
pub use v2020::{command, parse, registers, telemetry};
