//! [`Driver`]: the blocking shell over `embedded-io` 0.7 `Read + Write + ReadReady`.
//!
//! ```
//! # #[cfg(feature = "sim")] {
//! use chassis_protocol::driver::{Config, blocking::Driver};
//! use chassis_protocol::sim::{Board, SimClock, SimConfig, SimUart};
//! use chassis_protocol::{Register, Velocity};
//! use core::cell::Cell;
//!
//! // The simulated board behind an in-memory UART, with a simulated clock (1 ms a reading).
//! let time = Cell::new(0);
//! let uart = SimUart::new(Board::new(SimConfig::default()), &time);
//! let mut driver = Driver::new(uart, SimClock(&time), Config::DEFAULT);
//! driver.set_velocity(Velocity::new(0, 200, 0))?;
//! let voltage = driver.read_register(Register::MotorVoltage)?;
//! assert_eq!(voltage.value, 1_200);
//! # }
//! # Ok::<(), chassis_protocol::driver::Error<core::convert::Infallible>>(())
//! ```

use super::{Clock, Config, DriverCore, Error, Event, RxBuffer};
use crate::command::{Action, Motors, Register, Setting, Velocity, Write};
use crate::registers::Settings;
use crate::telemetry::Reply;
use embedded_io::{Read, ReadReady, Write as IoWrite};

/// The blocking driver: owns the UART and the clock (give them back with
/// [`release`](Driver::release)); bytes read but not yet parsed are kept between calls.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Driver<U, C> {
    uart: U,
    clock: C,
    core: DriverCore,
    rx: RxBuffer,
}

// RAM of the driver itself, without the UART, clock (and delay) it owns: 400 bytes on ARM.
#[cfg(target_arch = "arm")]
const _: () = assert!(core::mem::size_of::<Driver<(), ()>>() == 400);

