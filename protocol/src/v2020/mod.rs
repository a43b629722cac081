//! The board's **2020** firmware (`FF FE` commands; `FF FA` / `FF FB` / `FF FC` telemetry and
//! `#` replies; no checksum): its frames and its parsers, laid out as [`crate::v1`]'s.
//!
//! | module | what |
//! |---|---|
//! | [`command`] | master → board: velocity and turns, each motor, settings (actions, writes, reads) |
//! | [`telemetry`] | board → master: IMU, encoders, battery, register replies |
//! | [`parse`] | the two streaming parsers ([`crate::stream::Parser`]) and their counters |
//! | [`registers`] | [`Snapshot`](registers::Snapshot): every readable register at once |
//!
//! Every item is also re-exported at the crate's root (`chassis_protocol::Velocity`, …), where
//! the 2020 firmware's frames have always been.

pub mod command;
pub mod parse;
pub mod registers;
pub mod telemetry;
