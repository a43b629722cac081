//! The board's newer firmware, **v1.0.0** (2023): `7B … BCC 7D` frames, a different protocol
//! on the same 115 200 bps UART (the repository's `docs/protocol-v1.md`: every fact, with how
//! sure it is, and the decisions V1–V13).
//!
//! * Master → board: always 14 bytes, `7B`, a code, ten payload bytes, BCC, `7D`
//!   ([`Command`]).
//! * Board → master: a 32-byte [`Telemetry`] frame (code `00`) streamed at about 20–24 Hz,
//!   and 14-byte [`Reply`] frames to the five readback requests ([`Readback`]).
//! * BCC is the XOR of every byte from the `7B` to the byte before it ([`bcc`]); multi-byte
//!   values are big-endian.
//!
//! Velocities are SI units × 1000 (mm/s, mrad/s). Values whose scale nobody has established
//! (the accelerometer, the per-motor "mm/s or 1000·r") stay raw, and their docs say so. There is
//! no turn by angle in this generation: nothing here can send one.
//!
//! [`DownlinkParser`] and [`UplinkParser`] take bytes one at a time (or a slice), check the
//! start, end and BCC of every frame, and resynchronise on the next `7B` inside what they hold.
//!
//! ```
//! use chassis_protocol::v1::{BodyVelocity, Command, Readback};
//!
//! // 0.3 m/s forward (Y), the vendor's mecanum type 4.
//! let frame = Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode();
//! assert_eq!(frame, [0x7B, 0x25, 0x02, 0x04, 0, 0, 0x01, 0x2C, 0, 0, 0, 0, 0x75, 0x7D]);
//! // The vendor's readback request of the system settings.
//! let read = Command::Readback(Readback::System).encode();
//! assert_eq!(read[12], 0x48);
//! ```

mod command;
mod fields;
mod parse;
mod telemetry;

pub use crate::stream::{Frames, Parser};
pub use command::{BodyVelocity, Command, Geometry, MotorVelocity, Pid, Readback, SystemSettings};
pub use fields::{FIELDS, FieldError, Settings, field_readback};
pub use parse::{DownlinkParser, Stats, UplinkParser};
pub use telemetry::{Downlink, Reply, Telemetry};

use crate::wire;

/// First byte of every frame.
pub const START: u8 = 0x7B;
/// Last byte of every frame.
pub const END: u8 = 0x7D;
/// A master → board frame, and a reply: 14 bytes.
pub const COMMAND_LEN: usize = 14;
/// A telemetry frame: 32 bytes.
pub const TELEMETRY_LEN: usize = 32;
/// Byte 1 of a telemetry frame.
pub const TELEMETRY_CODE: u8 = 0x00;
/// The payload of a 14-byte frame: bytes 2..12.
pub const PAYLOAD_LEN: usize = 10;

/// The XOR of `bytes`: a frame's BCC is that of every byte before it.
#[must_use]
pub fn bcc(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0, |acc, b| acc ^ b)
}

/// Why bytes are not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FrameError {
    /// Not the frame's length (14, or 32 for telemetry).
    Length,
    /// The first byte is not `7B`.
    Start,
    /// The last byte is not `7D`.
    End,
    /// The BCC does not match.
    Checksum {
        /// The BCC of the bytes.
        computed: u8,
        /// The BCC the frame carries.
        carried: u8,
    },
    /// A code this direction does not have.
    UnknownCode(u8),
    /// Payload bytes the layout gives as `00` are not: a readback request's ten, the last two
    /// of `0x23`, `0x24`, `0x25` (anything else is not known to be harmless).
    Payload,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FrameError::Length => f.write_str("not a frame's length"),
            FrameError::Start => f.write_str("does not start with 7B"),
            FrameError::End => f.write_str("does not end with 7D"),
            FrameError::Checksum { computed, carried } => {
                write!(f, "BCC {carried:#04x}, the bytes give {computed:#04x}")
            }
            FrameError::UnknownCode(c) => write!(f, "unknown code {c:#04x}"),
            FrameError::Payload => f.write_str("payload bytes that must be 00 are not"),
        }
    }
}

impl core::error::Error for FrameError {}

/// Checks start, end and BCC of `bytes` as a frame of `len` bytes.
fn check(bytes: &[u8], len: usize) -> Result<(), FrameError> {
    if bytes.len() != len {
        return Err(FrameError::Length);
    }
    let last = len.saturating_sub(1);
    if wire::u8_at(bytes, frame::START) != START {
        return Err(FrameError::Start);
    }
    if wire::u8_at(bytes, last) != END {
        return Err(FrameError::End);
    }
    let body = last.saturating_sub(1);
    let computed = bcc(bytes.get(..body).unwrap_or(&[]));
    let carried = wire::u8_at(bytes, body);
    if computed != carried {
        return Err(FrameError::Checksum { computed, carried });
    }
    Ok(())
}

/// Byte offsets in a 14-byte frame (a command or a reply).
pub(crate) mod frame {
    pub const START: usize = 0;
    pub const CODE: usize = 1;
    /// The ten payload bytes.
    pub const PAYLOAD: usize = 2;
    pub const BCC: usize = 12;
    pub const END: usize = 13;
}

/// A 14-byte frame: `7B`, `code`, `payload`, BCC, `7D`.
fn frame14(code: u8, payload: &[u8; PAYLOAD_LEN]) -> [u8; COMMAND_LEN] {
    let mut out = [0u8; COMMAND_LEN];
    wire::put_u8(&mut out, frame::START, START);
    wire::put_u8(&mut out, frame::CODE, code);
    wire::put(&mut out, frame::PAYLOAD, payload);
    let sum = bcc(out.get(..frame::BCC).unwrap_or(&[]));
    wire::put_u8(&mut out, frame::BCC, sum);
    wire::put_u8(&mut out, frame::END, END);
    out
}

/// The payload of a checked 14-byte frame.
fn payload_of(bytes: &[u8]) -> [u8; PAYLOAD_LEN] {
    let mut p = [0u8; PAYLOAD_LEN];
    let payload = frame::PAYLOAD..frame::PAYLOAD + PAYLOAD_LEN;
    wire::put(&mut p, 0, bytes.get(payload).unwrap_or(&[]));
    p
}

#[cfg(test)]
mod tests;
