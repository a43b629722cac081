//! The board's serial port as the CLI opens it: refused clearly when the path is no serial
//! port, and optionally recorded, both directions time-stamped, as a Saleae Logic 2 export
//! (`chassis decode FILE --input saleae-csv --quiet-ms 40`, `--master-analyzer master` for
//! both sides). The bytes are stamped with the driver's own clock readings, and a gap of more
//! than 40 ms stands exactly where the host driver found the line quiet
//! ([`chassis_protocol::driver::Config::HOST`]'s `idle_ms`): the decode of a recording sees
//! the frames the driver saw.

use crate::newfile::NewFile;
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::host::{MonotonicClock, SerialError, SerialPort};
use chassis_protocol::driver::{Clock, Config};
use std::cell::Cell;
use std::io::{BufWriter, Write as _};
use std::rc::Rc;

/// A byte's time on the line at 115 200 bps (10 bits), in seconds.
pub const BYTE_S: f64 = 10.0 / 115_200.0;

/// A quiet line for the host driver ([`Config::HOST`]'s `idle_ms`), in seconds: a recording
/// is decoded with `--quiet-ms 40`.
#[allow(clippy::cast_lossless)]
pub const QUIET_S: f64 = Config::HOST.idle_ms as f64 / 1000.0;

/// The driver the CLI uses for a 2020 board: the host driver over a [`Port`].
pub type Board = Driver<Port, SharedClock>;

/// The driver the CLI uses for a v1.0.0 board.
pub type BoardV1 = Driver<Port, SharedClock, chassis_protocol::driver::v1::DriverCore>;

/// The host's monotonic clock, each reading also shown to the [`Port`] (whose recording is
/// stamped with the times the driver judges by).
#[derive(Clone, Debug)]
pub struct SharedClock {
    clock: MonotonicClock,
    last: Rc<Cell<u64>>,
}

impl SharedClock {
    /// The same clock (the same origin), its readings not shown to the port: for code beside
    /// the driver that reads the time.
    pub fn detached(&self) -> SharedClock {
        SharedClock {
            clock: self.clock,
            last: Rc::new(Cell::new(0)),
        }
    }
}

impl Clock for SharedClock {
    fn now_ms(&mut self) -> u64 {
        let now = self.clock.now_ms();
        self.last.set(now);
        now
    }
}

/// The capture file of `--record`, if given.
static RECORD: std::sync::Mutex<Option<Recorder>> = std::sync::Mutex::new(None);

/// From now on, the next port opened records both ways into `path` (`--record FILE`): the file
/// is made now, so a path that cannot be written fails before anything is sent.
pub fn record_to(path: &str) -> Result<(), String> {
    let recorder = Recorder::create(path)?;
    if let Ok(mut slot) = RECORD.lock() {
        *slot = Some(recorder);
    }
    Ok(())
}

/// Opens `path` as a 2020 board's port with the host defaults; `record`, if given (or set by
/// [`record_to`]), gets every byte both ways.
pub fn open(path: &str, record: Option<Recorder>) -> Result<Board, String> {
    let (mut port, clock) = open_port(path, record)?;
    port.stop = chassis_protocol::Velocity::STOP.encode().to_vec();
    Ok(Driver::new(port, clock, Config::HOST))
}

/// Opens `path` as a v1.0.0 board's port (as [`open`]).
pub fn open_v1(path: &str, record: Option<Recorder>) -> Result<BoardV1, String> {
    let (mut port, clock) = open_port(path, record)?;
    port.stop = chassis_protocol::v1::Command::BodyVelocity(
        chassis_protocol::v1::BodyVelocity::FORCED_STOP,
    )
    .encode()
    .to_vec();
    Ok(Driver::new_v1(port, clock, Config::HOST))
}

