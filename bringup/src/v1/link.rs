//! The v1.0.0 driver as a [`Link`]: its own calls on `Blocking` and `Async` (the shared
//! wrappers of [`crate::link`] over the v1.0.0 core, which implement [`Common`] for either
//! generation), one text for both.
//!
//! [`Common`]: crate::link::Common

use super::Link;
use crate::LinkError;
use crate::link::{impl_on_shells, kind};
use chassis_protocol::driver::v1::DriverCore;
use chassis_protocol::v1::{BodyVelocity, Readback, Reply};

impl_on_shells!(Link, core DriverCore, {
    async fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).await.map_err(kind)
    }
    async fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.driver.readback(readback).await.map_err(kind)
    }
});
