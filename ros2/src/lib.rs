//! `chassis-ros2`: a ROS 2 node for the chassis motor-controller board, on ros2-client (a
//! native Rust DDS): no ROS install is needed on the robot's computer, and it talks to a
//! Humble or Jazzy graph on the same `ROS_DOMAIN_ID`.
//!
//! - subscribes `/cmd_vel` (`geometry_msgs/Twist`, or `TwistStamped` with `--stamped`) and
//!   drives the board with it, re-sent every 50 ms, stopped when it goes quiet (0.5 s) or on
//!   SIGINT, SIGTERM and SIGHUP;
//! - publishes `/odom`, the `odom` → `base_link` transform on `/tf`, `/imu/data_raw`,
//!   `/battery_state` and `/diagnostics`.
//!
//! The port, the firmware's detection and the stop are the `chassis` tool's
//! ([`chassis_cli`]); the odometry is `chassis-odometry`'s. `docs/ros2.md` is the user's page.
//!
//! The messages ([`msg`]) are plain serde structs in ROS field order, their CDR bytes tested
//! against bytes worked out by hand:
//!
//! ```
//! use chassis_ros2::msg::{Message, Twist};
//! let mut twist = Twist::default();
//! twist.linear.x = 0.3;
//! assert_eq!((Twist::PACKAGE, Twist::NAME), ("geometry_msgs", "Twist"));
//! ```

#[macro_use]
extern crate chassis_cli;

pub mod app;
pub mod board;
pub mod convert;
pub mod diagnostics;
pub mod msg;
pub mod node;
pub mod odom;
pub mod params;
pub mod ros;
pub mod stats;
pub mod watchdog;
