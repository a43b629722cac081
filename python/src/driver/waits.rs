//! The waits of a chassis's calls: when a `timeout` ends, a nap, a wait for the next frame;
//! each with the GIL released between its looks and Python's signals checked.

use super::{Link, PyCore};
use crate::args::Real;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// When a wait of `timeout` seconds ends: `None` (no end) for `None`, infinity or a wait too
/// long to count (an int too large for a float included); `ValueError` for a negative number
/// or NaN.
pub fn deadline(timeout: Option<Real>) -> PyResult<Option<Instant>> {
    if let Some(t) = &timeout {
        if t.value.is_nan() || t.value < 0.0 {
            return Err(PyValueError::new_err(format!(
                "timeout = {t}: a number of seconds, 0 or more (None or math.inf waits for ever)"
            )));
        }
    }
    seconds_from_now(timeout.map(|t| t.value))
}

/// When a wait of `timeout` seconds ends (see [`deadline`]).
fn seconds_from_now(timeout: Option<f64>) -> PyResult<Option<Instant>> {
    match timeout {
        None => Ok(None),
        Some(t) if t.is_nan() || t < 0.0 => Err(PyValueError::new_err(format!(
            "timeout = {t}: a number of seconds, 0 or more (None or math.inf waits for ever)"
        ))),
        Some(t) => Ok(Duration::try_from_secs_f64(t)
            .ok()
            .and_then(|d| Instant::now().checked_add(d))),
    }
}

/// Waits until `timeout` seconds from now or a frame, polling the queue, the GIL released
/// between looks and signals checked (Ctrl-C raises `KeyboardInterrupt`).
pub fn wait_event<K: PyCore>(
    link: &Link<K>,
    py: Python<'_>,
    timeout: Option<f64>,
) -> PyResult<Option<K::Event>> {
    let end = seconds_from_now(timeout)?;
    loop {
        if let Some(e) = link.next_event()? {
            return Ok(Some(e));
        }
        if end.is_some_and(|end| Instant::now() >= end) {
            return Ok(None);
        }
        py.check_signals()?;
        crate::detach(py, || std::thread::sleep(Duration::from_millis(2)));
    }
}

/// Sleeps `time` with the GIL released, Python's signals checked every 10 ms.
pub fn nap(py: Python<'_>, time: Duration) -> PyResult<()> {
    let end = Instant::now() + time;
    loop {
        py.check_signals()?;
        let left = end.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Ok(());
        }
        crate::detach(py, || {
            std::thread::sleep(left.min(Duration::from_millis(10)))
        });
    }
}
