//! [`Driver`]: the blocking shell over `embedded-io` 0.7 `Read + Write + ReadReady`.
//!
//! It only moves bytes and time between the UART and the [`DriverCore`]: every decision (reply
//! matching, retries, timeouts, the settings sequences, the failsafe, the turn guard) is the
//! core's. A HAL that hands out RX and TX halves is driven through [`Split`](super::Split).
//!
//! ```
//! # #[cfg(feature = "sim")] {
//! use chassis_protocol::driver::{Config, blocking::Driver, reg};
//! use chassis_protocol::sim::{Board, SimClock, SimConfig, SimUart};
//! use chassis_protocol::Velocity;
//! use core::cell::Cell;
//!
//! // The simulated board behind an in-memory UART, with a simulated clock (1 ms a reading).
//! let time = Cell::new(0);
//! let uart = SimUart::new(Board::new(SimConfig::default()), &time);
//! let mut driver = Driver::new(uart, SimClock(&time), Config::DEFAULT);
//! driver.set_velocity(Velocity::new(0, 200, 0))?;
//! let centivolts: u16 = driver.read(reg::MotorVoltage)?; // typed: the register's own type
//! assert_eq!(centivolts, 1_200);
//! # }
//! # Ok::<(), chassis_protocol::driver::Error<core::convert::Infallible>>(())
//! ```

use super::v2020::UserFrame;
use super::{Clock, Config, Core, CoreError, DriverCore, Error, Outcome, Readable, Request, v1};
use crate::command::{Action, Motors, Register, Turn, Velocity, Write};
use crate::registers::Snapshot;
use embedded_io::{Read, ReadReady, Write as IoWrite};

/// Polls in a row that see the clock stand still before a wait gives up with
/// [`CoreError::ClockStalled`], whatever bytes arrive meanwhile (a millisecond clock that never
/// moves would otherwise hang a read). A million polls take far longer than a millisecond on
/// any microcontroller.
pub const STALL_POLLS: u32 = 1_000_000;

/// Reads (of up to 32 bytes each) one poll makes at most before it judges time and returns: a
/// UART that never runs dry cannot keep a call from ending. 128 reads is 4 KiB, more than a
/// second of the board's line.
pub const POLL_READS: u32 = 128;

/// The blocking driver: owns the UART and the clock. Everything it knows (the turn guard, bytes
/// read and not yet parsed, a frame half sent, the latest telemetry) is in its core `K`, which
/// [`release`](Driver::release) gives back with them and [`from_core`](Driver::from_core) takes
/// again.
///
/// `K` is the firmware generation: [`DriverCore`] (the 2020 firmware, the default: made by
/// [`Driver::new`]) or [`v1::DriverCore`] (v1.0.0: [`Driver::new_v1`]). The pump, the
/// failsafe and the cancel-safety are the same code for both; what a generation can do is in
/// its own `impl` block (there is no `turn` on v1.0.0):
///
/// ```
/// use chassis_protocol::driver::{Config, blocking::Driver};
/// use chassis_protocol::v1::BodyVelocity;
/// use embedded_io::{Read, ReadReady, Write};
///
/// fn drive<U: Read + Write + ReadReady>(uart: U) {
///     let mut driver = Driver::new_v1(uart, || 0, Config::DEFAULT);
///     let _ = driver.set_velocity(BodyVelocity::new(0, 300, 0));
/// }
/// ```
///
/// and the same with a turn does not compile:
///
/// ```compile_fail,E0599
/// use chassis_protocol::driver::{Config, blocking::Driver};
/// use embedded_io::{Read, ReadReady, Write};
///
/// fn drive<U: Read + Write + ReadReady>(uart: U) {
///     let mut driver = Driver::new_v1(uart, || 0, Config::DEFAULT);
///     let _ = driver.turn_by(900); // no turn by an angle on v1.0.0
/// }
/// ```
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Driver<U, C, K = DriverCore> {
    uart: U,
    clock: C,
    core: K,
}

