//! The parameters: a ROS 2 parameters file, `-p` flags on top, and every mistake a clear
//! error that names what is wrong.

use chassis_ros2::params::{DriveKind, EncoderCounts, Params, parse};

/// The parameters file of `docs/ros2.md`, every key given.
const FULL: &str = "\
chassis:
  ros__parameters:
    odom_frame: odom2
    base_frame: base_footprint
    imu_frame: imu
    publish_tf: false
    cmd_vel_timeout: 0.25
    drive: differential      # mecanum | omni | differential
    half_wheelbase: 0.15
    half_track: 0.2
    ticks_per_meter: 2048.0
    encoder_counts: per_frame
    speed_scale: 1200.0
    turn_scale: 264.0
";

fn overrides(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

#[test]
fn every_key_of_the_file_is_read() {
    let p = parse(Some((FULL, "full.yaml")), "chassis", &[]).unwrap();
    assert_eq!(p.odom_frame, "odom2");
    assert_eq!(p.base_frame, "base_footprint");
    assert_eq!(p.imu_frame, "imu");
    assert!(!p.publish_tf);
    assert_eq!(p.cmd_vel_timeout, 0.25);
    assert_eq!(p.drive, DriveKind::Differential);
    assert_eq!(p.half_wheelbase, 0.15);
    assert_eq!(p.half_track, 0.2);
    assert_eq!(p.ticks_per_meter, 2048.0);
    assert_eq!(p.encoder_counts, EncoderCounts::PerFrame);
    assert_eq!(p.speed_scale, Some(1200.0));
    assert_eq!(p.turn_scale, Some(264.0));
}

#[test]
fn nothing_given_is_the_documented_defaults() {
    let p = parse(None, "chassis", &[]).unwrap();
    assert_eq!(p, Params::default());
    assert_eq!(
        (
            p.odom_frame.as_str(),
            p.base_frame.as_str(),
            p.imu_frame.as_str()
        ),
        ("odom", "base_link", "imu_link")
    );
    assert!(p.publish_tf);
    assert_eq!(p.cmd_vel_timeout, 0.5);
    assert_eq!(p.drive, DriveKind::Mecanum);
    assert_eq!((p.half_wheelbase, p.half_track), (0.10, 0.12));
    assert_eq!(p.ticks_per_meter, 1000.0);
    assert_eq!(p.speed_scale, None);
    assert_eq!(p.turn_scale, None);
}

#[test]
fn flags_go_over_the_file() {
    let p = parse(
        Some((FULL, "full.yaml")),
        "chassis",
        &overrides(&[
            ("drive", "omni"),
            ("cmd_vel_timeout", "1"),
            ("publish_tf", "true"),
        ]),
    )
    .unwrap();
    assert_eq!(p.drive, DriveKind::Omni);
    assert_eq!(p.cmd_vel_timeout, 1.0);
    assert!(p.publish_tf);
    assert_eq!(p.odom_frame, "odom2");
}

#[test]
fn the_wildcard_section_and_a_slash_name_are_the_nodes_and_others_are_not() {
    let yaml = "\
/**:
  ros__parameters:
    odom_frame: from_wildcard
    base_frame: from_wildcard
/robot:
  ros__parameters:
    base_frame: own
other_node:
  ros__parameters:
    anything: 1
";
    let p = parse(Some((yaml, "f.yaml")), "robot", &[]).unwrap();
    assert_eq!(p.odom_frame, "from_wildcard");
    assert_eq!(p.base_frame, "own");
}

#[test]
fn bad_yaml_is_a_clear_error() {
    let e = parse(Some(("chassis: [unclosed", "bad.yaml")), "chassis", &[]).unwrap_err();
    assert!(e.starts_with("bad.yaml: not a YAML parameters file"), "{e}");
    let e = parse(Some(("- a\n- b\n", "list.yaml")), "chassis", &[]).unwrap_err();
    assert!(e.contains("a map of node names"), "{e}");
}

#[test]
fn an_unknown_key_is_an_error_naming_it() {
    let yaml = "chassis:\n  ros__parameters:\n    speed_scal: 1000.0\n";
    let e = parse(Some((yaml, "typo.yaml")), "chassis", &[]).unwrap_err();
    assert!(e.contains("unknown parameter `speed_scal`"), "{e}");
    assert!(e.contains("speed_scale"), "the known ones are listed: {e}");
    let e = parse(None, "chassis", &overrides(&[("wheel", "1")])).unwrap_err();
    assert!(e.contains("unknown parameter `wheel`"), "{e}");
}

#[test]
fn no_section_for_the_node_names_the_ones_there() {
    let e = parse(Some((FULL, "full.yaml")), "robot", &[]).unwrap_err();
    assert!(e.contains("no section for the node `robot`"), "{e}");
    assert!(e.contains("`chassis`"), "{e}");
    let yaml = "chassis:\n  params:\n    drive: omni\n";
    let e = parse(Some((yaml, "f.yaml")), "chassis", &[]).unwrap_err();
    assert!(e.contains("no `ros__parameters:`"), "{e}");
}

#[test]
fn values_of_the_wrong_kind_or_range_are_refused_by_name() {
    for (key, value, words) in [
        ("drive", "tank", "drive"),
        ("cmd_vel_timeout", "-1", "cmd_vel_timeout"),
        ("cmd_vel_timeout", "0", "cmd_vel_timeout"),
        ("cmd_vel_timeout", ".nan", "cmd_vel_timeout"),
        ("half_track", "0", "half_track"),
        ("speed_scale", "0", "speed_scale"),
        ("odom_rate", "-5", "odom_rate"),
        ("publish_tf", "maybe", "publish_tf"),
        ("odom_frame", "''", "odom_frame"),
        ("noise_pose_xy", "-1e-3", "noise_pose_xy"),
        ("encoder_counts", "total", "encoder_counts"),
    ] {
        let e = parse(None, "chassis", &overrides(&[(key, value)])).unwrap_err();
        assert!(e.contains(words), "{key}={value}: {e}");
    }
    // A negative scale flips an axis: allowed.
    let p = parse(None, "chassis", &overrides(&[("turn_scale", "-220")])).unwrap();
    assert_eq!(p.turn_scale, Some(-220.0));
}
