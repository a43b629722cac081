//! The bring-up on an STM32F411 (Nucleo-F411RE, Black Pill) with embassy, its UART read the way
//! firmware with DMA reads one: USART1 (PA9 TX, PA10 RX, 115 200 8N1) receives into a circular
//! DMA buffer (`RingBufferedUartRx`, DMA2 stream 2) that the CPU never touches byte by byte,
//! and the bytes go to the driver's sans-IO core a slice at a time (`DriverCore::receive`: the
//! parser's slice path, 3.5× faster than its byte path in the peer benchmark). The same
//! bring-up as every board (`chassis_bringup::v2020::bring_up`), over [`DmaLink`], a `Link`
//! written here on the core.
//!
//! # Why the core, not a shell
//!
//! The async shell would take this receiver: `RingBufferedUartRx::read` is cancel-safe (in
//! embassy-stm32 0.6 it copies out of the ring synchronously and only awaits the DMA's
//! half/full or the line's idle interrupt, so a dropped read leaves every byte in the ring), and
//! the shell feeds the core's slice path too. Driving the core directly is what the driver's
//! docs describe for DMA ("Feeding the core from an interrupt or a DMA buffer"), and it lets this
//! loop do two things a shell cannot:
//!
//! - **A line error is not a failed check.** embassy stops the ring on a framing, noise or
//!   overrun error and hands the error to the read; a shell would return it and the bring-up
//!   would fail the check it was in. Here it is counted and logged, the next read restarts the
//!   ring, and the parser resynchronises on the next frame (lost bytes are its daily bread); a
//!   line that stays broken is still caught by the failsafe, which sees no frames.
//! - **No frame can be cut.** Frames go out with `blocking_write` (at most 11 bytes: under 1 ms
//!   at 115 200 bps), with no `.await` inside a frame, so a dropped future can never leave half
//!   a frame on the wire for the board's parser to complete with the next one; a DMA write cut
//!   by a dropped future would. (The shells get the same guarantee from a buffered UART's write,
//!   which copies on its first poll.)
//!
//! Everything else is the async shell's pump, line for line in spirit: flush what the core has
//! to send, feed what was read, wait for bytes or the core's next deadline (at most
//! [`MAX_WAIT_MS`]), judge time only once the ring is drained, and end a request whose future
//! was dropped.
//!
//! Reception latency: without `eager_reads`, a read returns at the line's idle interrupt (after
//! each burst of telemetry) or at the ring's half/full mark, whichever comes first: within a
//! frame's time of its last byte at this board's rates.

#![no_std]
#![no_main]

use chassis_bringup::LinkError;
use chassis_bringup::link::Common;
use chassis_bringup::v2020::{Link, Plan, bring_up_and_park};
use chassis_protocol::driver::asynch::{MAX_WAIT_MS, STALL_WAITS};
use chassis_protocol::driver::{
    Config, CoreError, DriverCore, Error, Event, Outcome, Readable, Request, TurnState, reg,
};
use chassis_protocol::{Register, Snapshot, Turn, Velocity, Write};
use embassy_executor::Spawner;
use embassy_stm32::mode::Async;
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use embassy_stm32::{bind_interrupts, dma, peripherals};
use embassy_time::{Duration, Instant, with_timeout};
use embedded_io::Error as _;
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    USART1 => usart::InterruptHandler<peripherals::USART1>;
    DMA2_STREAM2 => dma::InterruptHandler<peripherals::DMA2_CH2>;
    DMA2_STREAM7 => dma::InterruptHandler<peripherals::DMA2_CH7>;
});

/// The DMA ring: 512 bytes are 290 ms of telemetry (1 782 B/s), 44 ms of a saturated line,
/// far longer than the loop ever leaves it unread.
const RING: usize = 512;

/// What one read takes out of the ring and hands the core as one slice.
const CHUNK: usize = 64;

/// The driver's clock: embassy-time, in ms.
fn now_ms() -> u64 {
    Instant::now().as_millis()
}

/// A UART error as the bring-up's transport error.
fn transport(e: usart::Error) -> LinkError {
    Error::Transport(e.kind())
}

