//! `chassis.open`: the limits it takes, the port opened, the firmware found (or taken as
//! given), and the chassis of that generation made by [`crate::generation`].

use crate::args::Int;
use crate::errors::{ChassisError, TimeoutError, TransportError};
use crate::signals;
use chassis_protocol::detect::{self, Firmware};
use chassis_protocol::driver::Config;
use chassis_protocol::driver::host::{MonotonicClock, SerialPort};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::ops::RangeInclusive;

/// The failsafe `open()` takes, in ms: shorter stops a healthy chassis between two frames of
/// its telemetry behind a USB-UART adapter; longer is no failsafe (v1.0.0 raises anything
/// under 300 ms to 300 ms).
const FAILSAFE_MS: RangeInclusive<i128> = 50..=5_000;
/// The board's latency `open()` takes, in ms.
const BOARD_LATENCY_MS: RangeInclusive<i128> = 0..=2_000;
/// The quiet line `open()` takes, in ms.
const IDLE_MS: RangeInclusive<i128> = 1..=500;
/// The reads a verified read may send: two replies must agree, so at least two.
const READ_TRIES: RangeInclusive<i128> = 2..=10;

/// The host configuration with the caller's changes, each checked against its range
/// (`ValueError` naming it and the range).
fn config(
    failsafe_ms: Option<Int>,
    board_latency_ms: Option<Int>,
    idle_ms: Option<Int>,
    read_tries: Option<Int>,
) -> PyResult<Config> {
    let mut c = Config::HOST;
    if let Some(v) = failsafe_ms {
        c.failsafe_ms = v.within("failsafe_ms", FAILSAFE_MS)?;
    }
    if let Some(v) = board_latency_ms {
        c.board_latency_ms = v.within("board_latency_ms", BOARD_LATENCY_MS)?;
    }
    if let Some(v) = idle_ms {
        c.idle_ms = v.within("idle_ms", IDLE_MS)?;
    }
    if let Some(v) = read_tries {
        c.read_tries = v.within("read_tries", READ_TRIES)?;
    }
    Ok(c)
}

/// The generation `firmware=` names.
fn firmware_of(name: &str) -> PyResult<Firmware> {
    Firmware::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!("firmware={name:?}: the board runs 2020 or v1.0.0"))
    })
}

/// The firmware the board on `path` runs, found from what it sends (see [`detect::detect`]);
/// `TimeoutError` when nothing came, `ChassisError` on bytes of neither firmware.
fn find_firmware(serial: &mut SerialPort, path: &str, config: &Config) -> PyResult<Firmware> {
    let mut clock = MonotonicClock::new();
    let found = detect::detect(serial, &mut clock, config)
        .map_err(|e| TransportError::new_err(format!("serial port {path}: {}", e.0)))?;
    match found.firmware {
        Some(f) => Ok(f),
        None if found.heard.bytes == 0 => Err(TimeoutError::new_err(format!(
            "nothing came from the board on {path} in {:.1} s, not even an answer to a register read of either firmware (is it powered, TX wired to RX and RX to TX, at 115200 bps?); firmware=\"2020\" or \"v1.0.0\" skips this check",
            found.elapsed_ms as f64 / 1000.0
        ))),
        None => Err(ChassisError::new_err(format!(
            "{} bytes came from {path}, but no frame of either firmware: another device, or a baud rate other than 115200?",
            found.heard.bytes
        ))),
    }
}

/// Opens `port` (a serial port path), finds the firmware if not given, and returns a `Chassis`
/// (2020) or a `ChassisV1` (v1.0.0) with the host defaults and its pump thread running.
#[pyfunction]
#[pyo3(signature = (port, *, firmware = None, failsafe_ms = None, board_latency_ms = None, idle_ms = None, read_tries = None))]
pub fn open(
    py: Python<'_>,
    port: &str,
    firmware: Option<&str>,
    failsafe_ms: Option<Int>,
    board_latency_ms: Option<Int>,
    idle_ms: Option<Int>,
    read_tries: Option<Int>,
) -> PyResult<Py<PyAny>> {
    let config = config(failsafe_ms, board_latency_ms, idle_ms, read_tries)?;
    let given = firmware.map(firmware_of).transpose()?;
    // Before the port opens: from here on SIGTERM and SIGHUP stop every chassis first.
    signals::install(py).map_err(ChassisError::new_err)?;
    let (serial, firmware) = crate::detach(py, || -> PyResult<(SerialPort, Firmware)> {
        let mut serial = SerialPort::open(port)
            .map_err(|e| TransportError::new_err(format!("cannot open {port}: {}", e.0)))?;
        let firmware = match given {
            Some(f) => f,
            None => find_firmware(&mut serial, port, &config)?,
        };
        Ok((serial, firmware))
    })?;
    (crate::generation::of(firmware).chassis)(py, serial, MonotonicClock::new(), config, port)
}
