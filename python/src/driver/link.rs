//! [`Link`]: the handle a chassis class holds: its driver shared with the pump thread and the
//! signal guard, the process that opened it, and the calls on it (those that never wait,
//! requests run a turn at a time, the stop, closing).

use super::shared::{PortDriver, STEP, Shared, Turn, pump};
use super::{PyCore, closed, is_closed};
use crate::errors::{ChassisError, TransportError};
use crate::signals::{self, StopFailed, Stoppable};
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::{MonotonicClock, SerialError};
use pyo3::prelude::*;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A driver with its pump thread.
pub struct Link<K: PyCore> {
    shared: Arc<Shared<K>>,
    /// The pump thread, taken (and joined) by whoever closes first: `close` takes `&self`, so
    /// a chassis in use by another thread still closes.
    pump: Mutex<Option<JoinHandle<()>>>,
    /// The port's path.
    pub port: String,
    /// The process that opened it (a child made by fork leaves it alone).
    pid: u32,
}

impl<K: PyCore> Link<K> {
    /// Starts the pump thread over `driver`, and puts the chassis under the signal guard.
    pub fn start(
        py: Python<'_>,
        mut driver: PortDriver<K>,
        clock: MonotonicClock,
        port: &str,
    ) -> Self {
        // Nobody waits inside the driver: every caller paces itself and lets go of the lock
        // between its turns.
        let _ = driver.uart_mut().set_wait_for_byte(Duration::ZERO);
        let shared = Arc::new(Shared::new(driver, clock, port.to_string()));
        let weak: Weak<dyn Stoppable> = Arc::downgrade(&shared) as Weak<dyn Stoppable>;
        signals::register(py, weak);
        let pump = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name("chassis-pump".into())
                .spawn(move || {
                    signals::keep_signals_off_this_thread();
                    pump(&shared);
                })
                .ok()
        };
        Link {
            shared,
            pump: Mutex::new(pump),
            port: port.to_string(),
            pid: std::process::id(),
        }
    }

    /// `ChassisError` in a child process made by fork: the chassis is the parent's.
    fn here(&self) -> PyResult<()> {
        let now = std::process::id();
        if now == self.pid {
            return Ok(());
        }
        Err(ChassisError::new_err(format!(
            "the chassis on {} was opened by process {} and this is process {now}, a child made by fork: a chassis is not shared between processes, so it does nothing here (the parent still drives it); open the port in the process that drives the chassis",
            self.port, self.pid
        )))
    }

    /// Runs `f` on the driver with the GIL released; `ChassisError` once closed. For calls that
    /// never wait (motion, a write with no reply): requests go through [`Link::request`].
    pub fn with<R: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut PortDriver<K>) -> Result<R, Error<SerialError>> + Send,
    ) -> PyResult<R> {
        self.here()?;
        let shared = &*self.shared;
        crate::detach(py, || {
            let mut guard = shared.lock();
            let st = &mut *guard;
            shared.usable(st)?;
            let Some(driver) = st.driver.as_mut() else {
                return Err(closed(&shared.port));
            };
            match f(driver) {
                Ok(r) => Ok(r),
                Err(e) => Err(shared.error(st, e)),
            }
        })
    }

    /// Runs a request to its end, the driver's lock taken only for each turn of the pump:
    /// another thread's stop goes out meanwhile. Waits for a request of another thread to end
    /// first. Python's signals are checked every turn (`KeyboardInterrupt` ends the request).
    pub fn request(&self, py: Python<'_>, request: K::Request) -> PyResult<K::Outcome> {
        self.here()?;
        let shared = &*self.shared;
        let mut request = Some(request);
        let id = loop {
            py.check_signals()?;
            let claimed = crate::detach(py, || {
                let claimed = shared.claim(&mut request);
                if matches!(claimed, Ok(None)) {
                    std::thread::sleep(STEP);
                }
                claimed
            })?;
            if let Some(id) = claimed {
                break id;
            }
        };
        match self.wait(py, id, true)? {
            Some(outcome) => Ok(outcome),
            None => Err(ChassisError::new_err(format!(
                "a stop() of another thread ended this request on {}: it cancels the turn outstanding first",
                self.port
            ))),
        }
    }

    /// Waits for request `id`: its outcome, or `None` if a stop took its place.
    fn wait(&self, py: Python<'_>, id: u64, signals: bool) -> PyResult<Option<K::Outcome>> {
        let shared = &*self.shared;
        loop {
            if signals {
                if let Err(e) = py.check_signals() {
                    shared.abandon(id);
                    return Err(e);
                }
            }
            let turn = crate::detach(py, || {
                let turn = shared.step(id);
                if matches!(turn, Turn::Waiting) {
                    std::thread::sleep(STEP);
                }
                turn
            });
            match turn {
                Turn::Waiting => {}
                Turn::Done(outcome) => return outcome.map(Some),
                Turn::Taken => return Ok(None),
            }
        }
    }

    /// Stops the chassis: the stop frame is written at once, ahead of anything not yet begun,
    /// whatever another thread waits for; then (2020) the cancel of a turn outstanding is
    /// waited for.
    pub fn stop(&self, py: Python<'_>) -> PyResult<()> {
        self.here()?;
        let shared = &*self.shared;
        let started = crate::detach(py, || shared.stop_now(None)).map_err(|e| match e {
            StopFailed::Closed => closed(&self.port),
            StopFailed::Port(text) => TransportError::new_err(text),
        })?;
        if let Some(id) = started {
            // Another thread's stop may take the cancel over: it is done either way.
            self.wait(py, id, false).map_err(|e| {
                if is_closed(&e, py) || !e.is_instance_of::<ChassisError>(py) {
                    return e;
                }
                let text = format!(
                    "the stop was sent, but the turn outstanding was not cancelled (the board may go on turning by what it still has to turn; the turn guard holds): {}",
                    e.value(py)
                );
                match e.get_type(py).call1((text.clone(),)) {
                    Ok(same) => PyErr::from_value(same),
                    Err(_) => ChassisError::new_err(text),
                }
            })?;
        }
        Ok(())
    }

    /// Reads the core (no I/O).
    pub fn core<R>(&self, f: impl FnOnce(&K) -> R) -> PyResult<R> {
        self.here()?;
        let state = self.shared.lock();
        state
            .driver
            .as_ref()
            .map(|d| f(d.core()))
            .ok_or_else(|| closed(&self.port))
    }

    /// The next frame the pump took in, if any.
    pub fn next_event(&self) -> PyResult<Option<K::Event>> {
        self.here()?;
        let mut state = self.shared.lock();
        if state.driver.is_none() {
            return Err(closed(&self.port));
        }
        if let Some(e) = state.pump_error.take() {
            return Err(TransportError::new_err(e));
        }
        Ok(state.events.pop_front())
    }

    /// The driver's clock now.
    pub fn now_ms(&self) -> u64 {
        self.shared.now_ms()
    }

    /// Frames thrown away because nobody polled.
    pub fn overflowed(&self) -> PyResult<u64> {
        self.here()?;
        Ok(self.shared.lock().overflowed)
    }

    /// Stops the chassis (best effort), ends the pump and closes the port. A call of another
    /// thread in progress ends at its next turn (closed). In a child made by fork: nothing.
    pub fn close(&self, py: Python<'_>) -> PyResult<()> {
        if std::process::id() != self.pid {
            return Ok(());
        }
        let result = self.stop(py);
        crate::detach(py, || self.shut());
        match result {
            Err(e) if e.is_instance_of::<ChassisError>(py) && is_closed(&e, py) => Ok(()),
            other => other,
        }
    }

    /// Ends the pump thread and drops the driver (no I/O).
    fn shut(&self) {
        self.shared.running.store(false, Ordering::SeqCst);
        let pump = self
            .pump
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        if let Some(t) = pump {
            let _ = t.join();
        }
        self.shared.lock().driver = None;
    }
}

impl<K: PyCore> Drop for Link<K> {
    fn drop(&mut self) {
        let pump = self
            .pump
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        if std::process::id() != self.pid {
            // A child made by fork: its pump thread is not here, and the port, the locks and
            // the chassis are the parent's. Touch nothing (not even the lock another thread
            // may have held at the fork), release nothing.
            std::mem::forget(pump);
            std::mem::forget(Arc::clone(&self.shared));
            return;
        }
        // Collected without `close()`: stop the chassis before the port goes.
        self.shared.running.store(false, Ordering::SeqCst);
        if let Some(t) = pump {
            let _ = t.join();
        }
        if let Ok(Some(id)) = self.shared.stop_now(None) {
            self.shared
                .wait_until(id, Instant::now() + super::STOP_WAIT);
        }
        self.shared.lock().driver = None;
    }
}
