//! The 2020 chassis's turns by an angle: sent once (the board adds turns up, so a second one
//! is refused while the first is outstanding), and waited for by reading the pending angle.

use super::Chassis;
use crate::args::Real;
use crate::driver::is_closed;
use crate::driver::waits::{deadline, nap};
use crate::errors::{ChassisError, TurnInProgressError};
use chassis_protocol as p;
use chassis_protocol::driver::{DriverCore, Request, TurnState};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::time::{Duration, Instant};

impl Chassis {
    /// `Chassis.turn`: `degrees` checked and rounded to 0.1°, the pending angle read first by a
    /// new driver, the turn sent once; `TurnInProgressError` with the angle still pending.
    pub(super) fn turn_by(&self, py: Python<'_>, degrees: Real) -> PyResult<()> {
        let shown = degrees.to_string();
        let degrees = degrees.value;
        if !(-6_553.5..=6_553.5).contains(&degrees) {
            return Err(PyValueError::new_err(format!(
                "degrees = {shown} is out of range (±6553.5)"
            )));
        }
        let deci = (degrees * 10.0).round() as i32;
        if deci == 0 {
            return Err(PyValueError::new_err(format!(
                "{degrees}° rounds to 0.0° (the board turns in steps of 0.1°): nothing sent"
            )));
        }
        if self.link.core(DriverCore::turn_state)? == TurnState::Unknown {
            // A new driver reads the pending angle first: an earlier program may have left
            // the board turning.
            self.link
                .request(py, Request::Read(p::Register::PendingAngle))?;
        }
        let result = self.link.with(py, |d| d.turn_by(deci));
        if let Err(e) = &result {
            if e.is_instance_of::<TurnInProgressError>(py) {
                let left = self.link.core(|c| match c.turn_state() {
                    TurnState::Turning { deci_degrees } => f64::from(deci_degrees) / 10.0,
                    _ => 0.0,
                })?;
                return Err(TurnInProgressError::new_err(format!(
                    "the board still has {left:.1}° of an earlier turn pending (it adds turns up): not sent; wait for it to end, or stop() cancels it"
                )));
            }
        }
        result
    }

    /// `Chassis.wait_turn`: the pending angle read every 100 ms until the turn is done or
    /// `timeout`; a signal's exception (or the chassis closed) cancels the turn.
    pub(super) fn wait_for_turn(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<bool> {
        let end = deadline(timeout)?;
        loop {
            if !self.link.core(DriverCore::turning)? {
                return Ok(true);
            }
            if end.is_some_and(|end| Instant::now() >= end) {
                return Ok(false);
            }
            let asked = nap(py, Duration::from_millis(100)).and_then(|()| {
                self.link
                    .request(py, Request::Read(p::Register::PendingAngle))
            });
            match asked {
                Ok(_) => {}
                // One lost reply is no reason to give up: the timeout bounds the wait.
                Err(e) if e.is_instance_of::<ChassisError>(py) && !is_closed(&e, py) => {}
                // A signal's exception (`KeyboardInterrupt`), or closed: the turn cancelled.
                Err(e) => {
                    let _ = self.link.stop(py);
                    return Err(e);
                }
            }
        }
    }
}
