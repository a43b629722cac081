//! [`Driver`]: the async shell (feature `async`) over `embedded-io-async` 0.7 `Read + Write`,
//! with an `embedded-hal-async` `DelayNs` to wait for deadlines. No `ReadReady` needed (plain
//! halves work: [`Split`](super::Split) joins an RX and a TX half), and it never busy-polls:
//! [`Driver::poll`] awaits bytes or the core's next deadline, so the executor runs other tasks
//! meanwhile.
//!
//! The UART's `read` must be cancel-safe (bytes stay buffered if the read future is dropped),
//! as embassy's `BufferedUart` and ring-buffered DMA receivers are: `poll` races the read
//! against a timer. The same calls as the blocking driver, `async`; all policy is the
//! [`DriverCore`]'s.
//!
//! Dropping a request's future (a `select` with a timeout) ends the request: the driver is
//! never left busy by it.

use super::{
    Clock, Config, CoreError, DriverCore, Error, Event, Outcome, Readable, Request, RxBuffer,
};
use crate::command::{Action, Motors, Register, Turn, Velocity, Write};
use crate::registers::Snapshot;
use embassy_futures::select::{Either, select};
use embedded_hal_async::delay::DelayNs;
use embedded_io_async::{Read, Write as IoWrite};

/// The longest [`Driver::poll`] waits when nothing is due, in ms: a loop around it still turns.
pub const MAX_WAIT_MS: u64 = 10;

/// Waits in a row that see the clock stand still before a request gives up with
/// [`CoreError::ClockStalled`].
pub const STALL_WAITS: u32 = 10_000;

/// The async driver: owns the UART, the clock and the delay (give them back with
/// [`release`](Driver::release)).
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Driver<U, C, D> {
    uart: U,
    clock: C,
    delay: D,
    core: DriverCore,
    rx: RxBuffer,
}

/// Ends the request in progress if its future is dropped before it finished.
struct Running<'a, U, C, D> {
    driver: &'a mut Driver<U, C, D>,
    done: bool,
}

impl<U, C, D> Drop for Running<'_, U, C, D> {
    fn drop(&mut self) {
        if !self.done {
            self.driver.core.abort();
        }
    }
}

