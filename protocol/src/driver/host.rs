//! A PC or a Raspberry Pi (feature `std`): [`SerialPort`], a serial-port transport on the
//! `serialport` crate (115 200 bps, 8N1), [`MonotonicClock`], and [`open`], which gives a
//! blocking driver with [`Config::HOST`] (defaults that fit a USB-UART adapter's latency).
//!
//! ```no_run
//! use chassis_protocol::driver::{host, reg};
//! use chassis_protocol::Velocity;
//!
//! let mut driver = host::open("/dev/ttyUSB0")?;
//! let volts = driver.read(reg::MotorVoltage)?;
//! driver.set_velocity(Velocity::new(0, 200, 0))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `host-tests/examples/host_pty.rs` drives the simulated board through a pseudo-terminal with
//! it: the real OS serial stack, no hardware.

use super::blocking::Driver;
use super::{Clock, Config};
use std::io::{self, Read as _, Write as _};
use std::time::{Duration, Instant};

/// The board's line speed.
pub const BAUD: u32 = 115_200;

/// How long `read_ready` waits for a first byte before it says none is there: the driver's
/// loop sleeps here instead of spinning.
pub const WAIT_FOR_BYTE: Duration = Duration::from_millis(1);

/// An OS serial port (a USB-UART adapter, a Raspberry Pi's UART, a pseudo-terminal) as the
/// driver's transport: `embedded-io` `Read + Write + ReadReady`.
pub struct SerialPort {
    port: Box<dyn serialport::SerialPort>,
    /// A byte read ahead by `read_ready`.
    held: Option<u8>,
}

impl core::fmt::Debug for SerialPort {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SerialPort")
            .field("name", &self.port.name())
            .field("held", &self.held)
            .finish()
    }
}

/// An error of the OS serial port.
#[derive(Debug)]
pub struct SerialError(pub io::Error);

impl core::fmt::Display for SerialError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "serial port: {}", self.0)
    }
}

impl std::error::Error for SerialError {}

impl embedded_io::Error for SerialError {
    fn kind(&self) -> embedded_io::ErrorKind {
        match self.0.kind() {
            io::ErrorKind::NotFound => embedded_io::ErrorKind::NotFound,
            io::ErrorKind::PermissionDenied => embedded_io::ErrorKind::PermissionDenied,
            io::ErrorKind::BrokenPipe => embedded_io::ErrorKind::BrokenPipe,
            io::ErrorKind::InvalidInput => embedded_io::ErrorKind::InvalidInput,
            io::ErrorKind::InvalidData => embedded_io::ErrorKind::InvalidData,
            io::ErrorKind::TimedOut => embedded_io::ErrorKind::TimedOut,
            io::ErrorKind::Interrupted => embedded_io::ErrorKind::Interrupted,
            _ => embedded_io::ErrorKind::Other,
        }
    }
}

impl From<serialport::Error> for SerialError {
    fn from(e: serialport::Error) -> Self {
        SerialError(e.into())
    }
}

impl SerialPort {
    /// Opens `path` at 115 200 bps, 8 data bits, no parity, 1 stop bit, no flow control, and
    /// throws away what the OS buffered before (a board that talked while nobody listened
    /// would otherwise hand over seconds of stale frames at once, all stamped now).
    pub fn open(path: &str) -> Result<Self, SerialError> {
        let port = serialport::new(path, BAUD)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(WAIT_FOR_BYTE)
            .open()?;
        port.clear(serialport::ClearBuffer::Input)?;
        Ok(SerialPort { port, held: None })
    }

    /// A port opened some other way (a pseudo-terminal, a port with other settings).
    pub fn from_port(mut port: Box<dyn serialport::SerialPort>) -> Result<Self, SerialError> {
        port.set_timeout(WAIT_FOR_BYTE)?;
        Ok(SerialPort { port, held: None })
    }

    /// How long [`ReadReady::read_ready`](embedded_io::ReadReady::read_ready) waits for a first
    /// byte before it says none is there ([`WAIT_FOR_BYTE`] unless set). A loop that paces
    /// itself (a thread woken by a timer) sets [`Duration::ZERO`]: it then takes in what
    /// arrived and returns at once, never sleeping inside the driver. Costs no system call.
    pub fn set_wait_for_byte(&mut self, wait: Duration) -> Result<(), SerialError> {
        self.port.set_timeout(wait)?;
        Ok(())
    }

