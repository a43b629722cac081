//! The 2020 chassis's registers: each read verified, given to Python typed (an `int`, a
//! `SystemMode`, volts, degrees) and taken back raw; a write confirmed by its read-back (and
//! refused when it would start a gyro calibration unasked); all of them read and restored.

use super::{Chassis, SystemMode};
use crate::driver::unconfirmed;
use crate::errors::{ChassisError, UnconfirmedError};
use crate::frames;
use chassis_protocol as p;
use chassis_protocol::driver::{Outcome, Request};
use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

/// A register's raw value from what `read` gives for it (see `Chassis.write`).
pub(super) fn raw_value(register: &str, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    if value.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{register}: {value} is a bool, not a value: give an int"
        )));
    }
    if let Ok(mode) = value.extract::<SystemMode>() {
        return Ok(mode.bits);
    }
    if register == "battery-range" {
        if let Ok((full, cutoff)) = value.extract::<(Option<f64>, Option<f64>)>() {
            return Ok((centivolts(full, "full")? << 16) | centivolts(cutoff, "cut-off")?);
        }
    }
    value.extract::<u32>().map_err(|e| {
        if e.is_instance_of::<PyOverflowError>(value.py()) {
            PyValueError::new_err(format!("{register} = {value} is out of range"))
        } else {
            e
        }
    })
}

/// One half of battery-range: volts in 0.01 V, `None` (the built-in table) as 0x7FFF.
fn centivolts(volts: Option<f64>, what: &str) -> PyResult<u32> {
    let Some(volts) = volts else {
        return Ok(0x7FFF);
    };
    let c = (volts * 100.0).round();
    if !(0.0..=655.35).contains(&volts) || !c.is_finite() {
        return Err(PyValueError::new_err(format!(
            "battery-range: {what} {volts} V is out of range (0..=655.35 V, or None for the built-in table)"
        )));
    }
    Ok(c as u32)
}

/// What `read` returns for a register.
fn typed_value(py: Python<'_>, register: p::Register, raw: u32) -> PyResult<Py<PyAny>> {
    Ok(match register {
        p::Register::PendingAngle => (f64::from(raw as i32) / 10.0)
            .into_pyobject(py)?
            .into_any()
            .unbind(),
        p::Register::SystemMode => SystemMode::from(p::SystemMode::from_bits(raw))
            .into_pyobject(py)?
            .into_any()
            .unbind(),
        p::Register::BatteryRange => {
            let volts = |v: u32| -> Option<f64> { (v != 0x7FFF).then(|| f64::from(v) / 100.0) };
            (volts(raw >> 16), volts(raw & 0xFFFF))
                .into_pyobject(py)?
                .into_any()
                .unbind()
        }
        _ => raw.into_pyobject(py)?.into_any().unbind(),
    })
}

/// The registers that differ between what a restore wanted and what the board reads:
/// `{name: (wanted, board)}`. Gyro compensation (system-mode bit 3) is kept as the board has
/// it, and the calibration value never written.
fn differs<'py>(
    py: Python<'py>,
    wanted: &p::Snapshot,
    board: &p::Snapshot,
) -> PyResult<Bound<'py, PyDict>> {
    let differs = PyDict::new(py);
    let keep_bit3 = |m: p::SystemMode| m.with_gyro_compensation(false).bits();
    for r in p::Snapshot::REGISTERS {
        let (w, b) = (wanted.value(r), board.value(r));
        let same = match r {
            p::Register::SystemMode => {
                keep_bit3(wanted.system_mode) == keep_bit3(board.system_mode)
            }
            // A restore never writes the calibration value (0xFFFF would calibrate).
            p::Register::GyroCalibration => true,
            _ => w == b,
        };
        if !same {
            differs.set_item(r.name(), (w, b))?;
        }
    }
    Ok(differs)
}

impl Chassis {
    /// A register's raw value, read verified.
    fn value(&self, py: Python<'_>, r: p::Register) -> PyResult<u32> {
        match self.link.request(py, Request::ReadVerified(r))? {
            Outcome::Value(v) => Ok(v),
            _ => Ok(0),
        }
    }

    /// Every register, each read verified.
    fn snapshot(&self, py: Python<'_>) -> PyResult<p::Snapshot> {
        match self.link.request(py, Request::ReadSettings)? {
            Outcome::Snapshot(s) => Ok(s),
            _ => Ok(p::Snapshot::default()),
        }
    }

    /// `Chassis.read`: the register of that name, read verified, typed.
    pub(super) fn read_register(&self, py: Python<'_>, register: &str) -> PyResult<Py<PyAny>> {
        let r = frames::register(register)?;
        let raw = self.value(py, r)?;
        typed_value(py, r, raw)
    }

    /// Whether writing `write` starts a gyro calibration (the board's system mode read to
    /// tell for a system-mode write).
    fn starts_calibration(&self, py: Python<'_>, write: p::Write) -> PyResult<bool> {
        Ok(match write {
            p::Write::GyroCalibration(0xFFFF) => true,
            p::Write::SystemMode(mode) if mode.gyro_compensation() => {
                let now = self.value(py, write.register())?;
                !p::SystemMode::from_bits(now).gyro_compensation()
            }
            _ => false,
        })
    }

    /// `Chassis.write` of a raw value: the write checked, sent (a calibration only with
    /// `calibrate`), and confirmed by a verified read-back.
    pub(super) fn write_register(
        &self,
        py: Python<'_>,
        register: &str,
        value: u32,
        calibrate: bool,
    ) -> PyResult<()> {
        let write = frames::write_of(register, value)?;
        p::driver::host::check_write(write).map_err(PyValueError::new_err)?;
        let r = write.register();
        let starts = self.starts_calibration(py, write)?;
        if starts && !calibrate {
            return Err(PyValueError::new_err(
                "this write starts a gyro calibration (30 s: the chassis must stay still); nothing written: pass calibrate=True to go ahead",
            ));
        }
        self.link.with(py, |d| d.write(write))?;
        // The frame went out: a read-back that fails leaves the write unconfirmed, whatever
        // the reason (as on v1.0.0).
        let back = self.value(py, r).map_err(|e| {
            unconfirmed(
                py,
                &format!("{register}: {value} was written (the frame went out), but not confirmed"),
                e,
            )
        })?;
        if back != write.value() && !(starts && r == p::Register::GyroCalibration) {
            return Err(UnconfirmedError::new_err(format!(
                "{register}: {value} was written (the frame went out) but the board reads {back}"
            )));
        }
        Ok(())
    }

    /// `Chassis.settings`: every register as the `chassis settings` JSON.
    pub(super) fn settings_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let snapshot = self.snapshot(py)?;
        let value =
            serde_json::to_value(snapshot).map_err(|e| ChassisError::new_err(e.to_string()))?;
        crate::json::to_dict(py, &value)
    }

    /// `Chassis.restore`: the settings checked, written, read back; what differs.
    pub(super) fn restore_settings<'py>(
        &self,
        py: Python<'py>,
        settings: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let value = crate::json::from_py(settings.as_any())?;
        let wanted: p::Snapshot = serde_json::from_value(value)
            .map_err(|e| PyValueError::new_err(format!("not a settings dict: {e}")))?;
        p::driver::host::check_settings(&wanted)
            .map_err(|e| PyValueError::new_err(format!("{e}; nothing was written")))?;
        self.link.request(py, Request::RestoreSettings(wanted))?;
        let board = self.snapshot(py).map_err(|e| {
            unconfirmed(
                py,
                "the settings were written (the frames went out), but reading them back failed",
                e,
            )
        })?;
        differs(py, &wanted, &board)
    }
}
