//! The v1.0.0 driver as a [`Link`]: its own calls on `Blocking` and `Async` (the shared
//! wrappers of [`crate::link`] over the v1.0.0 core, which implement [`Common`] for either
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
use chassis_protocol::driver::Clock;
use chassis_protocol::v1::{BodyVelocity, Readback, Reply};

#[cfg(feature = "blocking")]
#[maybe_async::sync_impl]
impl<U, C> Link for Blocking<U, C>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
{
    fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).map_err(kind)
    }
    fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.driver.readback(readback).map_err(kind)
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
    async fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.driver.set_velocity(velocity).await.map_err(kind)
    }
    async fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.driver.readback(readback).await.map_err(kind)
    }
}
