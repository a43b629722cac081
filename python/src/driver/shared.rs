//! What the pump thread, the Python calls and the signal guard share: the driver behind its
//! lock ([`State`]), and each thing done under that lock a turn at a time, never waiting
//! inside it: taking in what arrived, starting a request, a turn of a request, the stop.

use super::{PyCore, closed};
use crate::errors::{ChassisError, TransportError, driver_error};
use crate::signals::{StopFailed, Stoppable};
use chassis_protocol::driver::blocking::{Driver, STALL_POLLS};
use chassis_protocol::driver::host::{MonotonicClock, SerialError, SerialPort};
use chassis_protocol::driver::{Clock as _, CoreError, Error};
use pyo3::prelude::*;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Frames kept for `poll()` (a program that never polls loses the oldest, never blocks the
/// driver): 1 024 frames are 8 s of the 2020 board's telemetry.
const QUEUE: usize = 1_024;

/// How often the pump thread takes in what arrived and judges time (the failsafe): every
/// 10 ms, or sooner when the driver has a deadline (a reply, the failsafe) before then. Frames
/// reach `poll()` at most this late; the failsafe is judged on time.
const PUMP_EVERY: Duration = Duration::from_millis(10);

/// How long a blocking call sleeps between two turns of the pump, the driver's lock free.
pub const STEP: Duration = Duration::from_millis(1);

/// The driver of one generation over the serial port.
pub type PortDriver<K> = Driver<SerialPort, MonotonicClock, K>;

/// What the pump thread, the Python calls and the signal guard share.
pub struct Shared<K: PyCore> {
    state: Mutex<State<K>>,
    /// A copy of the driver's clock (the same origin).
    clock: MonotonicClock,
    /// Cleared to end the pump thread.
    pub running: AtomicBool,
    /// The port's path.
    pub port: String,
}

/// The driver and what goes with it, behind the lock.
pub struct State<K: PyCore> {
    /// The driver (`None` once closed).
    pub driver: Option<PortDriver<K>>,
    /// Frames taken in and not yet polled.
    pub events: VecDeque<K::Event>,
    /// Frames thrown away because nobody polled.
    pub overflowed: u64,
    /// The last error the pump thread met (the port unplugged), said once.
    pub pump_error: Option<String>,
    /// The request in progress, by the number its caller was given.
    owner: Option<u64>,
    /// The number the next request gets.
    next: u64,
    /// The process is ending on this signal: the chassis was stopped, nothing else goes out.
    ending: Option<&'static str>,
}

/// How one turn of the pump ended for a request.
pub enum Turn<O> {
    /// Still running.
    Waiting,
    /// Ended.
    Done(PyResult<O>),
    /// A stop of another thread ended it (2020: it cancels a turn outstanding first).
    Taken,
}

/// Takes in what arrived and judges time, without waiting: the frames into the queue (at most
/// 64 a call), the stop and a request's frames out.
fn pump_state<K: PyCore>(st: &mut State<K>) -> Result<(), Error<SerialError>> {
    let State {
        driver,
        events,
        overflowed,
        ..
    } = st;
    let Some(driver) = driver.as_mut() else {
        return Ok(());
    };
    for _ in 0..64 {
        match driver.poll()? {
            Some(event) => {
                if events.len() >= QUEUE {
                    events.pop_front();
                    *overflowed = overflowed.saturating_add(1);
                }
                events.push_back(event);
            }
            None => break,
        }
    }
    Ok(())
}

impl<K: PyCore> Shared<K> {
    /// `driver` shared, its clock `clock`, on `port`.
    pub fn new(driver: PortDriver<K>, clock: MonotonicClock, port: String) -> Self {
        Shared {
            state: Mutex::new(State {
                driver: Some(driver),
                events: VecDeque::new(),
                overflowed: 0,
                pump_error: None,
                owner: None,
                next: 0,
                ending: None,
            }),
            clock,
            running: AtomicBool::new(true),
            port,
        }
    }

    /// The state, whoever held the lock before having panicked or not.
    pub fn lock(&self) -> MutexGuard<'_, State<K>> {
        self.state
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The driver's clock now.
    pub fn now_ms(&self) -> u64 {
        let mut clock = self.clock;
        clock.now_ms()
    }

    /// A driver error as the exception of its kind, in the CLI's words.
    pub fn error(&self, st: &State<K>, e: Error<SerialError>) -> PyErr {
        match st.driver.as_ref() {
            Some(d) => driver_error(e, d.core().heard(self.now_ms()), &self.port),
            None => closed(&self.port),
        }
    }

    /// `ChassisError` once closed, or once the process is ending on a signal.
    pub fn usable(&self, st: &State<K>) -> PyResult<()> {
        if st.driver.is_none() {
            return Err(closed(&self.port));
        }
        if let Some(signal) = st.ending {
            return Err(ChassisError::new_err(format!(
                "the process is ending on {signal}: the chassis on {} was stopped, and nothing more is sent",
                self.port
            )));
        }
        Ok(())
    }

    /// Starts `request` unless another is in progress: its number, or `None` (try again).
    pub fn claim(&self, request: &mut Option<K::Request>) -> PyResult<Option<u64>> {
        let mut guard = self.lock();
        let st = &mut *guard;
        self.usable(st)?;
        let Some(driver) = st.driver.as_mut() else {
            return Err(closed(&self.port));
        };
        if st.owner.is_some() || driver.core().busy_for_user() {
            return Ok(None);
        }
        let Some(r) = request.take() else {
            return Ok(None);
        };
        if let Err(e) = driver.core_mut().start(r) {
            return Err(self.error(st, Error::Core(e)));
        }
        let id = st.take_number();
        // Its first frame out now.
        if let Err(e) = pump_state(st) {
            st.owner = None;
            return Err(self.error(st, e));
        }
        Ok(Some(id))
    }

    /// One turn of the pump for request `id`, and whether it has ended.
    pub fn step(&self, id: u64) -> Turn<K::Outcome> {
        let mut guard = self.lock();
        let st = &mut *guard;
        if st.driver.is_none() {
            return Turn::Done(Err(closed(&self.port)));
        }
        if st.owner != Some(id) {
            return Turn::Taken;
        }
        if let Err(e) = pump_state(st) {
            st.owner = None;
            return Turn::Done(Err(self.error(st, e)));
        }
        let now = self.now_ms();
        let Some(driver) = st.driver.as_mut() else {
            return Turn::Done(Err(closed(&self.port)));
        };
        let Some(outcome) = driver.core_mut().settle(now, STALL_POLLS) else {
            return Turn::Waiting;
        };
        st.owner = None;
        Turn::Done(outcome.map_err(|e| match (&e, &st.pump_error) {
            // The pump thread met a transport error, which ended the request.
            (CoreError::Aborted, Some(text)) => TransportError::new_err(text.clone()),
            _ => self.error(st, Error::Core(e)),
        }))
    }

    /// Ends request `id` if it is still in progress (a signal's exception while it waited).
    pub fn abandon(&self, id: u64) {
        let mut st = self.lock();
        if st.owner == Some(id) {
            st.owner = None;
            if let Some(driver) = st.driver.as_mut() {
                driver.core_mut().abort();
            }
        }
    }

    /// Queues the stop ahead of everything not yet begun and writes it out now; the number of
    /// the request it started (2020: the cancel of a turn outstanding), if any. With `ending`,
    /// nothing but stops goes out after it (the process is ending on that signal).
    pub fn stop_now(&self, ending: Option<&'static str>) -> Result<Option<u64>, StopFailed> {
        let mut guard = self.lock();
        let st = &mut *guard;
        if ending.is_some() {
            st.ending = ending;
        }
        let now = self.now_ms();
        let Some(driver) = st.driver.as_mut() else {
            return Err(StopFailed::Closed);
        };
        let cancels = driver.core().stop_starts_request();
        driver.core_mut().stop();
        let id = if cancels {
            if st.owner.is_some() {
                // The request in progress was ended for the cancel: its outcome is not the
                // cancel's (its owner learns that the stop took its place).
                let _ = driver.core_mut().settle(now, STALL_POLLS);
            }
            Some(st.take_number())
        } else {
            None
        };
        if let Err(e) = pump_state(st) {
            if cancels {
                st.owner = None;
            }
            return Err(StopFailed::Port(match e {
                Error::Transport(e) => format!("serial port {}: {}", self.port, e.0),
                other => format!("serial port {}: {other}", self.port),
            }));
        }
        Ok(id)
    }

    /// Waits, with no Python, until request `id` ends or `until`: whether it ended.
    pub fn wait_until(&self, id: u64, until: Instant) -> bool {
        loop {
            match self.step(id) {
                Turn::Waiting if Instant::now() < until => std::thread::sleep(STEP),
                Turn::Waiting => return false,
                Turn::Done(_) | Turn::Taken => return true,
            }
        }
    }
}

impl<K: PyCore> State<K> {
    /// A number for a request starting now, which owns the driver from now on.
    fn take_number(&mut self) -> u64 {
        let id = self.next;
        self.next = self.next.wrapping_add(1);
        self.owner = Some(id);
        id
    }
}

impl<K: PyCore> Stoppable for Shared<K> {
    fn port(&self) -> &str {
        &self.port
    }

    fn send_stop(&self, ending: Option<&'static str>) -> Result<Option<u64>, StopFailed> {
        self.stop_now(ending)
    }

    fn wait_stop(&self, id: u64, until: Instant) {
        self.wait_until(id, until);
    }
}

/// The pump thread: takes in what arrived and judges time, every [`PUMP_EVERY`].
pub fn pump<K: PyCore>(shared: &Shared<K>) {
    while shared.running.load(Ordering::SeqCst) {
        let mut nap = PUMP_EVERY;
        {
            let mut guard = shared.lock();
            let st = &mut *guard;
            if st.driver.is_none() {
                return;
            }
            if let Err(e) = pump_state(st) {
                st.pump_error = Some(match e {
                    Error::Transport(e) => format!("serial port: {}", e.0),
                    other => other.to_string(),
                });
            }
            if let Some(driver) = st.driver.as_ref() {
                if let Some(ms) = driver.core().wait_ms(shared.now_ms()) {
                    nap = nap.min(Duration::from_millis(ms.max(1)));
                }
            }
        }
        std::thread::sleep(nap);
    }
}
