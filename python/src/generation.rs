//! The one place a firmware generation is chosen: [`of`] turns the generation found on the
//! line, or named by the caller (`open(..., firmware=...)`, a simulated board's `firmware=`),
//! into what serves it here: its chassis class over a serial port, its simulated board.
//! Everything else either does not care which generation it serves or lives in that
//! generation's own module.

use crate::driver::{Chassis, ChassisV1, Link};
use chassis_protocol::detect::Firmware;
use chassis_protocol::driver::Config;
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::host::{MonotonicClock, SerialPort};
use chassis_protocol::sim::{self, Simulated};
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;

/// What serves one firmware generation in this package.
pub struct Generation {
    /// Its chassis (`Chassis`, `ChassisV1`) over a serial port (at `port`), with its clock and
    /// configuration, the pump thread running.
    pub chassis: fn(Python<'_>, SerialPort, MonotonicClock, Config, &str) -> PyResult<Py<PyAny>>,
    /// Its simulated board, seeded.
    pub board: fn(u64) -> Box<dyn Simulated + Send + Sync>,
}

/// What serves `firmware`.
pub fn of(firmware: Firmware) -> &'static Generation {
    match firmware {
        Firmware::V2020 => &V2020,
        Firmware::V1_0_0 => &V1,
    }
}

/// The 2020 firmware: `Chassis`, the 2020 simulated board.
const V2020: Generation = Generation {
    chassis: |py, serial, clock, config, port| {
        let driver = Driver::new(serial, clock, config);
        Chassis::from(Link::start(py, driver, clock, port)).into_py_any(py)
    },
    board: |seed| {
        let config = sim::SimConfig {
            seed,
            ..sim::SimConfig::default()
        };
        Box::new(sim::Board::new(config))
    },
};

/// Firmware v1.0.0: `ChassisV1`, the v1.0.0 simulated board.
const V1: Generation = Generation {
    chassis: |py, serial, clock, config, port| {
        let driver = Driver::new_v1(serial, clock, config);
        ChassisV1::from(Link::start(py, driver, clock, port)).into_py_any(py)
    },
    board: |seed| {
        let config = sim::v1::SimConfig {
            seed,
            ..sim::v1::SimConfig::default()
        };
        Box::new(sim::v1::Board::new(config))
    },
};
