//! The Python package `chassis` (its native part, `chassis.chassis_native`): the Rust crate
//! `chassis-protocol` for Python, with no protocol logic written again. The driver with its
//! failsafe and turn guard over a serial port (`open`, `Chassis`, `ChassisV1`), the frames and
//! parsers of both firmware generations, and simulated boards (`chassis.sim`).

mod args;
mod capture;
mod driver;
mod errors;
mod frames;
mod generation;
mod json;
mod parsers;
mod signals;
mod sim;

use pyo3::prelude::*;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::ThreadId;

/// Set by `chassis` at interpreter exit, once every chassis is stopped and closed
/// (`_interpreter_exiting`): the thread that said so (the one running the exit handlers).
static EXITING: AtomicBool = AtomicBool::new(false);
static EXIT_THREAD: OnceLock<ThreadId> = OnceLock::new();
/// Threads between the end of a [`detach`]ed call and taking the GIL back.
static RETURNING: AtomicUsize = AtomicUsize::new(0);

/// Runs `f` with the GIL released, as `py.detach` does, but a thread that comes back from it
/// after the interpreter began to exit never takes the GIL again: it waits there until the
/// process ends. CPython before 3.14 ends a thread that takes the GIL during finalization by
/// unwinding it, here through these Rust frames, which aborts the process (a daemon thread in a
/// blocking call of this package when the program ends); the chassis is stopped by then, and
/// the thread has nothing left to do.
pub(crate) fn detach<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> T {
    let result = py.detach(|| {
        let result = f();
        // Counted before the flag is read (both sequentially consistent): either this thread
        // sees the flag and stays, or `_interpreter_exiting` sees it returning and waits.
        RETURNING.fetch_add(1, Ordering::SeqCst);
        if EXITING.load(Ordering::SeqCst) && EXIT_THREAD.get() != Some(&std::thread::current().id())
        {
            RETURNING.fetch_sub(1, Ordering::SeqCst);
            loop {
                std::thread::park();
            }
        }
        result
    });
    RETURNING.fetch_sub(1, Ordering::SeqCst);
    result
}

/// Called by `chassis` at interpreter exit, after every chassis is stopped and closed: from
/// now on no thread takes the GIL back from a call of this package; those already on their
/// way are let through first (for at most half a second).
#[pyfunction]
fn _interpreter_exiting(py: Python<'_>) {
    let _ = EXIT_THREAD.set(std::thread::current().id());
    EXITING.store(true, Ordering::SeqCst);
    detach(py, || {
        let start = std::time::Instant::now();
        while RETURNING.load(Ordering::SeqCst) > 0
            && start.elapsed() < std::time::Duration::from_millis(500)
        {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    });
}

/// The native part of the `chassis` package.
#[pymodule]
fn chassis_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(_interpreter_exiting, m)?)?;
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
