//! Register reply (spec 2C / 2D), board → master, 6 bytes, sent once per read.
//!
//! | byte | 0 | 1 | 2 | 3 | 4 | 5 |
//! |---|---|---|---|---|---|---|
//! | | 23 (`#`) | reply code | Byte3 | Byte2 | Byte1 | Byte0 |
//!
//! The value is a big-endian `u32` (an `i32` for the pending angle, code `0x20`). There is no
//! `FF` header and no count byte.

use crate::command::{Register, SystemMode, Write};
use crate::error::Error;
use crate::wire;

/// Byte offsets of the reply frame.
mod field {
    pub const HEADER: usize = 0;
    pub const CODE: usize = 1;
    pub const VALUE: usize = 2;
}

/// The answer to a [`Setting::Read`](crate::Setting::Read).
///
/// It keeps the code as received, so a reply with a code this crate does not know still
/// decodes and re-encodes; [`Reply::register`] says which register it is.
///
/// ```
/// use chassis_protocol::{Register, Reply};
///
/// // The pending angle is -90.0°.
/// let reply = Reply::decode(&[0x23, 0x20, 0xFF, 0xFF, 0xFC, 0x7C])?;
/// assert_eq!(reply.register(), Some(Register::PendingAngle));
/// assert_eq!(reply.pending_deci_degrees(), Some(-900));
/// # Ok::<(), chassis_protocol::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Reply {
    /// Byte 1: the register's code ([`Register::reply_code`]).
    pub code: u8,
    /// Bytes 2–5, big-endian.
    pub value: u32,
}

impl Reply {
    /// The frame's first byte, ASCII `#`.
    pub const HEADER: u8 = 0x23;
    /// Length of the frame on the wire.
    pub const LEN: usize = 6;

    /// The reply to a read of `register` carrying `value`.
    #[must_use]
    pub const fn new(register: Register, value: u32) -> Self {
        Reply {
            code: register.reply_code(),
            value,
        }
    }

    /// The 6 bytes of this frame.
    #[must_use]
    pub fn encode(&self) -> [u8; Self::LEN] {
        let mut buf = [0u8; Self::LEN];
        wire::put_u8(&mut buf, field::HEADER, Self::HEADER);
        wire::put_u8(&mut buf, field::CODE, self.code);
        wire::put_u32(&mut buf, field::VALUE, self.value);
        buf
    }

    /// Decodes exactly one reply frame, whatever its code.
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        if bytes.len() != Self::LEN {
            return Err(Error::Length);
        }
        if wire::u8_at(bytes, field::HEADER) != Self::HEADER {
            return Err(Error::Header);
        }
        Ok(Reply {
            code: wire::u8_at(bytes, field::CODE),
            value: wire::u32_at(bytes, field::VALUE),
        })
    }

    /// The register this answers, `None` for a code the spec does not define.
    #[must_use]
    pub const fn register(&self) -> Option<Register> {
        Register::from_reply_code(self.code)
    }

    /// The reply as the [`Write`] that would set the same value (for a writable register whose
    /// value fits). Handy to restore settings read earlier.
    #[must_use]
    pub const fn as_write(&self) -> Option<Write> {
        match self.register() {
            Some(register) => Write::from_value(register, self.value),
            None => None,
        }
    }

    /// For a system-mode reply (`0x09`), the mode.
    #[must_use]
    pub const fn system_mode(&self) -> Option<SystemMode> {
        match self.register() {
            Some(Register::SystemMode) => Some(SystemMode::from_bits(self.value)),
            _ => None,
        }
    }

    /// For a pending-angle reply (`0x20`), the angle still to turn in 0.1° (signed).
    #[must_use]
    pub const fn pending_deci_degrees(&self) -> Option<i32> {
        match self.register() {
            Some(Register::PendingAngle) => Some(self.value as i32),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn golden_bytes() {
        // 2C-5: `#`, 0x09, Byte3..Byte0 = mecanum with gyro compensation.
        let golden = [0x23, 0x09, 0x00, 0x00, 0x00, 0x09];
        let reply = Reply::new(Register::SystemMode, 9);
        assert_eq!(reply.encode(), golden);
        assert_eq!(Reply::decode(&golden), Ok(reply));
        assert_eq!(reply.system_mode(), Some(SystemMode::from_bits(9)));
        assert_eq!(reply.pending_deci_degrees(), None);
        // 2C-8: full in Byte3..2, cut-off in Byte1..0.
        let golden = [0x23, 0x0C, 0x04, 0xEC, 0x7F, 0xFF];
        let reply = Reply::decode(&golden).unwrap();
        assert_eq!(
            reply.as_write(),
            Some(Write::BatteryRange {
                full_centivolts: 1_260,
                cutoff_centivolts: 0x7FFF
            })
        );
    }

    #[test]
    fn pending_angle_is_signed() {
        let reply = Reply::decode(&[0x23, 0x20, 0x00, 0x00, 0x03, 0x84]).unwrap();
        assert_eq!(reply.pending_deci_degrees(), Some(900));
        let reply = Reply::decode(&[0x23, 0x20, 0x80, 0x00, 0x00, 0x00]).unwrap();
        assert_eq!(reply.pending_deci_degrees(), Some(i32::MIN));
        assert_eq!(reply.as_write(), None);
    }

    #[test]
    fn unknown_codes_are_kept() {
        let bytes = [0x23, 0x42, 1, 2, 3, 4];
        let reply = Reply::decode(&bytes).unwrap();
        assert_eq!(reply.register(), None);
        assert_eq!(reply.encode(), bytes);
    }

    #[test]
    fn decode_errors() {
        assert_eq!(Reply::decode(&[0x23, 0x01, 0, 0, 0]), Err(Error::Length));
        assert_eq!(Reply::decode(&[0x24, 0x01, 0, 0, 0, 0]), Err(Error::Header));
    }
}
