//! The 2020 driver as a [`Link`]: its own calls on `Blocking` and `Async` (the shared
//! wrappers of [`crate::link`] over the 2020 core, which implement [`Common`] for either
//! generation), one text for both.
//!
//! [`Common`]: crate::link::Common

use super::Link;
use crate::LinkError;
use crate::link::{impl_on_shells, kind};
use chassis_protocol::driver::{CoreError, DriverCore, Error, Outcome, Request};
use chassis_protocol::{Register, Turn, Velocity, Write, registers::Snapshot};

impl_on_shells!(Link, core DriverCore, {
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
});

/// A verified read's value (any other outcome: the read is unconfirmed).
fn value(register: Register, outcome: Outcome) -> Result<u32, LinkError> {
    match outcome {
        Outcome::Value(v) => Ok(v),
        _ => Err(Error::Core(CoreError::Unconfirmed(register))),
    }
}
