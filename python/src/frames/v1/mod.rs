//! The v1.0.0 firmware's frames (`7B … BCC 7D`): [`commands`] (master → board) and
//! [`telemetry`] (board → master: the telemetry frame, the replies to readbacks).

mod commands;
mod telemetry;

pub use commands::{BodyVelocity, v1_uplink};
pub use telemetry::{ReadbackReply, Telemetry, reply_fields, v1_downlink};
