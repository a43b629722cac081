//! Battery telemetry (spec 2E-3), board → master, 1 Hz, 7 bytes.
//!
//! | byte | 0 | 1 | 2–3 | 4–5 | 6 |
//! |---|---|---|---|---|---|
//! | | FF | FC | voltage, u16 in 0.01 V | charge, u16 in % | count |

use super::telemetry_frame;
use crate::wire;

/// Byte offsets of the battery frame.
pub(crate) mod field {
    pub const HEADER: usize = 0;
    pub const CENTIVOLTS: usize = 2;
    pub const PERCENT: usize = 4;
    pub const SEQ: usize = 6;
}

/// One battery sample.
///
/// ```
/// use chassis_protocol::Battery;
///
/// // 11.00 V (1100 = 0x044C), 87 % (0x0057), count 3.
/// let bytes = [0xFF, 0xFC, 0x04, 0x4C, 0x00, 0x57, 0x03];
/// let battery = Battery::decode(&bytes)?;
/// assert_eq!(battery, Battery { centivolts: 1_100, percent: 87, seq: 3 });
/// assert_eq!(battery.millivolts(), 11_000);
/// # Ok::<(), chassis_protocol::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Battery {
    /// Battery voltage in 0.01 V (1100 = 11.00 V).
    pub centivolts: u16,
    /// Charge in percent, as the board reports it.
    pub percent: u16,
    /// Rolling count (wraps 255 → 0); a gap means frames were lost.
    pub seq: u8,
}

telemetry_frame!(Battery, [0xFF, 0xFC], 7, "battery");

impl Battery {
    /// Writes the frame's own fields (between the header and the count).
    fn write(&self, buf: &mut [u8; Self::LEN]) {
        wire::put_u16(buf, field::CENTIVOLTS, self.centivolts);
        wire::put_u16(buf, field::PERCENT, self.percent);
    }

    /// The fields of a frame whose header is already checked (the parser's hot path).
    #[inline]
    pub(crate) fn read(bytes: &[u8; Self::LEN]) -> Self {
        Battery {
            centivolts: wire::u16_at(bytes, field::CENTIVOLTS),
            percent: wire::u16_at(bytes, field::PERCENT),
            seq: wire::u8_at(bytes, field::SEQ),
        }
    }

    /// The voltage in millivolts (exact: 0.01 V = 10 mV).
    #[must_use]
    pub const fn millivolts(&self) -> u32 {
        (self.centivolts as u32).saturating_mul(10)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// From the 2E-3 table and its note: 1100 = 11 V.
    static GOLDEN: [u8; 7] = [0xFF, 0xFC, 0x04, 0x4C, 0x00, 0x64, 0xFF];

    #[test]
    fn golden_bytes() {
        let b = Battery {
            centivolts: 1_100,
            percent: 100,
            seq: 255,
        };
        assert_eq!(b.encode(), GOLDEN);
        assert_eq!(Battery::decode(&GOLDEN), Ok(b));
        assert_eq!(b.millivolts(), 11_000);
    }

    #[test]
    fn decode_errors() {
        assert_eq!(Battery::decode(&GOLDEN[..6]), Err(Error::Length));
        assert_eq!(
            Battery::decode(&[GOLDEN.as_slice(), &[0]].concat()),
            Err(Error::Length)
        );
        let mut bad = GOLDEN;
        bad[1] = 0xFA;
        assert_eq!(Battery::decode(&bad), Err(Error::Header));
    }
}