/// Opens `path` as the board's serial port, with the clock its recording is stamped by.
pub fn open_port(path: &str, record: Option<Recorder>) -> Result<(Port, SharedClock), String> {
    let record = record.or_else(|| RECORD.lock().ok().and_then(|mut r| r.take()));
    let port = open_serial(path)?;
    let record = record.map(|mut r| {
        r.armed = true;
        r
    });
    let clock = SharedClock {
        clock: MonotonicClock::new(),
        last: Rc::new(Cell::new(0)),
    };
    Ok((
        Port {
            port,
            path: path.to_string(),
            now: Rc::clone(&clock.last),
            record,
            interruptible: true,
            listener: None,
            stop: Vec::new(),
            stops: 0,
            tail: Vec::with_capacity(TAIL),
        },
        clock,
    ))
}

/// Opens `path` as a serial port with the host defaults (not recorded): refused clearly when it
/// is a file, a folder or a device that takes no serial settings.
pub fn open_serial(path: &str) -> Result<SerialPort, String> {
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_file() || meta.is_dir() {
            return Err(format!(
                "cannot open {path}: it is a {}, not a serial port (a USB-UART adapter is /dev/ttyUSB0 or /dev/ttyACM0, on Windows COM3)",
                if meta.is_dir() { "folder" } else { "file" }
            ));
        }
    }
    SerialPort::open(path).map_err(|e| {
        // ENOTTY, EINVAL: a device that takes no serial settings (/dev/null, /dev/urandom).
        // The serial port crate keeps the OS's words, not its number.
        let text = e.0.to_string();
        let not_serial = matches!(e.0.raw_os_error(), Some(25 | 22))
            || ["typewriter", "Inappropriate ioctl", "Invalid argument"]
                .iter()
                .any(|w| text.contains(w));
        if not_serial {
            format!("cannot open {path}: not a serial port (it takes no serial settings: {text})")
        } else {
            format!("cannot open {path}: {text}")
        }
    })
}

/// What is shown every byte read from the board ([`Port::listen`]).
type Listener = Box<dyn FnMut(&[u8])>;

/// The last bytes written that a [`Port`] keeps: the longest frame of either generation.
const TAIL: usize = 14;

/// The host serial port, with an optional recording of its bytes. Its waits for a byte end
/// with an error (kind `Interrupted`) once the command must end ([`crate::ending::ended`]), so
/// that no read keeps a stop waiting; [`Port::uninterrupted`] lets what stops the chassis run
/// to its end. It keeps what it wrote: what was sent is known, not assumed.
pub struct Port {
    port: SerialPort,
    path: String,
    /// The driver's last clock reading, in ms.
    now: Rc<Cell<u64>>,
    record: Option<Recorder>,
    /// Waits end when the command must.
    interruptible: bool,
    /// Shown every byte read from the board.
    listener: Option<Listener>,
    /// The generation's stop frame (empty: none counted).
    stop: Vec<u8>,
    /// Stop frames written whole so far.
    stops: u64,
    /// The last bytes written, the newest last (at most [`TAIL`]).
    tail: Vec<u8>,
}

impl Port {
    /// The path it was opened with.
    pub fn name(&self) -> &str {
        &self.path
    }

    /// The driver's last clock reading, ms (when it last looked: an error is judged then).
    pub fn now_ms(&self) -> u64 {
        self.now.get()
    }

    /// From now on the port's waits run to their end whatever ends the command: what follows
    /// stops the chassis.
    pub fn uninterrupted(&mut self) {
        self.interruptible = false;
    }

    /// From now on `listener` is shown every byte read from the board (`chassis record`
    /// counts the frames of the other generation with it).
    pub fn listen(&mut self, listener: impl FnMut(&[u8]) + 'static) {
        self.listener = Some(Box::new(listener));
    }

    /// The generation's stop frames written whole to the port so far: the evidence that a
    /// stop went out (a write that failed sent none).
    pub fn stops_sent(&self) -> u64 {
        self.stops
    }

    /// The recording, if any.
    pub fn recorder(&self) -> Option<&Recorder> {
        self.record.as_ref()
    }

