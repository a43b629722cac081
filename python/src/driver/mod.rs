//! `Chassis` (the 2020 firmware) and `ChassisV1` (v1.0.0): the crate's host driver over a serial
//! port, with a pump thread of its own, so that the failsafe and the telemetry run whatever the
//! Python program does (sleeps, computes, waits on a ROS callback).
//!
//! The driver sits behind a mutex that no call holds while it waits. A request (a verified
//! read, the settings, a readback, a write confirmed by its readback) is started in the
//! driver's sans-IO core, then pumped a turn at a time, the lock taken for each turn only
//! (every millisecond), so that a `stop()` of another thread, the pump thread's failsafe and the
//! signal guard reach the wire at once, whatever waits. Every blocking call releases the GIL
//! and checks Python's signals between its turns. A chassis inherited by a child process (a
//! `fork`) is inert there: it sends nothing, and using it raises `ChassisError`.
//!
//! Laid out alike for both generations. Written once, over any generation's core
//! ([`PyCore`]): [`shared`] (the driver behind its lock and the pump thread), [`link`] (the
//! handle a class holds: calls that never wait, requests run a turn at a time, the stop,
//! closing), [`waits`] (deadlines and naps), [`face`] (what every chassis shows Python: frames,
//! streams, counters) and [`class`] (the macro that makes a chassis class with the methods every
//! chassis has). Each generation's module holds what differs: [`v2020`] (`Chassis`: velocity in
//! raw units, motors, turns, registers) and [`v1`] (`ChassisV1`: velocity in SI units, motors,
//! readbacks, settings frames). [`open`] opens the port and finds the firmware;
//! [`crate::generation`] turns it into the chassis that serves it.

mod class;
mod face;
mod link;
mod opening;
mod shared;
pub mod v1;
pub mod v2020;
mod waits;

use crate::errors::{ChassisError, TimeoutError, UnconfirmedError, WrongReplyError};
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::{Core, StreamInfo};
use pyo3::prelude::*;
use std::time::Duration;

pub use link::Link;
pub use opening::open;
pub use v1::ChassisV1;
pub use v2020::{Chassis, SystemMode};

/// How long a stop that nobody waits for (a chassis collected, a process ending on a signal)
/// waits for what it started (2020: the cancel of a turn outstanding) before it lets go. The
/// stop frame itself is written at once.
pub const STOP_WAIT: Duration = Duration::from_secs(1);

/// A generation's driver core as the shared part uses it: what each generation's core gives
/// beyond the shells' [`Core`], each answered in that generation's module.
pub trait PyCore: Core<Event: Send, Request: Send, Outcome: Send> + Send + Sized + 'static {
    /// What has come from the board, judged at `now_ms`.
    fn heard(&self, now_ms: u64) -> Heard;
    /// Whether a stop now starts a request of its own (2020: the cancel of a turn outstanding).
    fn stop_starts_request(&self) -> bool;
    /// Whether the board was heard within the failsafe time, at `now_ms`.
    fn link_alive(&self, now_ms: u64) -> bool;
    /// Whether the driver has the chassis moving.
    fn moving(&self) -> bool;
    /// Times the failsafe has stopped the chassis.
    fn failsafe_stops(&self) -> u32;
    /// Each telemetry stream by its name, with what the driver counted of it.
    fn streams(&self) -> Vec<(String, StreamInfo)>;
    /// The parser's counters, by name.
    fn counters(&self) -> Vec<(&'static str, u32)>;
    /// An event as the frame Python is given; `None` for one that is not Python's (2020: the
    /// replies, which are the driver's reads).
    fn frame(py: Python<'_>, event: Self::Event) -> PyResult<Option<Py<PyAny>>>;
}

/// `ChassisError`: the chassis on `port` is closed.
fn closed(port: &str) -> PyErr {
    ChassisError::new_err(format!("the chassis on {port} is closed"))
}

/// Whether `e` says the chassis is closed.
fn is_closed(e: &PyErr, py: Python<'_>) -> bool {
    e.value(py).to_string().ends_with("is closed")
}

/// A write whose frame went out, confirmed by nothing (its read-back unanswered, disagreeing or
/// showing another value): `UnconfirmedError` on both generations, `what` then the reason. The
/// port failing, the chassis closed or a signal's exception go on as they are.
fn unconfirmed(py: Python<'_>, what: &str, e: PyErr) -> PyErr {
    let unanswered = e.is_instance_of::<TimeoutError>(py)
        || e.is_instance_of::<UnconfirmedError>(py)
        || e.is_instance_of::<WrongReplyError>(py);
    if !unanswered {
        return e;
    }
    UnconfirmedError::new_err(format!("{what}: {}", e.value(py)))
}
