//! `Chassis`: the 2020 firmware's chassis. What it shares with every chassis comes from
//! [`chassis_class!`]; here are its own methods: the velocity in raw units and the motors
//! (below), turns by an angle ([`motion`]), the registers ([`registers`], with
//! [`SystemMode`]); and what its core tells the shared part ([`PyCore`]).

mod motion;
mod registers;
mod system_mode;

pub use system_mode::SystemMode;

use super::PyCore;
use super::class::chassis_class;
use crate::args::{Int, Real};
use crate::frames;
use chassis_protocol as p;
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::{DriverCore, Event, StreamInfo};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The telemetry streams of the 2020 board.
const STREAMS: [p::Stream; 3] = [p::Stream::Imu, p::Stream::Encoders, p::Stream::Battery];

impl PyCore for DriverCore {
    fn heard(&self, now_ms: u64) -> Heard {
        DriverCore::heard(self, now_ms)
    }
    fn stop_starts_request(&self) -> bool {
        self.turning()
    }
    fn link_alive(&self, now_ms: u64) -> bool {
        DriverCore::link_alive(self, now_ms)
    }
    fn moving(&self) -> bool {
        DriverCore::moving(self)
    }
    fn failsafe_stops(&self) -> u32 {
        DriverCore::failsafe_stops(self)
    }
    fn streams(&self) -> Vec<(String, StreamInfo)> {
        STREAMS
            .map(|s| (format!("{s:?}").to_lowercase(), self.stream(s)))
            .into()
    }
    fn counters(&self) -> Vec<(&'static str, u32)> {
        let s = self.parser_stats();
        vec![
            ("frames", s.total_frames()),
            ("discarded", s.discarded),
            ("resyncs", s.resyncs),
            ("lock_losses", s.lock_losses),
        ]
    }
    fn frame(py: Python<'_>, event: Event) -> PyResult<Option<Py<PyAny>>> {
        match event {
            Event::Telemetry(f) => frames::downlink(py, f).map(Some),
            // Replies are the driver's (its reads): not telemetry.
            _ => Ok(None),
        }
    }
}

chassis_class! {
    /// A chassis running the 2020 firmware, driven over a serial port (made by `chassis.open`).
    ///
    /// Leaving a `with` block, an exception in it, `KeyboardInterrupt`, SIGTERM, SIGHUP, `close()`
    /// or the object being collected stops the chassis. While it moves, the driver's failsafe stops
    /// it when the board has been silent for `failsafe_ms` (200 ms), whatever the program (and each
    /// of its threads) is doing.
    pub struct Chassis(Link<DriverCore>) = "2020";
    words {
        frame: "telemetry frame",
        stops: "Stops the chassis",
        stop: "Stops the chassis; a turn in progress is cancelled (the angle still pending is read and\nthe opposite turn sent).",
        poll: "The next telemetry frame the driver took in (`Imu`, `Encoders`, `Battery`), or `None`\nwhen none is waiting. Never blocks.",
        moving: "Whether the driver has the chassis moving (a turn outstanding counts).",
        failsafe_stops: "Times the failsafe has stopped the chassis.",
        streams: "Per stream (`imu`, `encoders`, `battery`): frames, missed (by the counts), rate_hz.",
        counters: "The parser's counters, and frames dropped because nobody polled.",
    }

    /// Sets the body velocity (X sideways, Y forward, Z rotation; the board's raw units,
    /// ±65535). Safe to call every period.
    #[pyo3(
        signature = (x = Int::ZERO, y = Int::ZERO, z = Int::ZERO),
        text_signature = "(self, x=0, y=0, z=0)"
    )]
    fn set_velocity(&self, py: Python<'_>, x: Int, y: Int, z: Int) -> PyResult<()> {
        let v = frames::Velocity::new_checked(x, y, z)?;
        self.link.with(py, |d| d.set_velocity(v))
    }

    /// Drives each motor: closed-loop speeds (±65535), or open-loop duty in 0.01 % (±10000,
    /// `open_loop=True`). A value out of range is a `ValueError`, nothing sent.
    #[pyo3(signature = (values, open_loop = false))]
    fn set_motors(
        &self,
        py: Python<'_>,
        values: [Bound<'_, PyAny>; 4],
        open_loop: bool,
    ) -> PyResult<()> {
        let m = frames::Motors::new_checked(frames::ints(values, "values")?, open_loop)?.inner();
        self.link.with(py, |d| d.set_motors(m))
    }

    /// Turns by `degrees` (0.1° steps), sent **once**: the board adds turns up, so while one is
    /// outstanding another raises `TurnInProgressError` (nothing sent). `wait_turn()` waits
    /// for it; `stop()` cancels it.
    fn turn(&self, py: Python<'_>, degrees: Real) -> PyResult<()> {
        self.turn_by(py, degrees)
    }

    /// Waits until the turn is done (the pending angle reads 0): `True`, or `False` after
    /// `timeout` seconds (`None` or `math.inf`: for ever; negative or NaN: `ValueError`).
    /// `KeyboardInterrupt` while waiting cancels the turn.
    #[pyo3(signature = (timeout = None))]
    fn wait_turn(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<bool> {
        self.wait_for_turn(py, timeout)
    }

    /// Reads a register by name (`max-speed`, `kp`, `ki`, `gyro-gain`, `system-mode`,
    /// `gyro-calibration`, `motor-voltage`, `battery-range`, `pending-angle`), each read
    /// verified (two replies must agree): an `int`; a `SystemMode`; `(full_volts,
    /// cutoff_volts)` (`None` for the built-in table); the pending angle in degrees.
    fn read(&self, py: Python<'_>, register: &str) -> PyResult<Py<PyAny>> {
        self.read_register(py, register)
    }

    /// Writes a register and reads it back (`UnconfirmedError` if the board does not show the
    /// value). A write that starts a 30 s gyro calibration (gyro-calibration 0xFFFF,
    /// system-mode switching bit 3 on) needs `calibrate=True`.
    ///
    /// `value` is what `read` gives: an `int`; for system-mode a `SystemMode` too; for
    /// battery-range `(full_volts, cutoff_volts)`, `None` for the built-in table (the full
    /// voltage above the cut-off).
    #[pyo3(signature = (register, value, *, calibrate = false))]
    fn write(
        &self,
        py: Python<'_>,
        register: &str,
        value: &Bound<'_, PyAny>,
        calibrate: bool,
    ) -> PyResult<()> {
        let value = registers::raw_value(register, value)?;
        self.write_register(py, register, value, calibrate)
    }

    /// Every register, each read verified, as a dict (the `chassis settings` JSON).
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.settings_dict(py)
    }

    /// Writes settings back (a dict as `settings()` gives; never starts a gyro calibration),
    /// reads every register back and returns what differs: `{name: (wanted, board)}` (empty
    /// when all were restored; system-mode bit 3, gyro compensation, is kept as the board has
    /// it).
    fn restore<'py>(
        &self,
        py: Python<'py>,
        settings: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.restore_settings(py, settings)
    }

    /// The latest IMU frame (or `None`).
    #[getter]
    fn imu(&self) -> PyResult<Option<frames::Imu>> {
        self.link.core(|c| c.imu().map(|s| s.value.into()))
    }

    /// The latest encoder frame (or `None`).
    #[getter]
    fn encoders(&self) -> PyResult<Option<frames::Encoders>> {
        self.link.core(|c| c.encoders().map(|s| s.value.into()))
    }

    /// The latest battery frame (or `None`).
    #[getter]
    fn battery(&self) -> PyResult<Option<frames::Battery>> {
        self.link.core(|c| c.battery().map(|s| s.value.into()))
    }
}
