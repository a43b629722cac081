//! The v1.0.0 firmware's board → master frames: the telemetry frame (`Telemetry`) and the
//! replies to readbacks (`ReadbackReply`, its fields typed by [`reply_fields`]), and the class
//! of a frame a parser took in ([`v1_downlink`]).

use crate::args::Int;
use crate::errors::FrameError;
use crate::frames::{I16, U8, bad, each, same_fields};
use chassis_protocol::v1;
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// A v1.0.0 telemetry frame (32 bytes, ~22 Hz): measured velocity (mm/s, mrad/s), raw
/// accelerometer and gyro, the IMU's quaternion × 1000, battery in mV.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Telemetry {
    /// vx, vy (mm/s), wz (mrad/s).
    #[pyo3(get)]
    pub velocity: [i16; 3],
    /// Accelerometer x, y, z: raw (scale unknown).
    #[pyo3(get)]
    pub accel: [i16; 3],
    /// Gyro x, y, z: raw.
    #[pyo3(get)]
    pub gyro: [i16; 3],
    /// w, x, y, z × 1000.
    #[pyo3(get)]
    pub quaternion: [i16; 4],
    /// Battery, mV.
    #[pyo3(get)]
    pub battery_mv: i16,
}

same_fields!(Telemetry <=> v1::Telemetry { velocity, accel, gyro, quaternion, battery_mv });

#[pymethods]
impl Telemetry {
    #[new]
    #[pyo3(
        signature = (velocity = [Int::ZERO; 3], accel = [Int::ZERO; 3], gyro = [Int::ZERO; 3], quaternion = [Int::from(1000), Int::ZERO, Int::ZERO, Int::ZERO], battery_mv = Int::ZERO),
        text_signature = "(velocity=(0, 0, 0), accel=(0, 0, 0), gyro=(0, 0, 0), quaternion=(1000, 0, 0, 0), battery_mv=0)"
    )]
    fn new(
        velocity: [Int; 3],
        accel: [Int; 3],
        gyro: [Int; 3],
        quaternion: [Int; 4],
        battery_mv: Int,
    ) -> PyResult<Self> {
        Ok(Telemetry {
            velocity: each(&velocity, "velocity", I16)?,
            accel: each(&accel, "accel", I16)?,
            gyro: each(&gyro, "gyro", I16)?,
            quaternion: each(&quaternion, "quaternion", I16)?,
            battery_mv: battery_mv.within("battery_mv", I16)?,
        })
    }

    /// The heading from the quaternion, in degrees (−180…180].
    #[getter]
    fn yaw_degrees(&self) -> f64 {
        let [w, x, y, z] = self.quaternion.map(|v| f64::from(v) / 1000.0);
        let siny = 2.0 * (w * z + x * y);
        let cosy = 1.0 - 2.0 * (y * y + z * z);
        siny.atan2(cosy).to_degrees()
    }

    /// The frame's 32 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner().encode())
    }

    /// A telemetry frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        v1::Telemetry::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "Telemetry(velocity={:?}, accel={:?}, gyro={:?}, quaternion={:?}, battery_mv={})",
            self.velocity, self.accel, self.gyro, self.quaternion, self.battery_mv
        )
    }
}

/// A v1.0.0 reply to a readback (14 bytes): its request's name and the ten payload bytes,
/// typed by `fields()`.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct ReadbackReply {
    inner: v1::Reply,
}

impl From<v1::Reply> for ReadbackReply {
    fn from(inner: v1::Reply) -> Self {
        ReadbackReply { inner }
    }
}

/// A v1 reply's fields as a dict (the names the `chassis` command's JSON uses).
pub fn reply_fields<'py>(py: Python<'py>, reply: &v1::Reply) -> PyResult<Bound<'py, PyDict>> {
    let value = match reply.request {
        v1::Readback::System => reply.system().map(serde_json::to_value),
        v1::Readback::Geometry => reply.geometry().map(serde_json::to_value),
        v1::Readback::BodyVelocity => reply.body_velocity().map(serde_json::to_value),
        v1::Readback::MotorSpeeds => reply.motor_speeds().map(serde_json::to_value),
        v1::Readback::Pid => reply.pid().map(serde_json::to_value),
    };
    let value = value
        .transpose()
        .map_err(|e| FrameError::new_err(e.to_string()))?
        .unwrap_or(serde_json::Value::Null);
    crate::json::to_dict(py, &value)
}

#[pymethods]
impl ReadbackReply {
    /// The reply to the readback `request` (`system`, `geometry`, …) with its ten payload
    /// bytes.
    #[new]
    fn new(request: &str, payload: [Int; 10]) -> PyResult<Self> {
        let payload = each(&payload, "payload", U8)?;
        let request = v1::Readback::from_name(request).ok_or_else(|| {
            PyValueError::new_err(format!(
                "{request:?} is not a readback: give one of {}",
                v1::Readback::ALL.map(v1::Readback::name).join(", ")
            ))
        })?;
        Ok(v1::Reply { request, payload }.into())
    }

    /// The readback it answers: `system`, `geometry`, `body-velocity`, `motor-speeds`, `pid`.
    #[getter]
    fn request(&self) -> &'static str {
        self.inner.request.name()
    }

    /// Its code byte.
    #[getter]
    fn code(&self) -> u8 {
        self.inner.request.code()
    }

    /// The ten payload bytes.
    #[getter]
    fn payload<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.payload)
    }

    /// Its fields by name, typed (a dict).
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        reply_fields(py, &self.inner)
    }

    /// The frame's 14 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.encode())
    }

    /// A reply frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        v1::Reply::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "ReadbackReply(request={:?}, payload={:02X?})",
            self.inner.request.name(),
            self.inner.payload
        )
    }
}

/// A v1.0.0 board → master frame as its Python class.
pub fn v1_downlink(py: Python<'_>, frame: v1::Downlink) -> PyResult<Py<PyAny>> {
    match frame {
        v1::Downlink::Telemetry(t) => Telemetry::from(t).into_py_any(py),
        v1::Downlink::Reply(r) => ReadbackReply::from(r).into_py_any(py),
    }
}
