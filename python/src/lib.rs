//! The Python package `chassis` (its native part, `chassis.chassis_native`): the Rust crate
//! `chassis-protocol` for Python, with no protocol logic written again. The driver with its
//! failsafe and turn guard over a serial port (`open`, `Chassis`, `ChassisV1`), the frames and
//! parsers of both firmware generations, and simulated boards (`chassis.sim`).

mod capture;
mod driver;
mod errors;
mod frames;
mod json;
mod parsers;
mod sim;

use pyo3::prelude::*;

/// The native part of the `chassis` package.
#[pymodule]
fn chassis_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    m.add_function(wrap_pyfunction!(driver::open, m)?)?;
    m.add_class::<driver::Chassis>()?;
    m.add_class::<driver::ChassisV1>()?;
    m.add_class::<driver::SystemMode>()?;
    m.add_class::<frames::Velocity>()?;
    m.add_class::<frames::Turn>()?;
    m.add_class::<frames::Motors>()?;
    m.add_class::<frames::Read>()?;
    m.add_class::<frames::Write>()?;
    m.add_class::<frames::Action>()?;
    m.add_class::<frames::Imu>()?;
    m.add_class::<frames::Encoders>()?;
    m.add_class::<frames::Battery>()?;
    m.add_class::<frames::Reply>()?;
    m.add_class::<frames::BodyVelocity>()?;
    m.add_class::<frames::Telemetry>()?;
    m.add_class::<frames::ReadbackReply>()?;
    m.add_class::<parsers::DownlinkParser>()?;
    m.add_class::<parsers::UplinkParser>()?;
    m.add_class::<parsers::V1DownlinkParser>()?;
    m.add_class::<parsers::V1UplinkParser>()?;
    m.add_class::<sim::SimBoard>()?;
    m.add_class::<sim::SimPty>()?;
    m.add_function(wrap_pyfunction!(sim::pty, m)?)?;
    m.add_class::<capture::Decoded>()?;
    m.add_function(wrap_pyfunction!(capture::decode_capture, m)?)?;
    Ok(())
}
