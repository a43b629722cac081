//! `ChassisV1`: the v1.0.0 firmware's chassis (`7B … BCC 7D` frames). What it shares with every
//! chassis comes from [`chassis_class!`]; here are its own methods: the velocity in SI units
//! and the motors ([`motion`]), the readbacks and the settings frames ([`settings`]); and what
//! its core tells the shared part ([`PyCore`]).

mod motion;
mod settings;

use super::PyCore;
use super::class::chassis_class;
use crate::args::Real;
use crate::frames;
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::{StreamInfo, v1};
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::PyDict;

impl PyCore for v1::DriverCore {
    fn heard(&self, now_ms: u64) -> Heard {
        v1::DriverCore::heard(self, now_ms)
    }
    fn stop_starts_request(&self) -> bool {
        false
    }
    fn link_alive(&self, now_ms: u64) -> bool {
        v1::DriverCore::link_alive(self, now_ms)
    }
    fn moving(&self) -> bool {
        v1::DriverCore::moving(self)
    }
    fn failsafe_stops(&self) -> u32 {
        v1::DriverCore::failsafe_stops(self)
    }
    fn streams(&self) -> Vec<(String, StreamInfo)> {
        vec![("telemetry".into(), self.stream())]
    }
    fn counters(&self) -> Vec<(&'static str, u32)> {
        crate::parsers::v1_counts(self.parser_stats()).into()
    }
    fn frame(py: Python<'_>, event: v1::Event) -> PyResult<Option<Py<PyAny>>> {
        match event {
            v1::Event::Telemetry(t) => frames::Telemetry::from(t).into_py_any(py),
            v1::Event::Reply(r) => frames::ReadbackReply::from(r).into_py_any(py),
        }
        .map(Some)
    }
}

chassis_class! {
    /// A chassis running the v1.0.0 firmware (`7B … BCC 7D` frames), made by `chassis.open`. The
    /// same guarantees as `Chassis`; the failsafe sends the forced stop. There is no turn by an
    /// angle on v1.0.0, and no `turn` here.
    pub struct ChassisV1(Link<v1::DriverCore>) = "v1.0.0";
    words {
        frame: "frame",
        stops: "Sends the forced stop",
        stop: "Sends the forced stop.",
        poll: "The next frame the driver took in (`Telemetry`, or a `ReadbackReply` nobody asked for),\nor `None`.",
        moving: "Whether the driver has the chassis moving.",
        failsafe_stops: "Times the failsafe has sent the forced stop.",
        streams: "The telemetry stream: frames, rate_hz.",
        counters: "The parser's counters (frames, bad_checksum, bad_end, refused, discarded), and frames\ndropped because nobody polled.",
    }

    /// Sets the body velocity: vx sideways and vy forward in m/s, wz in rad/s
    /// (counter-clockwise). Safe to call every period.
    #[pyo3(
        signature = (vx = Real::from(0.0), vy = Real::from(0.0), wz = Real::from(0.0)),
        text_signature = "(self, vx=0.0, vy=0.0, wz=0.0)"
    )]
    fn set_velocity(&self, py: Python<'_>, vx: Real, vy: Real, wz: Real) -> PyResult<()> {
        let v = motion::body_velocity(&vx, &vy, &wz)?;
        self.link.with(py, |d| d.set_velocity(v))
    }

    /// Drives each motor (`0x26`; the board's own unit, raw, each -32768..=32767: out of range
    /// is a `ValueError`, nothing sent).
    fn set_motors(&self, py: Python<'_>, speeds: [Bound<'_, PyAny>; 4]) -> PyResult<()> {
        let m = motion::motor_velocity(speeds)?;
        self.link.with(py, |d| d.set_motors(m))
    }

    /// A readback by name (`system`, `geometry`, `body-velocity`, `motor-speeds`, `pid`: a dict
    /// of its fields) or one settings field (`wheel-diameter`, `pwm-max`, … : an `int`).
    fn read<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.read_name(py, name)
    }

    /// Writes one settings field: its frame is read back, written with the field changed (at
    /// least 100 ms after the previous settings frame), and read back again
    /// (`UnconfirmedError` if the board does not show it).
    fn write(&self, py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.write_field(py, name, value)
    }

    /// The three settings frames as a dict: `{"firmware": "v1.0.0", "system": {…},
    /// "geometry": {…}, "pid": {…}}` (the `chassis settings` JSON).
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.settings_dict(py)
    }

    /// Writes the three settings frames of a dict as `settings()` gives, each confirmed by its
    /// readback (v1.0.0 keeps them until power-off).
    fn restore(&self, py: Python<'_>, settings: &Bound<'_, PyDict>) -> PyResult<()> {
        self.restore_settings(py, settings)
    }

    /// The latest telemetry frame (or `None`).
    #[getter]
    fn telemetry(&self) -> PyResult<Option<frames::Telemetry>> {
        self.link.core(|c| c.telemetry().map(|s| s.value.into()))
    }
}