impl<U, C> Driver<U, C>
where
    U: Read + IoWrite + ReadReady,
    C: Clock,
{
    /// A driver for the 2020 firmware over `uart`, reading time from `clock`.
    pub fn new(uart: U, clock: C, config: Config) -> Self {
        Self::from_core(uart, clock, DriverCore::new(config))
    }
}

impl<U, C> Driver<U, C, v1::DriverCore>
where
    U: Read + IoWrite + ReadReady,
    C: Clock,
{
    /// A driver for the v1.0.0 firmware over `uart`, reading time from `clock` (the failsafe
    /// at least [`v1::MIN_FAILSAFE_MS`]).
    pub fn new_v1(uart: U, clock: C, config: Config) -> Self {
        Self::from_core(uart, clock, v1::DriverCore::new(config))
    }

    /// Sets the body velocity (`0x25`, SI units × 1000). Safe to call every period.
    pub fn set_velocity(
        &mut self,
        velocity: crate::v1::BodyVelocity,
    ) -> Result<(), Error<U::Error>> {
        self.send(|core, now| core.velocity(velocity, now))
    }

    /// Drives each motor (`0x26`, the board's own unit).
    pub fn set_motors(&mut self, motors: crate::v1::MotorVelocity) -> Result<(), Error<U::Error>> {
        self.send(|core, now| core.motors(motors, now))
    }

    /// One readback: the board's reply ([`CoreError::NoReadback`] after
    /// [`Config::read_tries`] requests unanswered).
    pub fn readback(
        &mut self,
        readback: crate::v1::Readback,
    ) -> Result<crate::v1::Reply, Error<U::Error>> {
        match self.run(v1::Request::Read(readback))? {
            v1::Outcome::Reply(reply) => Ok(reply),
            v1::Outcome::Done => Err(Error::Core(CoreError::NoReadback(readback))),
        }
    }

    /// The system settings (`0x33`).
    pub fn system(&mut self) -> Result<crate::v1::SystemSettings, Error<U::Error>> {
        let reply = self.readback(crate::v1::Readback::System)?;
        reply.system().ok_or(Error::Core(CoreError::NoReadback(
            crate::v1::Readback::System,
        )))
    }

    /// The geometry (`0x34`).
    pub fn geometry(&mut self) -> Result<crate::v1::Geometry, Error<U::Error>> {
        let reply = self.readback(crate::v1::Readback::Geometry)?;
        reply.geometry().ok_or(Error::Core(CoreError::NoReadback(
            crate::v1::Readback::Geometry,
        )))
    }

    /// The PID gains (`0x50`).
    pub fn pid(&mut self) -> Result<crate::v1::Pid, Error<U::Error>> {
        let reply = self.readback(crate::v1::Readback::Pid)?;
        reply
            .pid()
            .ok_or(Error::Core(CoreError::NoReadback(crate::v1::Readback::Pid)))
    }

    /// Writes a settings frame, [`v1::SETTINGS_GAP_MS`] after the previous one, and reads it
    /// back: `Ok` once the board shows what was written.
    pub fn write_settings(&mut self, settings: v1::Settings) -> Result<(), Error<U::Error>> {
        self.run(v1::Request::Write(settings)).map(|_| ())
    }
}

