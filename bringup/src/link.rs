//! [`Link`]: what the bring-up needs from a driver, so that it is written once for both shells.
//!
//! `Blocking` (feature `blocking`) wraps the blocking driver (any HAL with embedded-io 0.7
//! `Read + Write + ReadReady`, or embedded-hal-nb serial through `NbSerial`); `Async` (feature
//! `async`) wraps the async one (embassy's `BufferedUart`). With `blocking`, [`Link`]'s calls
//! are plain functions and the bring-up is plain blocking code: no executor, no future.
//!
//! Both wrappers take the driver's core as a parameter, as the driver does: `Blocking::new`
//! and `Async::new` make the 2020 driver (a [`Link`]), `Blocking::new_v1` and `Async::new_v1`
//! the v1.0.0 one (a [`LinkV1`](crate::v1::LinkV1), implemented in [`crate::v1`]).

#[cfg(any(feature = "blocking", feature = "async"))]
use chassis_protocol::driver::{Clock, CoreError, Outcome, Request};
use chassis_protocol::driver::{DriverCore, Error, Event};
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{Register, Turn, Velocity, Write};

/// A driver error with its transport error reduced to its kind, so that one bring-up serves
/// every HAL.
pub type LinkError = Error<embedded_io::ErrorKind>;

#[cfg(any(feature = "blocking", feature = "async"))]
pub(crate) fn kind<E: embedded_io::Error>(e: Error<E>) -> LinkError {
    e.map_transport(|e| e.kind())
}

/// The calls the bring-up makes; each is the driver call of the same name.
///
/// `async` (the futures are not `Send`: a bring-up runs on one core, in one task), or plain
/// functions with feature `blocking`.
#[allow(async_fn_in_trait)]
#[maybe_async::maybe_async(AFIT)]
pub trait Link {
    /// Milliseconds since boot (the driver's clock).
    fn now_ms(&mut self) -> u64;
    /// The driver's sans-IO core: latest telemetry, counters.
    fn core(&self) -> &DriverCore;
    /// Takes in what has arrived; the blocking shell returns at once, the async one waits a
    /// little for bytes.
    async fn poll(&mut self) -> Result<Option<Event>, LinkError>;
    /// Sets the body velocity.
    async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError>;
    /// Stops (and cancels a turn in progress).
    async fn stop(&mut self) -> Result<(), LinkError>;
    /// Sends a turn, once.
    async fn turn(&mut self, turn: Turn) -> Result<(), LinkError>;
    /// The angle still to turn, 0.1°.
    async fn turn_remaining(&mut self) -> Result<i32, LinkError>;
    /// Every register, each read verified.
    async fn read_settings(&mut self) -> Result<Snapshot, LinkError>;
    /// One register, untyped, read until two replies agree (there is no checksum: one reply
    /// can carry a changed byte).
    async fn read_verified(&mut self, register: Register) -> Result<u32, LinkError>;
    /// One register write.
    async fn write(&mut self, write: Write) -> Result<(), LinkError>;
    /// What the bring-up is doing (a check starts, passes, is skipped): for a program that
    /// shows its progress. Does nothing unless implemented.
    fn note(&mut self, note: crate::Note) {
        let _ = note;
    }
}

/// The blocking driver as a [`Link`] (feature `blocking`; the clock is copied: it must be a
/// handle, as a SysTick counter or `embassy_time` are). `K` is the driver's core: the 2020
/// one by default, [`v1::DriverCore`](chassis_protocol::driver::v1::DriverCore) for a
/// [`LinkV1`](crate::v1::LinkV1).
#[cfg(feature = "blocking")]
pub struct Blocking<U, C, K = DriverCore> {
    pub(crate) driver: chassis_protocol::driver::blocking::Driver<U, C, K>,
    pub(crate) clock: C,
}

#[cfg(feature = "blocking")]
impl<U, C> Blocking<U, C>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
{
    /// Wraps a new blocking driver for the 2020 firmware over `uart`.
    pub fn new(uart: U, clock: C, config: chassis_protocol::driver::Config) -> Self {
        let driver = chassis_protocol::driver::blocking::Driver::new(uart, clock.clone(), config);
        Blocking { driver, clock }
    }
}

#[cfg(feature = "blocking")]
impl<U, C> Blocking<U, C, chassis_protocol::driver::v1::DriverCore>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
{
    /// Wraps a new blocking driver for the v1.0.0 firmware over `uart` (its failsafe at least
    /// [`MIN_FAILSAFE_MS`](chassis_protocol::driver::v1::MIN_FAILSAFE_MS)).
    pub fn new_v1(uart: U, clock: C, config: chassis_protocol::driver::Config) -> Self {
        let driver =
            chassis_protocol::driver::blocking::Driver::new_v1(uart, clock.clone(), config);
        Blocking { driver, clock }
    }
}

#[cfg(feature = "blocking")]
impl<U, C, K> Blocking<U, C, K> {
    /// Wraps a blocking driver already made (opened on a PC's serial port, say); `clock` is
    /// a copy of its clock.
    pub const fn from_driver(
        driver: chassis_protocol::driver::blocking::Driver<U, C, K>,
        clock: C,
    ) -> Self {
        Blocking { driver, clock }
    }

