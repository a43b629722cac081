//! Readings and the odometry's state turned into ROS messages: units (REP-103, SI), frames,
//! covariances. Pure functions: the node stamps and publishes what they return.

use crate::msg::{
    BatteryState, Header, Imu, Odometry, Point, Pose, PoseWithCovariance, Quaternion, TfMessage,
    Time, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3,
};
use crate::odom::{Pose2, Twist2};

/// Standard gravity, m/s² per g.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// How raw IMU counts become SI units, and the variances published with them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuScale {
    /// Accelerometer counts per g.
    pub accel_per_g: f64,
    /// Gyro counts per rad/s.
    pub gyro_per_rad_s: f64,
    /// Each acceleration axis' variance, (m/s²)².
    pub accel_variance: f64,
    /// Each angular velocity axis' variance, (rad/s)².
    pub gyro_variance: f64,
    /// The orientation's variance on each axis, rad² (where there is one).
    pub orientation_variance: f64,
}

/// A 3×3 covariance with `v` on its diagonal.
fn diagonal3(v: f64) -> [f64; 9] {
    [v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, v]
}

/// `sensor_msgs/Imu` from raw counts: m/s² and rad/s; the orientation where there is one (x,
/// y, z, w), else the identity with covariance element 0 at `-1` ("no orientation", REP-145).
pub fn imu(
    header: Header,
    accel: [i16; 3],
    gyro: [i16; 3],
    orientation: Option<[f64; 4]>,
    scale: &ImuScale,
) -> Imu {
    let [ax, ay, az] = accel.map(|c| f64::from(c) / scale.accel_per_g * STANDARD_GRAVITY);
    let [gx, gy, gz] = gyro.map(|c| f64::from(c) / scale.gyro_per_rad_s);
    let (orientation, orientation_covariance) = match orientation {
        Some([x, y, z, w]) => (
            Quaternion { x, y, z, w },
            diagonal3(scale.orientation_variance),
        ),
        None => (
            Quaternion::IDENTITY,
            [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    };
    Imu {
        header,
        orientation,
        orientation_covariance,
        angular_velocity: Vector3 {
            x: gx,
            y: gy,
            z: gz,
        },
        angular_velocity_covariance: diagonal3(scale.gyro_variance),
        linear_acceleration: Vector3 {
            x: ax,
            y: ay,
            z: az,
        },
        linear_acceleration_covariance: diagonal3(scale.accel_variance),
    }
}

/// `sensor_msgs/BatteryState`: the voltage, the charge where the board reports one (else
/// NaN), everything it does not measure NaN or unknown.
pub fn battery(header: Header, volts: f32, fraction: Option<f32>) -> BatteryState {
    BatteryState {
        header,
        voltage: volts,
        temperature: f32::NAN,
        current: f32::NAN,
        charge: f32::NAN,
        capacity: f32::NAN,
        design_capacity: f32::NAN,
        percentage: fraction.unwrap_or(f32::NAN),
        power_supply_status: BatteryState::POWER_SUPPLY_STATUS_UNKNOWN,
        power_supply_health: BatteryState::POWER_SUPPLY_HEALTH_UNKNOWN,
        power_supply_technology: BatteryState::POWER_SUPPLY_TECHNOLOGY_UNKNOWN,
        present: true,
        cell_voltage: Vec::new(),
        cell_temperature: Vec::new(),
        location: String::new(),
        serial_number: String::new(),
    }
}

/// The frames `/odom` and `/tf` name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frames {
    /// The odometry frame (`odom`).
    pub odom: String,
    /// The body frame (`base_link`).
    pub base: String,
}

/// `nav_msgs/Odometry`: the pose in the odometry frame, the twist in the body frame.
pub fn odometry(
    stamp: Time,
    frames: &Frames,
    pose: Pose2,
    twist: Twist2,
    pose_covariance: [f64; 36],
    twist_covariance: [f64; 36],
) -> Odometry {
    Odometry {
        header: Header {
            stamp,
            frame_id: frames.odom.clone(),
        },
        child_frame_id: frames.base.clone(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point {
                    x: f64::from(pose.x),
                    y: f64::from(pose.y),
                    z: 0.0,
                },
                orientation: Quaternion::from_yaw(f64::from(pose.yaw)),
            },
            covariance: pose_covariance,
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: Vector3 {
                    x: f64::from(twist.vx),
                    y: f64::from(twist.vy),
                    z: 0.0,
                },
                angular: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: f64::from(twist.wz),
                },
            },
            covariance: twist_covariance,
        },
    }
}

