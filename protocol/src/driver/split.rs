//! [`Split`]: a UART handed out as two halves, as one value for the shells.

use embedded_io::{ErrorType, Read, ReadReady, Write as IoWrite};

/// A UART handed out as two halves (embassy's `split()`, a DMA ring-buffered RX with a plain
/// TX): one value that reads from `rx` and writes to `tx`, for the blocking shell (embedded-io
/// 0.7 `Read + ReadReady` and `Write`) and the async one (embedded-io-async 0.7 `Read` and
/// `Write`). Both halves must have the same error type, as HALs' halves do.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Split<R, W> {
    /// The receiving half.
    pub rx: R,
    /// The sending half.
    pub tx: W,
}

impl<R: ErrorType, W: ErrorType<Error = R::Error>> ErrorType for Split<R, W> {
    type Error = R::Error;
}

impl<R: Read, W: ErrorType<Error = R::Error>> Read for Split<R, W> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        self.rx.read(buf)
    }
}

impl<R: ReadReady, W: ErrorType<Error = R::Error>> ReadReady for Split<R, W> {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        self.rx.read_ready()
    }
}

impl<R: ErrorType, W: IoWrite<Error = R::Error>> IoWrite for Split<R, W> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        self.tx.write(buf)
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        self.tx.flush()
    }
}

#[cfg(feature = "async")]
impl<R: embedded_io_async::Read, W: ErrorType<Error = R::Error>> embedded_io_async::Read
    for Split<R, W>
{
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        self.rx.read(buf).await
    }
}

#[cfg(feature = "async")]
impl<R: ErrorType, W: embedded_io_async::Write<Error = R::Error>> embedded_io_async::Write
    for Split<R, W>
{
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        self.tx.write(buf).await
    }

    async fn flush(&mut self) -> Result<(), Self::Error> {
        self.tx.flush().await
    }
}