    /// The port's name, as the OS gives it.
    #[must_use]
    pub fn name(&self) -> Option<String> {
        self.port.name()
    }
}

impl embedded_io::ErrorType for SerialPort {
    type Error = SerialError;
}

impl embedded_io::ReadReady for SerialPort {
    /// Waits up to [`WAIT_FOR_BYTE`] for a byte.
    fn read_ready(&mut self) -> Result<bool, SerialError> {
        if self.held.is_some() || self.port.bytes_to_read()? > 0 {
            return Ok(true);
        }
        let mut byte = [0u8];
        match self.port.read(&mut byte) {
            Ok(1) => {
                let [b] = byte;
                self.held = Some(b);
                Ok(true)
            }
            Ok(_) => Ok(false),
            Err(e) if e.kind() == io::ErrorKind::TimedOut => Ok(false),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => Ok(false),
            Err(e) => Err(SerialError(e)),
        }
    }
}

impl embedded_io::Read for SerialPort {
    /// Hands out what is there without waiting (the driver calls it once `read_ready` said a
    /// byte is).
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, SerialError> {
        let Some((first, rest)) = buf.split_first_mut() else {
            return Ok(0);
        };
        let mut n = 0;
        let rest = match self.held.take() {
            Some(byte) => {
                *first = byte;
                n = 1;
                rest
            }
            None => buf,
        };
        let waiting = usize::try_from(self.port.bytes_to_read()?).unwrap_or(usize::MAX);
        let take = waiting.min(rest.len());
        if take > 0 {
            if let Some(into) = rest.get_mut(..take) {
                n = self.port.read(into).map_err(SerialError)?.saturating_add(n);
            }
        }
        Ok(n)
    }
}

impl embedded_io::Write for SerialPort {
    fn write(&mut self, buf: &[u8]) -> Result<usize, SerialError> {
        self.port.write(buf).map_err(SerialError)
    }

    fn flush(&mut self) -> Result<(), SerialError> {
        self.port.flush().map_err(SerialError)
    }
}

/// Milliseconds from a monotonic clock (`std::time::Instant`), from when it was made.
#[derive(Clone, Copy, Debug)]
pub struct MonotonicClock(Instant);

impl MonotonicClock {
    /// A clock starting at 0 now.
    #[must_use]
    pub fn new() -> Self {
        MonotonicClock(Instant::now())
    }
}

impl Default for MonotonicClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for MonotonicClock {
    fn now_ms(&mut self) -> u64 {
        u64::try_from(self.0.elapsed().as_millis()).unwrap_or(u64::MAX)
    }
}

/// The blocking driver over an OS serial port.
pub type HostDriver = Driver<SerialPort, MonotonicClock>;

/// Opens the serial port at `path` and gives a driver over it with [`Config::HOST`].
pub fn open(path: &str) -> Result<HostDriver, SerialError> {
    let port = SerialPort::open(path)?;
    Ok(Driver::new(port, MonotonicClock::new(), Config::HOST))
}

/// `Err` with the reason, in the `chassis` command's words, for a write the board would take
/// but that no owner means: a battery range whose full voltage is not above its cut-off
/// (0x7FFF for either, the built-in table, is always right). The `chassis` command and the
/// Python package check every write and every restore with it before anything is sent.
pub fn check_write(write: crate::Write) -> Result<(), String> {
    const TABLE: u16 = 0x7FFF;
    match write {
        crate::Write::BatteryRange {
            full_centivolts: full,
            cutoff_centivolts: cut,
        } if full != TABLE && cut != TABLE && full <= cut => Err(format!(
            "battery-range: full {:.2} V is not above cut-off {:.2} V (FULL comes first)",
            f64::from(full) / 100.0,
            f64::from(cut) / 100.0
        )),
        _ => Ok(()),
    }
}