impl<U, C, K> Driver<U, C, K>
where
    U: Read + IoWrite + ReadReady,
    C: Clock,
    K: Core,
{
    /// A driver that goes on from `core` (what [`release`](Driver::release) gave): the turn
    /// guard, bytes already read and a frame half sent carry over.
    pub const fn from_core(uart: U, clock: C, core: K) -> Self {
        Driver { uart, clock, core }
    }

    /// Gives back the UART, the clock and the core. Keep the core and hand it to
    /// [`from_core`](Driver::from_core) to go on: a new core does not know a turn this one
    /// sent.
    #[must_use = "the core holds the turn guard: pass it to Driver::from_core"]
    pub fn release(self) -> (U, C, K) {
        (self.uart, self.clock, self.core)
    }

    super::shell_accessors!();

    /// Stops the chassis (the generation's stop frame: STOP, or v1.0.0's forced stop); on the
    /// 2020 firmware, if a turn is outstanding, cancels it too (reads the angle still pending
    /// and sends the opposite turn) and returns when that is done. A frame a cut write left
    /// half sent is finished first: nothing else can go before it.
    pub fn stop(&mut self) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.core.stop();
        self.flush_out(now)?;
        if self.core.busy_for_user() {
            self.finish().map(|_| ())
        } else {
            Ok(())
        }
    }

    /// Runs any request to its end.
    pub fn run(&mut self, request: K::Request) -> Result<K::Outcome, Error<U::Error>> {
        self.core.start(request)?;
        self.finish()
    }

    /// Takes in what has arrived, without blocking: returns the first event, if any. Once every
    /// byte the UART holds is in (or [`POLL_READS`] reads), it judges time (quiet line, reply
    /// timeouts, the failsafe) and sends what the core has queued (a failsafe stop). Call it
    /// often: every loop, or from the UART interrupt.
    pub fn poll(&mut self) -> Result<Option<K::Event>, Error<U::Error>> {
        let now = self.clock.now_ms();
        let result = self.pump(now);
        if result.is_err() {
            self.core.abort();
        }
        result
    }

    /// Finishes what is to go out, lets `queue` put a frame in the core, and sends it.
    fn send(
        &mut self,
        queue: impl FnOnce(&mut K, u64) -> Result<(), CoreError>,
    ) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now)?;
        queue(&mut self.core, now)?;
        self.flush_out(now)
    }

    /// Pumps until the request in progress ends. Any error ends it (nothing stays busy).
    fn finish(&mut self) -> Result<K::Outcome, Error<U::Error>> {
        loop {
            let now = self.clock.now_ms();
            if let Err(e) = self.pump(now) {
                self.core.abort();
                return Err(e);
            }
            if let Some(outcome) = self.core.settle(now, STALL_POLLS) {
                return outcome.map_err(Error::Core);
            }
        }
    }

    fn pump(&mut self, now: u64) -> Result<Option<K::Event>, Error<U::Error>> {
        self.flush_out(now)?;
        let mut reads = 0;
        loop {
            if let Some(event) = self.core.drain(now) {
                return Ok(Some(event));
            }
            if reads >= POLL_READS || !self.uart.read_ready().map_err(Error::Transport)? {
                break;
            }
            let n = self
                .uart
                .read(self.core.rx_space())
                .map_err(Error::Transport)?;
            self.core.rx_filled(n);
            reads = reads.saturating_add(1);
            if n == 0 {
                break;
            }
        }
        let event = self.core.tick(now);
        self.flush_out(now)?;
        Ok(event)
    }

    /// Writes out everything the core has to send, a frame a cut write left half sent first
    /// (a `write` of 0 is [`Error::WriteZero`], not a panic), and flushes.
    fn flush_out(&mut self, now: u64) -> Result<(), Error<U::Error>> {
        let mut wrote = false;
        while let Some(bytes) = self.core.transmit(now) {
            let n = self.uart.write(bytes).map_err(Error::Transport)?;
            if n == 0 {
                return Err(Error::WriteZero);
            }
            self.core.transmitted(n, now);
            wrote = true;
        }
        if wrote {
            self.uart.flush().map_err(Error::Transport)?;
        }
        Ok(())
    }
}

