//! `/odom` and `/tf` from each simulated board's telemetry, against where the board truly
//! went (its own pose, integrated apart from the odometry crate), through the node's loop.

mod common;

use chassis_protocol::driver::{DriverCore, v1};
use chassis_ros2::board::Generation;
use chassis_ros2::msg::{Odometry, TfMessage};
use chassis_ros2::node::{self, Out};
use chassis_ros2::params::Params;
use chassis_ros2::stats::Latency;
use common::{Script, Sim, settings, steady, twist};

/// The last `/odom` and `/tf` published.
fn last(script: &Script) -> (Odometry, TfMessage) {
    let odom = script.published.iter().rev().find_map(|(_, o)| match o {
        Out::Odom(m) => Some((**m).clone()),
        _ => None,
    });
    let tf = script.published.iter().rev().find_map(|(_, o)| match o {
        Out::Tf(m) => Some(m.clone()),
        _ => None,
    });
    (odom.expect("/odom published"), tf.expect("/tf published"))
}

/// The yaw of a quaternion about z.
fn yaw(q: &chassis_ros2::msg::Quaternion) -> f64 {
    (2.0 * (q.w * q.z + q.x * q.y)).atan2(1.0 - 2.0 * (q.y * q.y + q.z * q.z))
}

/// Checks the published pose against the board's true pose (2 cm, 0.05 rad: the odometry
/// stops at the board's last frame, and the loop publishes every 20 ms).
fn agrees(script: &Script, truth: (f64, f64, f64)) {
    let (odom, tf) = last(script);
    let p = &odom.pose.pose.position;
    let (x, y, z) = truth;
    assert!(
        (p.x - x).abs() < 0.02 && (p.y - y).abs() < 0.02,
        "odom ({:.3}, {:.3}) against the board's ({x:.3}, {y:.3})",
        p.x,
        p.y
    );
    assert!((yaw(&odom.pose.pose.orientation) - z).abs() < 0.05);
    let t = &tf.transforms[0];
    assert_eq!(t.transform.translation.x, p.x);
    assert_eq!(t.transform.rotation, odom.pose.pose.orientation);
    assert_eq!(
        (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
        ("odom", "base_link")
    );
    assert_eq!(odom.header.stamp, t.header.stamp);
}

#[test]
fn the_2020_odometry_follows_the_board() {
    let sim = Sim::v2020();
    // 0.2 m/s forward turning 0.5 rad/s for 1.5 s, then stopped by the watchdog.
    let mut script = Script::new(steady(twist(0.2, 0.0, 0.5), 0, 1_500, 100), 2_400);
    let driver = DriverCore::open(&sim.path).expect("the pty opens");
    let params = Params {
        speed_scale: Some(1000.0),
        turn_scale: Some(220.0),
        ..Params::default()
    };
    node::run(
        driver,
        &settings(&sim.path, params),
        &mut script,
        &mut Latency::default(),
    );
    let truth = sim.true_pose();
    assert!(truth.0 > 0.2 && truth.2 > 0.5, "the board moved: {truth:?}");
    agrees(&script, truth);
    let (odom, _) = last(&script);
    // Standing still at the end, with a pose covariance grown by the travel.
    assert!(odom.twist.twist.linear.x.abs() < 1e-3);
    assert!(odom.pose.covariance[0] > 0.0 && odom.pose.covariance[35] > 0.0);
}

#[test]
fn the_v1_odometry_follows_the_board() {
    let sim = Sim::v1();
    let mut script = Script::new(steady(twist(0.3, -0.1, 0.0), 0, 1_000, 100), 1_800);
    let driver = v1::DriverCore::open(&sim.path).expect("the pty opens");
    let mut settings = settings(&sim.path, Params::default());
    // The node's v1.0.0 assumption: 1000 counts per g (milli-g).
    settings.imu = chassis_ros2::app::imu_scale(&settings.params, v1::DriverCore::NAME).0;
    node::run(driver, &settings, &mut script, &mut Latency::default());
    let truth = sim.true_pose();
    assert!(
        truth.0 > 0.25 && truth.1 < -0.08,
        "the board moved: {truth:?}"
    );
    agrees(&script, truth);
    let imu = script.published.iter().find_map(|(_, o)| match o {
        Out::Imu(m) => Some(m.clone()),
        _ => None,
    });
    let imu = imu.expect("/imu/data_raw published");
    // The simulated v1.0.0 board's accelerometer reads 1000 at rest on z: 1 g.
    assert!((imu.linear_acceleration.z - 9.806_65).abs() < 1e-9);
    assert!(
        imu.orientation_covariance[0] >= 0.0,
        "v1.0.0 gives an orientation"
    );
}

#[test]
fn no_transform_when_publish_tf_is_false_and_the_frames_are_the_parameters() {
    let sim = Sim::v2020();
    // Long enough for the 2020 board's battery frame (1 Hz).
    let mut script = Script::new(steady(twist(0.1, 0.0, 0.0), 0, 200, 100), 1_200);
    let params = Params {
        publish_tf: false,
        odom_frame: "odom_a".into(),
        base_frame: "base_footprint".into(),
        imu_frame: "imu_a".into(),
        ..Params::default()
    };
    let driver = DriverCore::open(&sim.path).expect("the pty opens");
    node::run(
        driver,
        &settings(&sim.path, params),
        &mut script,
        &mut Latency::default(),
    );
    let mut kinds = std::collections::BTreeSet::new();
    for (_, out) in &script.published {
        match out {
            Out::Odom(m) => {
                assert_eq!(m.header.frame_id, "odom_a");
                assert_eq!(m.child_frame_id, "base_footprint");
                kinds.insert("odom");
            }
            Out::Tf(_) => panic!("a transform published with publish_tf false"),
            Out::Imu(m) => {
                assert_eq!(m.header.frame_id, "imu_a");
                kinds.insert("imu");
            }
            Out::Battery(_) => {
                kinds.insert("battery");
            }
            Out::Diagnostics(_) => {
                kinds.insert("diagnostics");
            }
        }
    }
    assert_eq!(
        kinds.into_iter().collect::<Vec<_>>(),
        ["battery", "diagnostics", "imu", "odom"]
    );
}
