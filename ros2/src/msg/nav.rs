//! `nav_msgs/Odometry`.

use super::{Header, PoseWithCovariance, TwistWithCovariance};
use serde::{Deserialize, Serialize};

/// `nav_msgs/Odometry`: the pose in `header.frame_id` (`odom`), the twist in
/// `child_frame_id` (`base_link`), each with its covariance.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// When, and the frame of the pose.
    pub header: Header,
    /// The frame of the twist (the robot's body).
    pub child_frame_id: String,
    /// The pose, in the parent frame.
    pub pose: PoseWithCovariance,
    /// The velocity, in the child frame.
    pub twist: TwistWithCovariance,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::le;
    use crate::msg::{Point, Pose, Quaternion, Twist, Vector3, header, wire};

    #[test]
    fn odometry_bytes_pad_after_the_strings() {
        let mut pose_cov = [0.0; 36];
        pose_cov[0] = 0.5;
        let mut twist_cov = [0.0; 36];
        twist_cov[35] = 2.0;
        let odom = Odometry {
            header: header(3, 0, "odom"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: Point {
                        x: 1.0,
                        y: 0.0,
                        z: 0.0,
                    },
                    orientation: Quaternion::IDENTITY,
                },
                covariance: pose_cov,
            },
            twist: TwistWithCovariance {
                twist: Twist {
                    linear: Vector3 {
                        x: 0.25,
                        y: 0.0,
                        z: 0.0,
                    },
                    angular: Vector3::default(),
                },
                covariance: twist_cov,
            },
        };
        // Payload offsets: 0 sec, 4 nanosec, 8 length 5, 12 "odom" NUL, 17..20 padding to 4,
        // 20 length 10, 24 "base_link" NUL, 34..40 padding to 8, 40 the first f64.
        let mut expected = vec![0x00, 0x01, 0x00, 0x00];
        expected.extend_from_slice(&[3, 0, 0, 0, 0, 0, 0, 0]);
        expected.extend_from_slice(&[5, 0, 0, 0, b'o', b'd', b'o', b'm', 0, 0, 0, 0]);
        expected.extend_from_slice(&[10, 0, 0, 0]);
        expected.extend_from_slice(b"base_link\0");
        expected.extend_from_slice(&[0; 6]);
        assert_eq!(expected.len(), 4 + 40);
        // position 1, 0, 0; orientation x, y, z, w = 0, 0, 0, 1
        for v in [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
            expected.extend_from_slice(&le::f64(v));
        }
        expected.extend_from_slice(&le::f64(0.5));
        expected.extend_from_slice(&[0; 35 * 8]);
        expected.extend_from_slice(&le::f64(0.25));
        expected.extend_from_slice(&[0; 5 * 8]);
        expected.extend_from_slice(&[0; 35 * 8]);
        expected.extend_from_slice(&le::f64(2.0));
        assert_eq!(expected.len(), 4 + 720);
        // 1.0 and 0.5 written out once by hand, so the helper is not all the test trusts.
        assert_eq!(expected[44..52], [0, 0, 0, 0, 0, 0, 0xF0, 0x3F]);
        assert_eq!(expected[100..108], [0, 0, 0, 0, 0, 0, 0xE0, 0x3F]);
        assert_eq!(wire(&odom), expected);
    }
}
