//! The `nb` shell (feature `nb`): [`NbSerial`] adapts an `embedded-hal-nb` 1.0 serial port
//! (`serial::Read<u8> + serial::Write<u8>`, as rp2040-hal 0.12 and stm32f4xx-hal 0.23 provide)
//! to the `embedded-io` traits, so the [`blocking::Driver`](super::blocking::Driver) drives it:
//! one driver, no second copy of its logic.
//!
//! Reads never block: `read_ready` tries one byte and keeps it. Writes wait byte by byte, but
//! never for ever: a transmitter that accepts no byte for [`NbSerial::TX_SPINS`] tries in a row
//! is [`NbError::TxStalled`]. Errors keep the HAL's own error (overrun, framing, noise, parity:
//! exactly this link's faults), and [`NbError::serial_kind`] tells them apart portably.
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
    /// Tries in a row that a transmitter may answer `WouldBlock` before a write gives up. At
    /// 115 200 bps a byte leaves in 87 µs; a million tries is far longer on any MCU.
    pub const TX_SPINS: u32 = 1_000_000;

    /// Wraps a serial port.
    pub const fn new(serial: S) -> Self {
        NbSerial { serial, held: None }
    }

    /// The serial port, mutably (a test double's controls; do not read from or write to it
    /// behind the driver's back).
    pub fn inner_mut(&mut self) -> &mut S {
        &mut self.serial
    }

    /// Gives back the serial port, and a byte read ahead by `read_ready` if there is one.
    pub fn release(self) -> (S, Option<u8>) {
        (self.serial, self.held)
    }
}

/// An error of the serial port behind [`NbSerial`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NbError<E> {
    /// The HAL's own error.
    Serial(E),
    /// The transmitter accepted no byte for [`NbSerial::TX_SPINS`] tries.
    TxStalled,
}

impl<E: serial::Error> NbError<E> {
    /// The serial error's kind (overrun, framing, noise, parity, other); `None` for
    /// [`NbError::TxStalled`].
    pub fn serial_kind(&self) -> Option<serial::ErrorKind> {
        match self {
            NbError::Serial(e) => Some(e.kind()),
            NbError::TxStalled => None,
        }
    }
}

impl<E: serial::Error> embedded_io::Error for NbError<E> {
    fn kind(&self) -> embedded_io::ErrorKind {
        match self.serial_kind() {
            // Bytes arrived damaged: the data is wrong, the link goes on.
            Some(serial::ErrorKind::FrameFormat | serial::ErrorKind::Noise)
            | Some(serial::ErrorKind::Parity) => embedded_io::ErrorKind::InvalidData,
            // Bytes were lost; embedded-io has no kind for it.
            Some(serial::ErrorKind::Overrun | serial::ErrorKind::Other) | Some(_) => {
                embedded_io::ErrorKind::Other
            }
            None => embedded_io::ErrorKind::TimedOut,
        }
    }
}

impl<E: core::fmt::Debug> core::fmt::Display for NbError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            NbError::Serial(e) => write!(f, "serial error: {e:?}"),
            NbError::TxStalled => f.write_str("the transmitter accepted no byte"),
        }
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
            Err(nb::Error::Other(e)) => Err(NbError::Serial(e)),
        }
    }
}

impl<S: serial::Read<u8>> embedded_io::Read for NbSerial<S> {
    /// Hands out what is there without waiting, once `read_ready` said a byte is (the driver
    /// calls it only then). With nothing there it returns 0.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        let mut n: usize = 0;
        for slot in buf.iter_mut() {
            let byte = match self.held.take() {
                Some(byte) => byte,
                None => match self.serial.read() {
                    Ok(byte) => byte,
                    Err(nb::Error::WouldBlock) => break,
                    // Reported, never swallowed: the bytes of this call before it are given
                    // up (the parser resynchronises), the overrun or framing error is seen.
                    Err(nb::Error::Other(e)) => return Err(NbError::Serial(e)),
                },
            };
            *slot = byte;
            n = n.saturating_add(1);
        }
        Ok(n)
    }
}

impl<S: serial::Write<u8>> NbSerial<S> {
    fn wait<T>(
        mut attempt: impl FnMut(&mut S) -> nb::Result<T, S::Error>,
        serial: &mut S,
    ) -> Result<T, NbError<S::Error>> {
        for _ in 0..Self::TX_SPINS {
            match attempt(serial) {
                Ok(value) => return Ok(value),
                Err(nb::Error::WouldBlock) => {}
                Err(nb::Error::Other(e)) => return Err(NbError::Serial(e)),
            }
        }
        Err(NbError::TxStalled)
    }
}

impl<S: serial::Write<u8>> embedded_io::Write for NbSerial<S> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        for byte in buf {
            Self::wait(|s| s.write(*byte), &mut self.serial)?;
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        Self::wait(serial::Write::flush, &mut self.serial)
    }
}