    /// The driver, for what the bring-up does not use.
    pub fn driver(&mut self) -> &mut chassis_protocol::driver::blocking::Driver<U, C, K> {
        &mut self.driver
    }

    /// The driver back.
    pub fn into_driver(self) -> chassis_protocol::driver::blocking::Driver<U, C, K> {
        self.driver
    }
}

#[cfg(feature = "blocking")]
#[maybe_async::sync_impl]
impl<U, C> Link for Blocking<U, C>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
{
    fn now_ms(&mut self) -> u64 {
        self.clock.now_ms()
    }
    fn core(&self) -> &DriverCore {
        self.driver.core()
    }
    fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        self.driver.poll().map_err(kind)
    }
    fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).map_err(kind)
    }
    fn stop(&mut self) -> Result<(), LinkError> {
        self.driver.stop().map_err(kind)
    }
    fn turn(&mut self, turn: Turn) -> Result<(), LinkError> {
        self.driver.turn(turn).map_err(kind)
    }
    fn turn_remaining(&mut self) -> Result<i32, LinkError> {
        self.driver.turn_remaining().map_err(kind)
    }
    fn read_settings(&mut self) -> Result<Snapshot, LinkError> {
        self.driver.read_settings().map_err(kind)
    }
    fn read_verified(&mut self, register: Register) -> Result<u32, LinkError> {
        match self
            .driver
            .run(Request::ReadVerified(register))
            .map_err(kind)?
        {
            Outcome::Value(v) => Ok(v),
            _ => Err(Error::Core(CoreError::Unconfirmed(register))),
        }
    }
    fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.driver.write(write).map_err(kind)
    }
}

/// The async driver as a [`Link`] (feature `async`). `K` is the driver's core: the 2020 one
/// by default, [`v1::DriverCore`](chassis_protocol::driver::v1::DriverCore) for a
/// [`LinkV1`](crate::v1::LinkV1).
#[cfg(feature = "async")]
pub struct Async<U, C, D, K = DriverCore> {
    pub(crate) driver: chassis_protocol::driver::asynch::Driver<U, C, D, K>,
    pub(crate) clock: C,
}

#[cfg(feature = "async")]
impl<U, C, D> Async<U, C, D>
where
    U: embedded_io_async::Read + embedded_io_async::Write,
    C: Clock + Clone,
    D: embedded_hal_async::delay::DelayNs,
{
    /// Wraps a new async driver for the 2020 firmware over `uart`.
    pub fn new(uart: U, clock: C, delay: D, config: chassis_protocol::driver::Config) -> Self {
        let driver =
            chassis_protocol::driver::asynch::Driver::new(uart, clock.clone(), delay, config);
        Async { driver, clock }
    }
}

#[cfg(feature = "async")]
impl<U, C, D> Async<U, C, D, chassis_protocol::driver::v1::DriverCore>
where
    U: embedded_io_async::Read + embedded_io_async::Write,
    C: Clock + Clone,
    D: embedded_hal_async::delay::DelayNs,
{
    /// Wraps a new async driver for the v1.0.0 firmware over `uart`.
    pub fn new_v1(uart: U, clock: C, delay: D, config: chassis_protocol::driver::Config) -> Self {
        let driver =
            chassis_protocol::driver::asynch::Driver::new_v1(uart, clock.clone(), delay, config);
        Async { driver, clock }
    }
}

#[cfg(feature = "async")]
impl<U, C, D, K> Async<U, C, D, K> {
    /// The driver, for what the bring-up does not use.
    pub fn driver(&mut self) -> &mut chassis_protocol::driver::asynch::Driver<U, C, D, K> {
        &mut self.driver
    }
}

#[cfg(feature = "async")]
#[maybe_async::async_impl(AFIT)]
impl<U, C, D> Link for Async<U, C, D>
where
    U: embedded_io_async::Read + embedded_io_async::Write,
    C: Clock + Clone,
    D: embedded_hal_async::delay::DelayNs,
{
    fn now_ms(&mut self) -> u64 {
        self.clock.now_ms()
    }
    fn core(&self) -> &DriverCore {
        self.driver.core()
    }
    async fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        self.driver.poll().await.map_err(kind)
    }
    async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).await.map_err(kind)
    }
    async fn stop(&mut self) -> Result<(), LinkError> {
        self.driver.stop().await.map_err(kind)
    }
    async fn turn(&mut self, turn: Turn) -> Result<(), LinkError> {
        self.driver.turn(turn).await.map_err(kind)
    }
    async fn turn_remaining(&mut self) -> Result<i32, LinkError> {
        self.driver.turn_remaining().await.map_err(kind)
    }
    async fn read_settings(&mut self) -> Result<Snapshot, LinkError> {
        self.driver.read_settings().await.map_err(kind)
    }
    async fn read_verified(&mut self, register: Register) -> Result<u32, LinkError> {
        match self
            .driver
            .run(Request::ReadVerified(register))
            .await
            .map_err(kind)?
        {
            Outcome::Value(v) => Ok(v),
            _ => Err(Error::Core(CoreError::Unconfirmed(register))),
        }
    }
    async fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.driver.write(write).await.map_err(kind)
    }
}
