//! Encoder telemetry (spec 2E-2), board → master, 25 Hz, 11 bytes.
//!
//! | byte | 0 | 1 | 2–3 | 4–5 | 6–7 | 8–9 | 10 |
//! |---|---|---|---|---|---|---|---|
//! | | FF | FB | encoder 1 | encoder 2 | encoder 3 | encoder 4 | count |
//!
//! **Ambiguity A5**: the vendor states neither the signedness nor whether a value is a count per
//! period or a running total. They decode as `i16`; compute motion with wrapping differences
//! ([`Encoders::delta_since`]) and both readings work.

use super::telemetry_frame;
use crate::wire;

/// Byte offsets of the encoder frame.
pub(crate) mod field {
    pub const HEADER: usize = 0;
    /// Encoder 1..4.
    pub const TICKS: [usize; 4] = [2, 4, 6, 8];
    pub const SEQ: usize = 10;
}

/// One encoder sample: the four motors' encoder values.
///
/// ```
/// use chassis_protocol::Encoders;
///
/// let e = Encoders { ticks: [1, -2, 300, i16::MIN], seq: 9 };
/// assert_eq!(Encoders::decode(&e.encode()), Ok(e));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Encoders {
    /// Encoder 1..4 (MOTO1..MOTO4), raw (A5).
    pub ticks: [i16; 4],
    /// Rolling count (wraps 255 → 0); a gap means frames were lost.
    pub seq: u8,
}

telemetry_frame!(Encoders, [0xFF, 0xFB], 11, "encoder");

impl Encoders {
    /// Writes the frame's own fields (between the header and the count).
    fn write(&self, buf: &mut [u8; Self::LEN]) {
        for (&value, at) in self.ticks.iter().zip(field::TICKS) {
            wire::put_i16(buf, at, value);
        }
    }

    /// The fields of a frame whose header is already checked (the parser's hot path).
    #[inline]
    pub(crate) fn read(bytes: &[u8; Self::LEN]) -> Self {
        // (Each field by name, not `array::map`: see `Imu::read`.)
        let [t0, t1, t2, t3] = field::TICKS;
        let at = |offset| wire::i16_at(bytes, offset);
        Encoders {
            ticks: [at(t0), at(t1), at(t2), at(t3)],
            seq: wire::u8_at(bytes, field::SEQ),
        }
    }

    /// Per-motor wrapping difference from an earlier sample: right whether the board sends
    /// running totals (that wrap at 16 bits) or counts per period (then it is the change of rate).
    #[must_use]
    pub fn delta_since(&self, earlier: &Encoders) -> [i16; 4] {
        let mut delta = [0i16; 4];
        for ((d, now), before) in delta.iter_mut().zip(self.ticks).zip(earlier.ticks) {
            *d = now.wrapping_sub(before);
        }
        delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// From the 2E-2 table: encoders 0x0010, -4 (FF FC: a battery header inside the payload),
    /// 0x2301 (a `#` inside the payload), -32767 (80 01); count 0x00.
    static GOLDEN: [u8; 11] = [
        0xFF, 0xFB, 0x00, 0x10, 0xFF, 0xFC, 0x23, 0x01, 0x80, 0x01, 0x00,
    ];

    #[test]
    fn golden_bytes() {
        let e = Encoders {
            ticks: [0x10, -4, 0x2301, -32767],
            seq: 0,
        };
        assert_eq!(e.encode(), GOLDEN);
        assert_eq!(Encoders::decode(&GOLDEN), Ok(e));
    }

    #[test]
    fn decode_errors() {
        assert_eq!(Encoders::decode(&GOLDEN[..10]), Err(Error::Length));
        let mut bad = GOLDEN;
        bad[0] = 0x23;
        assert_eq!(Encoders::decode(&bad), Err(Error::Header));
    }

    #[test]
    fn deltas_wrap() {
        let before = Encoders {
            ticks: [i16::MAX, 0, -5, 100],
            seq: 1,
        };
        let after = Encoders {
            ticks: [i16::MIN, -3, 5, 100],
            seq: 2,
        };
        assert_eq!(after.delta_since(&before), [1, -3, 10, 0]);
    }
}
