//! Board → master: a 32-byte [`Telemetry`] frame (code `00`) streamed at about 20–24 Hz, and
//! 14-byte replies to the five readback requests ([`reply`]); [`Downlink`] is either, told
//! apart by byte 1.

pub(crate) mod reply;

use super::command::Readback;
use super::{COMMAND_LEN, END, FrameError, START, TELEMETRY_CODE, TELEMETRY_LEN, bcc, check};
use crate::wire;
pub use reply::Reply;

/// Byte offsets in the telemetry frame. Every value is a big-endian `i16`.
mod field {
    pub const START: usize = 0;
    /// The code byte, also where a reply's is.
    pub const CODE: usize = 1;
    /// vx, vy (mm/s), wz (mrad/s).
    pub const VELOCITY: [usize; 3] = [2, 4, 6];
    /// Accelerometer x, y, z.
    pub const ACCEL: [usize; 3] = [8, 10, 12];
    /// Gyro x, y, z.
    pub const GYRO: [usize; 3] = [14, 16, 18];
    /// The quaternion w, x, y, z, × 1000.
    pub const QUATERNION: [usize; 4] = [20, 22, 24, 26];
    /// Battery voltage, mV.
    pub const BATTERY: usize = 28;
    pub const BCC: usize = 30;
    pub const END: usize = 31;
}

/// The 32-byte telemetry frame, streamed at about 20–24 Hz.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Telemetry {
    /// Measured body velocity: vx, vy (mm/s), wz (mrad/s).
    pub velocity: [i16; 3],
    /// Accelerometer x, y, z: raw (scale unknown).
    pub accel: [i16; 3],
    /// Gyro x, y, z: raw (read by one user as mrad/s; not established).
    pub gyro: [i16; 3],
    /// The IMU's quaternion w, x, y, z, × 1000.
    pub quaternion: [i16; 4],
    /// Battery voltage, mV.
    pub battery_mv: i16,
}

impl Telemetry {
    /// The frame's 32 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; TELEMETRY_LEN] {
        let mut out = [0u8; TELEMETRY_LEN];
        wire::put_u8(&mut out, field::START, START);
        wire::put_u8(&mut out, field::CODE, TELEMETRY_CODE);
        let values = (field::VELOCITY.into_iter().zip(self.velocity))
            .chain(field::ACCEL.into_iter().zip(self.accel))
            .chain(field::GYRO.into_iter().zip(self.gyro))
            .chain(field::QUATERNION.into_iter().zip(self.quaternion))
            .chain(core::iter::once((field::BATTERY, self.battery_mv)));
        for (at, v) in values {
            wire::put_i16(&mut out, at, v);
        }
        let sum = bcc(out.get(..field::BCC).unwrap_or(&[]));
        wire::put_u8(&mut out, field::BCC, sum);
        wire::put_u8(&mut out, field::END, END);
        out
    }

    /// A telemetry frame: start, code `00`, end and BCC checked.
    pub fn decode(bytes: &[u8]) -> Result<Telemetry, FrameError> {
        check(bytes, TELEMETRY_LEN)?;
        let code = wire::u8_at(bytes, field::CODE);
        if code != TELEMETRY_CODE {
            return Err(FrameError::UnknownCode(code));
        }
        Ok(Telemetry::from_frame(bytes))
    }

    /// The values of a telemetry frame whose start, code, end and BCC are known to be right
    /// (what the parsers have checked already): no check again, and no bounds check, on the
    /// frame's 32 bytes.
    pub(crate) fn from_frame(bytes: &[u8]) -> Telemetry {
        let bytes: &[u8; TELEMETRY_LEN] = bytes.try_into().unwrap_or(&[0; TELEMETRY_LEN]);
        // Each field by name, not `array::map`: the optimiser does not always unroll that one,
        // and this is the parser's frame-completing byte (`cargo xtask icount`: 1 566 against
        // 894 instructions on the Cortex-M4).
        let at = |i: usize| wire::i16_at(bytes, i);
        let ([v0, v1, v2], [a0, a1, a2], [g0, g1, g2]) =
            (field::VELOCITY, field::ACCEL, field::GYRO);
        let [qw, qx, qy, qz] = field::QUATERNION;
        Telemetry {
            velocity: [at(v0), at(v1), at(v2)],
            accel: [at(a0), at(a1), at(a2)],
            gyro: [at(g0), at(g1), at(g2)],
            quaternion: [at(qw), at(qx), at(qy), at(qz)],
            battery_mv: at(field::BATTERY),
        }
    }
}

/// A board → master frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Downlink {
    /// 32 bytes, code `00`.
    Telemetry(Telemetry),
    /// 14 bytes, a readback code.
    Reply(Reply),
}

impl Downlink {
    /// The frame's length on the wire for the code in its byte 1, if the code is one of this
    /// direction's.
    #[must_use]
    pub const fn len_of(code: u8) -> Option<usize> {
        if code == TELEMETRY_CODE {
            Some(TELEMETRY_LEN)
        } else if Readback::from_code(code).is_some() {
            Some(COMMAND_LEN)
        } else {
            None
        }
    }

    /// A board → master frame (telemetry or a reply, told apart by byte 1).
    pub fn decode(bytes: &[u8]) -> Result<Downlink, FrameError> {
        match wire::u8_at(bytes, field::CODE) {
            TELEMETRY_CODE => Telemetry::decode(bytes).map(Downlink::Telemetry),
            _ => Reply::decode(bytes).map(Downlink::Reply),
        }
    }

    /// The frame of `bytes`, whose start, end and BCC are known to be right and whose length
    /// is that of its code (what the parsers have checked already), without checking them
    /// again: `None` if the code is none of this direction's.
    pub(crate) fn from_frame(bytes: &[u8]) -> Option<Downlink> {
        match wire::u8_at(bytes, field::CODE) {
            TELEMETRY_CODE => Some(Downlink::Telemetry(Telemetry::from_frame(bytes))),
            code => Some(Downlink::Reply(Reply {
                request: Readback::from_code(code)?,
                payload: super::payload_of(bytes),
            })),
        }
    }

    /// The frame's bytes.
    #[must_use]
    pub fn encode(&self) -> crate::FrameBytes<TELEMETRY_LEN> {
        match self {
            Downlink::Telemetry(t) => crate::FrameBytes::new(&t.encode()),
            Downlink::Reply(r) => crate::FrameBytes::new(&r.encode()),
        }
    }
}
