//! Kinematics and odometry for the chassis motor-controller board: `no_std`, no allocation,
//! `f32` throughout.
//!
//! * [`Geometry`]: a chassis (mecanum, omni or differential) and its sizes; the wheel speeds of
//!   a body twist ([`Geometry::wheel_speeds`]) and the body twist of wheel speeds
//!   ([`Geometry::body_twist`], least squares over the four wheels).
//! * [`Odometry`]: the pose, integrated along the exact arc, from the 2020 board's encoder
//!   frames ([`Odometry::encoders`]) or from the v1.0.0 board's measured body velocity and
//!   quaternion ([`Odometry::body`]); the twist; the covariances `nav_msgs/Odometry` carries.
//! * [`RawScale`]: the 2020 board's raw velocity frame values for a body twist, and back (the
//!   board states no unit, decision A8).
//!
//! Conventions are ROS's REP-103 and REP-105: x forward, y left, yaw counter-clockwise seen from
//! above, in m, m/s, rad and rad/s; the pose is in the odometry frame, which starts where the
//! odometry started (its first frame, or the last [`Odometry::reset`]), heading along x. The
//! board's motors are in its order: MOTO1 left front, MOTO2 right front, MOTO3 right rear,
//! MOTO4 left rear. The 2020 board's axes (X to the right, Y forward, Z counter-clockwise) are
//! decision A14 of `docs/protocol-2020.md`; the design, the covariance model and how to measure
//! a board's raw scale are in `docs/odometry.md`.
//!
//! Every computation is in `f32`: a Cortex-M4F does it in hardware; a Cortex-M0+ has no FPU
//! and does it in software (slower, nothing measured here).
//!
//! ```
//! use chassis_odometry::{Counts, Drive, Geometry, Noise, Odometry, Twist2};
//!
//! let geometry = Geometry {
//!     drive: Drive::Mecanum,
//!     half_wheelbase_m: 0.10,
//!     half_track_m: 0.12,
//!     ticks_per_m: 1_000.0,
//! };
//! // 1 m/s forward: every wheel's rim at 1 m/s.
//! let forward = Twist2 { vx: 1.0, vy: 0.0, wz: 0.0 };
//! assert_eq!(geometry.wheel_speeds(forward), [1.0; 4]);
//!
//! // Encoder frames 40 ms apart (25 Hz), running totals: the first only sets the reference.
//! let mut odometry = Odometry::new(geometry, Counts::RunningTotal, Noise::DEFAULT);
//! assert_eq!(odometry.encoders([0; 4], 0), None);
//! let twist = odometry.encoders([40; 4], 40).expect("a twist over 40 ms");
//! assert!((twist.vx - 1.0).abs() < 1e-6); // 40 ticks, 4 cm, in 40 ms
//! assert!((odometry.pose().x - 0.04).abs() < 1e-6);
//! ```

#![no_std]
#![forbid(unsafe_code)]
#![cfg_attr(docsrs, feature(doc_cfg))]

mod arc;
mod covariance;
mod kinematics;
mod odometry;
mod raw;
mod v1;

pub use arc::{Pose2, Twist2};
pub use covariance::Noise;
pub use kinematics::{Drive, Geometry, GeometryError};
pub use odometry::{Counts, DEFAULT_MAX_GAP_MS, Odometry};
pub use raw::RawScale;
pub use v1::{v1_twist, v1_yaw};
