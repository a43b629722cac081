//! The 2020 driver as a [`Link`]: its own calls on `Blocking` and `Async` (the shared
//! wrappers of [`crate::link`] over the 2020 core, which implement [`Common`] for either
//! generation).
//!
//! [`Common`]: crate::link::Common

#[cfg(feature = "async")]
use super::Async;
#[cfg(feature = "blocking")]
use super::Blocking;
use super::Link;
use crate::LinkError;
use crate::link::kind;
use chassis_protocol::driver::{Clock, CoreError, Error, Outcome, Request};
use chassis_protocol::{Register, Turn, Velocity, Write, registers::Snapshot};

#[cfg(feature = "blocking")]
#[maybe_async::sync_impl]
impl<U, C> Link for Blocking<U, C>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
{
    fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).map_err(kind)
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
        let outcome = self.driver.run(Request::ReadVerified(register));
        value(register, outcome.map_err(kind)?)
    }
    fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.driver.write(write).map_err(kind)
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
    async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).await.map_err(kind)
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
        let outcome = self.driver.run(Request::ReadVerified(register)).await;
        value(register, outcome.map_err(kind)?)
    }
    async fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.driver.write(write).await.map_err(kind)
    }
}

/// A verified read's value (any other outcome: the read is unconfirmed).
fn value(register: Register, outcome: Outcome) -> Result<u32, LinkError> {
    match outcome {
        Outcome::Value(v) => Ok(v),
        _ => Err(Error::Core(CoreError::Unconfirmed(register))),
    }
}
