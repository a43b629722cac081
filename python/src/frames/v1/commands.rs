//! The v1.0.0 firmware's commands (master → board): the body velocity (`BodyVelocity`, `0x25`),
//! and the class of a command a parser found ([`v1_uplink`]: the others as dicts).

use crate::args::Int;
use crate::errors::FrameError;
use crate::frames::{I16, U8, bad, same_fields};
use chassis_protocol::v1;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

/// A v1.0.0 body velocity (`0x25`): vx, vy in mm/s, wz in mrad/s; `ctl` 2 drives, the forced
/// stop is `ctl` 0 with everything 0; `kind` is the vehicle type (4: the vendor's mecanum).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyVelocity {
    /// Sideways, mm/s.
    #[pyo3(get)]
    pub vx_mm_s: i16,
    /// Forward, mm/s.
    #[pyo3(get)]
    pub vy_mm_s: i16,
    /// Rotation, mrad/s.
    #[pyo3(get)]
    pub wz_mrad_s: i16,
    /// Control byte.
    #[pyo3(get)]
    pub ctl: u8,
    /// Vehicle type.
    #[pyo3(get)]
    pub kind: u8,
}

same_fields!(BodyVelocity <=> v1::BodyVelocity { vx_mm_s, vy_mm_s, wz_mrad_s, ctl, kind });

#[pymethods]
impl BodyVelocity {
    #[new]
    #[pyo3(
        signature = (vx_mm_s = Int::ZERO, vy_mm_s = Int::ZERO, wz_mrad_s = Int::ZERO, ctl = Int::from(2), kind = Int::from(4)),
        text_signature = "(vx_mm_s=0, vy_mm_s=0, wz_mrad_s=0, ctl=2, kind=4)"
    )]
    fn new(vx_mm_s: Int, vy_mm_s: Int, wz_mrad_s: Int, ctl: Int, kind: Int) -> PyResult<Self> {
        Ok(BodyVelocity {
            vx_mm_s: vx_mm_s.within("vx_mm_s", I16)?,
            vy_mm_s: vy_mm_s.within("vy_mm_s", I16)?,
            wz_mrad_s: wz_mrad_s.within("wz_mrad_s", I16)?,
            ctl: ctl.within("ctl", U8)?,
            kind: kind.within("kind", U8)?,
        })
    }

    /// The forced stop.
    #[staticmethod]
    fn forced_stop() -> Self {
        v1::BodyVelocity::FORCED_STOP.into()
    }

    /// Whether this is the forced stop.
    #[getter]
    fn is_forced_stop(&self) -> bool {
        self.inner().is_forced_stop()
    }

    /// The frame's 14 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &v1::Command::BodyVelocity(self.inner()).encode())
    }

    /// A `0x25` frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        match v1::Command::decode(data).map_err(bad)? {
            v1::Command::BodyVelocity(v) => Ok(v.into()),
            _ => Err(FrameError::new_err("a v1.0.0 frame, not a body velocity")),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "BodyVelocity(vx_mm_s={}, vy_mm_s={}, wz_mrad_s={}, ctl={}, kind={})",
            self.vx_mm_s, self.vy_mm_s, self.wz_mrad_s, self.ctl, self.kind
        )
    }
}

/// A v1.0.0 master → board frame: a `BodyVelocity`, or a dict as `decode_capture` gives it
/// (`{"frame": "v1-readback", "request": "system", "code": 51}`).
pub fn v1_uplink(py: Python<'_>, frame: v1::Command) -> PyResult<Py<PyAny>> {
    if let v1::Command::BodyVelocity(v) = frame {
        return BodyVelocity::from(v).into_py_any(py);
    }
    let (value, _) = chassis_capture::describe_v1_uplink(&frame);
    Ok(crate::json::to_py(py, &value)?.unbind())
}
