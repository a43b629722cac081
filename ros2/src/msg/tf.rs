//! `tf2_msgs/TFMessage`.

use super::TransformStamped;
use serde::{Deserialize, Serialize};

/// `tf2_msgs/TFMessage`: what `/tf` carries, a sequence of transforms.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::le;
    use crate::msg::{Quaternion, Transform, Vector3, header, wire};

    #[test]
    fn tf_message_bytes() {
        let message = TfMessage {
            transforms: vec![TransformStamped {
                header: header(0, 1, "odom"),
                child_frame_id: "b".into(),
                transform: Transform {
                    translation: Vector3 {
                        x: -1.0,
                        y: 0.0,
                        z: 0.0,
                    },
                    rotation: Quaternion::IDENTITY,
                },
            }],
        };
        // 0 count 1, 4 sec, 8 nanosec, 12 length 5, 16 "odom" NUL, 21..24 padding, 24 length 2,
        // 28 "b" NUL, 30..32 padding to 8, 32 the translation.
        let mut expected = vec![0x00, 0x01, 0x00, 0x00, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0];
        expected.extend_from_slice(&[5, 0, 0, 0, b'o', b'd', b'o', b'm', 0, 0, 0, 0]);
        expected.extend_from_slice(&[2, 0, 0, 0, b'b', 0, 0, 0]);
        expected.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0xF0, 0xBF]); // -1.0
        for v in [0.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
            expected.extend_from_slice(&le::f64(v));
        }
        assert_eq!(wire(&message), expected);
    }
}