/// [`check_write`] for each register a restore of `settings` writes.
pub fn check_settings(settings: &crate::registers::Snapshot) -> Result<(), String> {
    check_write(crate::Write::BatteryRange {
        full_centivolts: settings.battery_full_centivolts,
        cutoff_centivolts: settings.battery_cutoff_centivolts,
    })
}

/// What has come from the board, for [`words_heard`]: what a person is told to check
/// depends on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Heard {
    /// Not a byte: power, wiring, baud rate.
    Nothing,
    /// Bytes, but no frame the driver's firmware generation reads: the other firmware, another
    /// device, another baud rate.
    NoFrame,
    /// Frames came, but none within the failsafe time: the board went quiet.
    Quiet,
    /// Frames arrive.
    Frames,
}

impl Heard {
    /// From a driver core's `last_heard_ms()`, `link_alive(now)` and the bytes its parser
    /// discarded.
    #[must_use]
    pub const fn from_link(last_heard_ms: Option<u64>, link_alive: bool, discarded: u32) -> Self {
        match (last_heard_ms, link_alive) {
            (None, _) if discarded > 0 => Heard::NoFrame,
            (None, _) => Heard::Nothing,
            (Some(_), false) => Heard::Quiet,
            (Some(_), true) => Heard::Frames,
        }
    }
}

/// A driver error in the words of the `chassis` command (and of the Python package), for a
/// person, told by what has come from the board on `port` ([`Heard`]).
#[must_use]
pub fn words_heard(e: super::CoreError, heard: Heard, port: &str) -> String {
    use super::CoreError;
    let read = match e {
        CoreError::Timeout(r) | CoreError::Unconfirmed(r) => format!("the read of {}", r.name()),
        CoreError::NoReadback(r) => format!("the readback of {}", r.name()),
        _ => return words(e, heard == Heard::Nothing, port),
    };
    match heard {
        Heard::Nothing => words(e, true, port),
        Heard::NoFrame => format!(
            "bytes came from the board on {port}, but no frame of the firmware this command speaks: no answer to {read} (the other firmware? `chassis detect` tells; or a baud rate other than 115200)"
        ),
        Heard::Quiet => format!(
            "the board on {port} went quiet: no answer to {read}, and no telemetry within the failsafe time (its power, the cable?)"
        ),
        Heard::Frames => words(e, false, port),
    }
}

/// A driver error in the words of the `chassis` command (and of the Python package), for a
/// person: `silent` says nothing at all came from the board on `port` (then, and only then, the
/// words ask about power and wiring).
#[must_use]
pub fn words(e: super::CoreError, silent: bool, port: &str) -> String {
    use super::CoreError;
    let readback = crate::v1::Readback::name;
    const WIRING: &str = "is it powered, TX wired to RX and RX to TX, at 115200 bps?";
    match e {
        CoreError::Timeout(r) | CoreError::Unconfirmed(r) if silent => format!(
            "nothing came from the board on {port}: no answer to the read of {} ({WIRING})",
            r.name()
        ),
        CoreError::Timeout(r) => format!(
            "the board did not answer the read of {} (its telemetry arrives: a reply lost on the line?)",
            r.name()
        ),
        CoreError::Unconfirmed(r) => format!(
            "the read of {} was not confirmed: its replies went missing or disagreed, while its telemetry arrives (a noisy line?)",
            r.name()
        ),
        CoreError::WrongReply { expected, got } => format!(
            "a reply with code {got:#04x} came while reading {}",
            expected.name()
        ),
        CoreError::Invalid { register, value } => format!(
            "a damaged reply: {value:#010x} cannot be {}'s value",
            register.name()
        ),
        CoreError::TurnInProgress => {
            "the board still has a turn pending (it adds turns up): `chassis stop` cancels it"
                .into()
        }
        CoreError::NoReadback(r) if silent => format!(
            "nothing came from the board on {port}: no answer to the readback of {} ({WIRING})",
            readback(r)
        ),
        CoreError::NoReadback(r) => format!(
            "the board did not answer the readback of {} (its telemetry arrives: a reply lost on the line?)",
            readback(r)
        ),
        CoreError::ReadbackDiffers(r) => format!(
            "the {} settings were written, but the board's readback does not show them (it did not take them, or keeps other values)",
            readback(r)
        ),
        other => other.to_string(),
    }
}
