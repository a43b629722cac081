//! [`Driver`]: the async shell (feature `async`) over `embedded-io-async` 0.7
//! `Read + Write + ReadReady` (embassy-stm32, embassy-rp), with an `embedded-hal-async`
//! `DelayNs` to wait between polls. The same calls as the blocking driver, `async`.

use super::{Clock, Config, DriverCore, Error, Event, RxBuffer};
use crate::command::{Action, Motors, Register, Setting, Velocity, Write};
use crate::registers::Settings;
use crate::telemetry::Reply;
use embedded_hal_async::delay::DelayNs;
use embedded_io_async::{Read, ReadReady, Write as IoWrite};

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

// RAM of the driver itself, without the UART, clock (and delay) it owns: 400 bytes on ARM.
#[cfg(target_arch = "arm")]
const _: () = assert!(core::mem::size_of::<Driver<(), (), ()>>() == 400);

impl<U, C, D> Driver<U, C, D>
where
    U: Read + IoWrite + ReadReady,
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

    /// Stops the chassis.
    pub async fn stop(&mut self) -> Result<(), Error<U::Error>> {
        let bytes = self.core.stop();
        self.send(&bytes).await
    }

    /// Turns by `deci_degrees` (0.1°) once; see [`crate::driver`] for the guard.
    pub async fn turn_by(&mut self, deci_degrees: i32) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.turn(deci_degrees, now)?;
        self.send(&bytes).await
    }

    /// Reads the angle still to turn (2D), in 0.1°; 0 ends the turn.
    pub async fn turn_remaining(&mut self) -> Result<i32, Error<U::Error>> {
        let reply = self.read_register(Register::PendingAngle).await?;
        Ok(reply.pending_deci_degrees().unwrap_or(0))
    }

    /// Reads one register and waits for its reply.
    pub async fn read_register(&mut self, register: Register) -> Result<Reply, Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.setting(Setting::Read(register), now)?;
        self.send(&bytes).await?;
        loop {
            match self.poll().await? {
                Some(Event::Reply(reply)) => return Ok(reply),
                Some(Event::StrayReply(reply)) => {
                    self.core.cancel_read();
                    return Err(Error::WrongReply {
                        expected: register,
                        got: reply.code,
                    });
                }
                Some(Event::Telemetry(_)) => continue,
                None => self.delay.delay_ms(1).await,
            }
            let now = self.clock.now_ms();
            if let Some(register) = self.core.reply_timed_out(now) {
                return Err(Error::Timeout(register));
            }
        }
    }

    /// Writes one register.
    pub async fn write(&mut self, write: Write) -> Result<(), Error<U::Error>> {
        self.setting(Setting::Write(write)).await
    }

    /// Runs one action.
    pub async fn action(&mut self, action: Action) -> Result<(), Error<U::Error>> {
        self.setting(Setting::Action(action)).await
    }

    /// Reads every register of a [`Settings`] snapshot.
    pub async fn read_settings(&mut self) -> Result<Settings, Error<U::Error>> {
        let mut settings = Settings::default();
        for register in Settings::REGISTERS {
            let reply = self.read_register(register).await?;
            settings.apply(&reply);
        }
        Ok(settings)
    }

    /// Takes in what has arrived without waiting for more; runs the failsafe and the quiet-line
    /// detection, as [`blocking::Driver::poll`](super::blocking::Driver::poll) does.
    pub async fn poll(&mut self) -> Result<Option<Event>, Error<U::Error>> {
        let now = self.clock.now_ms();
        if let Some(stop) = self.core.failsafe(now) {
            self.send(&stop).await?;
        }
        loop {
            if let Some(event) = self.rx.drain(&mut self.core, now) {
                return Ok(Some(event));
            }
            if !self.uart.read_ready()? {
                return Ok(self.core.quiet(now));
            }
            let n = self.uart.read(self.rx.space()).await?;
            self.rx.filled(n);
            if n == 0 {
                return Ok(None);
            }
        }
    }

    async fn setting(&mut self, setting: Setting) -> Result<(), Error<U::Error>> {
        let now = self.clock.now_ms();
        let bytes = self.core.setting(setting, now)?;
        self.send(&bytes).await
    }

    async fn send(&mut self, mut bytes: &[u8]) -> Result<(), Error<U::Error>> {
        while !bytes.is_empty() {
            let n = self.uart.write(bytes).await?;
            if n == 0 {
                return Err(Error::WriteZero);
            }
            bytes = bytes.get(n..).unwrap_or(&[]);
        }
        self.uart.flush().await?;
        Ok(())
    }
}
