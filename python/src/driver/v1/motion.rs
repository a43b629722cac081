//! The v1.0.0 chassis's motion frames from Python's numbers: the body velocity in SI units (the
//! frame's thousandths), the motors' raw speeds; each checked against the frame's 16 bits.

use crate::args::Real;
use crate::frames;
use chassis_protocol::v1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A speed in SI units as the board's thousandths.
fn milli(value: &Real, name: &str) -> PyResult<i16> {
    let m = (value.value * 1000.0).round();
    if !m.is_finite() || !(f64::from(i16::MIN)..=f64::from(i16::MAX)).contains(&m) {
        return Err(PyValueError::new_err(format!(
            "{name} = {value} is out of range (±32.767, the frame's 16 bits in thousandths)"
        )));
    }
    Ok(m as i16)
}

/// `ChassisV1.set_velocity`'s frame: vx, vy in m/s, wz in rad/s.
pub fn body_velocity(vx: &Real, vy: &Real, wz: &Real) -> PyResult<v1::BodyVelocity> {
    Ok(v1::BodyVelocity::new(
        milli(vx, "vx")?,
        milli(vy, "vy")?,
        milli(wz, "wz")?,
    ))
}

/// `ChassisV1.set_motors`'s frame: each speed raw, -32768..=32767.
pub fn motor_velocity(speeds: [Bound<'_, PyAny>; 4]) -> PyResult<v1::MotorVelocity> {
    let mut raw = [0i16; 4];
    for (i, (out, v)) in raw
        .iter_mut()
        .zip(frames::ints(speeds, "speeds")?)
        .enumerate()
    {
        *out = i16::try_from(v).map_err(|_| {
            PyValueError::new_err(format!(
                "speeds[{i}] = {v} is out of range (-32768..=32767, the frame's 16 bits)"
            ))
        })?;
    }
    Ok(v1::MotorVelocity::new(raw))
}
