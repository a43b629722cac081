//! IMU telemetry (spec 2E-1), board → master, 100 Hz, 15 bytes.
//!
//! | byte | 0 | 1 | 2–3 | 4–5 | 6–7 | 8–9 | 10–11 | 12–13 | 14 |
//! |---|---|---|---|---|---|---|---|---|---|
//! | | FF | FA | accel X | accel Y | accel Z | gyro X | gyro Y | gyro Z | count |
//!
//! Six big-endian `i16` in the sensor's raw units (not stated by the vendor).

use super::telemetry_frame;
use crate::wire;

/// Byte offsets of the IMU frame.
pub(crate) mod field {
    pub const HEADER: usize = 0;
    /// Accel X, Y, Z.
    pub const ACCEL: [usize; 3] = [2, 4, 6];
    /// Gyro X, Y, Z.
    pub const GYRO: [usize; 3] = [8, 10, 12];
    pub const SEQ: usize = 14;
}

/// One IMU sample.
///
/// ```
/// use chassis_protocol::Imu;
///
/// let imu = Imu { accel: [0, 0, 16_384], gyro: [-6, 0, 1], seq: 7 };
/// let bytes = imu.encode();
/// assert_eq!(&bytes[..2], &Imu::HEADER);
/// assert_eq!(Imu::decode(&bytes), Ok(imu));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Imu {
    /// Acceleration X, Y, Z, raw sensor counts.
    pub accel: [i16; 3],
    /// Angular rate X, Y, Z, raw sensor counts.
    pub gyro: [i16; 3],
    /// Rolling count (wraps 255 → 0); a gap means frames were lost.
    pub seq: u8,
}

telemetry_frame!(Imu, [0xFF, 0xFA], 15, "IMU");

impl Imu {
    /// Writes the frame's own fields (between the header and the count).
    fn write(&self, buf: &mut [u8; Self::LEN]) {
        for (&value, at) in self.accel.iter().zip(field::ACCEL) {
            wire::put_i16(buf, at, value);
        }
        for (&value, at) in self.gyro.iter().zip(field::GYRO) {
            wire::put_i16(buf, at, value);
        }
    }

    /// The fields of a frame whose header is already checked (the parser's hot path).
    #[inline]
    pub(crate) fn read(bytes: &[u8; Self::LEN]) -> Self {
        // (Each field by name, not `array::map`: that one the optimiser does not always unroll,
        // and this is the parser's hot path.)
        let ([ax, ay, az], [gx, gy, gz]) = (field::ACCEL, field::GYRO);
        let at = |offset| wire::i16_at(bytes, offset);
        Imu {
            accel: [at(ax), at(ay), at(az)],
            gyro: [at(gx), at(gy), at(gz)],
            seq: wire::u8_at(bytes, field::SEQ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// From the 2E-1 table: accel X = 0x0102, Y = -1 (FF FF), Z = 0x4000; gyro X = -6
    /// (FF FA, a false header inside the payload), Y = 0x7FFF, Z = -32768 (80 00); count 0xFE.
    static GOLDEN: [u8; 15] = [
        0xFF, 0xFA, 0x01, 0x02, 0xFF, 0xFF, 0x40, 0x00, 0xFF, 0xFA, 0x7F, 0xFF, 0x80, 0x00, 0xFE,
    ];

    fn golden() -> Imu {
        Imu {
            accel: [0x0102, -1, 0x4000],
            gyro: [-6, i16::MAX, i16::MIN],
            seq: 0xFE,
        }
    }

    #[test]
    fn golden_bytes() {
        assert_eq!(golden().encode(), GOLDEN);
        assert_eq!(Imu::decode(&GOLDEN), Ok(golden()));
    }

    #[test]
    fn decode_errors() {
        assert_eq!(Imu::decode(&GOLDEN[..14]), Err(Error::Length));
        let mut bad = GOLDEN;
        bad[1] = 0xFB;
        assert_eq!(Imu::decode(&bad), Err(Error::Header));
    }
}