impl<U, C> Driver<U, C>
where
    U: Read + IoWrite + ReadReady,
    C: Clock,
{
    /// Sets the body velocity (see [`Velocity`] for the drive types). Safe to call every period.
    pub fn set_velocity(&mut self, velocity: Velocity) -> Result<(), Error<U::Error>> {
        self.user_frame(UserFrame::Velocity(velocity))
    }

    /// Drives each motor ([`Motors::closed_loop`] or [`Motors::open_loop_duty`]).
    pub fn set_motors(&mut self, motors: Motors) -> Result<(), Error<U::Error>> {
        self.user_frame(UserFrame::Motors(motors))
    }

    /// Sends a turn, **once**: the turn is consumed, and while one is outstanding a new one is
    /// [`CoreError::TurnInProgress`]. [`turn_remaining`](Driver::turn_remaining) reading (nearly)
    /// 0 ends it; [`stop`](Driver::stop) cancels it. A new driver reads the pending angle first
    /// (an earlier one may have left the board turning).
    pub fn turn(&mut self, turn: Turn) -> Result<(), Error<U::Error>> {
        if self.core.turn_state() == super::TurnState::Unknown {
            self.turn_remaining()?;
        }
        let now = self.clock.now_ms();
        self.flush_out(now)?;
        self.core.turn(turn, now)?;
        self.flush_out(now)
    }

    /// [`turn`](Driver::turn) by `deci_degrees` (0.1°) standing still.
    pub fn turn_by(&mut self, deci_degrees: i32) -> Result<(), Error<U::Error>> {
        self.turn(Turn::by_deci_degrees(deci_degrees))
    }

    /// Reads the angle still to turn (2D), in 0.1°. When it reads (nearly) 0, the turn is over
    /// and a new one may be sent.
    pub fn turn_remaining(&mut self) -> Result<i32, Error<U::Error>> {
        self.read(super::reg::PendingAngle)
    }

    /// Reads a register, typed (`driver.read(reg::MaxSpeed)` is a `u16`): one read, one reply.
    /// A reply whose value cannot be the register's is [`CoreError::Invalid`].
    pub fn read<R: Readable>(&mut self, register: R) -> Result<R::Value, Error<U::Error>> {
        let _ = register;
        let raw = self.read_raw(R::REGISTER)?;
        R::from_raw(raw).ok_or(Error::Core(CoreError::Invalid {
            register: R::REGISTER,
            value: raw,
        }))
    }

    /// Reads a register until two replies agree ([`Request::ReadVerified`]), typed.
    pub fn read_verified<R: Readable>(&mut self, register: R) -> Result<R::Value, Error<U::Error>> {
        let _ = register;
        let raw = self.value(Request::ReadVerified(R::REGISTER))?;
        R::from_raw(raw).ok_or(Error::Core(CoreError::Invalid {
            register: R::REGISTER,
            value: raw,
        }))
    }

    /// Reads one register, untyped: its raw `u32`.
    pub fn read_raw(&mut self, register: Register) -> Result<u32, Error<U::Error>> {
        self.value(Request::Read(register))
    }

    /// Writes one register (2B). The board does not answer writes.
    pub fn write(&mut self, write: Write) -> Result<(), Error<U::Error>> {
        self.user_frame(UserFrame::Write(write))
    }

    /// Runs one action (2A).
    pub fn action(&mut self, action: Action) -> Result<(), Error<U::Error>> {
        self.user_frame(UserFrame::Action(action))
    }

    /// Reads every register of a [`Snapshot`], each read verified.
    pub fn read_settings(&mut self) -> Result<Snapshot, Error<U::Error>> {
        match self.run(Request::ReadSettings)? {
            Outcome::Snapshot(settings) => Ok(settings),
            _ => Ok(Snapshot::default()),
        }
    }

    /// Writes a snapshot back ([`Request::RestoreSettings`]: never starts a calibration).
    pub fn restore_settings(&mut self, settings: &Snapshot) -> Result<(), Error<U::Error>> {
        self.run(Request::RestoreSettings(*settings)).map(|_| ())
    }

    /// Finishes what is to go out, then sends `frame`.
    // Out of line: one body for the four calls that send a frame without a request.
    #[inline(never)]
    fn user_frame(&mut self, frame: UserFrame) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        self.flush_out(now)?;
        self.core.user_frame(frame, now)?;
        self.flush_out(now)
    }

    fn value(&mut self, request: Request) -> Result<u32, Error<U::Error>> {
        match self.run(request)? {
            Outcome::Value(raw) => Ok(raw),
            _ => Ok(0),
        }
    }
}
