//! What the tests against a board running the v1.0.0 firmware share: the simulated v1.0.0
//! board, served; the frames it must receive, written by hand from `docs/protocol-v1.md` (`7B`,
//! code, ten payload bytes, BCC = XOR of every byte before it, `7D`); the bytes it heard as
//! frames.

use super::TestBoard;
use chassis_protocol::sim::v1::{Board, SimConfig};

/// `0x25` forced stop: ctl 0, all zeros; BCC 7B ^ 25 = 5E.
pub const FORCED_STOP: [u8; 14] = [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D];

/// `0x25`: vy 0.3 m/s = 300 mm/s (01 2C), ctl 2, type 4; BCC 7B^25^02^04^01^2C = 75 (the keys'
/// forward at the default speed, `drive --vy 0.3`, the check's forward drive).
pub const FORWARD: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0x01, 0x2C, 0, 0, 0, 0, 0x75, 0x7D,
];

/// A simulated v1.0.0 board with its defaults, served.
pub fn v1_board() -> TestBoard<Board> {
    TestBoard::serving(Board::new(SimConfig::default()))
}

/// The heard bytes as 14-byte frames (each must be whole, its BCC and end right).
pub fn frames(heard: &[u8]) -> Vec<[u8; 14]> {
    assert_eq!(heard.len() % 14, 0, "only whole frames: {heard:02X?}");
    heard
        .chunks(14)
        .map(|c| {
            let frame = <[u8; 14]>::try_from(c).unwrap();
            assert_eq!(frame[0], 0x7B, "{frame:02X?}");
            assert_eq!(frame[13], 0x7D, "{frame:02X?}");
            assert_eq!(
                frame[..12].iter().fold(0, |x, b| x ^ b),
                frame[12],
                "BCC of {frame:02X?}"
            );
            frame
        })
        .collect()
}
