//! What every chassis shows Python, whatever its generation: its frames (polled, waited for,
//! iterated), the link's health, its streams and counters, and the end of a `with` block. The
//! generation answers through its core ([`PyCore`]); the classes call these from the methods
//! [`chassis_class!`](super::class::chassis_class) gives them.

use super::waits::{deadline, wait_event};
use super::{Link, PyCore, is_closed};
use crate::args::Real;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::Instant;

impl<K: PyCore> Link<K> {
    /// The next frame for Python the pump took in, or `None` when none is waiting. Never
    /// blocks.
    pub fn poll(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        while let Some(event) = self.next_event()? {
            if let Some(frame) = K::frame(py, event)? {
                return Ok(Some(frame));
            }
        }
        Ok(None)
    }

    /// The next frame for Python within `timeout` seconds (see [`deadline`]), or `None`.
    pub fn wait_frame(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<Option<Py<PyAny>>> {
        let end = deadline(timeout)?;
        loop {
            let left = end.map(|end| end.saturating_duration_since(Instant::now()).as_secs_f64());
            match wait_event(self, py, left)? {
                Some(event) => {
                    if let Some(frame) = K::frame(py, event)? {
                        return Ok(Some(frame));
                    }
                }
                None => return Ok(None),
            }
        }
    }

    /// The next frame, waited for; `None` (the iteration's end) once the chassis is closed.
    pub fn next_frame(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        match self.wait_frame(py, None) {
            Err(e) if is_closed(&e, py) => Ok(None),
            other => other,
        }
    }

    /// Whether the board was heard within the failsafe time.
    pub fn link_alive(&self) -> PyResult<bool> {
        let now = self.now_ms();
        self.core(|c| c.link_alive(now))
    }

    /// Per stream: frames, missed, rate_hz.
    pub fn streams<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let streams = self.core(K::streams)?;
        let d = PyDict::new(py);
        for (name, info) in streams {
            let s = PyDict::new(py);
            s.set_item("frames", info.frames)?;
            s.set_item("missed", info.missed)?;
            s.set_item("rate_hz", f64::from(info.rate_millihertz) / 1000.0)?;
            d.set_item(name, s)?;
        }
        Ok(d)
    }

    /// The parser's counters, and `not_polled`: frames dropped because nobody polled.
    pub fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let counters = self.core(K::counters)?;
        let d = crate::parsers::counts(py, &counters)?;
        d.set_item("not_polled", self.overflowed()?)?;
        Ok(d)
    }

    /// The end of a `with` block: the chassis stopped and closed; an error of that goes on
    /// only if no exception (`exc_value`) left the block.
    pub fn exit(&self, py: Python<'_>, exc_value: Option<Bound<'_, PyAny>>) -> PyResult<bool> {
        let closed = self.close(py);
        if exc_value.is_none() {
            closed?;
        }
        Ok(false)
    }
}
