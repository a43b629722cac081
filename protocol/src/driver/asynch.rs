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
//! # Cancellation
//!
//! Every method is **cancel-safe** in this sense: dropping its future at any `.await` (a
//! `select` with a timeout) never puts anything but whole frames on the wire, never leaves the
//! driver busy, and never sends a turn twice or loses one. What happened of the call is then:
//!
//! | method | dropped before its frame is queued | dropped after |
//! |---|---|---|
//! | `set_velocity`, `set_motors`, `write`, `action`, `turn` | nothing of it is sent | its frame is sent whole: what the UART did not take yet goes out at the start of the next call (any call, `poll` included) |
//! | `stop` | the stop is queued at once: it goes out at the start of the next call | as before; a turn's cancel, if one started, ends with the future (the failsafe starts it again if the link dies) |
//! | `read`, `read_verified`, `read_raw`, `turn_remaining`, `read_settings`, `restore_settings`, `run` | — | the request ends; a read already sent leaves its reply to come as a stray one, and the next read of that register waits for it (or for [`Config::late_reply_ms`](super::Config::late_reply_ms)); frames of a restore already sent stay sent |
//! | `poll` | — | bytes read stay in the core; nothing is lost |
//!
//! The UART's `write` must take no byte when its future is dropped before it completes, as
//! embassy's `BufferedUart` (and any write that copies into a buffer on its first poll) does.

use super::{Clock, Config, Core, CoreError, DriverCore, Error, Outcome, Readable, Request, v1};
use crate::command::{Action, Motors, Register, Turn, Velocity, Write};
use crate::registers::Snapshot;
use embassy_futures::select::{Either, select};
use embedded_hal_async::delay::DelayNs;
use embedded_io_async::{Read, Write as IoWrite};

/// The longest [`Driver::poll`] waits when nothing is due, in ms: a loop around it still turns.
pub const MAX_WAIT_MS: u64 = 10;

/// Turns of the pump in a row that see the clock stand still, whatever bytes arrive meanwhile,
/// before a request gives up with [`CoreError::ClockStalled`].
pub const STALL_WAITS: u32 = 10_000;

/// The async driver: owns the UART, the clock and the delay. Everything it knows is in its core
/// `K` ([`release`](Driver::release) gives it back, [`from_core`](Driver::from_core) takes it
/// again): [`DriverCore`] for the 2020 firmware ([`Driver::new`]), [`v1::DriverCore`] for
/// v1.0.0 ([`Driver::new_v1`]), one pump and one cancellation policy for both.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Driver<U, C, D, K = DriverCore> {
    uart: U,
    clock: C,
    delay: D,
    core: K,
}

/// Ends the request in progress if its future is dropped before it finished.
struct Running<'a, U, C, D, K: Core> {
    driver: &'a mut Driver<U, C, D, K>,
    done: bool,
}

impl<U, C, D, K: Core> Drop for Running<'_, U, C, D, K> {
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
        Self::from_core(uart, clock, delay, DriverCore::new(config))
    }

    /// Sets the body velocity. Safe to call every period.
    pub async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        self.core.velocity(velocity, now)?;
        self.flush_out(now).await
    }

    /// Drives each motor.
    pub async fn set_motors(&mut self, motors: Motors) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        self.core.motors(motors, now)?;
        self.flush_out(now).await
    }

    /// Sends a turn once; see [`crate::driver`] for the guard. A new driver reads the pending
    /// angle first.
    pub async fn turn(&mut self, turn: Turn) -> Result<(), Error<U::Error>> {
        if self.core.turn_state() == super::TurnState::Unknown {
            self.turn_remaining().await?;
        }
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        self.core.turn(turn, now)?;
        self.flush_out(now).await
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
        self.flush_out(now).await?;
        self.core.write(write, now)?;
        self.flush_out(now).await
    }

    /// Runs one action.
    pub async fn action(&mut self, action: Action) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        self.core.action(action, now)?;
        self.flush_out(now).await
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

    async fn value(&mut self, request: Request) -> Result<u32, Error<U::Error>> {
        match self.run(request).await? {
            Outcome::Value(raw) => Ok(raw),
            _ => Ok(0),
        }
    }
}

impl<U, C, D> Driver<U, C, D, v1::DriverCore>
where
    U: Read + IoWrite,
    C: Clock,
    D: DelayNs,
{
    /// A driver for the v1.0.0 firmware (the failsafe at least [`v1::MIN_FAILSAFE_MS`]).
    pub fn new_v1(uart: U, clock: C, delay: D, config: Config) -> Self {
        Self::from_core(uart, clock, delay, v1::DriverCore::new(config))
    }

    /// Sets the body velocity (`0x25`, SI units × 1000). Safe to call every period.
    pub async fn set_velocity(
        &mut self,
        velocity: crate::v1::BodyVelocity,
    ) -> Result<(), Error<U::Error>> {
        self.send(|core, now| core.velocity(velocity, now)).await
    }

    /// Drives each motor (`0x26`, the board's own unit).
    pub async fn set_motors(
        &mut self,
        motors: crate::v1::MotorVelocity,
    ) -> Result<(), Error<U::Error>> {
        self.send(|core, now| core.motors(motors, now)).await
    }

    /// One readback: the board's reply.
    pub async fn readback(
        &mut self,
        readback: crate::v1::Readback,
    ) -> Result<crate::v1::Reply, Error<U::Error>> {
        match self.run(v1::Request::Read(readback)).await? {
            v1::Outcome::Reply(reply) => Ok(reply),
            v1::Outcome::Done => Err(Error::Core(CoreError::NoReadback(readback))),
        }
    }

    /// Writes a settings frame ([`v1::SETTINGS_GAP_MS`] after the previous one) and reads it
    /// back: `Ok` once the board shows what was written.
    pub async fn write_settings(&mut self, settings: v1::Settings) -> Result<(), Error<U::Error>> {
        self.run(v1::Request::Write(settings)).await.map(|_| ())
    }
}

