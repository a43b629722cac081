//! The `nb` shell (feature `nb`): [`NbSerial`] adapts an `embedded-hal-nb` 1.0 serial port
//! (`serial::Read<u8> + serial::Write<u8>`, as stm32f4xx-hal, rp2040-hal and esp-hal provide) to
//! the `embedded-io` traits, so the [`blocking::Driver`](super::blocking::Driver) drives it: one
//! driver, no second copy of its logic.
//!
//! Reads never block: `read_ready` tries one byte and keeps it. Writes block byte by byte with
//! `nb::block!` (a command frame is 10 or 12 bytes: about 1 ms at 115 200 bps).
//!
//! ```text
//! let serial = NbSerial::new(hal_serial);
//! let mut driver = Driver::new(serial, clock, Config::DEFAULT);
//! ```

use embedded_hal_nb::nb;
use embedded_hal_nb::serial;

/// An `embedded-hal-nb` serial port seen as `embedded-io` `Read + Write + ReadReady`.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NbSerial<S> {
    serial: S,
    /// A byte taken by `read_ready`, not yet handed out.
    held: Option<u8>,
}

impl<S> NbSerial<S> {
    /// Wraps a serial port.
    pub const fn new(serial: S) -> Self {
        NbSerial { serial, held: None }
    }

    /// Gives the serial port back (a byte held by `read_ready` is returned with it).
    pub fn release(self) -> (S, Option<u8>) {
        (self.serial, self.held)
    }
}

/// The serial port's error, as an `embedded-io` error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NbError<E>(pub E);

impl<E: serial::Error> embedded_io::Error for NbError<E> {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}

impl<E: core::fmt::Debug> core::fmt::Display for NbError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "serial error: {:?}", self.0)
    }
}

impl<E: core::fmt::Debug> core::error::Error for NbError<E> {}

impl<S: serial::ErrorType> embedded_io::ErrorType for NbSerial<S> {
    type Error = NbError<S::Error>;
}

impl<S: serial::Read<u8>> embedded_io::ReadReady for NbSerial<S> {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        if self.held.is_some() {
            return Ok(true);
        }
        match self.serial.read() {
            Ok(byte) => {
                self.held = Some(byte);
                Ok(true)
            }
            Err(nb::Error::WouldBlock) => Ok(false),
            Err(nb::Error::Other(e)) => Err(NbError(e)),
        }
    }
}

impl<S: serial::Read<u8>> embedded_io::Read for NbSerial<S> {
    /// Hands out the held byte and whatever else is ready; blocks only if nothing is.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        let mut n: usize = 0;
        for slot in buf.iter_mut() {
            let byte = match self.held.take() {
                Some(byte) => byte,
                None if n == 0 => nb::block!(self.serial.read()).map_err(NbError)?,
                None => match self.serial.read() {
                    Ok(byte) => byte,
                    Err(nb::Error::WouldBlock) => break,
                    Err(nb::Error::Other(e)) => return Err(NbError(e)),
                },
            };
            *slot = byte;
            n = n.saturating_add(1);
        }
        Ok(n)
    }
}

impl<S: serial::Write<u8>> embedded_io::Write for NbSerial<S> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        for byte in buf {
            nb::block!(self.serial.write(*byte)).map_err(NbError)?;
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        nb::block!(self.serial.flush()).map_err(NbError)
    }
}
