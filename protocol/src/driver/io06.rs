//! Feature `embedded-io-06`: [`Io06`] makes a UART that implements `embedded-io` **0.6**
//! (stm32f4xx-hal 0.23, esp-hal with its 0.6 feature) usable by the
//! [`blocking::Driver`](super::blocking::Driver), which is written against 0.7: the same
//! driver, no second copy of it.

use embedded_io_06 as io06;

/// A UART implementing `embedded-io` 0.6, seen through the 0.7 traits.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Io06<T>(pub T);

/// The 0.6 UART's error, as a 0.7 error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Io06Error<E>(pub E);

impl<E: io06::Error> embedded_io::Error for Io06Error<E> {
    fn kind(&self) -> embedded_io::ErrorKind {
        match self.0.kind() {
            io06::ErrorKind::NotFound => embedded_io::ErrorKind::NotFound,
            io06::ErrorKind::PermissionDenied => embedded_io::ErrorKind::PermissionDenied,
            io06::ErrorKind::ConnectionRefused => embedded_io::ErrorKind::ConnectionRefused,
            io06::ErrorKind::ConnectionReset => embedded_io::ErrorKind::ConnectionReset,
            io06::ErrorKind::ConnectionAborted => embedded_io::ErrorKind::ConnectionAborted,
            io06::ErrorKind::NotConnected => embedded_io::ErrorKind::NotConnected,
            io06::ErrorKind::AddrInUse => embedded_io::ErrorKind::AddrInUse,
            io06::ErrorKind::AddrNotAvailable => embedded_io::ErrorKind::AddrNotAvailable,
            io06::ErrorKind::BrokenPipe => embedded_io::ErrorKind::BrokenPipe,
            io06::ErrorKind::AlreadyExists => embedded_io::ErrorKind::AlreadyExists,
            io06::ErrorKind::InvalidInput => embedded_io::ErrorKind::InvalidInput,
            io06::ErrorKind::InvalidData => embedded_io::ErrorKind::InvalidData,
            io06::ErrorKind::TimedOut => embedded_io::ErrorKind::TimedOut,
            io06::ErrorKind::Interrupted => embedded_io::ErrorKind::Interrupted,
            io06::ErrorKind::Unsupported => embedded_io::ErrorKind::Unsupported,
            io06::ErrorKind::OutOfMemory => embedded_io::ErrorKind::OutOfMemory,
            io06::ErrorKind::WriteZero => embedded_io::ErrorKind::WriteZero,
            _ => embedded_io::ErrorKind::Other,
        }
    }
}

impl<E: core::fmt::Debug> core::fmt::Display for Io06Error<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "UART error: {:?}", self.0)
    }
}

impl<E: core::fmt::Debug> core::error::Error for Io06Error<E> {}

impl<T: io06::ErrorType> embedded_io::ErrorType for Io06<T> {
    type Error = Io06Error<T::Error>;
}

impl<T: io06::Read> embedded_io::Read for Io06<T> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        self.0.read(buf).map_err(Io06Error)
    }
}

impl<T: io06::ReadReady> embedded_io::ReadReady for Io06<T> {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        self.0.read_ready().map_err(Io06Error)
    }
}

impl<T: io06::Write> embedded_io::Write for Io06<T> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        self.0.write(buf).map_err(Io06Error)
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        self.0.flush().map_err(Io06Error)
    }
}