impl<U, C> Driver<U, C>
where
    U: Read + IoWrite + ReadReady,
    C: Clock,
{
    /// A driver over `uart`, reading time from `clock`.
    pub fn new(uart: U, clock: C, config: Config) -> Self {
        Driver {
            uart,
            clock,
            core: DriverCore::new(config),
            rx: RxBuffer::new(),
        }
    }

    /// Gives back the UART and the clock.
    pub fn release(self) -> (U, C) {
        (self.uart, self.clock)
    }

    /// The UART (to inspect it; the driver keeps it).
    pub const fn uart(&self) -> &U {
        &self.uart
    }

    /// The UART, mutably (for a test double's controls; do not read from or write to it behind
    /// the driver's back).
    pub fn uart_mut(&mut self) -> &mut U {
        &mut self.uart
    }

    /// The sans-IO core: latest telemetry, stream rates, parser counters, link state.
    pub const fn core(&self) -> &DriverCore {
        &self.core
    }

    /// Sets the body velocity (see [`Velocity`] for the drive types). Safe to call every period.
    pub fn set_velocity(&mut self, velocity: Velocity) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.velocity(velocity, now);
        self.send(&bytes)
    }

    /// Drives each motor ([`Motors::closed_loop`] or [`Motors::open_loop_duty`]).
    pub fn set_motors(&mut self, motors: Motors) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.motors(motors, now);
        self.send(&bytes)
    }

    /// Stops the chassis.
    pub fn stop(&mut self) -> Result<(), Error<U::Error>> {
        let bytes = self.core.stop();
        self.send(&bytes)
    }

    /// Turns by `deci_degrees` (0.1°) **once**. While the turn is outstanding a new one is
    /// [`Error::TurnInProgress`]; [`turn_remaining`](Driver::turn_remaining) reading 0 ends it.
    pub fn turn_by(&mut self, deci_degrees: i32) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.turn(deci_degrees, now)?;
        self.send(&bytes)
    }

    /// Reads the angle still to turn (2D), in 0.1°. When it reads 0, the turn is over and a
    /// new one may be sent.
    pub fn turn_remaining(&mut self) -> Result<i32, Error<U::Error>> {
        let reply = self.read_register(Register::PendingAngle)?;
        Ok(reply.pending_deci_degrees().unwrap_or(0))
    }

    /// Reads one register: sends the read, then waits for its reply (telemetry that comes
    /// meanwhile is taken in, never flushed).
    pub fn read_register(&mut self, register: Register) -> Result<Reply, Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.setting(Setting::Read(register), now)?;
        self.send(&bytes)?;
        loop {
            match self.poll()? {
                Some(Event::Reply(reply)) => return Ok(reply),
                Some(Event::StrayReply(reply)) => {
                    // Give the read up: the caller hears of the wrong reply.
                    self.core.cancel_read();
                    return Err(Error::WrongReply {
                        expected: register,
                        got: reply.code,
                    });
                }
                _ => {}
            }
            let now = self.clock.now_ms();
            if let Some(register) = self.core.reply_timed_out(now) {
                return Err(Error::Timeout(register));
            }
        }
    }

    /// Reads a register until two replies agree (at most three reads). There is no checksum: a
    /// byte changed on the line changes a reply's value unseen, so settings that matter are
    /// worth reading this way. Two disagreeing replies and a third that matches neither is
    /// [`Error::Unconfirmed`].
    pub fn read_register_verified(&mut self, register: Register) -> Result<Reply, Error<U::Error>> {
        let mut first = None;
        let mut second = None;
        for _ in 0..3 {
            let reply = match self.read_register(register) {
                Ok(reply) => reply,
                // A reply lost or garbled on the line: try again.
                Err(Error::Timeout(_) | Error::WrongReply { .. }) => continue,
                Err(e) => return Err(e),
            };
            if first == Some(reply) || second == Some(reply) {
                return Ok(reply);
            }
            second = first;
            first = Some(reply);
        }
        Err(Error::Unconfirmed(register))
    }

    /// Writes one register (2B). The board does not answer writes.
    pub fn write(&mut self, write: Write) -> Result<(), Error<U::Error>> {
        self.setting(Setting::Write(write))
    }

    /// Runs one action (2A).
    pub fn action(&mut self, action: Action) -> Result<(), Error<U::Error>> {
        self.setting(Setting::Action(action))
    }

    /// Reads every register of a [`Settings`] snapshot.
    pub fn read_settings(&mut self) -> Result<Settings, Error<U::Error>> {
        let mut settings = Settings::default();
        for register in Settings::REGISTERS {
            let reply = self.read_register(register)?;
            settings.apply(&reply);
        }
        Ok(settings)
    }

    /// Writes a snapshot back (all but the gyro calibration value, see [`Settings::writes`]).
    pub fn restore_settings(&mut self, settings: &Settings) -> Result<(), Error<U::Error>> {
        for write in settings.writes() {
            self.write(write)?;
        }
        Ok(())
    }

    /// Takes in what has arrived, without blocking: returns the first event, if any. Also runs
    /// the failsafe (sends stop if telemetry went silent while moving) and tells the parser
    /// when the line has gone quiet. Call it often: every loop, or from the UART interrupt.
    pub fn poll(&mut self) -> Result<Option<Event>, Error<U::Error>> {
        let now = self.clock.now_ms();
        if let Some(stop) = self.core.failsafe(now) {
            self.send(&stop)?;
        }
        loop {
            if let Some(event) = self.rx.drain(&mut self.core, now) {
                return Ok(Some(event));
            }
            if !self.uart.read_ready()? {
                return Ok(self.core.quiet(now));
            }
            let n = self.uart.read(self.rx.space())?;
            self.rx.filled(n);
            if n == 0 {
                return Ok(None);
            }
        }
    }

    fn setting(&mut self, setting: Setting) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.setting(setting, now)?;
        self.send(&bytes)
    }

    /// Writes all of `bytes` (a `write` of 0 is [`Error::WriteZero`], not a panic) and flushes.
    fn send(&mut self, mut bytes: &[u8]) -> Result<(), Error<U::Error>> {
        while !bytes.is_empty() {
            let n = self.uart.write(bytes)?;
            if n == 0 {
                return Err(Error::WriteZero);
            }
            bytes = bytes.get(n..).unwrap_or(&[]);
        }
        self.uart.flush()?;
        Ok(())
    }
}