/// The `odom` → `base_link` transform of the same pose, for `/tf`.
pub fn transform(stamp: Time, frames: &Frames, pose: Pose2) -> TfMessage {
    TfMessage {
        transforms: vec![TransformStamped {
            header: Header {
                stamp,
                frame_id: frames.odom.clone(),
            },
            child_frame_id: frames.base.clone(),
            transform: Transform {
                translation: Vector3 {
                    x: f64::from(pose.x),
                    y: f64::from(pose.y),
                    z: 0.0,
                },
                rotation: Quaternion::from_yaw(f64::from(pose.yaw)),
            },
        }],
    }
}

/// A `Twist` from `/cmd_vel` as the planar velocity the chassis can follow (x, y, yaw rate;
/// the rest is not the chassis'), with any value that is not finite taken as 0.
pub fn planar(twist: &Twist) -> Twist2 {
    let finite = |v: f64| if v.is_finite() { v as f32 } else { 0.0 };
    Twist2 {
        vx: finite(twist.linear.x),
        vy: finite(twist.linear.y),
        wz: finite(twist.angular.z),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCALE: ImuScale = ImuScale {
        accel_per_g: 16_384.0,
        gyro_per_rad_s: 1000.0,
        accel_variance: 0.04,
        gyro_variance: 0.0004,
        orientation_variance: 0.001,
    };

    #[test]
    fn imu_counts_become_si_units() {
        let m = imu(
            Header::default(),
            [0, -8_192, 16_384],
            [0, 500, -1000],
            None,
            &SCALE,
        );
        assert_eq!(m.linear_acceleration.z, STANDARD_GRAVITY);
        assert_eq!(m.linear_acceleration.y, -STANDARD_GRAVITY / 2.0);
        assert_eq!(m.angular_velocity.y, 0.5);
        assert_eq!(m.angular_velocity.z, -1.0);
        assert_eq!(m.orientation_covariance[0], -1.0);
        assert_eq!(m.angular_velocity_covariance[4], 0.0004);
        assert_eq!(m.linear_acceleration_covariance[8], 0.04);
        let q = [0.0, 0.0, 0.6, 0.8];
        let m = imu(Header::default(), [0; 3], [0; 3], Some(q), &SCALE);
        assert_eq!(
            m.orientation,
            Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.6,
                w: 0.8
            }
        );
        assert_eq!(m.orientation_covariance[0], 0.001);
    }

    #[test]
    fn a_cmd_vel_keeps_the_plane_and_drops_what_is_not_finite() {
        let mut t = Twist::default();
        t.linear.x = 0.5;
        t.linear.y = f64::NAN;
        t.linear.z = 3.0;
        t.angular.z = -1.25;
        t.angular.x = 2.0;
        assert_eq!(
            planar(&t),
            Twist2 {
                vx: 0.5,
                vy: 0.0,
                wz: -1.25
            }
        );
        t.angular.z = f64::INFINITY;
        assert_eq!(planar(&t).wz, 0.0);
    }

    #[test]
    fn odometry_and_transform_carry_the_same_pose() {
        let frames = Frames {
            odom: "odom".into(),
            base: "base_link".into(),
        };
        let pose = Pose2 {
            x: 1.5,
            y: -0.5,
            yaw: core::f32::consts::FRAC_PI_2,
        };
        let twist = Twist2 {
            vx: 0.25,
            vy: 0.0,
            wz: 0.5,
        };
        let o = odometry(Time::default(), &frames, pose, twist, [0.0; 36], [1.0; 36]);
        let tf = transform(Time::default(), &frames, pose);
        assert_eq!(o.header.frame_id, "odom");
        assert_eq!(o.child_frame_id, "base_link");
        assert_eq!(o.pose.pose.position.x, 1.5);
        assert_eq!(o.twist.twist.angular.z, 0.5);
        assert_eq!(o.twist.covariance[35], 1.0);
        let t = &tf.transforms[0];
        assert_eq!(t.transform.translation.y, -0.5);
        assert_eq!(t.transform.rotation, o.pose.pose.orientation);
        // 90° about z: (0, 0, sin 45°, cos 45°).
        assert!((t.transform.rotation.z - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-7);
        assert_eq!(t.child_frame_id, "base_link");
    }

    #[test]
    fn battery_without_a_charge_is_nan() {
        let b = battery(Header::default(), 11.8, None);
        assert_eq!(b.voltage, 11.8);
        assert!(b.percentage.is_nan() && b.current.is_nan());
        assert_eq!(
            battery(Header::default(), 12.0, Some(0.87)).percentage,
            0.87
        );
        assert!(b.present);
    }
}