impl<U, C, D> Driver<U, C, D>
where
    U: Read + IoWrite,
    C: Clock,
    D: DelayNs,
{
    /// A driver over `uart`, reading time from `clock`, waiting with `delay`.
    pub fn new(uart: U, clock: C, delay: D, config: Config) -> Self {
        Driver {
            uart,
            clock,
            delay,
            core: DriverCore::new(config),
            rx: RxBuffer::new(),
        }
    }

    /// Gives back the UART, the clock and the delay.
    pub fn release(self) -> (U, C, D) {
        (self.uart, self.clock, self.delay)
    }

    /// The UART (to inspect it; the driver keeps it).
    pub const fn uart(&self) -> &U {
        &self.uart
    }

    /// The sans-IO core.
    pub const fn core(&self) -> &DriverCore {
        &self.core
    }

    /// The sans-IO core, mutably: [`DriverCore::abandon_turn`], [`DriverCore::abort`].
    pub fn core_mut(&mut self) -> &mut DriverCore {
        &mut self.core
    }

    /// Sets the body velocity. Safe to call every period.
    pub async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.velocity(velocity, now);
        self.send(&bytes).await
    }

    /// Drives each motor.
    pub async fn set_motors(&mut self, motors: Motors) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.motors(motors, now);
        self.send(&bytes).await
    }

    /// Stops the chassis, and cancels an outstanding turn (see the blocking driver's `stop`).
    pub async fn stop(&mut self) -> Result<(), Error<U::Error>> {
        let bytes = self.core.stop();
        self.send(&bytes).await?;
        if self.core.busy() {
            self.guarded().await.map(|_| ())
        } else {
            Ok(())
        }
    }

    /// Sends a turn once; see [`crate::driver`] for the guard.
    pub async fn turn(&mut self, turn: Turn) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.turn(turn, now)?;
        self.send(&bytes).await
    }

    /// [`turn`](Driver::turn) by `deci_degrees` (0.1°) standing still.
    pub async fn turn_by(&mut self, deci_degrees: i32) -> Result<(), Error<U::Error>> {
        self.turn(Turn::by_deci_degrees(deci_degrees)).await
    }

    /// Reads the angle still to turn (2D), in 0.1°; (nearly) 0 ends the turn.
    pub async fn turn_remaining(&mut self) -> Result<i32, Error<U::Error>> {
        self.read(super::reg::PendingAngle).await
    }

    /// Reads a register, typed.
    pub async fn read<R: Readable>(&mut self, register: R) -> Result<R::Value, Error<U::Error>> {
        let _ = register;
        let raw = self.value(Request::Read(R::REGISTER)).await?;
        R::from_raw(raw).ok_or(Error::Core(CoreError::Invalid {
            register: R::REGISTER,
            value: raw,
        }))
    }

    /// Reads a register until two replies agree, typed.
    pub async fn read_verified<R: Readable>(
        &mut self,
        register: R,
    ) -> Result<R::Value, Error<U::Error>> {
        let _ = register;
        let raw = self.value(Request::ReadVerified(R::REGISTER)).await?;
        R::from_raw(raw).ok_or(Error::Core(CoreError::Invalid {
            register: R::REGISTER,
            value: raw,
        }))
    }

    /// Reads one register, untyped.
    pub async fn read_raw(&mut self, register: Register) -> Result<u32, Error<U::Error>> {
        self.value(Request::Read(register)).await
    }

    /// Writes one register.
    pub async fn write(&mut self, write: Write) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.write(write, now);
        self.send(&bytes).await
    }

    /// Runs one action.
    pub async fn action(&mut self, action: Action) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.action(action, now);
        self.send(&bytes).await
    }

    /// Reads every register of a [`Snapshot`], each read verified.
    pub async fn read_settings(&mut self) -> Result<Snapshot, Error<U::Error>> {
        match self.run(Request::ReadSettings).await? {
            Outcome::Snapshot(settings) => Ok(settings),
            _ => Ok(Snapshot::default()),
        }
    }

    /// Writes a snapshot back (never starts a calibration).
    pub async fn restore_settings(&mut self, settings: &Snapshot) -> Result<(), Error<U::Error>> {
        self.run(Request::RestoreSettings(*settings))
            .await
            .map(|_| ())
    }

    /// Runs any [`Request`] to its end.
    pub async fn run(&mut self, request: Request) -> Result<Outcome, Error<U::Error>> {
        self.core.start(request)?;
        self.guarded().await
    }

    /// Waits for the next event, at most [`MAX_WAIT_MS`] (or until the core's next deadline,
    /// if sooner); `Ok(None)` if none came. Runs the quiet-line detection, reply timeouts and
    /// the failsafe on the way. Yields while it waits.
    pub async fn poll(&mut self) -> Result<Option<Event>, Error<U::Error>> {
        let result = self.pump().await;
        if result.is_err() {
            self.core.abort();
        }
        result.map(|(event, _)| event)
    }

    async fn value(&mut self, request: Request) -> Result<u32, Error<U::Error>> {
        match self.run(request).await? {
            Outcome::Value(raw) => Ok(raw),
            _ => Ok(0),
        }
    }

    /// Pumps until the request in progress ends; if this future is dropped first, the request
    /// is ended with it.
    async fn guarded(&mut self) -> Result<Outcome, Error<U::Error>> {
        let mut running = Running {
            driver: self,
            done: false,
        };
        let result = running.driver.finish().await;
        running.done = true;
        result
    }

    async fn finish(&mut self) -> Result<Outcome, Error<U::Error>> {
        loop {
            let now = match self.pump().await {
                Ok((_, now)) => now,
                Err(e) => {
                    self.core.abort();
                    return Err(e);
                }
            };
            if let Some(outcome) = self.core.settle(now, self.rx.is_empty(), STALL_WAITS) {
                return outcome.map_err(Error::Core);
            }
        }
    }

    /// One turn of the pump: the event it brought, if any, and the time it ended at.
    async fn pump(&mut self) -> Result<(Option<Event>, u64), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        if let Some(event) = self.rx.drain(&mut self.core, now) {
            return Ok((Some(event), now));
        }
        let wait = self
            .core
            .next_deadline()
            .map_or(MAX_WAIT_MS, |due| due.saturating_sub(now).min(MAX_WAIT_MS));
        let wait = u32::try_from(wait).unwrap_or(u32::MAX);
        let read = match select(self.uart.read(self.rx.space()), self.delay.delay_ms(wait)).await {
            Either::First(read) => Some(read.map_err(Error::Transport)?),
            Either::Second(()) => None,
        };
        let now = self.clock.now_ms();
        if let Some(n) = read {
            self.rx.filled(n);
            if let Some(event) = self.rx.drain(&mut self.core, now) {
                return Ok((Some(event), now));
            }
            if n >= RxBuffer::LEN {
                // The buffer came back full: more is likely waiting. Judge time only once
                // everything buffered is in.
                return Ok((None, now));
            }
        }
        let event = self.core.tick(now);
        self.flush_out(now).await?;
        Ok((event, now))
    }

    async fn flush_out(&mut self, now: u64) -> Result<(), Error<U::Error>> {
        while let Some(frame) = self.core.transmit(now) {
            self.send(frame.as_slice()).await?;
        }
        Ok(())
    }

    async fn send(&mut self, mut bytes: &[u8]) -> Result<(), Error<U::Error>> {
        while !bytes.is_empty() {
            let n = self.uart.write(bytes).await.map_err(Error::Transport)?;
            if n == 0 {
                return Err(Error::WriteZero);
            }
            bytes = bytes.get(n..).unwrap_or(&[]);
        }
        self.uart.flush().await.map_err(Error::Transport)
    }
}