/// The bring-up's [`Link`] on the sans-IO [`DriverCore`]: bytes from the DMA ring in, frames
/// out by blocking writes.
pub struct DmaLink<'d> {
    core: DriverCore,
    rx: RingBufferedUartRx<'d>,
    tx: UartTx<'d, Async>,
    /// `chunk[start..end]`: read from the ring, not yet through the parser (the rest of a read
    /// that completed an event).
    chunk: [u8; CHUNK],
    start: usize,
    end: usize,
    /// Framing, noise and overrun errors seen (each restarted the ring).
    line_errors: u32,
}

/// Ends the request in progress if the future that runs it is dropped first.
struct Running<'a, 'd> {
    link: &'a mut DmaLink<'d>,
    done: bool,
}

impl Drop for Running<'_, '_> {
    fn drop(&mut self) {
        if !self.done {
            self.link.core.abort();
        }
    }
}

impl<'d> DmaLink<'d> {
    /// A link over a started ring-buffered receiver and the UART's transmitter.
    pub fn new(rx: RingBufferedUartRx<'d>, tx: UartTx<'d, Async>, config: Config) -> Self {
        DmaLink {
            core: DriverCore::new(config),
            rx,
            tx,
            chunk: [0; CHUNK],
            start: 0,
            end: 0,
            line_errors: 0,
        }
    }

    /// Line errors seen so far.
    pub const fn line_errors(&self) -> u32 {
        self.line_errors
    }

    /// Writes out everything the core has to send, whole frames, without an `.await`.
    fn flush_out(&mut self, now: u64) -> Result<(), LinkError> {
        let mut wrote = false;
        while let Some(bytes) = self.core.transmit(now) {
            let n = bytes.len();
            self.tx.blocking_write(bytes).map_err(transport)?;
            self.core.transmitted(n, now);
            wrote = true;
        }
        if wrote {
            // The reply timeout of a read counts from its last byte on the wire.
            self.tx.blocking_flush().map_err(transport)?;
        }
        Ok(())
    }

    /// The slice path: what is left of the last read, to the core in one call. The core takes
    /// it all unless a frame completes an event; the rest waits for the next call.
    fn feed(&mut self, now: u64) -> Option<Event> {
        if self.start >= self.end {
            return None;
        }
        let (event, rest) = self.core.receive(&self.chunk[self.start..self.end], now);
        self.start = self.end - rest.len();
        event
    }

    /// One turn of the pump: the event it brought, if any, and the time it ended at.
    async fn pump(&mut self) -> Result<(Option<Event>, u64), LinkError> {
        let now = now_ms();
        self.flush_out(now)?;
        if let Some(event) = self.feed(now) {
            return Ok((Some(event), now));
        }
        let wait = self
            .core
            .wait_ms(now)
            .map_or(MAX_WAIT_MS, |w| w.min(MAX_WAIT_MS));
        let read = with_timeout(Duration::from_millis(wait), self.rx.read(&mut self.chunk)).await;
        let now = now_ms();
        match read {
            Ok(Ok(n)) => {
                self.start = 0;
                self.end = n;
                if let Some(event) = self.feed(now) {
                    return Ok((Some(event), now));
                }
                if n == CHUNK {
                    // More is likely waiting in the ring: judge time only once it is all in.
                    return Ok((None, now));
                }
            }
            Ok(Err(e)) => {
                self.line_errors = self.line_errors.saturating_add(1);
                defmt::warn!(
                    "USART1: {} ({} line errors; the ring restarts)",
                    e,
                    self.line_errors
                );
            }
            Err(_) => {} // Nothing came before the core's next deadline.
        }
        let event = self.core.tick(now);
        self.flush_out(now)?;
        Ok((event, now))
    }

    /// Pumps until the request in progress ends.
    async fn finish(&mut self) -> Result<Outcome, LinkError> {
        loop {
            let now = match self.pump().await {
                Ok((_, now)) => now,
                Err(e) => {
                    self.core.abort();
                    return Err(e);
                }
            };
            if let Some(outcome) = self.core.settle(now, STALL_WAITS) {
                return outcome.map_err(Error::Core);
            }
        }
    }

