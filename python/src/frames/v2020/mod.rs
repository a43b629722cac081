//! The 2020 firmware's frames: [`commands`] (master → board: `FF FE`) and [`telemetry`]
//! (board → master: `FF FA/FB/FC`, `#` replies).

mod commands;
mod telemetry;

pub use commands::{Action, Motors, Read, Turn, Velocity, Write, register, uplink, write_of};
pub use telemetry::{Battery, Encoders, Imu, Reply, downlink};
