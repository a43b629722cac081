//! `builtin_interfaces/Time` and `std_msgs/Header`.

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time`: seconds and nanoseconds since the clock's epoch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds (`int32`).
    pub sec: i32,
    /// Nanoseconds in the second, 0..1e9 (`uint32`).
    pub nanosec: u32,
}

impl Time {
    /// The time `nanos` ns after the epoch, saturated to what the message can hold.
    pub fn from_nanos(nanos: i64) -> Time {
        let sec = nanos.div_euclid(1_000_000_000);
        let nanosec = nanos.rem_euclid(1_000_000_000);
        match i32::try_from(sec) {
            Ok(sec) => Time {
                sec,
                nanosec: u32::try_from(nanosec).unwrap_or(0),
            },
            Err(_) if sec < 0 => Time {
                sec: i32::MIN,
                nanosec: 0,
            },
            Err(_) => Time {
                sec: i32::MAX,
                nanosec: 999_999_999,
            },
        }
    }

    /// Nanoseconds since the epoch (a `nanosec` past a second is taken as it is).
    pub fn to_nanos(self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }
}

/// `std_msgs/Header`: when and in which frame.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// When the data was true.
    pub stamp: Time,
    /// The coordinate frame the data is in.
    pub frame_id: String,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::wire;

    #[test]
    fn time_from_nanos_splits_and_saturates() {
        assert_eq!(
            Time::from_nanos(1_500_000_001),
            Time {
                sec: 1,
                nanosec: 500_000_001
            }
        );
        assert_eq!(
            Time::from_nanos(-1),
            Time {
                sec: -1,
                nanosec: 999_999_999
            }
        );
        assert_eq!(Time::from_nanos(i64::MAX).sec, i32::MAX);
        assert_eq!(Time::from_nanos(i64::MIN).sec, i32::MIN);
        assert_eq!(Time::from_nanos(1_500_000_001).to_nanos(), 1_500_000_001);
    }

    #[test]
    fn header_bytes() {
        // stamp 2 s + 7 ns, frame "odom": 4 + 4 bytes of time, then the string's length 5
        // (the NUL counted), "odom", NUL.
        let header = Header {
            stamp: Time { sec: 2, nanosec: 7 },
            frame_id: "odom".into(),
        };
        assert_eq!(
            wire(&header),
            [
                0x00, 0x01, 0x00, 0x00, // CDR little-endian, no options
                0x02, 0x00, 0x00, 0x00, // sec
                0x07, 0x00, 0x00, 0x00, // nanosec
                0x05, 0x00, 0x00, 0x00, // length of "odom" + NUL
                b'o', b'd', b'o', b'm', 0x00,
            ]
        );
    }
}