impl<U, C, D, K> Driver<U, C, D, K>
where
    U: Read + IoWrite,
    C: Clock,
    D: DelayNs,
    K: Core,
{
    /// A driver that goes on from `core` (what [`release`](Driver::release) gave).
    pub const fn from_core(uart: U, clock: C, delay: D, core: K) -> Self {
        Driver {
            uart,
            clock,
            delay,
            core,
        }
    }

    /// Gives back the UART, the clock, the delay and the core (keep it for
    /// [`from_core`](Driver::from_core): it holds the turn guard and a frame half sent).
    #[must_use = "the core holds the turn guard: pass it to Driver::from_core"]
    pub fn release(self) -> (U, C, D, K) {
        (self.uart, self.clock, self.delay, self.core)
    }

    super::shell_accessors!();

    /// Stops the chassis (the generation's stop frame) and, on the 2020 firmware, cancels an
    /// outstanding turn (see the blocking driver's `stop`).
    pub async fn stop(&mut self) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.core.stop();
        self.flush_out(now).await?;
        if self.core.busy_for_user() {
            self.guarded().await.map(|_| ())
        } else {
            Ok(())
        }
    }

    /// Runs any request to its end.
    pub async fn run(&mut self, request: K::Request) -> Result<K::Outcome, Error<U::Error>> {
        self.core.start(request)?;
        self.guarded().await
    }

    /// Waits for the next event, at most [`MAX_WAIT_MS`] (or until the core's next deadline,
    /// if sooner); `Ok(None)` if none came. Runs the quiet-line detection, reply timeouts and
    /// the failsafe on the way. Yields while it waits.
    pub async fn poll(&mut self) -> Result<Option<K::Event>, Error<U::Error>> {
        let result = self.pump().await;
        if result.is_err() {
            self.core.abort();
        }
        result.map(|(event, _)| event)
    }

    /// Finishes what is to go out, lets `queue` put a frame in the core, and sends it.
    async fn send(
        &mut self,
        queue: impl FnOnce(&mut K, u64) -> Result<(), CoreError>,
    ) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        queue(&mut self.core, now)?;
        self.flush_out(now).await
    }

    /// Pumps until the request in progress ends; if this future is dropped first, the request
    /// is ended with it.
    async fn guarded(&mut self) -> Result<K::Outcome, Error<U::Error>> {
        let mut running = Running {
            driver: self,
            done: false,
        };
        let result = running.driver.finish().await;
        running.done = true;
        result
    }

    async fn finish(&mut self) -> Result<K::Outcome, Error<U::Error>> {
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

    /// One turn of the pump: the event it brought, if any, and the time it ended at.
    async fn pump(&mut self) -> Result<(Option<K::Event>, u64), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now).await?;
        if let Some(event) = self.core.drain(now) {
            return Ok((Some(event), now));
        }
        let wait = self
            .core
            .wait_ms(now)
            .map_or(MAX_WAIT_MS, |w| w.min(MAX_WAIT_MS));
        let wait = u32::try_from(wait).unwrap_or(u32::MAX);
        let read = match select(
            self.uart.read(self.core.rx_space()),
            self.delay.delay_ms(wait),
        )
        .await
        {
            Either::First(read) => Some(read.map_err(Error::Transport)?),
            Either::Second(()) => None,
        };
        let now = self.clock.now_ms();
        if let Some(n) = read {
            self.core.rx_filled(n);
            if let Some(event) = self.core.drain(now) {
                return Ok((Some(event), now));
            }
            if n >= self.core.rx_space().len() {
                // The buffer came back full: more is likely waiting. Judge time only once
                // everything buffered is in.
                return Ok((None, now));
            }
        }
        let event = self.core.tick(now);
        self.flush_out(now).await?;
        Ok((event, now))
    }

    /// Writes out everything the core has to send, a frame a cut write left half sent first.
    /// Dropped at its `.await`, the bytes the UART has not taken stay in the core.
    async fn flush_out(&mut self, now: u64) -> Result<(), Error<U::Error>> {
        let mut wrote = false;
        while let Some(bytes) = self.core.transmit(now) {
            let n = self.uart.write(bytes).await.map_err(Error::Transport)?;
            if n == 0 {
                return Err(Error::WriteZero);
            }
            self.core.transmitted(n, now);
            wrote = true;
        }
        if wrote {
            self.uart.flush().await.map_err(Error::Transport)?;
        }
        Ok(())
    }
}
