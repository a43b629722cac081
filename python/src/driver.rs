//! `Chassis` (the 2020 firmware) and `ChassisV1` (v1.0.0): the crate's host driver over a serial
//! port, with a pump thread of its own, so that the failsafe and the telemetry run whatever the
//! Python program does (sleeps, computes, waits on a ROS callback).
//!
//! The driver sits behind a mutex that no call holds while it waits. A request (a verified
//! read, the settings, a readback, a write confirmed by its readback) is started in the
//! driver's sans-IO core, then pumped a turn at a time, the lock taken for each turn only
//! (every millisecond), so that a `stop()` of another thread, the pump thread's failsafe and the
//! signal guard reach the wire at once, whatever waits. Every blocking call releases the GIL
//! and checks Python's signals between its turns. A chassis inherited by a child process (a
//! `fork`) is inert there: it sends nothing, and using it raises `ChassisError`.

use crate::args::{Int, Real};
use crate::errors::{self, ChassisError, TurnInProgressError, driver_error};
use crate::frames;
use crate::signals::{self, StopFailed, Stoppable};
use chassis_protocol as p;
use chassis_protocol::detect::{self, Firmware};
use chassis_protocol::driver::blocking::{Driver, STALL_POLLS};
use chassis_protocol::driver::host::{MonotonicClock, SerialError, SerialPort};
use chassis_protocol::driver::{
    Clock as _, Config, Core, CoreError, DriverCore, Error, Event, Outcome, Request, TurnState, v1,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Frames kept for `poll()` (a program that never polls loses the oldest, never blocks the
/// driver): 1 024 frames are 8 s of the 2020 board's telemetry.
const QUEUE: usize = 1_024;

/// How often the pump thread takes in what arrived and judges time (the failsafe): every
/// 10 ms, or sooner when the driver has a deadline (a reply, the failsafe) before then. Frames
/// reach `poll()` at most this late; the failsafe is judged on time.
const PUMP_EVERY: Duration = Duration::from_millis(10);

/// How long a blocking call sleeps between two turns of the pump, the driver's lock free.
const STEP: Duration = Duration::from_millis(1);

/// How long a stop that nobody waits for (a chassis collected, a process ending on a signal)
/// waits for what it started (2020: the cancel of a turn outstanding) before it lets go. The
/// stop frame itself is written at once.
pub const STOP_WAIT: Duration = Duration::from_secs(1);

/// What each generation's core gives the Python side beyond the shells' [`Core`].
pub trait Generation:
    Core<Event: Send, Request: Send, Outcome: Send> + Send + Sized + 'static
{
    /// What has come from the board, judged at `now_ms`.
    fn heard(&self, now_ms: u64) -> p::driver::host::Heard;
    /// Whether a stop now starts a request of its own (2020: the cancel of a turn outstanding).
    fn stop_starts_request(&self) -> bool;
}

impl Generation for DriverCore {
    fn heard(&self, now_ms: u64) -> p::driver::host::Heard {
        DriverCore::heard(self, now_ms)
    }
    fn stop_starts_request(&self) -> bool {
        self.turning()
    }
}

impl Generation for v1::DriverCore {
    fn heard(&self, now_ms: u64) -> p::driver::host::Heard {
        v1::DriverCore::heard(self, now_ms)
    }
    fn stop_starts_request(&self) -> bool {
        false
    }
}

/// What the pump thread, the Python calls and the signal guard share.
pub struct Shared<K: Generation> {
    state: Mutex<State<K>>,
    /// A copy of the driver's clock (the same origin).
    clock: MonotonicClock,
    running: AtomicBool,
    port: String,
}

/// The driver and what goes with it, behind the lock.
struct State<K: Generation> {
    driver: Option<Driver<SerialPort, MonotonicClock, K>>,
    events: VecDeque<K::Event>,
    /// Frames thrown away because nobody polled.
    overflowed: u64,
    /// The last error the pump thread met (the port unplugged), said once.
    pump_error: Option<String>,
    /// The request in progress, by the number its caller was given.
    owner: Option<u64>,
    /// The number the next request gets.
    next: u64,
    /// The process is ending on this signal: the chassis was stopped, nothing else goes out.
    ending: Option<&'static str>,
}

/// How one turn of the pump ended for a request.
enum Turn<O> {
    /// Still running.
    Waiting,
    /// Ended.
    Done(PyResult<O>),
    /// A stop of another thread ended it (2020: it cancels a turn outstanding first).
    Taken,
}

/// Takes in what arrived and judges time, without waiting: the frames into the queue (at most
/// 64 a call), the stop and a request's frames out.
fn pump_state<K: Generation>(st: &mut State<K>) -> Result<(), Error<SerialError>> {
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

impl<K: Generation> Shared<K> {
    fn lock(&self) -> MutexGuard<'_, State<K>> {
        self.state
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn now_ms(&self) -> u64 {
        let mut clock = self.clock;
        clock.now_ms()
    }

    /// A driver error as the exception of its kind, in the CLI's words.
    fn error(&self, st: &State<K>, e: Error<SerialError>) -> PyErr {
        match st.driver.as_ref() {
            Some(d) => driver_error(e, d.core().heard(self.now_ms()), &self.port),
            None => closed(&self.port),
        }
    }

    /// `ChassisError` once closed, or once the process is ending on a signal.
    fn usable(&self, st: &State<K>) -> PyResult<()> {
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
    fn claim(&self, request: &mut Option<K::Request>) -> PyResult<Option<u64>> {
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
        let id = st.next;
        st.next = st.next.wrapping_add(1);
        st.owner = Some(id);
        // Its first frame out now.
        if let Err(e) = pump_state(st) {
            st.owner = None;
            return Err(self.error(st, e));
        }
        Ok(Some(id))
    }

    /// One turn of the pump for request `id`, and whether it has ended.
    fn step(&self, id: u64) -> Turn<K::Outcome> {
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
            (CoreError::Aborted, Some(text)) => errors::TransportError::new_err(text.clone()),
            _ => self.error(st, Error::Core(e)),
        }))
    }

    /// Ends request `id` if it is still in progress (a signal's exception while it waited).
    fn abandon(&self, id: u64) {
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
    fn stop_now(&self, ending: Option<&'static str>) -> Result<Option<u64>, StopFailed> {
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
            let id = st.next;
            st.next = st.next.wrapping_add(1);
            st.owner = Some(id);
            Some(id)
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
    fn wait_until(&self, id: u64, until: Instant) -> bool {
        loop {
            match self.step(id) {
                Turn::Waiting if Instant::now() < until => std::thread::sleep(STEP),
                Turn::Waiting => return false,
                Turn::Done(_) | Turn::Taken => return true,
            }
        }
    }
}

impl<K: Generation> Stoppable for Shared<K> {
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

/// A driver with its pump thread.
pub struct Link<K: Generation> {
    shared: Arc<Shared<K>>,
    /// The pump thread, taken (and joined) by whoever closes first: `close` takes `&self`, so
    /// a chassis in use by another thread still closes.
    pump: Mutex<Option<JoinHandle<()>>>,
    /// The port's path.
    pub port: String,
    /// The process that opened it (a child made by fork leaves it alone).
    pid: u32,
}

impl<K: Generation> Link<K> {
    /// Starts the pump thread over `driver`, and puts the chassis under the signal guard.
    fn start(
        py: Python<'_>,
        mut driver: Driver<SerialPort, MonotonicClock, K>,
        clock: MonotonicClock,
        port: String,
    ) -> Self {
        // Nobody waits inside the driver: every caller paces itself and lets go of the lock
        // between its turns.
        let _ = driver.uart_mut().set_wait_for_byte(Duration::ZERO);
        let shared = Arc::new(Shared {
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
            port: port.clone(),
        });
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
            port,
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
        f: impl FnOnce(&mut Driver<SerialPort, MonotonicClock, K>) -> Result<R, Error<SerialError>>
        + Send,
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
            StopFailed::Port(text) => errors::TransportError::new_err(text),
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
            return Err(errors::TransportError::new_err(e));
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

impl<K: Generation> Drop for Link<K> {
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
            self.shared.wait_until(id, Instant::now() + STOP_WAIT);
        }
        self.shared.lock().driver = None;
    }
}

/// The pump thread: takes in what arrived and judges time, every [`PUMP_EVERY`].
fn pump<K: Generation>(shared: &Shared<K>) {
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

fn closed(port: &str) -> PyErr {
    ChassisError::new_err(format!("the chassis on {port} is closed"))
}

fn is_closed(e: &PyErr, py: Python<'_>) -> bool {
    e.value(py).to_string().ends_with("is closed")
}

/// The failsafe `open()` takes, in ms: shorter stops a healthy chassis between two frames of
/// its telemetry behind a USB-UART adapter; longer is no failsafe (v1.0.0 raises anything
/// under 300 ms to 300 ms).
const FAILSAFE_MS: std::ops::RangeInclusive<i128> = 50..=5_000;
/// The board's latency `open()` takes, in ms.
const BOARD_LATENCY_MS: std::ops::RangeInclusive<i128> = 0..=2_000;
/// The quiet line `open()` takes, in ms.
const IDLE_MS: std::ops::RangeInclusive<i128> = 1..=500;
/// The reads a verified read may send: two replies must agree, so at least two.
const READ_TRIES: std::ops::RangeInclusive<i128> = 2..=10;

/// The host configuration with the caller's changes, each checked against its range
/// (`ValueError` naming it and the range).
fn config(
    failsafe_ms: Option<Int>,
    board_latency_ms: Option<Int>,
    idle_ms: Option<Int>,
    read_tries: Option<Int>,
) -> PyResult<Config> {
    let mut c = Config::HOST;
    if let Some(v) = failsafe_ms {
        c.failsafe_ms = v.within("failsafe_ms", FAILSAFE_MS)?;
    }
    if let Some(v) = board_latency_ms {
        c.board_latency_ms = v.within("board_latency_ms", BOARD_LATENCY_MS)?;
    }
    if let Some(v) = idle_ms {
        c.idle_ms = v.within("idle_ms", IDLE_MS)?;
    }
    if let Some(v) = read_tries {
        c.read_tries = v.within("read_tries", READ_TRIES)?;
    }
    Ok(c)
}

/// The generation's name as `firmware=` takes it.
fn firmware_of(name: &str) -> PyResult<Firmware> {
    match name {
        "2020" => Ok(Firmware::V2020),
        "v1.0.0" | "v1" => Ok(Firmware::V1_0_0),
        _ => Err(PyValueError::new_err(format!(
            "firmware={name:?}: the board runs 2020 or v1.0.0"
        ))),
    }
}

/// Opens `port` (a serial port path), finds the firmware if not given, and returns a `Chassis`
/// (2020) or a `ChassisV1` (v1.0.0) with the host defaults and its pump thread running.
#[pyfunction]
#[pyo3(signature = (port, *, firmware = None, failsafe_ms = None, board_latency_ms = None, idle_ms = None, read_tries = None))]
pub fn open(
    py: Python<'_>,
    port: &str,
    firmware: Option<&str>,
    failsafe_ms: Option<Int>,
    board_latency_ms: Option<Int>,
    idle_ms: Option<Int>,
    read_tries: Option<Int>,
) -> PyResult<Py<PyAny>> {
    let config = config(failsafe_ms, board_latency_ms, idle_ms, read_tries)?;
    let given = firmware.map(firmware_of).transpose()?;
    // Before the port opens: from here on SIGTERM and SIGHUP stop every chassis first.
    signals::install(py).map_err(ChassisError::new_err)?;
    let path = port.to_string();
    let opened = crate::detach(py, || -> Result<(SerialPort, Firmware), PyErr> {
        let mut serial = SerialPort::open(&path)
            .map_err(|e| errors::TransportError::new_err(format!("cannot open {path}: {}", e.0)))?;
        let firmware = match given {
            Some(f) => f,
            None => {
                let mut clock = MonotonicClock::new();
                let found = detect::detect(&mut serial, &mut clock, &config).map_err(|e| {
                    errors::TransportError::new_err(format!("serial port {path}: {}", e.0))
                })?;
                match found.firmware {
                    Some(f) => f,
                    None if found.heard.bytes == 0 => {
                        return Err(errors::TimeoutError::new_err(format!(
                            "nothing came from the board on {path} in {:.1} s, not even an answer to a register read of either firmware (is it powered, TX wired to RX and RX to TX, at 115200 bps?); firmware=\"2020\" or \"v1.0.0\" skips this check",
                            found.elapsed_ms as f64 / 1000.0
                        )));
                    }
                    None => {
                        return Err(ChassisError::new_err(format!(
                            "{} bytes came from {path}, but no frame of either firmware: another device, or a baud rate other than 115200?",
                            found.heard.bytes
                        )));
                    }
                }
            }
        };
        Ok((serial, firmware))
    })?;
    let (serial, firmware) = opened;
    let clock = MonotonicClock::new();
    Ok(match firmware {
        Firmware::V2020 => {
            let driver = Driver::new(serial, clock, config);
            Chassis {
                link: Link::start(py, driver, clock, port.to_string()),
            }
            .into_pyobject(py)?
            .into_any()
            .unbind()
        }
        Firmware::V1_0_0 => {
            let driver = Driver::new_v1(serial, clock, config);
            ChassisV1 {
                link: Link::start(py, driver, clock, port.to_string()),
            }
            .into_pyobject(py)?
            .into_any()
            .unbind()
        }
    })
}

/// When a wait of `timeout` seconds ends: `None` (no end) for `None`, infinity or a wait too
/// long to count (an int too large for a float included); `ValueError` for a negative number
/// or NaN.
fn deadline(timeout: Option<Real>) -> PyResult<Option<Instant>> {
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

/// Waits until `until` or a frame, polling the queue, the GIL released between looks and
/// signals checked (Ctrl-C raises `KeyboardInterrupt`).
fn wait_event<K: Generation>(
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

/// A write whose frame went out, confirmed by nothing (its read-back unanswered, disagreeing or
/// showing another value): `UnconfirmedError` on both generations, `what` then the reason. The
/// port failing, the chassis closed or a signal's exception go on as they are.
fn unconfirmed(py: Python<'_>, what: &str, e: PyErr) -> PyErr {
    let unanswered = e.is_instance_of::<errors::TimeoutError>(py)
        || e.is_instance_of::<errors::UnconfirmedError>(py)
        || e.is_instance_of::<errors::WrongReplyError>(py);
    if !unanswered {
        return e;
    }
    errors::UnconfirmedError::new_err(format!("{what}: {}", e.value(py)))
}

/// Sleeps `time` with the GIL released, Python's signals checked every 10 ms.
fn nap(py: Python<'_>, time: Duration) -> PyResult<()> {
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

fn stream_dict<'py>(py: Python<'py>, info: p::driver::StreamInfo) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("frames", info.frames)?;
    d.set_item("missed", info.missed)?;
    d.set_item("rate_hz", f64::from(info.rate_millihertz) / 1000.0)?;
    Ok(d)
}

// ----- 2020 -----

/// A chassis running the 2020 firmware, driven over a serial port (made by `chassis.open`).
///
/// Leaving a `with` block, an exception in it, `KeyboardInterrupt`, SIGTERM, SIGHUP, `close()`
/// or the object being collected stops the chassis. While it moves, the driver's failsafe stops
/// it when the board has been silent for `failsafe_ms` (200 ms), whatever the program (and each
/// of its threads) is doing.
#[pyclass(module = "chassis", weakref)]
pub struct Chassis {
    link: Link<DriverCore>,
}

/// A register's raw value from what `read` gives for it (see `Chassis.write`).
fn raw_value(register: &str, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    use pyo3::exceptions::{PyOverflowError, PyTypeError};
    use pyo3::types::PyBool;
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
            let centi = |v: Option<f64>, what: &str| -> PyResult<u32> {
                let Some(volts) = v else { return Ok(0x7FFF) };
                let c = (volts * 100.0).round();
                if !(0.0..=655.35).contains(&volts) || !c.is_finite() {
                    return Err(PyValueError::new_err(format!(
                        "battery-range: {what} {volts} V is out of range (0..=655.35 V, or None for the built-in table)"
                    )));
                }
                Ok(c as u32)
            };
            return Ok((centi(full, "full")? << 16) | centi(cutoff, "cut-off")?);
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

impl Chassis {
    /// A register's raw value, read verified.
    fn value(&self, py: Python<'_>, r: p::Register) -> PyResult<u32> {
        match self.link.request(py, Request::ReadVerified(r))? {
            Outcome::Value(v) => Ok(v),
            _ => Ok(0),
        }
    }
}

#[pymethods]
impl Chassis {
    /// `"2020"`.
    #[getter]
    fn firmware(&self) -> &'static str {
        "2020"
    }

    /// The serial port's path.
    #[getter]
    fn port(&self) -> &str {
        &self.link.port
    }

    /// Sets the body velocity (X sideways, Y forward, Z rotation; the board's raw units,
    /// ±65535). Safe to call every period.
    #[pyo3(
        signature = (x = Int::ZERO, y = Int::ZERO, z = Int::ZERO),
        text_signature = "(self, x=0, y=0, z=0)"
    )]
    fn set_velocity(&self, py: Python<'_>, x: Int, y: Int, z: Int) -> PyResult<()> {
        let v = frames::Velocity::new_checked(x, y, z)?;
        self.link.with(py, |d| d.set_velocity(v))
    }

    /// Drives each motor: closed-loop speeds (±65535), or open-loop duty in 0.01 % (±10000,
    /// `open_loop=True`). A value out of range is a `ValueError`, nothing sent.
    #[pyo3(signature = (values, open_loop = false))]
    fn set_motors(
        &self,
        py: Python<'_>,
        values: [Bound<'_, PyAny>; 4],
        open_loop: bool,
    ) -> PyResult<()> {
        let m = frames::Motors::new_checked(frames::ints(values, "values")?, open_loop)?.inner();
        self.link.with(py, |d| d.set_motors(m))
    }

    /// Stops the chassis; a turn in progress is cancelled (the angle still pending is read and
    /// the opposite turn sent).
    fn stop(&self, py: Python<'_>) -> PyResult<()> {
        self.link.stop(py)
    }

    /// Turns by `degrees` (0.1° steps), sent **once**: the board adds turns up, so while one is
    /// outstanding another raises `TurnInProgressError` (nothing sent). `wait_turn()` waits
    /// for it; `stop()` cancels it.
    fn turn(&self, py: Python<'_>, degrees: Real) -> PyResult<()> {
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

    /// Waits until the turn is done (the pending angle reads 0): `True`, or `False` after
    /// `timeout` seconds (`None` or `math.inf`: for ever; negative or NaN: `ValueError`).
    /// `KeyboardInterrupt` while waiting cancels the turn.
    #[pyo3(signature = (timeout = None))]
    fn wait_turn(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<bool> {
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

    /// Reads a register by name (`max-speed`, `kp`, `ki`, `gyro-gain`, `system-mode`,
    /// `gyro-calibration`, `motor-voltage`, `battery-range`, `pending-angle`), each read
    /// verified (two replies must agree): an `int`; a `SystemMode`; `(full_volts,
    /// cutoff_volts)` (`None` for the built-in table); the pending angle in degrees.
    fn read(&self, py: Python<'_>, register: &str) -> PyResult<Py<PyAny>> {
        let r = frames::register(register)?;
        let raw = self.value(py, r)?;
        typed_value(py, r, raw)
    }

    /// Writes a register and reads it back (`UnconfirmedError` if the board does not show the
    /// value). A write that starts a 30 s gyro calibration (gyro-calibration 0xFFFF,
    /// system-mode switching bit 3 on) needs `calibrate=True`.
    ///
    /// `value` is what `read` gives: an `int`; for system-mode a `SystemMode` too; for
    /// battery-range `(full_volts, cutoff_volts)`, `None` for the built-in table (the full
    /// voltage above the cut-off).
    #[pyo3(signature = (register, value, *, calibrate = false))]
    fn write(
        &self,
        py: Python<'_>,
        register: &str,
        value: &Bound<'_, PyAny>,
        calibrate: bool,
    ) -> PyResult<()> {
        let value = raw_value(register, value)?;
        let write = frames::write_of(register, value)?;
        p::driver::host::check_write(write).map_err(PyValueError::new_err)?;
        let r = write.register();
        let starts = match write {
            p::Write::GyroCalibration(0xFFFF) => true,
            p::Write::SystemMode(mode) if mode.gyro_compensation() => {
                let now = self.value(py, r)?;
                !p::SystemMode::from_bits(now).gyro_compensation()
            }
            _ => false,
        };
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
            return Err(errors::UnconfirmedError::new_err(format!(
                "{register}: {value} was written (the frame went out) but the board reads {back}"
            )));
        }
        Ok(())
    }

    /// Every register, each read verified, as a dict (the `chassis settings` JSON).
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let snapshot = match self.link.request(py, Request::ReadSettings)? {
            Outcome::Snapshot(s) => s,
            _ => p::Snapshot::default(),
        };
        let value =
            serde_json::to_value(snapshot).map_err(|e| ChassisError::new_err(e.to_string()))?;
        crate::json::to_dict(py, &value)
    }

    /// Writes settings back (a dict as `settings()` gives; never starts a gyro calibration),
    /// reads every register back and returns what differs: `{name: (wanted, board)}` (empty
    /// when all were restored; system-mode bit 3, gyro compensation, is kept as the board has
    /// it).
    fn restore<'py>(
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
        let board = match self.link.request(py, Request::ReadSettings).map_err(|e| {
            unconfirmed(
                py,
                "the settings were written (the frames went out), but reading them back failed",
                e,
            )
        })? {
            Outcome::Snapshot(s) => s,
            _ => p::Snapshot::default(),
        };
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

    /// The next telemetry frame the driver took in (`Imu`, `Encoders`, `Battery`), or `None`
    /// when none is waiting. Never blocks.
    fn poll(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        loop {
            match self.link.next_event()? {
                Some(Event::Telemetry(f)) => return Ok(Some(frames::downlink(py, f)?)),
                // Replies are the driver's (its reads): not telemetry.
                Some(_) => continue,
                None => return Ok(None),
            }
        }
    }

    /// Waits up to `timeout` seconds (`None` or `math.inf`: for ever; negative or NaN:
    /// `ValueError`) for the next telemetry frame; `None` if none came.
    #[pyo3(signature = (timeout = None))]
    fn wait_frame(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<Option<Py<PyAny>>> {
        let end = deadline(timeout)?;
        loop {
            let left = end.map(|end| end.saturating_duration_since(Instant::now()).as_secs_f64());
            match wait_event(&self.link, py, left)? {
                Some(Event::Telemetry(f)) => return Ok(Some(frames::downlink(py, f)?)),
                Some(_) => continue,
                None => return Ok(None),
            }
        }
    }

    /// Iterating a chassis yields its telemetry frames as they come (blocking; Ctrl-C raises
    /// `KeyboardInterrupt`); it ends when the chassis is closed.
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// The next telemetry frame (waits for it).
    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        match self.wait_frame(py, None) {
            Err(e) if is_closed(&e, py) => Ok(None),
            other => other,
        }
    }

    /// Whether the board was heard within the failsafe time.
    #[getter]
    fn link_alive(&self) -> PyResult<bool> {
        let now = self.link.now_ms();
        self.link.core(|c| c.link_alive(now))
    }

    /// Whether the driver has the chassis moving (a turn outstanding counts).
    #[getter]
    fn moving(&self) -> PyResult<bool> {
        self.link.core(DriverCore::moving)
    }

    /// Times the failsafe has stopped the chassis.
    #[getter]
    fn failsafe_stops(&self) -> PyResult<u32> {
        self.link.core(DriverCore::failsafe_stops)
    }

    /// Per stream (`imu`, `encoders`, `battery`): frames, missed (by the counts), rate_hz.
    #[getter]
    fn streams<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let infos = self.link.core(|c| {
            [p::Stream::Imu, p::Stream::Encoders, p::Stream::Battery].map(|s| (s, c.stream(s)))
        })?;
        let d = PyDict::new(py);
        for (s, info) in infos {
            d.set_item(format!("{s:?}").to_lowercase(), stream_dict(py, info)?)?;
        }
        Ok(d)
    }

    /// The parser's counters, and frames dropped because nobody polled.
    #[getter]
    fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.link.core(|c| *c.parser_stats())?;
        let d = PyDict::new(py);
        d.set_item("frames", s.total_frames())?;
        d.set_item("discarded", s.discarded)?;
        d.set_item("resyncs", s.resyncs)?;
        d.set_item("lock_losses", s.lock_losses)?;
        d.set_item("not_polled", self.link.overflowed()?)?;
        Ok(d)
    }

    /// The latest IMU frame (or `None`).
    #[getter]
    fn imu(&self) -> PyResult<Option<frames::Imu>> {
        self.link.core(|c| c.imu().map(|s| s.value.into()))
    }

    /// The latest encoder frame (or `None`).
    #[getter]
    fn encoders(&self) -> PyResult<Option<frames::Encoders>> {
        self.link.core(|c| c.encoders().map(|s| s.value.into()))
    }

    /// The latest battery frame (or `None`).
    #[getter]
    fn battery(&self) -> PyResult<Option<frames::Battery>> {
        self.link.core(|c| c.battery().map(|s| s.value.into()))
    }

    /// Stops the chassis and closes the port (again: nothing).
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        self.link.close(py)
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Stops the chassis and closes the port; an exception in the block goes on.
    fn __exit__(
        &self,
        py: Python<'_>,
        exc_type: Option<Bound<'_, PyAny>>,
        exc_value: Option<Bound<'_, PyAny>>,
        traceback: Option<Bound<'_, PyAny>>,
    ) -> PyResult<bool> {
        let _ = (exc_type, traceback);
        let closed = self.link.close(py);
        if exc_value.is_none() {
            closed?;
        }
        Ok(false)
    }

    fn __repr__(&self) -> String {
        format!("Chassis(port={:?}, firmware=\"2020\")", self.link.port)
    }
}

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

// ----- v1.0.0 -----

/// A chassis running the v1.0.0 firmware (`7B … BCC 7D` frames), made by `chassis.open`. The
/// same guarantees as `Chassis`; the failsafe sends the forced stop. There is no turn by an
/// angle on v1.0.0, and no `turn` here.
#[pyclass(module = "chassis", weakref)]
pub struct ChassisV1 {
    link: Link<v1::DriverCore>,
}

/// The keys of the dict `ChassisV1.settings()` gives.
const V1_KEYS: [&str; 4] = ["firmware", "system", "geometry", "pid"];

/// One part of a v1.0.0 settings dict (`parse`d), every key a field of it: a key that is none
/// (a typo) is a `ValueError`, and nothing is written. `show` gives the fields back, for the
/// message.
fn section<T>(
    value: &serde_json::Value,
    name: &str,
    parse: impl Fn(serde_json::Value) -> Result<T, serde_json::Error>,
    show: impl Fn(&T) -> Result<serde_json::Value, serde_json::Error>,
) -> PyResult<T> {
    let part = value.get(name).cloned().unwrap_or(serde_json::Value::Null);
    let bad = |e: &dyn std::fmt::Display| {
        PyValueError::new_err(format!(
            "not v1.0.0 settings: {name}: {e}; nothing was written"
        ))
    };
    let parsed = parse(part.clone()).map_err(|e| bad(&e))?;
    // Every field is needed: a key the fields do without is none of them.
    if let Some(map) = part.as_object() {
        for key in map.keys() {
            let mut without = map.clone();
            without.remove(key);
            if parse(serde_json::Value::Object(without)).is_ok() {
                let fields = show(&parsed)
                    .ok()
                    .and_then(|v| v.as_object().map(|m| m.keys().cloned().collect::<Vec<_>>()))
                    .unwrap_or_default();
                return Err(bad(&format!(
                    "{key:?} is not one of its fields ({})",
                    fields.join(", ")
                )));
            }
        }
    }
    Ok(parsed)
}

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

impl ChassisV1 {
    /// One readback: the board's reply.
    fn readback(&self, py: Python<'_>, r: p::v1::Readback) -> PyResult<p::v1::Reply> {
        match self.link.request(py, v1::Request::Read(r))? {
            v1::Outcome::Reply(reply) => Ok(reply),
            v1::Outcome::Done => Err(ChassisError::new_err("the readback ended with no reply")),
        }
    }

    /// A settings frame written, 100 ms after the previous one, and confirmed by its readback.
    fn write_settings(&self, py: Python<'_>, s: v1::Settings) -> PyResult<()> {
        self.link.request(py, v1::Request::Write(s)).map(|_| ())
    }
}

#[pymethods]
impl ChassisV1 {
    /// `"v1.0.0"`.
    #[getter]
    fn firmware(&self) -> &'static str {
        "v1.0.0"
    }

    /// The serial port's path.
    #[getter]
    fn port(&self) -> &str {
        &self.link.port
    }

    /// Sets the body velocity: vx sideways and vy forward in m/s, wz in rad/s
    /// (counter-clockwise). Safe to call every period.
    #[pyo3(
        signature = (vx = Real::from(0.0), vy = Real::from(0.0), wz = Real::from(0.0)),
        text_signature = "(self, vx=0.0, vy=0.0, wz=0.0)"
    )]
    fn set_velocity(&self, py: Python<'_>, vx: Real, vy: Real, wz: Real) -> PyResult<()> {
        let v = p::v1::BodyVelocity::new(milli(&vx, "vx")?, milli(&vy, "vy")?, milli(&wz, "wz")?);
        self.link.with(py, |d| d.set_velocity(v))
    }

    /// Drives each motor (`0x26`; the board's own unit, raw, each -32768..=32767: out of range
    /// is a `ValueError`, nothing sent).
    fn set_motors(&self, py: Python<'_>, speeds: [Bound<'_, PyAny>; 4]) -> PyResult<()> {
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
        let m = p::v1::MotorVelocity::new(raw);
        self.link.with(py, |d| d.set_motors(m))
    }

    /// Sends the forced stop.
    fn stop(&self, py: Python<'_>) -> PyResult<()> {
        self.link.stop(py)
    }

    /// A readback by name (`system`, `geometry`, `body-velocity`, `motor-speeds`, `pid`: a dict
    /// of its fields) or one settings field (`wheel-diameter`, `pwm-max`, … : an `int`).
    fn read<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        if let Some(r) = p::v1::Readback::from_name(name) {
            let reply = self.readback(py, r)?;
            return Ok(frames::reply_fields(py, &reply)?.into_any());
        }
        let Some(r) = p::v1::field_readback(name) else {
            return Err(PyValueError::new_err(format!(
                "{name:?} is not a v1.0.0 readback or settings field: give one of {}, or {}",
                p::v1::Readback::ALL.map(p::v1::Readback::name).join(", "),
                p::v1::FIELDS.map(|(n, _)| n).join(", ")
            )));
        };
        let reply = self.readback(py, r)?;
        let value = reply
            .field(name)
            .ok_or_else(|| ChassisError::new_err(format!("no {name} in the board's reply")))?;
        Ok(value.into_pyobject(py)?.into_any())
    }

    /// Writes one settings field: its frame is read back, written with the field changed (at
    /// least 100 ms after the previous settings frame), and read back again
    /// (`UnconfirmedError` if the board does not show it).
    fn write(&self, py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        if value.is_instance_of::<pyo3::types::PyBool>() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{name}: {value} is a bool, not a value: give an int"
            )));
        }
        let value: u16 = value.extract::<Int>()?.within(name, 0..=65_535)?;
        let Some(r) = p::v1::field_readback(name) else {
            return Err(PyValueError::new_err(format!(
                "{name:?} is not a v1.0.0 settings field: give one of {}",
                p::v1::FIELDS.map(|(n, _)| n).join(", ")
            )));
        };
        let reply = self.readback(py, r)?;
        let settings = reply.with_field(name, value).map_err(|e| match e {
            p::v1::FieldError::OutOfRange => {
                PyValueError::new_err(format!("{name} = {value} is out of range (0..=255)"))
            }
            p::v1::FieldError::NotHere => {
                ChassisError::new_err(format!("the board's readback does not hold {name}"))
            }
        })?;
        self.write_settings(py, settings).map_err(|e| {
            unconfirmed(
                py,
                &format!("{name}: {value} was written (the frame went out), but not confirmed"),
                e,
            )
        })
    }

    /// The three settings frames as a dict: `{"firmware": "v1.0.0", "system": {…},
    /// "geometry": {…}, "pid": {…}}` (the `chassis settings` JSON).
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut got = Vec::new();
        for r in [
            p::v1::Readback::System,
            p::v1::Readback::Geometry,
            p::v1::Readback::Pid,
        ] {
            got.push(self.readback(py, r)?);
        }
        let (Some(system), Some(geometry), Some(pid)) = (
            got.first().and_then(p::v1::Reply::system),
            got.get(1).and_then(p::v1::Reply::geometry),
            got.get(2).and_then(p::v1::Reply::pid),
        ) else {
            return Err(ChassisError::new_err(
                "a readback came back as another frame",
            ));
        };
        let value = serde_json::json!({
            "firmware": "v1.0.0",
            "system": system,
            "geometry": geometry,
            "pid": pid,
        });
        crate::json::to_dict(py, &value)
    }

    /// Writes the three settings frames of a dict as `settings()` gives, each confirmed by its
    /// readback (v1.0.0 keeps them until power-off).
    fn restore(&self, py: Python<'_>, settings: &Bound<'_, PyDict>) -> PyResult<()> {
        let value = crate::json::from_py(settings.as_any())?;
        if value.get("firmware").and_then(|f| f.as_str()) != Some("v1.0.0") {
            return Err(PyValueError::new_err(
                "not v1.0.0 settings: the dict must have \"firmware\": \"v1.0.0\" (as settings() gives)",
            ));
        }
        if let Some(key) = value
            .as_object()
            .and_then(|m| m.keys().find(|k| !V1_KEYS.contains(&k.as_str())))
        {
            return Err(PyValueError::new_err(format!(
                "not v1.0.0 settings: no key {key:?} in them (they are {}, as settings() gives); nothing was written",
                V1_KEYS.join(", ")
            )));
        }
        let all = [
            p::v1::Settings::System(section(&value, "system", serde_json::from_value, |t| {
                serde_json::to_value(t)
            })?),
            p::v1::Settings::Geometry(section(&value, "geometry", serde_json::from_value, |t| {
                serde_json::to_value(t)
            })?),
            p::v1::Settings::Pid(section(&value, "pid", serde_json::from_value, |t| {
                serde_json::to_value(t)
            })?),
        ];
        for (i, s) in all.into_iter().enumerate() {
            self.write_settings(py, s).map_err(|e| {
                let before = if i == 0 {
                    String::new()
                } else {
                    " (the frames before it were written and confirmed)".into()
                };
                unconfirmed(
                    py,
                    &format!(
                        "the {} settings were written (the frame went out), but not confirmed{before}",
                        s.readback().name()
                    ),
                    e,
                )
            })?;
        }
        Ok(())
    }

    /// The next frame the driver took in (`Telemetry`, or a `ReadbackReply` nobody asked for),
    /// or `None`.
    fn poll(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        match self.link.next_event()? {
            Some(v1::Event::Telemetry(t)) => Ok(Some(
                frames::Telemetry::from(t)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind(),
            )),
            Some(v1::Event::Reply(r)) => Ok(Some(
                frames::ReadbackReply::from(r)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind(),
            )),
            None => Ok(None),
        }
    }

    /// Waits up to `timeout` seconds (`None` or `math.inf`: for ever; negative or NaN:
    /// `ValueError`) for the next frame.
    #[pyo3(signature = (timeout = None))]
    fn wait_frame(&self, py: Python<'_>, timeout: Option<Real>) -> PyResult<Option<Py<PyAny>>> {
        let end = deadline(timeout)?;
        let left = end.map(|end| end.saturating_duration_since(Instant::now()).as_secs_f64());
        match wait_event(&self.link, py, left)? {
            Some(v1::Event::Telemetry(t)) => Ok(Some(
                frames::Telemetry::from(t)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind(),
            )),
            Some(v1::Event::Reply(r)) => Ok(Some(
                frames::ReadbackReply::from(r)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind(),
            )),
            None => Ok(None),
        }
    }

    /// Iterating a chassis yields its frames as they come (blocking; Ctrl-C raises
    /// `KeyboardInterrupt`); it ends when the chassis is closed.
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// The next frame (waits for it).
    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        match self.wait_frame(py, None) {
            Err(e) if is_closed(&e, py) => Ok(None),
            other => other,
        }
    }

    /// The latest telemetry frame (or `None`).
    #[getter]
    fn telemetry(&self) -> PyResult<Option<frames::Telemetry>> {
        self.link.core(|c| c.telemetry().map(|s| s.value.into()))
    }

    /// Whether the board was heard within the failsafe time.
    #[getter]
    fn link_alive(&self) -> PyResult<bool> {
        let now = self.link.now_ms();
        self.link.core(|c| c.link_alive(now))
    }

    /// Whether the driver has the chassis moving.
    #[getter]
    fn moving(&self) -> PyResult<bool> {
        self.link.core(v1::DriverCore::moving)
    }

    /// Times the failsafe has sent the forced stop.
    #[getter]
    fn failsafe_stops(&self) -> PyResult<u32> {
        self.link.core(v1::DriverCore::failsafe_stops)
    }

    /// The telemetry stream: frames, rate_hz.
    #[getter]
    fn streams<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let info = self.link.core(v1::DriverCore::stream)?;
        let d = PyDict::new(py);
        d.set_item("telemetry", stream_dict(py, info)?)?;
        Ok(d)
    }

    /// The parser's counters (frames, bad_checksum, bad_end, refused, discarded), and frames
    /// dropped because nobody polled.
    #[getter]
    fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.link.core(v1::DriverCore::parser_stats)?;
        let d = PyDict::new(py);
        d.set_item("frames", s.frames)?;
        d.set_item("bad_checksum", s.bad_checksum)?;
        d.set_item("bad_end", s.bad_end)?;
        d.set_item("refused", s.refused)?;
        d.set_item("discarded", s.discarded)?;
        d.set_item("not_polled", self.link.overflowed()?)?;
        Ok(d)
    }

    /// Sends the forced stop and closes the port (again: nothing).
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        self.link.close(py)
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Sends the forced stop and closes the port; an exception in the block goes on.
    fn __exit__(
        &self,
        py: Python<'_>,
        exc_type: Option<Bound<'_, PyAny>>,
        exc_value: Option<Bound<'_, PyAny>>,
        traceback: Option<Bound<'_, PyAny>>,
    ) -> PyResult<bool> {
        let _ = (exc_type, traceback);
        let closed = self.link.close(py);
        if exc_value.is_none() {
            closed?;
        }
        Ok(false)
    }

    fn __repr__(&self) -> String {
        format!("ChassisV1(port={:?}, firmware=\"v1.0.0\")", self.link.port)
    }
}
