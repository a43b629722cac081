//! `chassis.sim`: a simulated board of either generation, in the process (`Board`) or served in
//! real time on a pseudo-terminal (`pty()`), so that every example and test runs on a laptop.

use crate::args::Int;
use chassis_protocol::detect::Firmware;
use chassis_protocol::sim::{Simulated, serve};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::io::{self, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// Either generation's simulated board, as [`generation`](crate::generation) makes it.
struct AnyBoard(Box<dyn Simulated + Send + Sync>);

impl Simulated for AnyBoard {
    fn receive(&mut self, bytes: &[u8]) {
        self.0.receive(bytes);
    }
    fn advance(&mut self, now_ms: u64) {
        self.0.advance(now_ms);
    }
    fn transmit(&mut self, buf: &mut [u8]) -> usize {
        self.0.transmit(buf)
    }
    fn byte_arrived(&self) -> bool {
        self.0.byte_arrived()
    }
    fn now_ms(&self) -> u64 {
        self.0.now_ms()
    }
}

/// The simulated board of the generation `firmware` names.
fn board(firmware: &str, seed: u64) -> PyResult<AnyBoard> {
    let firmware = Firmware::from_name(firmware).ok_or_else(|| {
        PyValueError::new_err(format!(
            "firmware={firmware:?}: the simulated board runs 2020 or v1.0.0"
        ))
    })?;
    Ok(AnyBoard((crate::generation::of(firmware).board)(seed)))
}

/// A simulated board in this process, with no clock of its own: `receive` what a master sends,
/// `advance` its time (ms), `transmit` what it sent since.
#[pyclass(module = "chassis.sim", name = "Board")]
pub struct SimBoard {
    board: AnyBoard,
}

/// How far `Board.advance` moves the board's clock at once: an hour (it simulates every
/// millisecond; an hour takes a fraction of a second, and Ctrl-C is heard meanwhile).
const AHEAD_MS: u64 = 3_600_000;

/// A seed as `Board` and `pty` take it (any 64-bit unsigned value).
fn seed_of(seed: &Int) -> PyResult<u64> {
    seed.within("seed", 0..=i128::from(u64::MAX))
}

#[pymethods]
impl SimBoard {
    #[new]
    #[pyo3(
        signature = (firmware = "2020", seed = Int::from(1)),
        text_signature = "(firmware=\"2020\", seed=1)"
    )]
    fn new(firmware: &str, seed: Int) -> PyResult<Self> {
        Ok(SimBoard {
            board: board(firmware, seed_of(&seed)?)?,
        })
    }

    /// Bytes from the master.
    fn receive(&mut self, data: pyo3::pybacked::PyBackedBytes) {
        self.board.receive(&data);
    }

    /// Moves the board's clock to `now_ms` (a time already past: nothing), at most an hour
    /// (3 600 000 ms) ahead of where it is (`ValueError` beyond); Python's signals are heard
    /// meanwhile (Ctrl-C raises `KeyboardInterrupt`, the board left where it got to).
    fn advance(&mut self, py: Python<'_>, now_ms: Int) -> PyResult<()> {
        let now_ms: u64 = now_ms.within("now_ms", 0..=i128::from(u64::MAX))?;
        let from = self.board.now_ms();
        if now_ms.saturating_sub(from) > AHEAD_MS {
            return Err(PyValueError::new_err(format!(
                "now_ms = {now_ms} is more than an hour ({AHEAD_MS} ms) ahead of the board's time ({from} ms): the board is simulated a millisecond at a time, advance it an hour at a time at most"
            )));
        }
        let mut at = from;
        while at < now_ms {
            at = now_ms.min(at.saturating_add(10_000));
            self.board.advance(at);
            py.check_signals()?;
        }
        Ok(())
    }

    /// What the board sent since the last call (at most 64 KiB).
    fn transmit<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let mut out = Vec::new();
        let mut buf = [0u8; 256];
        while out.len() < 65_536 {
            let n = self.board.transmit(&mut buf);
            if n == 0 {
                break;
            }
            out.extend_from_slice(buf.get(..n).unwrap_or(&[]));
        }
        PyBytes::new(py, &out)
    }

    /// The board's time, ms.
    #[getter]
    fn now_ms(&self) -> u64 {
        self.board.now_ms()
    }
}

/// The board's end of the pseudo-terminal: records what it is sent; while silent, drops what it
/// sends (a cut TX wire).
struct Tap {
    inner: serialport::TTYPort,
    heard: Arc<Mutex<Vec<u8>>>,
    silent: Arc<AtomicBool>,
}

impl Read for Tap {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Ok(mut heard) = self.heard.lock() {
            heard.extend_from_slice(buf.get(..n).unwrap_or(&[]));
        }
        Ok(n)
    }
}

