//! The 14-byte replies to the readback requests: the request's code and ten bytes laid out as
//! the matching command.

use super::super::command::{BodyVelocity, Geometry, MotorVelocity, Pid, Readback, SystemSettings};
use super::super::{COMMAND_LEN, FrameError, PAYLOAD_LEN, check, frame14, payload_of};
use crate::wire;

/// A 14-byte reply to a readback request: its code, and ten bytes laid out as the matching
/// write (typed by [`Reply::system`], [`Reply::geometry`], …).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Reply {
    /// The request it answers.
    pub request: Readback,
    /// The ten payload bytes.
    pub payload: [u8; PAYLOAD_LEN],
}

impl Reply {
    /// The frame's 14 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; COMMAND_LEN] {
        frame14(self.request.code(), &self.payload)
    }

    /// A reply frame: start, a readback code, end and BCC checked.
    pub fn decode(bytes: &[u8]) -> Result<Reply, FrameError> {
        check(bytes, COMMAND_LEN)?;
        let code = wire::u8_at(bytes, super::super::frame::CODE);
        let request = Readback::from_code(code).ok_or(FrameError::UnknownCode(code))?;
        Ok(Reply {
            request,
            payload: payload_of(bytes),
        })
    }

    /// The reply of `0x33`.
    #[must_use]
    pub fn system(&self) -> Option<SystemSettings> {
        (self.request == Readback::System).then(|| SystemSettings::from_payload(&self.payload))
    }

    /// The reply of `0x34`.
    #[must_use]
    pub fn geometry(&self) -> Option<Geometry> {
        (self.request == Readback::Geometry).then(|| Geometry::from_payload(&self.payload))
    }

    /// The reply of `0x35`, laid out as a body-velocity command.
    #[must_use]
    pub fn body_velocity(&self) -> Option<BodyVelocity> {
        (self.request == Readback::BodyVelocity).then(|| BodyVelocity::from_payload(&self.payload))
    }

    /// The reply of `0x36`: control mode, type, M1..M4.
    #[must_use]
    pub fn motor_speeds(&self) -> Option<MotorVelocity> {
        (self.request == Readback::MotorSpeeds).then(|| MotorVelocity::from_payload(&self.payload))
    }

    /// The reply of `0x50`.
    #[must_use]
    pub fn pid(&self) -> Option<Pid> {
        (self.request == Readback::Pid).then(|| Pid::from_payload(&self.payload))
    }
}
