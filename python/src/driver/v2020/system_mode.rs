//! `SystemMode`: the 2020 system-mode register (0x09), by field, as `Chassis.read` gives it and
//! `Chassis.write` takes it.

use crate::args::Int;
use chassis_protocol as p;
use pyo3::prelude::*;

/// The system-mode register (0x09), by field.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct SystemMode {
    /// The raw bits.
    #[pyo3(get)]
    pub bits: u32,
}

impl SystemMode {
    fn mode(&self) -> p::SystemMode {
        p::SystemMode::from_bits(self.bits)
    }
}

impl From<p::SystemMode> for SystemMode {
    fn from(m: p::SystemMode) -> Self {
        SystemMode { bits: m.bits() }
    }
}

#[pymethods]
impl SystemMode {
    #[new]
    fn new(bits: Int) -> PyResult<Self> {
        Ok(SystemMode {
            bits: bits.within("bits", 0..=i128::from(u32::MAX))?,
        })
    }

    /// `omni`, `mecanum`, `differential`, `differential-open-loop`.
    #[getter]
    fn drive_type(&self) -> &'static str {
        match self.mode().drive_type() {
            p::DriveType::Omni => "omni",
            p::DriveType::Mecanum => "mecanum",
            p::DriveType::Differential => "differential",
            p::DriveType::DifferentialOpenLoop => "differential-open-loop",
            p::DriveType::Reserved(_) => "reserved",
        }
    }

    /// Bit 3: gyro compensation.
    #[getter]
    fn gyro_compensation(&self) -> bool {
        self.mode().gyro_compensation()
    }

    /// Gyro correction at rest.
    #[getter]
    fn gyro_correction_at_rest(&self) -> bool {
        self.mode().gyro_correction_at_rest()
    }

    /// Motor direction reversed.
    #[getter]
    fn motor_reversed(&self) -> bool {
        self.mode().motor_reversed()
    }

    /// Encoder direction reversed.
    #[getter]
    fn encoder_reversed(&self) -> bool {
        self.mode().encoder_reversed()
    }

    /// Steering reversed.
    #[getter]
    fn steering_reversed(&self) -> bool {
        self.mode().steering_reversed()
    }

    /// Gyro direction reversed.
    #[getter]
    fn gyro_reversed(&self) -> bool {
        self.mode().gyro_reversed()
    }

    fn __repr__(&self) -> String {
        format!(
            "SystemMode(0x{:08X}: drive_type={:?}, gyro_compensation={})",
            self.bits,
            self.drive_type(),
            if self.gyro_compensation() {
                "True"
            } else {
                "False"
            }
        )
    }
}
