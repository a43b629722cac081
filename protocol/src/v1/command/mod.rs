//! Master → board: always 14 bytes, `7B`, a code, ten payload bytes, BCC, `7D` ([`Command`]).
//! The velocity frames are in [`motion`], the settings frames in [`settings`], the five
//! readback requests ([`Readback`]: ten `00`) here.

pub(crate) mod motion;
pub(crate) mod settings;

use super::{COMMAND_LEN, FrameError, PAYLOAD_LEN, check, frame14, payload_of};
use crate::wire;
pub use motion::{BodyVelocity, MotorVelocity};
pub use settings::{Geometry, Pid, SystemSettings};

/// Where the two payload bytes the layout gives as `00` start in `0x23`, `0x24` and `0x25`.
const UNUSED_TAIL: usize = 8;

/// The five readback requests (their reply carries the same code).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Readback {
    /// `0x33`: the system settings ([`SystemSettings`]).
    System,
    /// `0x34`: the geometry ([`Geometry`]).
    Geometry,
    /// `0x35`: the body-velocity state (documented, unverified).
    BodyVelocity,
    /// `0x36`: the per-motor speeds from the encoders (documented, unverified).
    MotorSpeeds,
    /// `0x50`: the PID gains ([`Pid`]).
    Pid,
}

impl Readback {
    /// All five.
    pub const ALL: [Readback; 5] = [
        Readback::System,
        Readback::Geometry,
        Readback::BodyVelocity,
        Readback::MotorSpeeds,
        Readback::Pid,
    ];

    /// Its code byte.
    #[must_use]
    pub const fn code(self) -> u8 {
        match self {
            Readback::System => 0x33,
            Readback::Geometry => 0x34,
            Readback::BodyVelocity => 0x35,
            Readback::MotorSpeeds => 0x36,
            Readback::Pid => 0x50,
        }
    }

    /// The request of a code byte.
    #[must_use]
    pub const fn from_code(code: u8) -> Option<Readback> {
        match code {
            0x33 => Some(Readback::System),
            0x34 => Some(Readback::Geometry),
            0x35 => Some(Readback::BodyVelocity),
            0x36 => Some(Readback::MotorSpeeds),
            0x50 => Some(Readback::Pid),
            _ => None,
        }
    }
}

/// A master → board frame (14 bytes). There is no turn by angle in v1.0.0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Command {
    /// `0x25`.
    BodyVelocity(BodyVelocity),
    /// `0x26`.
    MotorVelocity(MotorVelocity),
    /// `0x23`.
    System(SystemSettings),
    /// `0x24`.
    Geometry(Geometry),
    /// `0x40`.
    Pid(Pid),
    /// `0x33` `0x34` `0x35` `0x36` `0x50`: ten `00`.
    Readback(Readback),
}

impl Command {
    /// Its code byte.
    #[must_use]
    pub const fn code(&self) -> u8 {
        match self {
            Command::BodyVelocity(_) => 0x25,
            Command::MotorVelocity(_) => 0x26,
            Command::System(_) => 0x23,
            Command::Geometry(_) => 0x24,
            Command::Pid(_) => 0x40,
            Command::Readback(r) => r.code(),
        }
    }

    /// Whether `code` is a master → board code.
    #[must_use]
    pub const fn is_code(code: u8) -> bool {
        matches!(code, 0x23..=0x26 | 0x40) || Readback::from_code(code).is_some()
    }

    /// The frame's 14 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; COMMAND_LEN] {
        let payload = match self {
            Command::BodyVelocity(v) => v.payload(),
            Command::MotorVelocity(m) => m.payload(),
            Command::System(s) => s.payload(),
            Command::Geometry(g) => g.payload(),
            Command::Pid(p) => p.payload(),
            Command::Readback(_) => [0; PAYLOAD_LEN],
        };
        frame14(self.code(), &payload)
    }

    /// A frame's command: start, end and BCC checked; a readback request's payload must be
    /// ten `00`, as the vendor sends it ([`FrameError::Payload`]).
    pub fn decode(bytes: &[u8]) -> Result<Command, FrameError> {
        check(bytes, COMMAND_LEN)?;
        let p = payload_of(bytes);
        let code = wire::u8_at(bytes, super::frame::CODE);
        // Bytes the layout gives as `00 00` (the last two of 0x23, 0x24, 0x25) must be.
        if matches!(code, 0x23..=0x25) && wire::u16_at(&p, UNUSED_TAIL) != 0 {
            return Err(FrameError::Payload);
        }
        Ok(match code {
            0x25 => Command::BodyVelocity(BodyVelocity::from_payload(&p)),
            0x26 => Command::MotorVelocity(MotorVelocity::from_payload(&p)),
            0x23 => Command::System(SystemSettings::from_payload(&p)),
            0x24 => Command::Geometry(Geometry::from_payload(&p)),
            0x40 => Command::Pid(Pid::from_payload(&p)),
            code => {
                let request = Readback::from_code(code).ok_or(FrameError::UnknownCode(code))?;
                if p != [0; PAYLOAD_LEN] {
                    return Err(FrameError::Payload);
                }
                Command::Readback(request)
            }
        })
    }
}
