//! `geometry_msgs`: vectors, points, quaternions, poses, twists and transforms.

use super::Header;
use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

/// `geometry_msgs/Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// X.
    pub x: f64,
    /// Y.
    pub y: f64,
    /// Z.
    pub z: f64,
}

/// `geometry_msgs/Point`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// X.
    pub x: f64,
    /// Y.
    pub y: f64,
    /// Z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion` (x, y, z, w on the wire; the default is the identity).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// X.
    pub x: f64,
    /// Y.
    pub y: f64,
    /// Z.
    pub z: f64,
    /// W.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion::IDENTITY
    }
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };

    /// The rotation by `yaw` radians about z (counter-clockwise seen from above, REP-103).
    pub fn from_yaw(yaw: f64) -> Quaternion {
        let half = yaw / 2.0;
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: half.sin(),
            w: half.cos(),
        }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Where.
    pub position: Point,
    /// Which way it faces.
    pub orientation: Quaternion,
}

/// `geometry_msgs/PoseWithCovariance`: a pose and its 6×6 covariance, row-major, over
/// (x, y, z, rotation about x, about y, about z).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance.
    #[serde(with = "BigArray")]
    pub covariance: [f64; 36],
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        PoseWithCovariance {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/Twist`: linear velocity (m/s) and angular velocity (rad/s).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// m/s.
    pub linear: Vector3,
    /// rad/s.
    pub angular: Vector3,
}

/// `geometry_msgs/TwistWithCovariance`: as [`PoseWithCovariance`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Its covariance.
    #[serde(with = "BigArray")]
    pub covariance: [f64; 36],
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        TwistWithCovariance {
            twist: Twist::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/TwistStamped`: a twist and when (what Jazzy's controllers take).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistStamped {
    /// When, and the frame.
    pub header: Header,
    /// The twist.
    pub twist: Twist,
}

/// `geometry_msgs/Transform`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// m.
    pub translation: Vector3,
    /// The rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`: the transform from `header.frame_id` to
/// `child_frame_id`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// When, and the parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The transform.
    pub transform: Transform,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::{header, wire};

    #[test]
    fn twist_bytes() {
        // Six f64, no padding: the payload starts aligned.
        let twist = Twist {
            linear: Vector3 {
                x: 1.0,
                y: -2.0,
                z: 0.5,
            },
            angular: Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.25,
            },
        };
        #[rustfmt::skip]
        let expected = [
            0x00, 0x01, 0x00, 0x00,
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F, // 1.0 = 0x3FF0_0000_0000_0000
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0, // -2.0 = 0xC000_0000_0000_0000
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F, // 0.5 = 0x3FE0_0000_0000_0000
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // 0.0
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // 0.0
            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F, // 0.25 = 0x3FD0_0000_0000_0000
        ];
        assert_eq!(wire(&twist), expected);
    }

    #[test]
    fn twist_stamped_bytes_pad_the_string_to_the_next_f64() {
        // Header: 8 bytes of time, length 2, "b" NUL: 14 bytes of payload; the first f64 goes
        // at offset 16, after 2 bytes of padding.
        let stamped = TwistStamped {
            header: header(1, 0, "b"),
            twist: Twist {
                linear: Vector3 {
                    x: 2.0,
                    y: 0.0,
                    z: 0.0,
                },
                angular: Vector3::default(),
            },
        };
        let mut expected = vec![
            0x00, 0x01, 0x00, 0x00, 1, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, b'b', 0, 0, 0,
        ];
        expected.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0x00, 0x40]); // 2.0 = 0x4000_0000_0000_0000
        expected.extend_from_slice(&[0; 40]);
        assert_eq!(wire(&stamped), expected);
    }

    #[test]
    fn quaternion_from_yaw_is_the_rotation_about_z() {
        let q = Quaternion::from_yaw(core::f64::consts::PI);
        assert!(q.z > 0.999_999 && q.w.abs() < 1e-9);
        assert_eq!(Quaternion::from_yaw(0.0), Quaternion::IDENTITY);
        assert_eq!(Quaternion::default(), Quaternion::IDENTITY);
    }
}