    /// Ends the recording (flushes the file): what it wrote, or the first error.
    pub fn finish_recording(&mut self) -> Option<Result<Counts, String>> {
        self.record.as_mut().map(Recorder::finish)
    }
}

impl std::fmt::Debug for Port {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Port")
            .field("path", &self.path)
            .field("record", &self.record)
            .field("interruptible", &self.interruptible)
            .field("stops", &self.stops)
            .finish_non_exhaustive()
    }
}

impl embedded_io::ErrorType for Port {
    type Error = SerialError;
}

impl embedded_io::ReadReady for Port {
    fn read_ready(&mut self) -> Result<bool, SerialError> {
        if self.interruptible {
            if let Some(ending) = crate::ending::ended() {
                return Err(SerialError(std::io::Error::new(
                    std::io::ErrorKind::Interrupted,
                    ending.words(),
                )));
            }
        }
        let ready = self.port.read_ready()?;
        if let (false, Some(record)) = (ready, self.record.as_mut()) {
            record.nothing_waiting(self.now.get());
        }
        Ok(ready)
    }
}

impl embedded_io::Read for Port {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, SerialError> {
        let n = self.port.read(buf)?;
        let bytes = buf.get(..n).unwrap_or_default();
        if let Some(record) = self.record.as_mut() {
            record.board(bytes, self.now.get());
        }
        if let Some(listener) = self.listener.as_mut() {
            listener(bytes);
        }
        Ok(n)
    }
}

impl embedded_io::Write for Port {
    fn write(&mut self, buf: &[u8]) -> Result<usize, SerialError> {
        let n = self.port.write(buf)?;
        let bytes = buf.get(..n).unwrap_or_default();
        if let Some(record) = self.record.as_mut() {
            record.master(bytes, self.now.get());
        }
        for &byte in bytes {
            if self.tail.len() == TAIL {
                self.tail.remove(0);
            }
            self.tail.push(byte);
            if !self.stop.is_empty() && self.tail.ends_with(&self.stop) {
                self.stops = self.stops.saturating_add(1);
            }
        }
        Ok(n)
    }

    fn flush(&mut self) -> Result<(), SerialError> {
        self.port.flush()
    }
}

/// Bytes and frames recorded so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Bytes from the board.
    pub board_bytes: u64,
    /// Bytes the master (this program) sent.
    pub master_bytes: u64,
}

/// A capture file being written: `name,type,start_time,duration,data` rows, one per byte,
/// `board` or `master`, times in seconds of the driver's clock.
#[derive(Debug)]
pub struct Recorder {
    /// The file until it is finished.
    out: Option<BufWriter<NewFile>>,
    path: String,
    /// Attached to a port that opened: the file is kept even if the command fails (a capture
    /// of a failure is what a bug report needs). Never attached: it is thrown away, and what
    /// was at the path stays.
    armed: bool,
    /// When the last byte of each side started, in s.
    last: [f64; 2],
    /// The driver's clock when bytes from the board last came, in ms.
    last_read_ms: Option<u64>,
    /// The driver has found the line quiet since then (as its `tick` judges: nothing waiting,
    /// and `idle_ms` since the last byte).
    quiet_seen: bool,
    /// This program sent bytes since the board's last were read.
    sent_since_read: bool,
    counts: Counts,
    error: Option<String>,
}

impl Recorder {
    /// Creates `path` (fails at once if it cannot be written) and writes the header.
    pub fn create(path: &str) -> Result<Recorder, String> {
        let mut out = BufWriter::new(NewFile::create(path)?);
        writeln!(out, "name,type,start_time,duration,data")
            .map_err(|e| format!("cannot write {path}: {e}"))?;
        Ok(Recorder {
            out: Some(out),
            path: path.to_string(),
            armed: false,
            last: [f64::NEG_INFINITY; 2],
            last_read_ms: None,
            quiet_seen: true,
            sent_since_read: false,
            counts: Counts::default(),
            error: None,
        })
    }

