//! The simulated board behind in-memory adapters (feature `driver`): a UART ([`SimUart`]), a
//! clock ([`SimClock`]) and, with `async`, a delay ([`SimDelay`]), all on one shared
//! millisecond counter, so a test drives the board in simulated time. The UART takes either
//! board ([`Simulated`]): the 2020 [`Board`] by default, or a [`v1::Board`](super::v1::Board).

use super::{Board, Simulated};

/// The board behind an in-memory UART (features `sim` and `driver`): `embedded-io` `Read`,
/// `Write` and `ReadReady`, for testing a master, or the [`crate::driver`], on the host. The
/// board's time follows a shared [`Cell`](core::cell::Cell) of milliseconds, which
/// [`SimClock`] advances.
#[derive(Debug)]
pub struct SimUart<'t, B: Simulated = Board> {
    board: B,
    time: &'t core::cell::Cell<u64>,
    burst_ms: u64,
}

impl<'t, B: Simulated> SimUart<'t, B> {
    /// `board` behind a UART, on the clock `time`.
    pub fn new(board: B, time: &'t core::cell::Cell<u64>) -> Self {
        SimUart {
            board,
            time,
            burst_ms: 1,
        }
    }

    /// Hands the board's bytes over only every `burst_ms` ms, all at once, as a USB-UART
    /// adapter does (its latency timer: 1 to 16 ms): a frame is often cut across two bursts.
    #[must_use]
    pub fn with_bursts(mut self, burst_ms: u64) -> Self {
        self.burst_ms = burst_ms.max(1);
        self
    }

    /// The board (to inspect it in a test).
    pub fn board(&self) -> &B {
        &self.board
    }

    /// The board (to inject faults in a test).
    pub fn board_mut(&mut self) -> &mut B {
        &mut self.board
    }

    fn catch_up(&mut self) {
        let now = self.time.get();
        let burst = now.checked_rem(self.burst_ms).unwrap_or(0);
        self.board.advance(now.saturating_sub(burst));
    }
}

impl<B: Simulated> embedded_io::ErrorType for SimUart<'_, B> {
    type Error = core::convert::Infallible;
}

impl<B: Simulated> embedded_io::Read for SimUart<'_, B> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        self.catch_up();
        Ok(self.board.transmit(buf))
    }
}

impl<B: Simulated> embedded_io::ReadReady for SimUart<'_, B> {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        self.catch_up();
        Ok(self.board.byte_arrived())
    }
}

impl<B: Simulated> embedded_io::Write for SimUart<'_, B> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        self.catch_up();
        self.board.receive(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Waits (yields to the executor) until a byte is there, as a real UART's read does.
#[cfg(feature = "async")]
impl<B: Simulated> embedded_io_async::Read for SimUart<'_, B> {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        loop {
            if embedded_io::ReadReady::read_ready(self)? || buf.is_empty() {
                return embedded_io::Read::read(self, buf);
            }
            embassy_futures::yield_now().await;
        }
    }
}

#[cfg(feature = "async")]
impl<B: Simulated> embedded_io_async::Write for SimUart<'_, B> {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        embedded_io::Write::write(self, buf)
    }

    async fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// A simulated delay for the async driver: waiting moves the shared time on, and yields once.
#[cfg(feature = "async")]
#[derive(Clone, Copy, Debug)]
pub struct SimDelay<'t>(pub &'t core::cell::Cell<u64>);

#[cfg(feature = "async")]
impl embedded_hal_async::delay::DelayNs for SimDelay<'_> {
    async fn delay_ns(&mut self, ns: u32) {
        let ms = u64::from(ns.div_ceil(1_000_000));
        self.0.set(self.0.get().saturating_add(ms));
        // A real timer always hands the executor back: so does this one.
        embassy_futures::yield_now().await;
    }
}

/// A simulated clock: every reading moves the shared time on by 1 ms, so a driver that polls
/// makes time pass. Share the cell with a [`SimUart`].
#[derive(Clone, Copy, Debug)]
pub struct SimClock<'t>(pub &'t core::cell::Cell<u64>);

impl crate::driver::Clock for SimClock<'_> {
    fn now_ms(&mut self) -> u64 {
        let now = self.0.get().saturating_add(1);
        self.0.set(now);
        now
    }
}