    /// [`finish`](Self::finish), ending the request if this future is dropped first.
    async fn guarded(&mut self) -> Result<Outcome, LinkError> {
        let mut running = Running {
            link: self,
            done: false,
        };
        let result = running.link.finish().await;
        running.done = true;
        result
    }

    /// Runs a request to its end.
    async fn run(&mut self, request: Request) -> Result<Outcome, LinkError> {
        self.core.start(request)?;
        self.guarded().await
    }

    /// Finishes what is to go out, lets `queue` put a frame in the core, and sends it.
    fn send(
        &mut self,
        queue: impl FnOnce(&mut DriverCore, u64) -> Result<(), CoreError>,
    ) -> Result<(), LinkError> {
        let now = now_ms();
        self.flush_out(now)?;
        queue(&mut self.core, now)?;
        self.flush_out(now)
    }
}

impl Common for DmaLink<'_> {
    type Core = DriverCore;
    type Event = Event;
    fn now_ms(&mut self) -> u64 {
        now_ms()
    }
    fn core(&self) -> &DriverCore {
        &self.core
    }
    async fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        let result = self.pump().await;
        if result.is_err() {
            self.core.abort();
        }
        result.map(|(event, _)| event)
    }
    async fn stop(&mut self) -> Result<(), LinkError> {
        self.core.stop();
        self.flush_out(now_ms())?;
        if self.core.busy_for_user() {
            // Cancelling a turn: read the pending angle, send the opposite.
            self.guarded().await.map(|_| ())
        } else {
            Ok(())
        }
    }
}

impl Link for DmaLink<'_> {
    async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.send(|core, now| core.velocity(velocity, now))
    }
    async fn turn(&mut self, turn: Turn) -> Result<(), LinkError> {
        if self.core.turn_state() == TurnState::Unknown {
            // A turn an earlier program left pending would add up with this one.
            self.turn_remaining().await?;
        }
        self.send(|core, now| core.turn(turn, now))
    }
    async fn turn_remaining(&mut self) -> Result<i32, LinkError> {
        let register = Register::PendingAngle;
        match self.run(Request::Read(register)).await? {
            Outcome::Value(raw) => {
                reg::PendingAngle::from_raw(raw).ok_or(Error::Core(CoreError::Invalid {
                    register,
                    value: raw,
                }))
            }
            _ => Err(Error::Core(CoreError::Unconfirmed(register))),
        }
    }
    async fn read_settings(&mut self) -> Result<Snapshot, LinkError> {
        match self.run(Request::ReadSettings).await? {
            Outcome::Snapshot(settings) => Ok(settings),
            _ => Ok(Snapshot::default()),
        }
    }
    async fn read_verified(&mut self, register: Register) -> Result<u32, LinkError> {
        match self.run(Request::ReadVerified(register)).await? {
            Outcome::Value(raw) => Ok(raw),
            _ => Err(Error::Core(CoreError::Unconfirmed(register))),
        }
    }
    async fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.send(|core, now| core.write(write, now))
    }
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(Default::default());
    let mut config = usart::Config::default();
    config.baudrate = 115_200;
    // USART1's DMA requests on the F411: TX on DMA2 stream 7, RX on DMA2 stream 2 (channel 4).
    let uart = match Uart::new(
        p.USART1, p.PA10, p.PA9, p.DMA2_CH7, p.DMA2_CH2, Irqs, config,
    ) {
        Ok(uart) => uart,
        Err(e) => {
            defmt::error!("USART1 configuration refused: {}", e);
            return;
        }
    };
    let (tx, rx) = uart.split();
    let mut ring = [0u8; RING];
    let mut rx = rx.into_ring_buffered(&mut ring);
    // Receive from now on: the DMA fills the ring while the rest starts.
    rx.start_uart();
    defmt::info!(
        "chassis bring-up: STM32F411, USART1 at 115200 bps into a {}-byte DMA ring, the driver core fed slices",
        RING
    );
    let mut link = DmaLink::new(rx, tx, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT).await;
}