    /// What was recorded so far.
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// The port had nothing to read at the driver's `now_ms`: the driver finds the line quiet
    /// if nothing came for its `idle_ms`.
    fn nothing_waiting(&mut self, now_ms: u64) {
        let idle = u64::from(Config::HOST.idle_ms);
        if self
            .last_read_ms
            .is_none_or(|t| now_ms.saturating_sub(t) >= idle)
        {
            self.quiet_seen = true;
        }
    }

    /// Bytes the board sent, read at the driver's `now_ms`: they came one after the other and
    /// ended about then. The gap before them is longer than [`QUIET_S`] exactly when the
    /// driver found the line quiet in between.
    fn board(&mut self, bytes: &[u8], now_ms: u64) {
        if bytes.is_empty() {
            return;
        }
        let now = now_ms as f64 / 1000.0;
        let arrived = now - BYTE_S * bytes.len() as f64;
        let last = self.last.first().copied().unwrap_or(f64::NEG_INFINITY);
        let first = if self.quiet_seen {
            arrived.max(last + QUIET_S + 0.000_5)
        } else {
            arrived.min(last + QUIET_S - 0.005)
        };
        // Read after something this program sent: stamped after it (the clock's millisecond
        // steps could put a reply before its read, which a decode would not await).
        let sent = self.last.get(1).copied().unwrap_or(f64::NEG_INFINITY);
        let first = if self.sent_since_read {
            first.max(sent + BYTE_S)
        } else {
            first
        };
        self.sent_since_read = false;
        self.quiet_seen = false;
        self.last_read_ms = Some(now_ms);
        self.counts.board_bytes += bytes.len() as u64;
        self.rows(0, first, bytes);
    }

    /// Bytes this program sent at the driver's `now_ms`: they leave from then on.
    fn master(&mut self, bytes: &[u8], now_ms: u64) {
        self.sent_since_read = true;
        self.counts.master_bytes += bytes.len() as u64;
        self.rows(1, now_ms as f64 / 1000.0, bytes);
    }

    fn rows(&mut self, side: usize, first: f64, bytes: &[u8]) {
        let name = if side == 0 { "board" } else { "master" };
        let Some(last) = self.last.get_mut(side) else {
            return;
        };
        let mut t = first.max(*last + BYTE_S).max(0.0);
        for byte in bytes {
            if let (None, Some(out)) = (&self.error, self.out.as_mut()) {
                if let Err(e) = writeln!(out, "{name},data,{t:.7},{BYTE_S:.7},0x{byte:02X}") {
                    self.error = Some(format!("cannot write {}: {e}", self.path));
                }
            }
            *last = t;
            t += BYTE_S;
        }
    }

    /// Flushes the file: the counts, or the first error writing it.
    pub fn finish(&mut self) -> Result<Counts, String> {
        if let Some(out) = self.out.take() {
            let committed = out
                .into_inner()
                .map_err(|e| format!("cannot write {}: {}", self.path, e.error()))
                .and_then(NewFile::commit);
            if let Err(e) = committed {
                self.error.get_or_insert(e);
            }
        }
        match &self.error {
            Some(e) => Err(e.clone()),
            None => Ok(self.counts),
        }
    }
}

/// The first error of a recording finished on its own (when its command ended): `main`
/// reports it.
static RECORD_ERROR: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Drops a `--record` recording no port took (its partial file is removed, what was at its
/// path stays).
pub fn discard_unused_recording() {
    if let Ok(mut slot) = RECORD.lock() {
        slot.take();
    }
}

/// A recording's error, if one ended with one.
pub fn record_error() -> Option<String> {
    RECORD_ERROR.lock().ok().and_then(|mut e| e.take())
}

impl Drop for Recorder {
    fn drop(&mut self) {
        // Never attached, or finished (and its error given) already.
        if !self.armed || self.out.is_none() {
            return;
        }
        if let Err(e) = self.finish() {
            if let Ok(mut slot) = RECORD_ERROR.lock() {
                slot.get_or_insert(e);
            }
        }
    }
}