impl Write for Tap {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.silent.load(Ordering::SeqCst) {
            return Ok(buf.len());
        }
        self.inner.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// A simulated board served in real time on a pseudo-terminal: open `path` as a serial port
/// (`chassis.open(pty.path)`). A context manager; `close()` stops it.
#[pyclass(module = "chassis.sim", name = "Pty")]
pub struct SimPty {
    path: String,
    firmware: String,
    stop: Arc<AtomicBool>,
    silent: Arc<AtomicBool>,
    heard: Arc<Mutex<Vec<u8>>>,
    thread: Option<JoinHandle<()>>,
    keep: Option<serialport::TTYPort>,
    /// The process serving it (a child made by fork leaves it alone).
    pid: u32,
}

impl SimPty {
    /// In a child made by fork the serving thread is not there: let go of everything without
    /// joining or closing (the parent's board goes on). Whether this is such a child.
    fn forked(&mut self) -> bool {
        if std::process::id() == self.pid {
            return false;
        }
        std::mem::forget(self.thread.take());
        std::mem::forget(self.keep.take());
        true
    }
}

#[pymethods]
impl SimPty {
    /// The path to open.
    #[getter]
    fn path(&self) -> &str {
        &self.path
    }

    /// The firmware the board runs.
    #[getter]
    fn firmware(&self) -> &str {
        &self.firmware
    }

    /// Every byte the board was sent so far.
    #[getter]
    fn received<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let heard = self.heard.lock().map(|h| h.clone()).unwrap_or_default();
        PyBytes::new(py, &heard)
    }

    /// While `True`, the board sends nothing (it still hears everything): a cut wire, a
    /// board that hangs.
    #[getter]
    fn get_silent(&self) -> bool {
        self.silent.load(Ordering::SeqCst)
    }

    #[setter]
    fn set_silent(&self, silent: bool) {
        self.silent.store(silent, Ordering::SeqCst);
    }

    /// Stops serving (again: nothing; in a child process made by fork: nothing).
    fn close(&mut self, py: Python<'_>) {
        if self.forked() {
            return;
        }
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            crate::detach(py, || {
                let _ = t.join();
            });
        }
        self.keep = None;
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __exit__(
        &mut self,
        py: Python<'_>,
        exc_type: Option<Bound<'_, PyAny>>,
        exc_value: Option<Bound<'_, PyAny>>,
        traceback: Option<Bound<'_, PyAny>>,
    ) -> bool {
        let _ = (exc_type, exc_value, traceback);
        self.close(py);
        false
    }

    fn __repr__(&self) -> String {
        format!("Pty(path={:?}, firmware={:?})", self.path, self.firmware)
    }
}

impl Drop for SimPty {
    fn drop(&mut self) {
        if self.forked() {
            return;
        }
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Serves a simulated board (`firmware` "2020" or "v1.0.0") on a new pseudo-terminal; returns
/// a `Pty` whose `path` a program opens as the board's serial port.
#[pyfunction]
#[pyo3(
    signature = (firmware = "2020", seed = Int::from(1)),
    text_signature = "(firmware=\"2020\", seed=1)"
)]
pub fn pty(firmware: &str, seed: Int) -> PyResult<SimPty> {
    use serialport::SerialPort as _;
    let board = board(firmware, seed_of(&seed)?)?;
    let (mut board_end, path_end) = serialport::TTYPort::pair()
        .map_err(|e| PyOSError::new_err(format!("cannot make a pseudo-terminal: {e}")))?;
    board_end
        .set_timeout(Duration::from_millis(1))
        .map_err(|e| PyOSError::new_err(format!("pseudo-terminal: {e}")))?;
    let path = path_end
        .name()
        .ok_or_else(|| PyOSError::new_err("the pseudo-terminal has no path"))?;
    let stop = Arc::new(AtomicBool::new(false));
    let silent = Arc::new(AtomicBool::new(false));
    let heard = Arc::new(Mutex::new(Vec::new()));
    let tap = Tap {
        inner: board_end,
        heard: Arc::clone(&heard),
        silent: Arc::clone(&silent),
    };
    let flag = Arc::clone(&stop);
    let thread = std::thread::Builder::new()
        .name("chassis-sim".into())
        .spawn(move || {
            crate::signals::keep_signals_off_this_thread();
            let _ = serve(board, tap, &flag);
        })
        .map_err(|e| PyOSError::new_err(format!("cannot start the simulated board: {e}")))?;
    Ok(SimPty {
        path,
        firmware: firmware.to_string(),
        stop,
        silent,
        heard,
        thread: Some(thread),
        keep: Some(path_end),
        pid: std::process::id(),
    })
}
